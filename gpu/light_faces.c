/*
 * light_faces.c - the views from which each light renders its reflective
 * shadow map (and its shadow map for direct light):
 *   directional: one orthographic view covering the scene's bounding sphere;
 *   spot (half angle <= LPV_SPOT_MAX_SINGLE_FACE): one perspective view with
 *     fov = 2 x outer cone;
 *   point, and wider spots: six 90-degree cube faces (+x -x +y -y +z -z), the
 *     octree thesis' omnidirectional injection.
 * Lights past LPV_MAX_LIGHTS or LPV_MAX_FACES are left out (reported in the
 * stats as the light count used).
 *
 * The shadow maps of direct light (docs/shadows.md) have their own faces at
 * shadow_size: the same perspective and cube faces, widened by
 * LPV_SHADOW_BORDER_TEXELS so the filter near a cube edge reads inside the
 * face, and for a directional light LPV_SHADOW_CASCADES orthographic
 * cascades fitted to the camera's view (core/shadow_cascades.c). Spots
 * wider than LPV_SHADOW_SPOT_MAX_SINGLE_FACE (45 degrees, not the RSM's 80)
 * get cube faces: one face that wide would have coarser texels.
 */
#include <math.h>
#include <string.h>

#include <cglm/cglm.h>

#include "engine_internal.h"
#include "shadow_cascades.h"

static void any_up(const vec3 dir, vec3 up)
{
    if (fabsf(dir[1]) > 0.99f)
        glm_vec3_copy((vec3){0.0f, 0.0f, 1.0f}, up);
    else
        glm_vec3_copy((vec3){0.0f, 1.0f, 0.0f}, up);
}

static void scene_sphere(const lpv_engine *e, vec3 centre, float *radius)
{
    vec3 ext;
    for (int i = 0; i < 3; ++i) {
        centre[i] = 0.5f * (e->scene_min[i] + e->scene_max[i]);
        ext[i] = e->scene_max[i] - e->scene_min[i];
    }
    *radius = 0.5f * glm_vec3_norm(ext);
    if (!(*radius > 1e-6f) || !isfinite(*radius))
        *radius = 1.0f;
}

/* Far plane for a perspective view from p: past the farthest bounds corner. */
static float far_from(const lpv_engine *e, const vec3 p)
{
    float far2 = 0.0f;
    for (int k = 0; k < 8; ++k) {
        vec3 c = {(k & 1) ? e->scene_max[0] : e->scene_min[0], (k & 2) ? e->scene_max[1] : e->scene_min[1],
                  (k & 4) ? e->scene_max[2] : e->scene_min[2]};
        float d2 = glm_vec3_distance2((float *)p, c);
        if (d2 > far2)
            far2 = d2;
    }
    return sqrtf(far2) * 1.01f + 1e-3f;
}

/* Point lights and spots wider than one face get six cube faces. */
static int light_is_wide(const lpv_light *src)
{
    return src->type == LPV_LIGHT_POINT || (src->type == LPV_LIGHT_SPOT && src->outer_cone > LPV_SPOT_MAX_SINGLE_FACE);
}

static void perspective_face(struct LpvFaceGpu *f, const vec3 eye, const vec3 dir, float half_fov, float near_z,
                             float far_z, int light, int size)
{
    mat4 view, proj;
    vec3 centre, up;
    glm_vec3_add((float *)eye, (float *)dir, centre);
    any_up(dir, up);
    glm_lookat((float *)eye, centre, up, view);
    glm_perspective(2.0f * half_fov, 1.0f, near_z, far_z, proj);
    glm_mat4_mul(proj, view, f->view_proj);
    f->info[0] = (float)light;
    f->info[1] = 1.0f;
    f->info[2] = tanf(half_fov);
    f->info[3] = (float)size;
    glm_vec3_copy((float *)dir, f->axis);
    f->axis[3] = 0.0f;
}

void lpv_light_faces_build(lpv_engine *e)
{
    struct LpvLightBlock *b = &e->light_block;
    memset(b, 0, sizeof *b);
    vec3 centre;
    float radius;
    scene_sphere(e, centre, &radius);
    float near_z = 1e-3f * radius;
    const int n = e->settings.rsm_size;
    int faces = 0, lights = 0;

    for (uint32_t l = 0; l < e->light_count && lights < LPV_MAX_LIGHTS; ++l) {
        const lpv_light *src = &e->lights[l];
        int wide = light_is_wide(src);
        int need = wide ? 6 : 1;
        if (faces + need > LPV_MAX_FACES)
            break;
        struct LpvLightGpu *g = &b->lights[lights];
        vec3 dir = {src->direction[0], src->direction[1], src->direction[2]};
        if (!(glm_vec3_norm(dir) > 1e-8f))
            glm_vec3_copy((vec3){0.0f, -1.0f, 0.0f}, dir);
        glm_vec3_normalize(dir);
        vec3 pos = {src->position[0], src->position[1], src->position[2]};
        glm_vec3_copy(pos, g->position_type);
        g->position_type[3] = (float)src->type;
        glm_vec3_copy(dir, g->direction_range);
        g->direction_range[3] = src->range > 0.0f ? src->range : 0.0f;
        for (int c = 0; c < 3; ++c)
            g->intensity[c] = src->color[c] * src->intensity;
        g->cone_faces[0] = cosf(src->inner_cone);
        g->cone_faces[1] = cosf(src->outer_cone);
        if (src->type != LPV_LIGHT_SPOT) {
            g->cone_faces[0] = -1.0f;
            g->cone_faces[1] = -2.0f;
        }
        g->cone_faces[2] = (float)faces;
        g->cone_faces[3] = (float)need;

        if (src->type == LPV_LIGHT_DIRECTIONAL) {
            struct LpvFaceGpu *f = &b->faces[faces];
            mat4 view, proj;
            vec3 eye, up;
            glm_vec3_scale(dir, -2.0f * radius, eye);
            glm_vec3_add(eye, centre, eye);
            any_up(dir, up);
            glm_lookat(eye, centre, up, view);
            glm_ortho(-radius, radius, -radius, radius, radius * 0.5f, radius * 3.5f, proj);
            glm_mat4_mul(proj, view, f->view_proj);
            f->info[0] = (float)lights;
            f->info[1] = 0.0f;
            float texel = 2.0f * radius / (float)n;
            f->info[2] = texel * texel;
            f->info[3] = (float)n;
            glm_vec3_copy(dir, f->axis);
        } else if (!wide) {
            float half = src->outer_cone > 1e-3f ? src->outer_cone : 1e-3f;
            perspective_face(&b->faces[faces], pos, dir, half, near_z, far_from(e, pos), lights, n);
        } else {
            static const float axes[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
            for (int k = 0; k < 6; ++k)
                perspective_face(&b->faces[faces + k], pos, axes[k], (float)(M_PI / 4.0), near_z, far_from(e, pos),
                                 lights, n);
        }
        faces += need;
        ++lights;
    }
    b->counts[0] = (float)lights;
    b->counts[1] = (float)faces;
    e->face_count = faces;
}

void lpv_light_face_counts(const lpv_engine *e, int *rsm_faces, int *shadow_faces)
{
    int faces = 0, shadows = 0;
    for (uint32_t l = 0; l < e->light_count && l < LPV_MAX_LIGHTS; ++l) {
        const lpv_light *src = &e->lights[l];
        int need = light_is_wide(src) ? 6 : 1;
        if (faces + need > LPV_MAX_FACES)
            break;
        faces += need;
        shadows += src->type == LPV_LIGHT_DIRECTIONAL ? LPV_SHADOW_CASCADES
                   : (src->type == LPV_LIGHT_SPOT && src->outer_cone <= LPV_SHADOW_SPOT_MAX_SINGLE_FACE) ? 1
                                                                                                          : 6;
    }
    *rsm_faces = faces;
    *shadow_faces = shadows;
}

static void shadow_perspective_face(struct LpvShadowFaceGpu *f, const vec3 eye, const vec3 dir, float tan_half,
                                    float near_z, float far_z, int light, int size)
{
    /* Widen the face so the central 2 tan_half of it keeps
     * LPV_SHADOW_BORDER_TEXELS free on each side. */
    float t = tan_half * (float)size / ((float)size - 2.0f * LPV_SHADOW_BORDER_TEXELS);
    mat4 view, proj;
    vec3 centre, up;
    glm_vec3_add((float *)eye, (float *)dir, centre);
    any_up(dir, up);
    glm_lookat((float *)eye, centre, up, view);
    glm_perspective(2.0f * atanf(t), 1.0f, near_z, far_z, proj);
    glm_mat4_mul(proj, view, f->view_proj);
    f->info[0] = 2.0f * t / (float)size; /* m per texel per m of depth */
    f->info[1] = 1.0f;
    f->info[2] = (float)light;
    f->info[3] = 0.0f;
    glm_vec3_copy((float *)dir, f->axis);
    f->axis[3] = 0.0f;
}

int lpv_shadow_faces_build(const lpv_engine *e, struct LpvShadowBlock *b, char *err, size_t err_size)
{
    memset(b, 0, sizeof *b);
    const struct LpvLightBlock *lb = &e->light_block;
    const int size = e->settings.shadow_size;
    vec3 centre;
    float radius;
    scene_sphere(e, centre, &radius);
    const float near_z = 1e-3f * radius;
    int faces = 0;
    for (int l = 0; l < (int)lb->counts[0]; ++l) {
        const struct LpvLightGpu *g = &lb->lights[l];
        const int type = (int)g->position_type[3];
        vec3 pos = {g->position_type[0], g->position_type[1], g->position_type[2]};
        vec3 dir = {g->direction_range[0], g->direction_range[1], g->direction_range[2]};
        const int first = faces;
        if (type == LPV_LIGHT_TYPE_DIRECTIONAL) {
            lpv_shadow_cascade c[LPV_SHADOW_CASCADES];
            if (faces + LPV_SHADOW_CASCADES > LPV_MAX_SHADOW_FACES)
                return lpv_error(err, err_size, "too many shadow-map faces");
            if (lpv_shadow_cascades_fit(&e->view, dir, e->scene_min, e->scene_max, size, LPV_SHADOW_BORDER_TEXELS,
                                        LPV_SHADOW_CASCADES, c) != 0)
                return lpv_error(err, err_size, "light %d: shadow cascades cannot be fitted to this view", l);
            for (int k = 0; k < LPV_SHADOW_CASCADES; ++k) {
                struct LpvShadowFaceGpu *f = &b->faces[faces++];
                glm_mat4_copy(c[k].view_proj, f->view_proj);
                f->info[0] = c[k].texel;
                f->info[1] = 0.0f;
                f->info[2] = (float)l;
                f->info[3] = (float)k;
                glm_vec3_copy(dir, f->axis);
            }
        } else if (type == LPV_LIGHT_TYPE_SPOT &&
                   acosf(fminf(fmaxf(g->cone_faces[1], -1.0f), 1.0f)) <= LPV_SHADOW_SPOT_MAX_SINGLE_FACE) {
            if (faces + 1 > LPV_MAX_SHADOW_FACES)
                return lpv_error(err, err_size, "too many shadow-map faces");
            float outer = acosf(fminf(fmaxf(g->cone_faces[1], -1.0f), 1.0f));
            float half = outer > 1e-3f ? outer : 1e-3f;
            shadow_perspective_face(&b->faces[faces++], pos, dir, tanf(half), near_z, far_from(e, pos), l, size);
        } else {
            if (faces + 6 > LPV_MAX_SHADOW_FACES)
                return lpv_error(err, err_size, "too many shadow-map faces");
            static const float axes[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
            for (int k = 0; k < 6; ++k)
                shadow_perspective_face(&b->faces[faces++], pos, axes[k], 1.0f, near_z, far_from(e, pos), l, size);
        }
        b->lights[l][0] = (float)first;
        b->lights[l][1] = (float)(faces - first);
        b->lights[l][2] = type == LPV_LIGHT_TYPE_DIRECTIONAL ? 1.0f : 0.0f;
    }
    b->counts[0] = (float)faces;
    b->counts[1] = (float)size;
    b->counts[2] = 1.0f / (float)size;
    return 0;
}
