/*
 * light_faces.c - the views from which each light renders its reflective
 * shadow map (and its shadow map for direct light):
 *   directional: one orthographic view covering the scene's bounding sphere;
 *   spot (half angle <= LPV_SPOT_MAX_SINGLE_FACE): one perspective view with
 *     fov = 2 x outer cone;
 *   point, and wider spots: six 90-degree cube faces (+x -x +y -y +z -z), the
 *     octree thesis' omnidirectional injection;
 *   area light samples (emissive surfaces, docs/area-lights.md): five
 *     90-degree faces around the normal n of the emitting side (n, then
 *     +-t, +-b; a double-sided emitter's back is samples of its own), each
 *     a square tile of side max(min(N, 32), N/2) texels in layers after the
 *     punctual lights' (N = rsm_size), so K samples cost about 5K/4 layers
 *     instead of 5K (docs/area-lights.md: at the default N = 128, 64^2 faces
 *     gave half the direct-light error of 32^2 ones for less time than
 *     doubling the samples).
 * Every punctual face fills its own layer. Lights past LPV_MAX_LIGHTS or
 * LPV_MAX_FACES are left out (reported in the stats as the light count used).
 *
 * The shadow maps of direct light (docs/shadows.md) have their own faces at
 * shadow_size: the same perspective and cube faces, widened by
 * LPV_SHADOW_BORDER_TEXELS so the filter near a cube edge reads inside the
 * face, and for a directional light LPV_SHADOW_CASCADES orthographic
 * cascades fitted to the camera's view (core/shadow_cascades.c). Spots
 * wider than LPV_SHADOW_SPOT_MAX_SINGLE_FACE (45 degrees, not the RSM's 80)
 * get cube faces: one face that wide would have coarser texels. An area
 * light sample's five faces get shadow-map faces too, tiled by the same rule
 * at N = shadow_size (four to a layer), widened like the cube faces.
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

/* Near planes (issue 30, docs/shadows.md "Near planes"). A light's
 * perspective faces clip what lies closer to the eye than their near plane,
 * so the near plane must stay inside the air around the light: a lamp in a
 * 20 cm closed fixture in a 480 m scene otherwise lit the whole scene
 * through the fixture's walls with the old near = 1e-3 x the scene's radius
 * (0.24 m). The rule, for every perspective face of the RSMs and the shadow
 * maps:
 *   near = min(1e-3 x radius, max(precision floor, 0.5 x d)),
 * d the distance from the eye to the nearest surface that can shadow what
 * the light lights (light_clearance and scan_triangles: the scene's
 * triangles, unless the reach voxels, core/reach.h, show clear air that far;
 * kept per light). A point at
 * distance d can lie at depth d / sqrt(3) along a 90-degree face's axis (the
 * face's corner), so 0.5 d keeps everything at distance >= d in front of the
 * near plane. The floor keeps the depth precision. The shadow maps hold
 * reversed depth (shadow_maps.c: near / depth, float precision relative at
 * every depth), so theirs is only NEAR_REVERSED_FLOOR x the radius. The
 * RSMs keep the standard projection: a depth stored as
 * GL_DEPTH_COMPONENT32F (pass_rsm.c) near 1 has a step of 2^-24, so a
 * receiver at depth z (m) along the face's axis is known to eps z^2 / near
 * (eps = 2^-23 with the projection's arithmetic); that must stay under
 * NEAR_PRECISION_TEXELS of the texel there, 2 tan(half fov) z / size, for
 * the farthest z the face sees (the farthest corner of the scene's bounds
 * along its axis): near >= eps z_max size / (2 tan(half) x 0.25), a quarter
 * of the smallest depth bias (0.5 texel, shadow.glsl). Where the floor
 * passes the old value, the old value stays (its precision was enough
 * before). */
#define NEAR_FRACTION 0.5f
#define NEAR_OLD_FRACTION 1e-3f      /* x the scene's bounding radius: the cap */
#define NEAR_DEPTH_EPS 1.1920929e-7f /* 2^-23 */
#define NEAR_PRECISION_TEXELS 0.25f
#define NEAR_REVERSED_FLOOR 1e-6f /* x the radius: a reversed-depth face's floor (size 0) */

/* The squared distance from p to triangle abc (Ericson, Real-Time Collision
 * Detection 5.1.5: the closest point by the Voronoi regions). */
static float triangle_distance2(const vec3 p, const vec3 a, const vec3 b, const vec3 c)
{
    vec3 ab, ac, ap, q;
    glm_vec3_sub((float *)b, (float *)a, ab);
    glm_vec3_sub((float *)c, (float *)a, ac);
    glm_vec3_sub((float *)p, (float *)a, ap);
    const float d1 = glm_vec3_dot(ab, ap), d2 = glm_vec3_dot(ac, ap);
    if (d1 <= 0.0f && d2 <= 0.0f)
        return glm_vec3_distance2((float *)p, (float *)a);
    vec3 bp;
    glm_vec3_sub((float *)p, (float *)b, bp);
    const float d3 = glm_vec3_dot(ab, bp), d4 = glm_vec3_dot(ac, bp);
    if (d3 >= 0.0f && d4 <= d3)
        return glm_vec3_distance2((float *)p, (float *)b);
    const float vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) {
        glm_vec3_scale(ab, d1 / (d1 - d3), q);
        glm_vec3_add((float *)a, q, q);
        return glm_vec3_distance2((float *)p, q);
    }
    vec3 cp;
    glm_vec3_sub((float *)p, (float *)c, cp);
    const float d5 = glm_vec3_dot(ab, cp), d6 = glm_vec3_dot(ac, cp);
    if (d6 >= 0.0f && d5 <= d6)
        return glm_vec3_distance2((float *)p, (float *)c);
    const float vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) {
        glm_vec3_scale(ac, d2 / (d2 - d6), q);
        glm_vec3_add((float *)a, q, q);
        return glm_vec3_distance2((float *)p, q);
    }
    const float va = d3 * d6 - d5 * d4;
    if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f) {
        vec3 bc;
        glm_vec3_sub((float *)c, (float *)b, bc);
        glm_vec3_scale(bc, (d4 - d3) / ((d4 - d3) + (d5 - d6)), q);
        glm_vec3_add((float *)b, q, q);
        return glm_vec3_distance2((float *)p, q);
    }
    const float den = 1.0f / (va + vb + vc);
    vec3 u, w;
    glm_vec3_scale(ab, vb * den, u);
    glm_vec3_scale(ac, vc * den, w);
    glm_vec3_add((float *)a, u, q);
    glm_vec3_add(q, w, q);
    return glm_vec3_distance2((float *)p, q);
}

/* The near plane of a perspective face of `size` texels from eye along the
 * unit axis, half field of view atan(tan_half), d from nearest_surface: the
 * rule above; size 0: a face of reversed depth (a shadow map), whose floor
 * is NEAR_REVERSED_FLOOR x the radius. */
static float face_near(const lpv_engine *e, const vec3 eye, const vec3 axis, float tan_half, int size, float d,
                       float radius)
{
    float zmax = 0.0f;
    for (int k = 0; k < 8; ++k) {
        vec3 c = {(k & 1) ? e->scene_max[0] : e->scene_min[0], (k & 2) ? e->scene_max[1] : e->scene_min[1],
                  (k & 4) ? e->scene_max[2] : e->scene_min[2]};
        const float z = (c[0] - eye[0]) * axis[0] + (c[1] - eye[1]) * axis[1] + (c[2] - eye[2]) * axis[2];
        if (z > zmax)
            zmax = z;
    }
    const float cap = NEAR_OLD_FRACTION * radius;
    const float floor_z = size > 0 ? NEAR_DEPTH_EPS * zmax * (float)size / (2.0f * NEAR_PRECISION_TEXELS * tan_half)
                                   : NEAR_REVERSED_FLOOR * radius;
    const float near_z = fmaxf(floor_z, NEAR_FRACTION * d);
    return near_z < cap ? near_z : cap;
}

/* The distances (m) from the lights pending in e->clearance.pending
 * (their position, normal and search radius in clearance.key) to the
 * nearest of the scene's triangles, up to the search radius (the answer
 * when nothing is closer), into e->clearance.distance: one pass over the
 * triangles for all of them (a triangle's vertices are read once). For an
 * area light sample (a non-zero normal n: its emitting side) only what lies
 * in front of its plane can shadow a receiver it lights, and its own
 * emitter lies in the plane: triangles with no vertex in front of the plane
 * do not count (a triangle that crosses it counts whole). */
static void scan_triangles(lpv_engine *e)
{
    const lpv_scene *g = &e->geometry;
    const int count = e->clearance.pending_count;
    float best2[LPV_MAX_LIGHTS + LPV_MAX_AREA_LIGHTS], eps[LPV_MAX_LIGHTS + LPV_MAX_AREA_LIGHTS];
    int has_n[LPV_MAX_LIGHTS + LPV_MAX_AREA_LIGHTS];
    for (int j = 0; j < count; ++j) {
        const float *k = e->clearance.key[e->clearance.pending[j]];
        best2[j] = k[6] * k[6];
        has_n[j] = k[3] != 0.0f || k[4] != 0.0f || k[5] != 0.0f;
        /* off the plane: past the float error of the sample's position */
        eps[j] = 1e-5f * (1.0f + fmaxf(fabsf(k[0]), fmaxf(fabsf(k[1]), fabsf(k[2]))));
    }
    if (!g->vertices || !g->indices)
        for (int j = 0; j < count; ++j)
            best2[j] = 0.0f; /* no geometry to tell: the floor of the rule */
    for (uint32_t t = 0; g->vertices && g->indices && t + 2 < g->index_count; t += 3) {
        if (g->indices[t] >= g->vertex_count || g->indices[t + 1] >= g->vertex_count ||
            g->indices[t + 2] >= g->vertex_count)
            continue;
        const float *v[3];
        float lo[3], hi[3];
        for (int k = 0; k < 3; ++k)
            v[k] = g->vertices[g->indices[t + (uint32_t)k]].position;
        for (int i = 0; i < 3; ++i) {
            lo[i] = fminf(v[0][i], fminf(v[1][i], v[2][i]));
            hi[i] = fmaxf(v[0][i], fmaxf(v[1][i], v[2][i]));
        }
        for (int j = 0; j < count; ++j) {
            const float *k = e->clearance.key[e->clearance.pending[j]];
            float box2 = 0.0f; /* the triangle's box farther than the best: skip */
            for (int i = 0; i < 3; ++i) {
                const float out = k[i] < lo[i] ? lo[i] - k[i] : (k[i] > hi[i] ? k[i] - hi[i] : 0.0f);
                box2 += out * out;
            }
            if (box2 > best2[j])
                continue;
            if (has_n[j]) {
                int ahead = 0;
                for (int m = 0; m < 3; ++m)
                    ahead |= (v[m][0] - k[0]) * k[3] + (v[m][1] - k[1]) * k[4] + (v[m][2] - k[2]) * k[5] > eps[j];
                if (!ahead)
                    continue; /* in the emitter's plane or behind it */
            }
            const float d2 = triangle_distance2(k, v[0], v[1], v[2]);
            if (d2 < best2[j])
                best2[j] = d2;
        }
    }
    for (int j = 0; j < count; ++j)
        e->clearance.distance[e->clearance.pending[j]] = sqrtf(best2[j]);
    e->clearance.pending_count = 0;
}

/* The d of face_near for light l of the light block at p (n: an area light
 * sample's emitting side, else NULL), kept per light and found again only
 * when the light, the scene's size or its geometry changed. The reach
 * voxels answer when the air around p is clear out to the search radius
 * (and every material is opaque: the voxels hold only the opaque surfaces;
 * cut-out and blended ones cast shadows too); otherwise the light waits for
 * scan_triangles (lpv_light_faces_build builds the faces again after it)
 * and 0 stands in meanwhile. */
static float light_clearance(lpv_engine *e, int l, const vec3 p, const float *n, float radius)
{
    const float within = NEAR_OLD_FRACTION * radius / NEAR_FRACTION;
    float key[8] = {p[0], p[1], p[2], n ? n[0] : 0.0f, n ? n[1] : 0.0f, n ? n[2] : 0.0f, within, 0.0f};
    memcpy(&key[7], &e->geometry_sig, sizeof key[7]); /* the low half of the signature */
    if (memcmp(key, e->clearance.key[l], sizeof key) != 0) {
        memcpy(e->clearance.key[l], key, sizeof key);
        if (e->reach.all_opaque && !lpv_reach_solid_within(&e->reach, p, within))
            e->clearance.distance[l] = within;
        else {
            e->clearance.distance[l] = 0.0f;
            e->clearance.pending[e->clearance.pending_count++] = l;
        }
    }
    return e->clearance.distance[l];
}

/* The first LPV_MAX_LIGHTS of the scene's punctual lights in the light
 * block's order: the directional ones first (as many as counts[3] says),
 * then the others, each kind in scene order, so that the shading loops over
 * each kind apart (shading.glsl: llvmpipe runs a loop's code for every kind
 * of light otherwise). Returns how many. */
static int punctual_in_order(const lpv_engine *e, const lpv_light *out[LPV_MAX_LIGHTS])
{
    int n = 0;
    for (int pass = 0; pass < 2; ++pass)
        for (uint32_t l = 0; l < e->light_count && n < LPV_MAX_LIGHTS; ++l)
            if ((e->lights[l].type == LPV_LIGHT_DIRECTIONAL) == (pass == 0))
                out[n++] = &e->lights[l];
    return n;
}

/* Point lights and spots wider than one face get six cube faces. */
static int light_is_wide(const lpv_light *src)
{
    return src->type == LPV_LIGHT_POINT || (src->type == LPV_LIGHT_SPOT && src->outer_cone > LPV_SPOT_MAX_SINGLE_FACE);
}

/* d: the light's clearance (light_clearance), for the near plane. */
static void perspective_face(const lpv_engine *e, struct LpvFaceGpu *f, const vec3 eye, const vec3 dir,
                             float half_fov, float d, float radius, int light, int size)
{
    const float near_z = face_near(e, eye, dir, tanf(half_fov), size, d, radius), far_z = far_from(e, eye);
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

/* The side of an area light face (texels) in layers of side n (rsm_size for
 * the RSMs, shadow_size for the shadow maps). */
static int area_face_side(int n)
{
    int side = n / 2;
    int floor_side = n < 32 ? n : 32;
    return side > floor_side ? side : floor_side;
}

/* Area light faces one layer of side n holds. */
static int area_faces_per_layer(int n)
{
    const int per_row = n / area_face_side(n);
    return per_row * per_row;
}

/* Layers that `faces` area light faces fill in layers of side n. */
static int area_layers(int n, int faces)
{
    const int per_layer = area_faces_per_layer(n);
    return (faces + per_layer - 1) / per_layer;
}

/* Tile of area light face j (counted over all samples) in layers of side n
 * from `layer` on: xy lower-left corner (uv), z side (uv), w layer. */
static void area_tile(int n, int j, int layer, float tile[4])
{
    const int side = area_face_side(n), per_row = n / side, per_layer = per_row * per_row;
    const int in_layer = j % per_layer;
    tile[0] = (float)((in_layer % per_row) * side) / (float)n;
    tile[1] = (float)((in_layer / per_row) * side) / (float)n;
    tile[2] = (float)side / (float)n;
    tile[3] = (float)(layer + j / per_layer);
}

/* Area light samples lpv_light_faces_build will add after `lights` punctual
 * lights holding `faces` faces. */
static int area_samples_fitting(const lpv_engine *e, int lights, int faces)
{
    int n = 0;
    for (size_t k = 0; k < e->area_sample_count; ++k) {
        if (lights + n >= LPV_MAX_LIGHTS + LPV_MAX_AREA_LIGHTS || faces + LPV_AREA_FACES > LPV_MAX_FACES)
            break;
        faces += LPV_AREA_FACES;
        ++n;
    }
    return n;
}

/* The area light samples after the punctual lights: lights [lights, ...),
 * faces [faces, ...), layers from `layer` on. Returns the samples added. */
static int add_area_lights(lpv_engine *e, int lights, int faces, int layer, float radius)
{
    struct LpvLightBlock *b = &e->light_block;
    const int n = e->settings.rsm_size, side = area_face_side(n);
    int added = 0, back_fed = 0;
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
        const float d = light_clearance(e, l, pos, nrm, radius);
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
        /* Every sample sees the same surfaces: only the first one's feed the
         * GV, and the first facing against it (the back of a double-sided
         * emitter, docs/area-lights.md), which sees the other half of them. */
        int feeds = k == 0;
        if (k > 0 && !back_fed && glm_vec3_dot(nrm, b->lights[lights].direction_range) < -0.99f)
            feeds = back_fed = 1;
        for (int i = 0; i < LPV_AREA_FACES; ++i) {
            struct LpvFaceGpu *f = &b->faces[faces];
            perspective_face(e, f, pos, axes[i], (float)(M_PI / 4.0), d, radius, l, side);
            f->axis[3] = feeds ? 0.0f : 1.0f;
            area_tile(n, (int)k * LPV_AREA_FACES + i, layer, f->tile);
            ++faces;
        }
        ++added;
    }
    e->rsm.area_face_side = side;
    e->rsm.layers = layer + area_layers(n, added * LPV_AREA_FACES);
    return added;
}

static void build_faces(lpv_engine *e);

void lpv_light_faces_build(lpv_engine *e)
{
    e->clearance.pending_count = 0;
    build_faces(e);
    if (e->clearance.pending_count > 0) { /* lights near surfaces: their distances, then their faces */
        scan_triangles(e);
        build_faces(e);
    }
}

static void build_faces(lpv_engine *e)
{
    struct LpvLightBlock *b = &e->light_block;
    memset(b, 0, sizeof *b);
    vec3 centre;
    float radius;
    scene_sphere(e, centre, &radius);
    const int n = e->settings.rsm_size;
    int faces = 0, lights = 0;

    const lpv_light *order[LPV_MAX_LIGHTS];
    const int ordered = punctual_in_order(e, order);
    int directional = 0;
    for (int i = 0; i < ordered; ++i) {
        const lpv_light *src = order[i];
        int wide = light_is_wide(src);
        int need = wide ? 6 : 1;
        if (faces + need > LPV_MAX_FACES)
            break;
        directional += src->type == LPV_LIGHT_DIRECTIONAL;
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
            perspective_face(e, &b->faces[faces], pos, dir, half, light_clearance(e, lights, pos, NULL, radius), radius,
                             lights, n);
        } else {
            static const float axes[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
            const float d = light_clearance(e, lights, pos, NULL, radius);
            for (int k = 0; k < 6; ++k)
                perspective_face(e, &b->faces[faces + k], pos, axes[k], (float)(M_PI / 4.0), d, radius, lights, n);
        }
        for (int k = 0; k < need; ++k) { /* a punctual face fills its own layer */
            b->faces[faces + k].tile[2] = 1.0f;
            b->faces[faces + k].tile[3] = (float)(faces + k);
        }
        faces += need;
        ++lights;
    }
    b->counts[2] = (float)lights;
    b->counts[3] = (float)directional;
    e->rsm.punctual_faces = faces;
    const int area = add_area_lights(e, lights, faces, faces, radius);
    lights += area;
    faces += area * LPV_AREA_FACES;
    b->counts[0] = (float)lights;
    b->counts[1] = (float)faces;
    e->rsm.face_count = faces;
}

void lpv_light_face_counts(const lpv_engine *e, int *rsm_layers, int *shadow_layers)
{
    int faces = 0, shadows = 0, lights = 0;
    const lpv_light *order[LPV_MAX_LIGHTS];
    const int ordered = punctual_in_order(e, order);
    for (int i = 0; i < ordered; ++i) {
        const lpv_light *src = order[i];
        int need = light_is_wide(src) ? 6 : 1;
        if (faces + need > LPV_MAX_FACES)
            break;
        faces += need;
        ++lights;
        shadows += src->type == LPV_LIGHT_DIRECTIONAL ? LPV_SHADOW_CASCADES
                   : (src->type == LPV_LIGHT_SPOT && src->outer_cone <= LPV_SHADOW_SPOT_MAX_SINGLE_FACE) ? 1
                                                                                                          : 6;
    }
    /* Area light samples: their faces' tiles, four to a layer, in both. */
    const int area_faces = area_samples_fitting(e, lights, faces) * LPV_AREA_FACES;
    *rsm_layers = faces + area_layers(e->settings.rsm_size, area_faces);
    *shadow_layers = shadows + area_layers(e->settings.shadow_size, area_faces);
}

/* d: the light's clearance (light_clearance), for the near plane. */
static void shadow_perspective_face(const lpv_engine *e, struct LpvShadowFaceGpu *f, const vec3 eye, const vec3 dir,
                                    float tan_half, float d, float radius, int light, int size)
{
    /* Widen the face so the central 2 tan_half of it keeps
     * LPV_SHADOW_BORDER_TEXELS free on each side. */
    float t = tan_half * (float)size / ((float)size - 2.0f * LPV_SHADOW_BORDER_TEXELS);
    const float near_z = face_near(e, eye, dir, t, 0, d, radius);
    mat4 view, proj;
    vec3 centre, up;
    glm_vec3_add((float *)eye, (float *)dir, centre);
    any_up(dir, up);
    glm_lookat((float *)eye, centre, up, view);
    /* Reversed depth with no far plane (shadow_maps.c draws with clip z in
     * [0, w]): clip z = near, w = depth, so the map holds near / depth. */
    glm_mat4_zero(proj);
    proj[0][0] = proj[1][1] = 1.0f / t;
    proj[2][3] = -1.0f;
    proj[3][2] = near_z;
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
    int faces = 0, area_faces = 0;
    const int punctual = (int)lb->counts[2];
    for (int l = 0; l < (int)lb->counts[0]; ++l) {
        const struct LpvLightGpu *g = &lb->lights[l];
        const int type = (int)g->position_type[3];
        vec3 pos = {g->position_type[0], g->position_type[1], g->position_type[2]};
        vec3 dir = {g->direction_range[0], g->direction_range[1], g->direction_range[2]};
        const int first = faces;
        /* an area light sample's clearance is in front of its emitter */
        const float d = e->clearance.distance[l]; /* found by lpv_light_faces_build */
        if (type == LPV_LIGHT_TYPE_AREA) {
            /* The RSM's five faces (front, four sides), each a tile in the
             * layers after the punctual lights' (whose count is known once
             * they are all placed: the layer index is rebased below). */
            if (faces + LPV_AREA_FACES > LPV_MAX_SHADOW_FACES)
                return lpv_error(err, err_size, "too many shadow-map faces");
            const int side = area_face_side(size);
            for (int k = 0; k < LPV_AREA_FACES; ++k) {
                const float *axis = lb->faces[(int)g->cone_faces[2] + k].axis;
                vec3 ax = {axis[0], axis[1], axis[2]};
                struct LpvShadowFaceGpu *f = &b->faces[faces++];
                shadow_perspective_face(e, f, pos, ax, 1.0f, d, radius, l, side);
                area_tile(size, area_faces++, 0, f->tile);
            }
        } else if (type == LPV_LIGHT_TYPE_DIRECTIONAL) {
            lpv_shadow_cascade c[LPV_SHADOW_CASCADES];
            if (faces + LPV_SHADOW_CASCADES > LPV_MAX_SHADOW_FACES)
                return lpv_error(err, err_size, "too many shadow-map faces");
            if (lpv_shadow_cascades_fit(&e->view, dir, e->scene_min, e->scene_max, size, LPV_SHADOW_BORDER_TEXELS,
                                        LPV_SHADOW_CASCADES, c) != 0)
                return lpv_error(err, err_size, "light %d: shadow cascades cannot be fitted to this view", l);
            for (int k = 0; k < LPV_SHADOW_CASCADES; ++k) {
                struct LpvShadowFaceGpu *f = &b->faces[faces++];
                /* reversed depth in [0, 1] as the perspective faces' (the
                 * cascade's near plane at 1, its far plane at 0) */
                mat4 reverse = GLM_MAT4_IDENTITY_INIT;
                reverse[2][2] = -0.5f;
                reverse[3][2] = 0.5f;
                glm_mat4_mul(reverse, c[k].view_proj, f->view_proj);
                f->info[0] = c[k].texel;
                f->info[1] = 0.0f;
                f->info[2] = (float)l;
                f->info[3] = (float)k;
                glm_vec3_copy(dir, f->axis);
            }
        } else if (type == LPV_LIGHT_TYPE_SPOT && lpv_spot_outer_angle(g) <= LPV_SHADOW_SPOT_MAX_SINGLE_FACE) {
            if (faces + 1 > LPV_MAX_SHADOW_FACES)
                return lpv_error(err, err_size, "too many shadow-map faces");
            float outer = lpv_spot_outer_angle(g);
            float half = outer > 1e-3f ? outer : 1e-3f;
            shadow_perspective_face(e, &b->faces[faces++], pos, dir, tanf(half), d, radius, l, size);
        } else {
            if (faces + 6 > LPV_MAX_SHADOW_FACES)
                return lpv_error(err, err_size, "too many shadow-map faces");
            static const float axes[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
            for (int k = 0; k < 6; ++k)
                shadow_perspective_face(e, &b->faces[faces++], pos, axes[k], 1.0f, d, radius, l, size);
        }
        b->lights[l][0] = (float)first;
        b->lights[l][1] = (float)(faces - first);
        b->lights[l][2] = type == LPV_LIGHT_TYPE_DIRECTIONAL ? 1.0f : type == LPV_LIGHT_TYPE_AREA ? 2.0f : 0.0f;
    }
    /* Punctual faces fill one layer each, in order; area tiles follow. */
    int punctual_faces = 0;
    for (int l = 0; l < punctual && l < (int)lb->counts[0]; ++l)
        punctual_faces += (int)b->lights[l][1];
    for (int f = 0; f < faces; ++f) {
        if (f < punctual_faces) {
            b->faces[f].tile[0] = b->faces[f].tile[1] = 0.0f;
            b->faces[f].tile[2] = 1.0f;
            b->faces[f].tile[3] = (float)f;
        } else
            b->faces[f].tile[3] += (float)punctual_faces;
    }
    b->counts[3] = (float)(punctual_faces + area_layers(size, area_faces));
    b->counts[0] = (float)faces;
    b->counts[1] = (float)size;
    b->counts[2] = 1.0f / (float)size;
    return 0;
}
