/*
 * test_scene.c - the scene model (core/scene.h): the built-in Cornell box,
 * lpv_scene_add_defaults' default camera and light, bounds and freeing.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
/* cmocka.h after the headers it needs */
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene.h"
#include "scene_defaults.h"
#include "scene_planes.h"

static void assert_vec3(const float *v, float x, float y, float z, float tol)
{
    if (fabsf(v[0] - x) > tol || fabsf(v[1] - y) > tol || fabsf(v[2] - z) > tol)
        fail_msg("(%g, %g, %g) != (%g, %g, %g) within %g", v[0], v[1], v[2], x, y, z, tol);
}

static const lpv_draw *draw_named(const lpv_scene *s, const char *name)
{
    for (uint32_t d = 0; d < s->draw_count; d++)
        if (strcmp(s->materials[s->draws[d].material].name, name) == 0)
            return &s->draws[d];
    fail_msg("no draw with material %s", name);
    return NULL;
}

/* The normal of every vertex of a draw. */
static void assert_draw_normal(const lpv_scene *s, const char *name, float x, float y, float z, float tol)
{
    const lpv_draw *d = draw_named(s, name);
    for (uint32_t i = d->first_index; i < d->first_index + d->index_count; i++)
        assert_vec3(s->vertices[s->indices[i]].normal, x, y, z, tol);
}

static void test_builtin_cornell(void **state)
{
    (void)state;
    lpv_scene s;
    memset(&s, 0x5a, sizeof s);
    assert_int_equal(lpv_scene_builtin_cornell(&s), 0);
    assert_string_equal(s.source, "built-in:cornell-box");
    assert_int_equal(s.index_count, 36 * 3); /* 18 quads */
    assert_int_equal(s.vertex_count, 72);
    assert_int_equal(s.draw_count, 8);
    assert_int_equal(s.material_count, 8);
    assert_int_equal(s.texture_count, 0);
    assert_int_equal(s.default_light_added, 0);
    assert_int_equal(lpv_scene_emissive_draw_count(&s), 1);

    static const char *names[8] = {"floor", "ceiling", "backWall", "rightWall",
                                   "leftWall", "shortBox", "tallBox", "light"};
    uint32_t total = 0;
    for (int i = 0; i < 8; i++) {
        const lpv_draw *d = draw_named(&s, names[i]);
        assert_int_equal(d->index_count % 3, 0);
        total += d->index_count;
        const lpv_material *m = &s.materials[d->material];
        assert_int_equal(m->double_sided, i < 7); /* the lamp emits downwards only */
        assert_true(m->metallic == 0.0f && m->roughness == 0.9f);
        assert_int_equal(m->base_color_texture, -1);
        assert_true(m->base_color[3] == 1.0f);
    }
    assert_int_equal(total, s.index_count);
    assert_int_equal(draw_named(&s, "shortBox")->index_count, 36);
    assert_int_equal(draw_named(&s, "tallBox")->index_count, 36);

    /* MTL colours */
    assert_vec3(s.materials[draw_named(&s, "leftWall")->material].base_color, 0.63f, 0.065f, 0.05f, 0);
    assert_vec3(s.materials[draw_named(&s, "rightWall")->material].base_color, 0.14f, 0.45f, 0.091f, 0);
    assert_vec3(s.materials[draw_named(&s, "floor")->material].base_color, 0.725f, 0.71f, 0.68f, 0);
    assert_vec3(s.materials[draw_named(&s, "light")->material].emission, 17.0f / 683.0f, 12.0f / 683.0f,
                4.0f / 683.0f, 1e-7f);
    assert_vec3(s.materials[draw_named(&s, "floor")->material].emission, 0, 0, 0, 0);

    /* unit normals into the room (the walls lean by up to 0.03 m) */
    for (uint32_t v = 0; v < s.vertex_count; v++) {
        const float *n = s.vertices[v].normal;
        assert_true(fabsf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1.0f) < 1e-5f);
    }
    assert_draw_normal(&s, "floor", 0, 1, 0, 0.02f);
    assert_draw_normal(&s, "ceiling", 0, -1, 0, 0.02f);
    assert_draw_normal(&s, "backWall", 0, 0, 1, 0.02f);
    assert_draw_normal(&s, "leftWall", 1, 0, 0, 0.02f);   /* red, at x = -1 */
    assert_draw_normal(&s, "rightWall", -1, 0, 0, 0.02f); /* green, at x = +1 */
    assert_draw_normal(&s, "light", 0, -1, 0, 1e-6f);

    /* the blocks face outward: every face normal points away from the block's centre,
     * and the winding agrees with the normal */
    const char *blocks[2] = {"shortBox", "tallBox"};
    for (int b = 0; b < 2; b++) {
        const lpv_draw *d = draw_named(&s, blocks[b]);
        float c[3] = {0, 0, 0};
        for (uint32_t i = d->first_index; i < d->first_index + d->index_count; i++)
            for (int k = 0; k < 3; k++)
                c[k] += s.vertices[s.indices[i]].position[k] / (float)d->index_count;
        for (uint32_t t = d->first_index; t < d->first_index + d->index_count; t += 3) {
            const float *p0 = s.vertices[s.indices[t]].position;
            const float *p1 = s.vertices[s.indices[t + 1]].position;
            const float *p2 = s.vertices[s.indices[t + 2]].position;
            const float *n = s.vertices[s.indices[t]].normal;
            float mid[3], e1[3], e2[3], w[3];
            for (int k = 0; k < 3; k++) {
                mid[k] = (p0[k] + p1[k] + p2[k]) / 3.0f - c[k];
                e1[k] = p1[k] - p0[k];
                e2[k] = p2[k] - p0[k];
            }
            w[0] = e1[1] * e2[2] - e1[2] * e2[1];
            w[1] = e1[2] * e2[0] - e1[0] * e2[2];
            w[2] = e1[0] * e2[1] - e1[1] * e2[0];
            assert_true(n[0] * mid[0] + n[1] * mid[1] + n[2] * mid[2] > 0.0f);
            assert_true(n[0] * w[0] + n[1] * w[1] + n[2] * w[2] > 0.0f);
        }
    }
    /* and the room's triangles are wound towards the inside too */
    const lpv_draw *fl = draw_named(&s, "floor");
    for (uint32_t t = fl->first_index; t < fl->first_index + fl->index_count; t += 3) {
        const float *p0 = s.vertices[s.indices[t]].position;
        const float *p1 = s.vertices[s.indices[t + 1]].position;
        const float *p2 = s.vertices[s.indices[t + 2]].position;
        float wy = (p1[2] - p0[2]) * (p2[0] - p0[0]) - (p1[0] - p0[0]) * (p2[2] - p0[2]);
        assert_true(wy > 0.0f);
    }

    /* bounds of the OBJ */
    assert_vec3(s.bounds_min, -1.02f, 0.0f, -1.04f, 1e-6f);
    assert_vec3(s.bounds_max, 1.00f, 1.99f, 0.99f, 1e-6f);

    /* the spot and the camera */
    assert_int_equal(s.light_count, 1);
    const lpv_light *l = &s.lights[0];
    assert_int_equal(l->type, LPV_LIGHT_SPOT);
    assert_string_equal(l->name, "CeilingSpot");
    assert_true(fabsf(l->intensity - 2174.0565f / 683.0f) < 1e-6f);
    assert_vec3(l->position, 0, 1.95f, 0, 0);
    assert_vec3(l->direction, 0, -1, 0, 0);
    assert_vec3(l->color, 1, 0.85f, 0.6f, 0);
    assert_true(l->inner_cone == 0.9162978f && l->outer_cone == 1.3089969f && l->range == 0.0f);
    assert_int_equal(s.camera_count, 1);
    const lpv_camera *c = &s.cameras[0];
    assert_string_equal(c->name, "Camera");
    assert_vec3(c->eye, 0, 1, 3.9f, 0);
    assert_vec3(c->forward, 0, 0, -1, 0);
    assert_vec3(c->up, 0, 1, 0, 0);
    assert_true(c->yfov == 0.6806784f && c->aspect == 1.0f && c->znear == 0.1f && c->zfar == 1000.0f);

    /* the box has a camera, a spot and an emitter: no defaults */
    char err[256];
    assert_int_equal(lpv_scene_add_defaults(&s, err, sizeof err), 0);
    assert_int_equal(s.light_count, 1);
    assert_int_equal(s.camera_count, 1);
    assert_int_equal(s.default_light_added, 0);
    assert_int_equal(s.default_camera_added, 0);

    lpv_scene_free(&s);
    static const lpv_scene zero;
    assert_memory_equal(&s, &zero, sizeof zero);
}

/* A floor quad 4 m x 4 m at y = 1 and a point 3 m above it: no lights, no emission. */
static void make_dark_scene(lpv_scene *s)
{
    memset(s, 0, sizeof *s);
    s->vertex_count = 5;
    s->vertices = calloc(s->vertex_count, sizeof *s->vertices);
    s->index_count = 6;
    s->indices = calloc(s->index_count, sizeof *s->indices);
    s->draw_count = 1;
    s->draws = calloc(1, sizeof *s->draws);
    s->material_count = 1;
    s->materials = calloc(1, sizeof *s->materials);
    assert_non_null(s->vertices);
    assert_non_null(s->indices);
    assert_non_null(s->draws);
    assert_non_null(s->materials);
    const float p[5][3] = {{-1, 1, -2}, {3, 1, -2}, {3, 1, 2}, {-1, 1, 2}, {0, 4, 0}};
    for (int i = 0; i < 5; i++) {
        memcpy(s->vertices[i].position, p[i], sizeof p[i]);
        s->vertices[i].normal[1] = 1.0f;
    }
    const uint32_t idx[6] = {0, 2, 1, 0, 3, 2};
    memcpy(s->indices, idx, sizeof idx);
    s->draws[0].index_count = 6;
    lpv_material_init(&s->materials[0]);
    lpv_scene_compute_bounds(s);
}

static void test_defaults_added(void **state)
{
    (void)state;
    lpv_scene s;
    char err[256];
    make_dark_scene(&s);
    assert_vec3(s.bounds_min, -1, 1, -2, 0);
    assert_vec3(s.bounds_max, 3, 4, 2, 0);
    assert_int_equal(lpv_scene_emissive_draw_count(&s), 0);

    assert_int_equal(lpv_scene_add_defaults(&s, err, sizeof err), 0);
    /* an open scene: a camera outside the bounds looking at their centre */
    assert_int_equal(s.camera_count, 1);
    assert_int_equal(s.default_camera_added, 1);
    const lpv_camera *c = &s.cameras[0];
    assert_string_equal(c->name, "default");
    assert_true(c->eye[2] > s.bounds_max[2] && c->eye[1] > s.bounds_max[1]);
    float to_c[3] = {1 - c->eye[0], 2.5f - c->eye[1], 0 - c->eye[2]};
    float len = sqrtf(to_c[0] * to_c[0] + to_c[1] * to_c[1] + to_c[2] * to_c[2]);
    assert_true((to_c[0] * c->forward[0] + to_c[1] * c->forward[1] + to_c[2] * c->forward[2]) / len > 0.999f);

    assert_int_equal(s.light_count, 1);
    assert_int_equal(s.default_light_added, 1);
    const lpv_light *l = &s.lights[0];
    assert_int_equal(l->type, LPV_LIGHT_POINT);
    assert_string_equal(l->name, "default");
    assert_vec3(l->color, 1, 1, 1, 0);
    assert_true(l->range == 0.0f);
    /* on the lit (upper) side of the floor, and about 1 W/m^2 on it:
     * I / d^2 at the floor's centre within a factor 3 of 1 */
    assert_true(l->position[1] > 1.0f);
    float d[3] = {l->position[0] - 1, l->position[1] - 1, l->position[2]};
    float e = l->intensity / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    assert_true(e > 1.0f / 3.0f && e < 3.0f);

    /* idempotent: a camera and a light exist now */
    assert_int_equal(lpv_scene_add_defaults(&s, err, sizeof err), 0);
    assert_int_equal(s.light_count, 1);
    assert_int_equal(s.camera_count, 1);
    lpv_scene_free(&s);
}

static void test_defaults_respect_emission_and_lights(void **state)
{
    (void)state;
    lpv_scene s;
    char err[256];
    make_dark_scene(&s);
    s.materials[0].emission[1] = 0.5f;
    assert_int_equal(lpv_scene_emissive_draw_count(&s), 1);
    assert_int_equal(lpv_scene_add_defaults(&s, err, sizeof err), 0);
    assert_int_equal(s.light_count, 0);
    assert_int_equal(s.default_light_added, 0);
    assert_int_equal(s.camera_count, 1); /* still no camera in the file */

    /* an emissive material no draw uses does not count */
    s.draws[0].material = 0;
    lpv_material *m = realloc(s.materials, 2 * sizeof *m);
    assert_non_null(m);
    s.materials = m;
    s.material_count = 2;
    s.materials[1] = s.materials[0];
    s.materials[0].emission[1] = 0.0f;
    assert_int_equal(lpv_scene_emissive_draw_count(&s), 0);
    assert_int_equal(lpv_scene_add_defaults(&s, err, sizeof err), 0);
    assert_int_equal(s.light_count, 1);
    assert_int_equal(s.camera_count, 1);
    lpv_scene_free(&s);

    /* an existing light: nothing added but the camera */
    make_dark_scene(&s);
    s.lights = calloc(1, sizeof *s.lights);
    assert_non_null(s.lights);
    s.light_count = 1;
    assert_int_equal(lpv_scene_add_defaults(&s, err, sizeof err), 0);
    assert_int_equal(s.light_count, 1);
    assert_int_equal(s.default_light_added, 0);
    assert_int_equal(s.default_camera_added, 1);
    lpv_scene_free(&s);
}

static void test_defaults_empty(void **state)
{
    (void)state;
    /* empty scene: bounds 0, size taken as 1; finite camera and light */
    lpv_scene s;
    char err[256];
    memset(&s, 0, sizeof s);
    lpv_scene_compute_bounds(&s);
    assert_vec3(s.bounds_min, 0, 0, 0, 0);
    assert_vec3(s.bounds_max, 0, 0, 0, 0);
    assert_int_equal(lpv_scene_add_defaults(&s, err, sizeof err), 0);
    assert_int_equal(s.light_count, 1);
    assert_int_equal(s.camera_count, 1);
    for (int i = 0; i < 3; ++i)
        assert_true(isfinite(s.lights[0].position[i]) && isfinite(s.cameras[0].eye[i]));
    assert_true(s.lights[0].intensity > 0.0f && isfinite(s.lights[0].intensity));
    lpv_scene_free(&s);
}

static void test_bounds_ignore_non_finite(void **state)
{
    (void)state;
    lpv_scene s;
    memset(&s, 0, sizeof s);
    s.vertex_count = 4;
    s.vertices = calloc(4, sizeof *s.vertices);
    assert_non_null(s.vertices);
    const float p[4][3] = {{1, 2, 3}, {NAN, 100, 100}, {-1, INFINITY, 0}, {4, -5, 6}};
    for (int i = 0; i < 4; i++)
        memcpy(s.vertices[i].position, p[i], sizeof p[i]);
    lpv_scene_compute_bounds(&s);
    assert_vec3(s.bounds_min, 1, -5, 3, 0);
    assert_vec3(s.bounds_max, 4, 2, 6, 0);
    lpv_scene_free(&s);
}

/* The lookup's plane normals (core/scene_planes.h) of the built-in box: the
 * normals of its flat surfaces off the axes (the slanted left wall; the
 * blocks' eight sides, whose opposite sides share a normal up to its sign:
 * seven in all), each as n and -n, unit, none twice, the largest (the left
 * wall) first; the room's other walls, floor, ceiling and the blocks' tops
 * lie on axes. */
static void test_plane_normals(void **state)
{
    (void)state;
    lpv_scene s;
    assert_int_equal(lpv_scene_builtin_cornell(&s), 0);
    float n[LPV_MAX_LOOKUP_PLANES][3];
    const int count = lpv_scene_plane_normals(&s, n, LPV_MAX_LOOKUP_PLANES);
    assert_int_equal(count, 14);
    for (int i = 0; i < count; ++i) {
        const float len = sqrtf(n[i][0] * n[i][0] + n[i][1] * n[i][1] + n[i][2] * n[i][2]);
        assert_true(fabsf(len - 1.0f) < 1e-6f);
        const int zeros = (n[i][0] == 0.0f) + (n[i][1] == 0.0f) + (n[i][2] == 0.0f);
        assert_true(zeros < 2);
        if (i % 2 == 1)
            for (int k = 0; k < 3; ++k)
                assert_true(n[i][k] == -n[i - 1][k]);
        for (int j = 0; j < i; ++j) /* all different */
            assert_true(fabsf(n[i][0] - n[j][0]) > LPV_LOOKUP_PLANE_TOLERANCE ||
                        fabsf(n[i][1] - n[j][1]) > LPV_LOOKUP_PLANE_TOLERANCE ||
                        fabsf(n[i][2] - n[j][2]) > LPV_LOOKUP_PLANE_TOLERANCE);
    }
    /* the left wall (about 2 x 2 m, facing +x into the room) is the largest */
    assert_true(fabsf(n[0][0]) > 0.99f);
    /* room for fewer: the largest pairs, in the same order */
    float few[5][3];
    assert_int_equal(lpv_scene_plane_normals(&s, few, 5), 4);
    assert_memory_equal(few, n, sizeof(float[4][3]));
    /* a floor whose normal is off +y by less than the tolerance (not along
     * the axis, so not left out as one) is not listed: the lookup finds its
     * pixels by the axis, and no pixel may match an axis and a plane
     * (lookup.glsl's search stops at the first it finds) */
    const lpv_draw *floor = &s.draws[0];
    for (uint32_t i = 0; i < floor->index_count; ++i) {
        lpv_vertex *v = &s.vertices[s.indices[floor->first_index + i]];
        assert_true(v->normal[1] == 1.0f);
        v->normal[0] = 5e-7f;
    }
    float nudged[LPV_MAX_LOOKUP_PLANES][3];
    assert_int_equal(lpv_scene_plane_normals(&s, nudged, LPV_MAX_LOOKUP_PLANES), count);
    assert_memory_equal(nudged, n, sizeof(float[14][3]));
    for (int i = 0; i < count; ++i)
        for (int a = 0; a < 6; ++a) {
            float axis[3] = {0.0f, 0.0f, 0.0f};
            axis[a >> 1] = (a & 1) ? -1.0f : 1.0f;
            assert_true(fabsf(nudged[i][0] - axis[0]) > LPV_LOOKUP_PLANE_TOLERANCE ||
                        fabsf(nudged[i][1] - axis[1]) > LPV_LOOKUP_PLANE_TOLERANCE ||
                        fabsf(nudged[i][2] - axis[2]) > LPV_LOOKUP_PLANE_TOLERANCE);
        }
    lpv_scene_free(&s);
}

static void test_free_zeroed_and_null(void **state)
{
    (void)state;
    lpv_scene s;
    memset(&s, 0, sizeof s);
    lpv_scene_free(&s);
    lpv_scene_free(&s);
    lpv_scene_free(NULL);
    static const lpv_scene zero;
    assert_memory_equal(&s, &zero, sizeof zero);
    assert_int_equal(lpv_scene_emissive_draw_count(&s), 0);
    assert_int_equal(lpv_scene_emissive_draw_count(NULL), 0);

    /* a scene with textures */
    s.texture_count = 2;
    s.textures = calloc(2, sizeof *s.textures);
    assert_non_null(s.textures);
    s.textures[0].rgba8 = malloc(16);
    s.textures[0].width = s.textures[0].height = 2;
    lpv_scene_free(&s);
    assert_memory_equal(&s, &zero, sizeof zero);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_builtin_cornell),
        cmocka_unit_test(test_defaults_added),
        cmocka_unit_test(test_defaults_respect_emission_and_lights),
        cmocka_unit_test(test_defaults_empty),
        cmocka_unit_test(test_bounds_ignore_non_finite),
        cmocka_unit_test(test_plane_normals),
        cmocka_unit_test(test_free_zeroed_and_null),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
