/* view_choice.c - see view_choice.h. */
#include "view_choice.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const lpv_flag FLAGS[] = {
    {"camera", 0, "N|NAME", "a camera of the glTF file, by index or name (default: the file's first)"},
    {"eye", 0, "X,Y,Z", "an explicit camera at X,Y,Z looking at --target (default: where the\n"
                        "view that frames the scene's bounds stands)"},
    {"target", 0, "X,Y,Z", "where an explicit camera looks (default: the scene bounds' centre)"},
    {"fov", 0, "DEG", "vertical field of view (default: the camera's, else 45)"},
    {"size", 0, "WxH", "image size (default 512 wide, height from the camera's aspect)"},
};
#define N_FLAGS (sizeof FLAGS / sizeof FLAGS[0])

const lpv_flag *lpv_view_flags(size_t *count)
{
    if (count)
        *count = N_FLAGS;
    return FLAGS;
}

static int bad(char *err, size_t n, const char *name, const char *value, const char *want)
{
    snprintf(err, n, "--%s %s: expected %s", name, value, want);
    return -1;
}

int lpv_view_flag_parse(lpv_view_choice *c, const char *name, const char *v, char *err, size_t n)
{
    if (!v)
        v = "";
    if (strcmp(name, "camera") == 0) {
        c->camera = v;
    } else if (strcmp(name, "eye") == 0) {
        if (lpv_flag_parse_floats(v, c->eye, 3) != 0)
            return bad(err, n, name, v, "X,Y,Z");
        c->has_eye = 1;
    } else if (strcmp(name, "target") == 0) {
        if (lpv_flag_parse_floats(v, c->target, 3) != 0)
            return bad(err, n, name, v, "X,Y,Z");
        c->has_target = 1;
    } else if (strcmp(name, "fov") == 0) {
        if (lpv_flag_parse_floats(v, &c->fov_deg, 1) != 0 || !(c->fov_deg > 0.0f && c->fov_deg < 179.0f))
            return bad(err, n, name, v, "degrees in (0, 179)");
        c->has_fov = 1;
    } else if (strcmp(name, "size") == 0) {
        if (sscanf(v, "%dx%d", &c->width, &c->height) != 2 || c->width < 1 || c->height < 1 || c->width > 16384 ||
            c->height > 16384)
            return bad(err, n, name, v, "WxH, 1..16384 each");
    } else {
        return 0;
    }
    return 1;
}

static int parse_flag(void *target, const lpv_flag *f, const char *value, char *err, size_t n)
{
    return lpv_view_flag_parse(target, f->name, value, err, n) == 1 ? 0 : -1;
}

lpv_flag_group lpv_view_flag_group(lpv_view_choice *c)
{
    return (lpv_flag_group){FLAGS, N_FLAGS, parse_flag, c};
}

const char *lpv_view_flags_help(void)
{
    static char help[2048];
    return lpv_flags_section_help(help, sizeof help, "Camera", FLAGS, N_FLAGS);
}

int lpv_view_resolve(const lpv_view_choice *c, const lpv_scene *scene, lpv_view *view, char *err, size_t n)
{
    int w = c->width ? c->width : 512;
    int h = c->height;
    const lpv_camera *cam = NULL;
    if (c->camera) {
        int i = lpv_view_find_camera(scene, c->camera);
        if (i < 0) {
            snprintf(err, n, "--camera %s: %s has %u camera(s) and none with that index or name", c->camera,
                     scene->source, scene->camera_count);
            return -1;
        }
        cam = &scene->cameras[i];
    } else if (scene->camera_count && !c->has_eye) {
        cam = &scene->cameras[0];
    }
    if (!h) {
        float aspect = (cam && cam->aspect > 0.0f) ? cam->aspect : 1.0f;
        h = (int)lroundf((float)w / aspect);
        if (h < 1)
            h = 1;
    }
    if (c->has_eye || c->has_target) {
        float target[3] = {0.5f * (scene->bounds_min[0] + scene->bounds_max[0]),
                           0.5f * (scene->bounds_min[1] + scene->bounds_max[1]),
                           0.5f * (scene->bounds_min[2] + scene->bounds_max[2])};
        lpv_view framed;
        lpv_view_frame_bounds(scene, w, h, &framed);
        const float *eye = c->has_eye ? c->eye : framed.eye;
        if (c->has_target)
            memcpy(target, c->target, sizeof target);
        float fov = c->has_fov ? c->fov_deg * 0.01745329252f : (cam ? cam->yfov : framed.yfov);
        if (lpv_view_look_at(eye, target, fov, w, h, view) != 0) {
            snprintf(err, n, "--eye/--target: eye and target must differ");
            return -1;
        }
        return 0;
    }
    if (cam) {
        lpv_view_from_camera(cam, w, h, view);
        if (c->has_fov)
            view->yfov = c->fov_deg * 0.01745329252f;
    } else {
        lpv_view_frame_bounds(scene, w, h, view);
        if (c->has_fov)
            view->yfov = c->fov_deg * 0.01745329252f;
    }
    return 0;
}
