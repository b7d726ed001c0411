/*
 * shadow_cascades.c - cascaded shadow maps fitted to the camera's view (see
 * shadow_cascades.h and docs/shadows.md).
 */
#include "shadow_cascades.h"

#include <math.h>
#include <string.h>

#include <cglm/cglm.h>

#include "lpv_shared.h"

static int finite3(const float v[3])
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

/* A radius rounded up to 1/64 of its power of two: the same slice shape gives
 * the same radius whatever float noise its corners carry, so the texel size
 * stays fixed while the camera turns. */
static float stable_radius(float r)
{
    float step = exp2f(floorf(log2f(r)) - 6.0f);
    return ceilf(r / step) * step;
}

int lpv_shadow_cascades_fit(const lpv_view *view, const float light_dir[3], const float scene_min[3],
                            const float scene_max[3], int size, float border_texels, int count,
                            lpv_shadow_cascade *out)
{
    vec3 d = {light_dir[0], light_dir[1], light_dir[2]};
    if (!finite3(d) || !(glm_vec3_norm(d) > 1e-8f) || !finite3(view->eye) || !finite3(view->forward) ||
        !finite3(scene_min) || !finite3(scene_max) || size < 1 || count < 1 || count > LPV_SHADOW_CASCADES ||
        !(2.0f * border_texels < (float)size))
        return -1;
    glm_vec3_normalize(d);
    vec3 eye = {view->eye[0], view->eye[1], view->eye[2]};
    vec3 fwd = {view->forward[0], view->forward[1], view->forward[2]};
    vec3 up = {view->up[0], view->up[1], view->up[2]};
    if (!(glm_vec3_norm(fwd) > 1e-8f))
        return -1;
    glm_vec3_normalize(fwd);
    vec3 right;
    glm_vec3_cross(fwd, up, right);
    if (!(glm_vec3_norm(right) > 1e-8f))
        glm_vec3_cross(fwd, (vec3){0.0f, 0.0f, 1.0f}, right);
    if (!(glm_vec3_norm(right) > 1e-8f))
        glm_vec3_cross(fwd, (vec3){1.0f, 0.0f, 0.0f}, right);
    glm_vec3_normalize(right);
    glm_vec3_cross(right, fwd, up);

    /* The view depth range the scene occupies: its bounds' corners along the
     * view direction, from the camera's near plane on. */
    vec3 ext;
    glm_vec3_sub((float *)scene_max, (float *)scene_min, ext);
    float scene_radius = 0.5f * glm_vec3_norm(ext);
    if (!(scene_radius > 1e-6f))
        scene_radius = 1.0f;
    float near_z = view->znear > 0.0f ? view->znear : 1e-3f * scene_radius;
    float d_lo = INFINITY, d_hi = -INFINITY, t_lo = INFINITY, t_hi = -INFINITY;
    for (int k = 0; k < 8; ++k) {
        vec3 c = {(k & 1) ? scene_max[0] : scene_min[0], (k & 2) ? scene_max[1] : scene_min[1],
                  (k & 4) ? scene_max[2] : scene_min[2]};
        vec3 rel;
        glm_vec3_sub(c, eye, rel);
        float z = glm_vec3_dot(rel, fwd);
        d_lo = fminf(d_lo, z);
        d_hi = fmaxf(d_hi, z);
        float t = glm_vec3_dot(c, d); /* along the light's travel */
        t_lo = fminf(t_lo, t);
        t_hi = fmaxf(t_hi, t);
    }
    if (view->orthographic) {
        d_lo = fmaxf(d_lo, 0.0f);
    } else {
        d_lo = fmaxf(d_lo, near_z);
    }
    if (view->zfar > 0.0f)
        d_hi = fminf(d_hi, view->zfar);
    if (!(d_hi > d_lo)) /* the scene lies behind the camera: cover a sliver in front */
        d_hi = d_lo + scene_radius;
    /* Round the range outwards to quarter octaves, so a camera that moves a
     * little keeps its splits (and texel sizes) instead of changing them
     * every frame. */
    d_hi = exp2f(ceilf(4.0f * log2f(d_hi)) / 4.0f);
    if (d_lo > near_z)
        d_lo = fmaxf(near_z, exp2f(floorf(4.0f * log2f(d_lo)) / 4.0f));
    if (view->zfar > 0.0f && d_hi > view->zfar)
        d_hi = fmaxf(view->zfar, d_lo + 1e-3f);
    const float log_base = fmaxf(d_lo, near_z);

    /* No cascade needs to be larger than the scene's bounding sphere. */
    vec3 scene_centre;
    glm_vec3_center((float *)scene_min, (float *)scene_max, scene_centre);

    /* The light's frame: a rotation that depends only on its direction. */
    vec3 lup = {0.0f, 1.0f, 0.0f};
    if (fabsf(d[1]) > 0.99f)
        glm_vec3_copy((vec3){0.0f, 0.0f, 1.0f}, lup);
    mat4 rot;
    glm_lookat((vec3){0.0f, 0.0f, 0.0f}, d, lup, rot);

    const float aspect = (float)view->width / (float)(view->height > 0 ? view->height : 1);
    const float tan_half = view->orthographic ? 0.0f : tanf(0.5f * view->yfov);
    const float scale = (float)size / ((float)size - 2.0f * border_texels);
    float split = d_lo;
    for (int i = 0; i < count; ++i) {
        float f = (float)(i + 1) / (float)count;
        float far_i = LPV_SHADOW_SPLIT_LAMBDA * log_base * powf(d_hi / log_base, f) +
                      (1.0f - LPV_SHADOW_SPLIT_LAMBDA) * (d_lo + (d_hi - d_lo) * f);
        if (i == count - 1)
            far_i = d_hi;
        float near_i = split;
        split = far_i;

        /* The slice's eight corners and their bounding sphere (centroid). */
        vec3 corners[8], centre = {0.0f, 0.0f, 0.0f};
        for (int k = 0; k < 8; ++k) {
            float z = (k & 4) ? far_i : near_i;
            float h = view->orthographic ? view->ymag : z * tan_half;
            float w = h * aspect;
            for (int a = 0; a < 3; ++a)
                corners[k][a] = eye[a] + fwd[a] * z + right[a] * ((k & 1) ? w : -w) + up[a] * ((k & 2) ? h : -h);
            glm_vec3_add(centre, corners[k], centre);
        }
        glm_vec3_scale(centre, 1.0f / 8.0f, centre);
        float r = 0.0f;
        for (int k = 0; k < 8; ++k)
            r = fmaxf(r, glm_vec3_distance(centre, corners[k]));
        if (r >= scene_radius) {
            glm_vec3_copy(scene_centre, centre);
            r = scene_radius;
        }
        r = stable_radius(fmaxf(r, 1e-4f));
        float half = r * scale;
        float texel = 2.0f * half / (float)size;

        /* Snap the centre to whole texels across the light's rays. */
        vec3 c_ls;
        glm_mat4_mulv3(rot, centre, 1.0f, c_ls);
        c_ls[0] = floorf(c_ls[0] / texel + 0.5f) * texel;
        c_ls[1] = floorf(c_ls[1] / texel + 0.5f) * texel;
        mat4 inv;
        glm_mat4_inv(rot, inv);
        vec3 snapped;
        glm_mat4_mulv3(inv, c_ls, 1.0f, snapped);

        /* Depth: every caster of the scene towards the light, and the sphere. */
        float tc = glm_vec3_dot(snapped, d);
        float lo = fminf(t_lo, tc - r), hi = fmaxf(t_hi, tc + r);
        float pad = 0.01f * (hi - lo) + 1e-3f;
        vec3 leye;
        glm_vec3_scale(d, tc - lo + pad, leye);
        glm_vec3_sub(snapped, leye, leye); /* snapped - d * (tc - lo + pad) */
        vec3 target;
        glm_vec3_add(leye, d, target);
        mat4 lview, proj;
        glm_lookat(leye, target, lup, lview);
        glm_ortho(-half, half, -half, half, 0.5f * pad, hi - lo + 2.0f * pad, proj);
        glm_mat4_mul(proj, lview, out[i].view_proj);
        out[i].texel = texel;
        out[i].split_near = near_i;
        out[i].split_far = far_i;
        glm_vec3_copy(snapped, out[i].centre);
        out[i].radius = half;
    }
    return 0;
}
