/* view.c - see view.h. */
#include "view.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static void normalize3(float v[3])
{
    float l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0.0f && isfinite(l))
        for (int i = 0; i < 3; ++i)
            v[i] /= l;
}

void lpv_view_from_camera(const lpv_camera *cam, int width, int height, lpv_view *out)
{
    memset(out, 0, sizeof *out);
    memcpy(out->eye, cam->eye, sizeof out->eye);
    memcpy(out->forward, cam->forward, sizeof out->forward);
    memcpy(out->up, cam->up, sizeof out->up);
    normalize3(out->forward);
    normalize3(out->up);
    out->orthographic = cam->orthographic;
    out->yfov = cam->yfov > 0.0f ? cam->yfov : 0.8f;
    out->ymag = cam->ymag > 0.0f ? cam->ymag : 1.0f;
    out->znear = cam->znear;
    out->zfar = cam->zfar;
    out->width = width;
    out->height = height;
}

int lpv_view_look_at(const float eye[3], const float target[3], float yfov, int width, int height, lpv_view *out)
{
    memset(out, 0, sizeof *out);
    if (!(yfov > 0.0f && yfov < (float)M_PI))
        return LPV_VIEW_BAD_FOV;
    /* in double: eye and target 2e19 m apart squared overflow float */
    double f[3], len = 0.0;
    for (int i = 0; i < 3; ++i) {
        if (!isfinite(eye[i]) || !isfinite(target[i]))
            return LPV_VIEW_NOT_FINITE;
        f[i] = (double)target[i] - (double)eye[i];
        len += f[i] * f[i];
    }
    len = sqrt(len);
    if (!(len > 1e-9))
        return LPV_VIEW_EYE_IS_TARGET;
    for (int i = 0; i < 3; ++i) {
        out->eye[i] = eye[i];
        out->forward[i] = (float)(f[i] / len);
    }
    if (fabsf(out->forward[1]) > 0.999f) {
        out->up[2] = -1.0f;
    } else {
        out->up[1] = 1.0f;
    }
    out->yfov = yfov;
    out->width = width;
    out->height = height;
    return 0;
}

void lpv_view_frame_bounds(const lpv_scene *scene, int width, int height, lpv_view *out)
{
    float c[3], r = 0.0f;
    for (int i = 0; i < 3; ++i) {
        c[i] = 0.5f * (scene->bounds_min[i] + scene->bounds_max[i]);
        float h = 0.5f * (scene->bounds_max[i] - scene->bounds_min[i]);
        r += h * h;
    }
    r = sqrtf(r);
    if (!(r > 1e-6f) || !isfinite(r))
        r = 1.0f;
    const float yfov = 0.785398f; /* 45 degrees */
    float dist = r / sinf(0.5f * yfov);
    float eye[3] = {c[0], c[1], c[2] + dist};
    lpv_view_look_at(eye, c, yfov, width, height, out);
}

int lpv_view_find_camera(const lpv_scene *scene, const char *s)
{
    char *end = NULL;
    long idx = strtol(s, &end, 10);
    if (end != s && *end == '\0')
        return (idx >= 0 && (unsigned long)idx < scene->camera_count) ? (int)idx : -1;
    for (uint32_t i = 0; i < scene->camera_count; ++i)
        if (strcmp(scene->cameras[i].name, s) == 0)
            return (int)i;
    return -1;
}

int lpv_view_project(const lpv_view *v, const float p[3], float *px, float *py)
{
    /* Camera basis: right = forward x up, true up = right x forward. */
    const float *f = v->forward;
    float r[3] = {f[1] * v->up[2] - f[2] * v->up[1], f[2] * v->up[0] - f[0] * v->up[2],
                  f[0] * v->up[1] - f[1] * v->up[0]};
    normalize3(r);
    float u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
    float d[3] = {p[0] - v->eye[0], p[1] - v->eye[1], p[2] - v->eye[2]};
    float z = d[0] * f[0] + d[1] * f[1] + d[2] * f[2];
    float x = d[0] * r[0] + d[1] * r[1] + d[2] * r[2];
    float y = d[0] * u[0] + d[1] * u[1] + d[2] * u[2];
    float aspect = (float)v->width / (float)v->height;
    float half_h;
    if (v->orthographic) {
        half_h = v->ymag;
    } else {
        if (!(z > 0.0f))
            return -1;
        half_h = z * tanf(0.5f * v->yfov);
    }
    float ndc_x = x / (half_h * aspect), ndc_y = y / half_h;
    *px = (ndc_x * 0.5f + 0.5f) * (float)v->width;
    *py = (0.5f - ndc_y * 0.5f) * (float)v->height;
    return 0;
}
