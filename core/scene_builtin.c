/*
 * scene_builtin.c - the built-in Cornell box (lpv_scene_builtin_cornell).
 *
 * Geometry and colours are copied from CornellBox-Original-fixed.obj and
 * CornellBox-Original.mtl (Guedis Cardenas and Morgan McGuire, Williams
 * College 2011, public domain; ../shared/scenes/), never read at run time.
 * Y-up metres exactly like the OBJ; ../shared/scenes/cornell-box.glb stores the
 * same box and its node rotation brings it to this frame, and the light, the
 * spot and the camera match that file after lpv_gltf_load_file (checked by
 * tests/test_gltf.c). Units: docs/units.md.
 */
#include "scene.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { FACE_INWARD = 0, FACE_OUTWARD = 1 };

typedef struct cornell_object {
    const char *name;
    float kd[3];
    float emission[3]; /* W/(m^2 sr) */
    int orient;        /* FACE_INWARD: walls face the room; FACE_OUTWARD: blocks */
    int first_quad, quad_count;
} cornell_object;

/* Every quad of the OBJ, in file order, 4 corners each (x, y, z in m). */
static const float cornell_quads[][4][3] = {
    /* floor */
    {{-1.01f, 0.00f, 0.99f}, {1.00f, 0.00f, 0.99f}, {1.00f, 0.00f, -1.04f}, {-0.99f, 0.00f, -1.04f}},
    /* ceiling */
    {{-1.02f, 1.99f, 0.99f}, {-1.02f, 1.99f, -1.04f}, {1.00f, 1.99f, -1.04f}, {1.00f, 1.99f, 0.99f}},
    /* backWall */
    {{-0.99f, 0.00f, -1.04f}, {1.00f, 0.00f, -1.04f}, {1.00f, 1.99f, -1.04f}, {-1.02f, 1.99f, -1.04f}},
    /* rightWall (green) */
    {{1.00f, 0.00f, -1.04f}, {1.00f, 0.00f, 0.99f}, {1.00f, 1.99f, 0.99f}, {1.00f, 1.99f, -1.04f}},
    /* leftWall (red) */
    {{-1.01f, 0.00f, 0.99f}, {-0.99f, 0.00f, -1.04f}, {-1.02f, 1.99f, -1.04f}, {-1.02f, 1.99f, 0.99f}},
    /* shortBox: top, left, front, right, back, bottom */
    {{0.53f, 0.60f, 0.75f}, {0.70f, 0.60f, 0.17f}, {0.13f, 0.60f, 0.00f}, {-0.05f, 0.60f, 0.57f}},
    {{-0.05f, 0.00f, 0.57f}, {-0.05f, 0.60f, 0.57f}, {0.13f, 0.60f, 0.00f}, {0.13f, 0.00f, 0.00f}},
    {{0.53f, 0.00f, 0.75f}, {0.53f, 0.60f, 0.75f}, {-0.05f, 0.60f, 0.57f}, {-0.05f, 0.00f, 0.57f}},
    {{0.70f, 0.00f, 0.17f}, {0.70f, 0.60f, 0.17f}, {0.53f, 0.60f, 0.75f}, {0.53f, 0.00f, 0.75f}},
    {{0.13f, 0.00f, 0.00f}, {0.13f, 0.60f, 0.00f}, {0.70f, 0.60f, 0.17f}, {0.70f, 0.00f, 0.17f}},
    {{0.53f, 0.00f, 0.75f}, {0.70f, 0.00f, 0.17f}, {0.13f, 0.00f, 0.00f}, {-0.05f, 0.00f, 0.57f}},
    /* tallBox: top, left, back, right, front, bottom */
    {{-0.53f, 1.20f, 0.09f}, {0.04f, 1.20f, -0.09f}, {-0.14f, 1.20f, -0.67f}, {-0.71f, 1.20f, -0.49f}},
    {{-0.53f, 0.00f, 0.09f}, {-0.53f, 1.20f, 0.09f}, {-0.71f, 1.20f, -0.49f}, {-0.71f, 0.00f, -0.49f}},
    {{-0.71f, 0.00f, -0.49f}, {-0.71f, 1.20f, -0.49f}, {-0.14f, 1.20f, -0.67f}, {-0.14f, 0.00f, -0.67f}},
    {{-0.14f, 0.00f, -0.67f}, {-0.14f, 1.20f, -0.67f}, {0.04f, 1.20f, -0.09f}, {0.04f, 0.00f, -0.09f}},
    {{0.04f, 0.00f, -0.09f}, {0.04f, 1.20f, -0.09f}, {-0.53f, 1.20f, 0.09f}, {-0.53f, 0.00f, 0.09f}},
    {{-0.53f, 0.00f, 0.09f}, {0.04f, 0.00f, -0.09f}, {-0.14f, 0.00f, -0.67f}, {-0.71f, 0.00f, -0.49f}},
    /* light */
    {{-0.24f, 1.98f, 0.16f}, {-0.24f, 1.98f, -0.22f}, {0.23f, 1.98f, -0.22f}, {0.23f, 1.98f, 0.16f}},
};

#define CORNELL_QUAD_COUNT ((int)(sizeof cornell_quads / sizeof cornell_quads[0]))

/* The MTL's Ke of the light is (17, 12, 4) nits; glTF stores it as
 * emissiveFactor (1, 12/17, 4/17) x emissiveStrength 17 and lpvd divides by
 * 683 lm/W (docs/units.md). */
#define KE_TO_RADIANCE(v) ((v) / LPV_LUMENS_PER_WATT)

static const cornell_object cornell_objects[] = {
    {"floor", {0.725f, 0.71f, 0.68f}, {0, 0, 0}, FACE_INWARD, 0, 1},
    {"ceiling", {0.725f, 0.71f, 0.68f}, {0, 0, 0}, FACE_INWARD, 1, 1},
    {"backWall", {0.725f, 0.71f, 0.68f}, {0, 0, 0}, FACE_INWARD, 2, 1},
    {"rightWall", {0.14f, 0.45f, 0.091f}, {0, 0, 0}, FACE_INWARD, 3, 1},
    {"leftWall", {0.63f, 0.065f, 0.05f}, {0, 0, 0}, FACE_INWARD, 4, 1},
    {"shortBox", {0.725f, 0.71f, 0.68f}, {0, 0, 0}, FACE_OUTWARD, 5, 6},
    {"tallBox", {0.725f, 0.71f, 0.68f}, {0, 0, 0}, FACE_OUTWARD, 11, 6},
    {"light",
     {0.78f, 0.78f, 0.78f},
     {KE_TO_RADIANCE(17.0f), KE_TO_RADIANCE(12.0f), KE_TO_RADIANCE(4.0f)},
     FACE_INWARD,
     17,
     1},
};

#define CORNELL_OBJECT_COUNT ((int)(sizeof cornell_objects / sizeof cornell_objects[0]))

static void sub3(const float *a, const float *b, float *out)
{
    out[0] = a[0] - b[0];
    out[1] = a[1] - b[1];
    out[2] = a[2] - b[2];
}

static void cross3(const float *a, const float *b, float *out)
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static float dot3(const float *a, const float *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void quad_centre(const float q[4][3], float *c)
{
    for (int k = 0; k < 3; k++)
        c[k] = 0.25f * (q[0][k] + q[1][k] + q[2][k] + q[3][k]);
}

int lpv_scene_builtin_cornell(lpv_scene *scene)
{
    if (!scene)
        return -1;
    memset(scene, 0, sizeof *scene);

    const uint32_t nverts = 4u * CORNELL_QUAD_COUNT;
    const uint32_t nidx = 6u * CORNELL_QUAD_COUNT;
    scene->vertices = calloc(nverts, sizeof *scene->vertices);
    scene->indices = calloc(nidx, sizeof *scene->indices);
    scene->draws = calloc(CORNELL_OBJECT_COUNT, sizeof *scene->draws);
    scene->materials = calloc(CORNELL_OBJECT_COUNT, sizeof *scene->materials);
    scene->lights = calloc(1, sizeof *scene->lights);
    scene->cameras = calloc(1, sizeof *scene->cameras);
    if (!scene->vertices || !scene->indices || !scene->draws || !scene->materials ||
        !scene->lights || !scene->cameras) {
        lpv_scene_free(scene);
        return -1;
    }

    /* The room's centre, to orient the walls, floor, ceiling and lamp inward. */
    float room_lo[3] = {INFINITY, INFINITY, INFINITY}, room_hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int q = 0; q < 5; q++)
        for (int c = 0; c < 4; c++)
            for (int k = 0; k < 3; k++) {
                room_lo[k] = fminf(room_lo[k], cornell_quads[q][c][k]);
                room_hi[k] = fmaxf(room_hi[k], cornell_quads[q][c][k]);
            }
    float room_centre[3];
    for (int k = 0; k < 3; k++)
        room_centre[k] = 0.5f * (room_lo[k] + room_hi[k]);

    uint32_t v = 0, ix = 0;
    for (int o = 0; o < CORNELL_OBJECT_COUNT; o++) {
        const cornell_object *obj = &cornell_objects[o];
        lpv_material *m = &scene->materials[o];
        lpv_material_init(m);
        strncpy(m->name, obj->name, LPV_NAME_MAX - 1);
        m->base_color[0] = obj->kd[0];
        m->base_color[1] = obj->kd[1];
        m->base_color[2] = obj->kd[2];
        memcpy(m->emission, obj->emission, sizeof m->emission);
        m->roughness = 0.9f;
        /* two-sided, except the lamp: a double-sided emitter would light the
         * ceiling above it too (docs/area-lights.md); it lights the room */
        m->double_sided = obj->emission[0] == 0.0f && obj->emission[1] == 0.0f && obj->emission[2] == 0.0f;

        /* A block's centre: the mean of its corners. */
        float block_centre[3] = {0, 0, 0};
        for (int q = obj->first_quad; q < obj->first_quad + obj->quad_count; q++)
            for (int c = 0; c < 4; c++)
                for (int k = 0; k < 3; k++)
                    block_centre[k] += cornell_quads[q][c][k] / (4.0f * (float)obj->quad_count);

        scene->draws[o].first_index = ix;
        scene->draws[o].material = o;
        for (int q = obj->first_quad; q < obj->first_quad + obj->quad_count; q++) {
            const float(*quad)[3] = cornell_quads[q];
            /* Flat normal of the (slightly non-planar) quad from its diagonals,
             * the best planar fit; then orient it explicitly, since the OBJ's
             * winding is not consistent. */
            float d0[3], d1[3], n[3], centre[3], towards[3];
            sub3(quad[2], quad[0], d0);
            sub3(quad[3], quad[1], d1);
            cross3(d0, d1, n);
            float len = sqrtf(dot3(n, n));
            for (int k = 0; k < 3; k++)
                n[k] /= len;
            quad_centre(quad, centre);
            if (obj->orient == FACE_INWARD)
                sub3(room_centre, centre, towards);
            else
                sub3(centre, block_centre, towards);
            int flip = dot3(n, towards) < 0.0f;
            if (flip)
                for (int k = 0; k < 3; k++)
                    n[k] = -n[k];

            for (int c = 0; c < 4; c++) {
                lpv_vertex *vx = &scene->vertices[v + (uint32_t)c];
                memcpy(vx->position, quad[c], sizeof vx->position);
                memcpy(vx->normal, n, sizeof vx->normal);
                /* A simple planar parameterisation over the quad's corners. */
                vx->uv[0] = (c == 1 || c == 2) ? 1.0f : 0.0f;
                vx->uv[1] = (c >= 2) ? 1.0f : 0.0f;
            }
            /* Two triangles, wound counter-clockwise seen from the normal's side. */
            static const uint32_t keep[6] = {0, 1, 2, 0, 2, 3};
            static const uint32_t swap[6] = {0, 2, 1, 0, 3, 2};
            const uint32_t *order = flip ? swap : keep;
            for (int t = 0; t < 6; t++)
                scene->indices[ix + (uint32_t)t] = v + order[t];
            v += 4;
            ix += 6;
        }
        scene->draws[o].index_count = ix - scene->draws[o].first_index;
    }
    scene->vertex_count = v;
    scene->index_count = ix;
    scene->draw_count = CORNELL_OBJECT_COUNT;
    scene->material_count = CORNELL_OBJECT_COUNT;

    /* The spot under the ceiling, as cornell-box.glb's KHR_lights_punctual
     * light: 2174.0565 cd -> W/sr with 683 lm/W. */
    lpv_light *l = &scene->lights[0];
    l->type = LPV_LIGHT_SPOT;
    strncpy(l->name, "CeilingSpot", LPV_NAME_MAX - 1);
    l->color[0] = 1.0f;
    l->color[1] = 0.85f;
    l->color[2] = 0.6f;
    l->intensity = 2174.0565f / LPV_LUMENS_PER_WATT;
    l->range = 0.0f;
    l->inner_cone = 0.9162978f;
    l->outer_cone = 1.3089969f;
    l->position[0] = 0.0f;
    l->position[1] = 1.95f;
    l->position[2] = 0.0f;
    l->direction[0] = 0.0f;
    l->direction[1] = -1.0f;
    l->direction[2] = 0.0f;
    scene->light_count = 1;

    lpv_camera *cam = &scene->cameras[0];
    strncpy(cam->name, "Camera", LPV_NAME_MAX - 1);
    cam->orthographic = 0;
    cam->yfov = 0.6806784f;
    cam->aspect = 1.0f;
    cam->znear = 0.1f;
    cam->zfar = 1000.0f;
    cam->eye[0] = 0.0f;
    cam->eye[1] = 1.0f;
    cam->eye[2] = 3.9f;
    cam->forward[0] = 0.0f;
    cam->forward[1] = 0.0f;
    cam->forward[2] = -1.0f;
    cam->up[0] = 0.0f;
    cam->up[1] = 1.0f;
    cam->up[2] = 0.0f;
    scene->camera_count = 1;

    scene->default_light_added = 0;
    strncpy(scene->source, "built-in:cornell-box", sizeof scene->source - 1);
    lpv_scene_compute_bounds(scene);
    return 0;
}
