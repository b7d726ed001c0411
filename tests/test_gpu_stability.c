/*
 * test_gpu_stability.c - hard cases through the real GL pipeline (llvmpipe
 * in CI): no NaN, no Inf, no energy from nowhere. "Energy" is the total flux
 * (W) of a propagation step's output, sum of c0 * sqrt(4 pi) per channel; it
 * must never grow from one step to the next (1e-6 relative slack for float
 * rounding, see docs/propagation.md).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "context.h"
#include "engine.h"
#include "oracle.h"
#include "scene.h"
#include "test_util.h"

static lpv_gl_context *ctx;
static lpv_engine *engine;

static int setup(void **state)
{
    (void)state;
    return lpvt_gl_open(&ctx, &engine);
}

static int teardown(void **state)
{
    (void)state;
    lpvt_gl_close(ctx, engine);
    return 0;
}

/* A small test scene: a floor quad and a back wall, grey, plus lights. */
typedef struct builder {
    lpv_scene s;
} builder;

static void add_quad(lpv_scene *s, const float c[4][3], const float n[3])
{
    uint32_t base = s->vertex_count;
    s->vertices = realloc(s->vertices, (s->vertex_count + 4) * sizeof *s->vertices);
    s->indices = realloc(s->indices, (s->index_count + 6) * sizeof *s->indices);
    for (int i = 0; i < 4; ++i) {
        lpv_vertex *v = &s->vertices[s->vertex_count++];
        memset(v, 0, sizeof *v);
        memcpy(v->position, c[i], sizeof v->position);
        memcpy(v->normal, n, sizeof v->normal);
    }
    const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    for (int i = 0; i < 6; ++i)
        s->indices[s->index_count++] = base + idx[i];
    s->draws[0].index_count = s->index_count;
}

static void make_room(lpv_scene *s, const float floor_normal[3])
{
    memset(s, 0, sizeof *s);
    s->draws = calloc(1, sizeof *s->draws);
    s->draw_count = 1;
    s->materials = calloc(1, sizeof *s->materials);
    s->material_count = 1;
    s->materials[0] = (lpv_material){.name = "grey", .base_color = {0.7f, 0.7f, 0.7f, 1}, .base_color_texture = -1};
    const float floor_q[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
    const float wall_q[4][3] = {{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}};
    add_quad(s, floor_q, floor_normal);
    add_quad(s, wall_q, (const float[3]){0, 0, 1});
    snprintf(s->source, sizeof s->source, "test-room");
    lpv_scene_compute_bounds(s);
}

static void add_point_light(lpv_scene *s, const float pos[3], float intensity)
{
    s->lights = realloc(s->lights, (s->light_count + 1) * sizeof *s->lights);
    lpv_light *l = &s->lights[s->light_count++];
    memset(l, 0, sizeof *l);
    l->type = LPV_LIGHT_POINT;
    l->color[0] = l->color[1] = l->color[2] = 1.0f;
    l->intensity = intensity;
    memcpy(l->position, pos, sizeof l->position);
    l->direction[1] = -1.0f;
}

static double total_flux(const lpv_cell *cells, size_t n)
{
    double f[3];
    lpv_grid g = {.dims = {(int)n, 1, 1}, .cell_size = 1.0f};
    lpv_oracle_total_flux(&g, cells, f);
    return f[0] + f[1] + f[2];
}

/* Ticks scene with settings s and checks the accumulated grid and (if
 * view) the frame are finite and c0 >= 0. Returns the last step's energy. */
static double tick_checked(const lpv_scene *scene, lpv_settings s, int with_view)
{
    char err[1024] = "";
    if (lpv_engine_set_settings(engine, &s, err, sizeof err) != 0 ||
        lpv_engine_set_scene(engine, scene, err, sizeof err) != 0)
        fail_msg("%s", err);
    lpv_view view;
    float eye[3] = {0.5f, 0.6f, 2.5f}, target[3] = {0.5f, 0.3f, 0.0f};
    assert_int_equal(lpv_view_look_at(eye, target, 0.9f, 32, 32, &view), 0);
    assert_int_equal(lpv_engine_set_view(engine, with_view ? &view : NULL, err, sizeof err), 0);
    if (lpv_engine_tick(engine, err, sizeof err) != 0)
        fail_msg("tick: %s", err);
    const lpv_grid *g = lpv_engine_grid(engine);
    size_t cells = lpv_grid_cell_count(g);
    lpv_cell *acc = calloc(cells, sizeof *acc), *last = calloc(cells, sizeof *last);
    assert_int_equal(lpv_engine_read_grid(engine, LPV_GRID_ACCUMULATED, acc, cells), cells);
    assert_int_equal(lpv_engine_read_grid(engine, LPV_GRID_LAST_STEP, last, cells), cells);
    for (size_t i = 0; i < cells; ++i) {
        const float *a = (const float *)&acc[i];
        for (int k = 0; k < 12; ++k)
            assert_true(isfinite(a[k]));
        assert_true(acc[i].r[0] >= 0.0f && acc[i].g[0] >= 0.0f && acc[i].b[0] >= 0.0f);
    }
    double e = total_flux(last, cells);
    assert_true(isfinite(e));
    if (with_view) {
        float *rgba = calloc((size_t)32 * 32 * 4, sizeof *rgba);
        assert_int_equal(lpv_engine_render(engine, LPV_TERMS_FULL, rgba, err, sizeof err), 0);
        for (size_t i = 0; i < (size_t)32 * 32 * 4; ++i)
            assert_true(isfinite(rgba[i]) && rgba[i] >= 0.0f);
        free(rgba);
    }
    free(acc);
    free(last);
    return e;
}

/* Energy of step k's output never exceeds step k-1's. */
static void assert_energy_non_increasing(const lpv_scene *scene, lpv_settings s, int steps)
{
    double prev = INFINITY;
    for (int k = 1; k <= steps; ++k) {
        s.iterations = k;
        double e = tick_checked(scene, s, 0);
        assert_true(e <= prev * (1.0 + 1e-6) + 1e-30);
        prev = e;
    }
}

static void test_degenerate_normals_and_triangles(void **state)
{
    (void)state;
    lpv_scene s;
    make_room(&s, (const float[3]){NAN, NAN, NAN});
    s.vertices[4].normal[0] = s.vertices[4].normal[1] = s.vertices[4].normal[2] = 0.0f; /* zero-length */
    /* a zero-area triangle */
    s.indices = realloc(s.indices, (s.index_count + 3) * sizeof *s.indices);
    s.indices[s.index_count++] = 0;
    s.indices[s.index_count++] = 0;
    s.indices[s.index_count++] = 1;
    s.draws[0].index_count = s.index_count;
    add_point_light(&s, (const float[3]){0.5f, 0.8f, 0.5f}, 1.0f);
    lpv_settings set = {.grid_dims = {8, 8, 8}, .rsm_size = 32};
    double e = tick_checked(&s, set, 1);
    assert_true(e > 0.0); /* light still got in */
    assert_energy_non_increasing(&s, set, 4);
    lpv_scene_free(&s);
}

static void test_light_on_cell_corner(void **state)
{
    (void)state;
    lpv_scene s;
    make_room(&s, (const float[3]){0, 1, 0});
    lpv_settings set = {.grid_dims = {8, 8, 8}, .rsm_size = 32, .bounds_min = {0, 0, 0}, .bounds_max = {1, 1, 1}};
    lpv_grid g;
    assert_int_equal(lpv_grid_place(set.grid_dims, set.bounds_min, set.bounds_max, &g), 0);
    float corner[3] = {g.origin[0] + 4 * g.cell_size, g.origin[1] + 5 * g.cell_size, g.origin[2] + 4 * g.cell_size};
    add_point_light(&s, corner, 2.0f);
    assert_true(tick_checked(&s, set, 1) > 0.0);
    assert_energy_non_increasing(&s, set, 4);
    lpv_scene_free(&s);
}

static void test_vpls_on_grid_boundary(void **state)
{
    (void)state;
    lpv_scene s;
    make_room(&s, (const float[3]){0, 1, 0});
    add_point_light(&s, (const float[3]){0.5f, 0.9f, 0.5f}, 1.0f);
    /* bounds that end exactly at the floor and wall: VPLs sit on the boundary */
    lpv_settings set = {.grid_dims = {8, 8, 8}, .rsm_size = 32, .bounds_min = {0, 0, 0}, .bounds_max = {1, 1, 1}};
    lpv_grid g;
    assert_int_equal(lpv_grid_place(set.grid_dims, set.bounds_min, set.bounds_max, &g), 0);
    set.bounds_min[1] = -0.5f * g.cell_size; /* floor exactly on the lower face */
    set.bounds_max[1] = 1.0f - 0.5f * g.cell_size;
    tick_checked(&s, set, 1);
    assert_energy_non_increasing(&s, set, 3);
    lpv_scene_free(&s);
}

static void test_dynamic_range_1e6(void **state)
{
    (void)state;
    lpv_scene s;
    make_room(&s, (const float[3]){0, 1, 0});
    add_point_light(&s, (const float[3]){0.2f, 0.5f, 0.5f}, 1e3f);
    add_point_light(&s, (const float[3]){0.8f, 0.5f, 0.5f}, 1e-3f);
    lpv_settings set = {.grid_dims = {16, 16, 16}, .rsm_size = 64};
    tick_checked(&s, set, 1);
    assert_energy_non_increasing(&s, set, 3);
    lpv_scene_free(&s);
}

static void test_extreme_intensity(void **state)
{
    (void)state;
    lpv_scene s;
    make_room(&s, (const float[3]){0, 1, 0});
    add_point_light(&s, (const float[3]){0.5f, 0.5f, 0.5f}, 1e30f);
    lpv_settings set = {.grid_dims = {8, 8, 8}, .rsm_size = 32};
    tick_checked(&s, set, 1);
    lpv_scene_free(&s);
}

static void test_thousand_steps(void **state)
{
    (void)state;
    lpv_scene s;
    make_room(&s, (const float[3]){0, 1, 0});
    add_point_light(&s, (const float[3]){0.5f, 0.5f, 0.5f}, 1.0f);
    lpv_settings set = {.grid_dims = {8, 8, 8}, .rsm_size = 32, .iterations = 1};
    double first = tick_checked(&s, set, 0);
    set.iterations = 1000;
    double last = tick_checked(&s, set, 1);
    assert_true(first > 0.0);
    assert_true(last <= first * (1.0 + 1e-6));
    lpv_scene_free(&s);
}

static void test_tiny_and_flat_grids(void **state)
{
    (void)state;
    lpv_scene s;
    make_room(&s, (const float[3]){0, 1, 0});
    add_point_light(&s, (const float[3]){0.5f, 0.5f, 0.5f}, 1.0f);
    lpv_settings one = {.grid_dims = {1, 1, 1}, .rsm_size = 32};
    tick_checked(&s, one, 1);
    assert_energy_non_increasing(&s, one, 3);
    lpv_settings flat = {.grid_dims = {1, 1, 64}, .rsm_size = 32};
    tick_checked(&s, flat, 1);
    assert_energy_non_increasing(&s, flat, 4);
    lpv_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_degenerate_normals_and_triangles),
        cmocka_unit_test(test_light_on_cell_corner),
        cmocka_unit_test(test_vpls_on_grid_boundary),
        cmocka_unit_test(test_dynamic_range_1e6),
        cmocka_unit_test(test_extreme_intensity),
        cmocka_unit_test(test_thousand_steps),
        cmocka_unit_test(test_tiny_and_flat_grids),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
