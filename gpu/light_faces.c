/*
 * light_faces.c - the views from which each light renders its reflective
 * shadow map (and its shadow map for direct light):
 *   directional: one orthographic view covering the scene's bounding sphere;
 *   spot (half angle <= LPV_SPOT_MAX_SINGLE_FACE): one perspective view with
 *     fov = 2 x outer cone;
 *   point, and wider spots: six 90-degree cube faces (+x -x +y -y +z -z), the
 *     octree thesis' omnidirectional injection;
 *   area light samples (emissive surfaces, docs/area-lights.md): five
 *     90-degree faces around the emitter's normal n (n, then +-t, +-b), each
 *     a square tile of side max(min(N, 32), N/2) texels in layers after the
 *     punctual lights' (N = rsm_size), so K samples cost about 5K/4 layers
 *     instead of 5K (docs/area-lights.md: at the default N = 128, 64^2 faces
 *     gave half the direct-light error of 32^2 ones for less time than
 *     doubling the samples).
 * Every punctual face fills its own layer. Lights past LPV_MAX_LIGHTS or
 * LPV_MAX_FACES are left out (reported in the stats as the light count used).
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

/* The side of an area light face (texels) for RSM side n, and how many fit
 * along a layer's side. */
static int area_face_side(int n)
{
    int side = n / 2;
    int floor_side = n < 32 ? n : 32;
    return side > floor_side ? side : floor_side;
}

/* The area light samples after the punctual lights: lights [lights, ...),
 * faces [faces, ...), layers from `layer` on. Returns the samples added. */
static int add_area_lights(lpv_engine *e, int lights, int faces, int layer, float near_z)
{
    struct LpvLightBlock *b = &e->light_block;
    const int n = e->settings.rsm_size, side = area_face_side(n), per_row = n / side;
    const int per_layer = per_row * per_row;
    int added = 0;
    for (size_t k = 0; k < e->area_sample_count; ++k) {
        if (lights + added >= LPV_MAX_LIGHTS + LPV_MAX_AREA_LIGHTS || faces + LPV_AREA_FACES > LPV_MAX_FACES)
            break;
        const lpv_area_sample *a = &e->area_samples[k];
        const int l = lights + added;
        struct LpvLightGpu *g = &b->lights[l];
        vec3 nrm = {a->normal[0], a->normal[1], a->normal[2]}, pos, t, bt, up;
        glm_vec3_normalize(nrm);
        /* The light and its maps' eye sit on the emitter: its own surface
         * (and anything flush with it) is edge-on to the side faces and
         * behind the front face's near plane, so it stays out of the maps. */
        glm_vec3_copy((float *)a->position, pos);
        glm_vec3_copy(pos, g->position_type);
        g->position_type[3] = (float)LPV_LIGHT_TYPE_AREA;
        glm_vec3_copy(nrm, g->direction_range);
        g->direction_range[3] = 0.0f;
        for (int c = 0; c < 3; ++c)
            g->intensity[c] = a->intensity[c];
        g->intensity[3] = (float)(a->area / M_PI);
        g->cone_faces[0] = -1.0f;
        g->cone_faces[1] = -2.0f;
        g->cone_faces[2] = (float)faces;
        g->cone_faces[3] = (float)LPV_AREA_FACES;
        any_up(nrm, up);
        glm_vec3_cross(up, nrm, t);
        glm_vec3_normalize(t);
        glm_vec3_cross(nrm, t, bt);
        vec3 axes[LPV_AREA_FACES];
        glm_vec3_copy(nrm, axes[0]);
        glm_vec3_copy(t, axes[1]);
        glm_vec3_negate_to(t, axes[2]);
        glm_vec3_copy(bt, axes[3]);
        glm_vec3_negate_to(bt, axes[4]);
        for (int i = 0; i < LPV_AREA_FACES; ++i) {
            struct LpvFaceGpu *f = &b->faces[faces];
            perspective_face(f, pos, axes[i], (float)(M_PI / 4.0), near_z, far_from(e, pos), l, side);
            /* Every sample sees the same surfaces: only the first one's feed the GV. */
            f->axis[3] = k == 0 ? 0.0f : 1.0f;
            const int j = (int)k * LPV_AREA_FACES + i, in_layer = j % per_layer;
            f->tile[0] = (float)((in_layer % per_row) * side) / (float)n;
            f->tile[1] = (float)((in_layer / per_row) * side) / (float)n;
            f->tile[2] = (float)side / (float)n;
            f->tile[3] = (float)(layer + j / per_layer);
            ++faces;
        }
        ++added;
    }
    e->area_face_side = side;
    e->rsm_layers = layer + (added * LPV_AREA_FACES + per_layer - 1) / per_layer;
    return added;
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
        for (int k = 0; k < need; ++k) { /* a punctual face fills its own layer */
            b->faces[faces + k].tile[2] = 1.0f;
            b->faces[faces + k].tile[3] = (float)(faces + k);
        }
        faces += need;
        ++lights;
    }
    b->counts[2] = (float)lights;
    e->punctual_faces = faces;
    const int area = add_area_lights(e, lights, faces, faces, near_z);
    lights += area;
    faces += area * LPV_AREA_FACES;
    b->counts[0] = (float)lights;
    b->counts[1] = (float)faces;
    e->face_count = faces;
}
