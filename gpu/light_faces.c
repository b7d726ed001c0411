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
 */
#include <math.h>
#include <string.h>

#include <cglm/cglm.h>

#include "engine_internal.h"

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
        int wide = src->type == LPV_LIGHT_POINT ||
                   (src->type == LPV_LIGHT_SPOT && src->outer_cone > LPV_SPOT_MAX_SINGLE_FACE);
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
