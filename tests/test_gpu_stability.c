/*
 * test_gpu_stability.c - hard cases through the real GL pipeline (llvmpipe
 * in CI): no NaN, no Inf, no energy from nowhere. "Energy" is the total flux
 * (W) of a propagation step's output, sum of c0 * sqrt(4 pi) per channel; it
 * must never grow from one step to the next (1e-6 relative slack for float
 * rounding, see docs/propagation.md). The scenes are the hard cases of
 * bench/accuracy/hard_cases.h, which lpvd-hard-cases also compares with the
 * path-traced reference (docs/hard-cases.md). Every case runs three times:
 * with the paper's pipeline (the four departures of docs/propagation.md
 * off), with the case's own settings, whose departures are the defaults (on). With the
 * far field the light in flight moves from level to level, so "a step's
 * output" is every level's (and every normal bin's) together. A third run
 * goes through the octree technique (docs/octree.md) on the smallest cubic
 * power-of-two grid holding the case's: there "a step's output" is every
 * octree level's last step together.
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
#include "hard_cases.h"
#include "oracle.h"
#include "test_util.h"

/* Builds hard case `name` (bench/accuracy/hard_cases.h: the same scenes
 * lpvd-hard-cases compares with the reference). */
static void build(const char *name, lpv_hard_scene *h)
{
    assert_int_equal(lpv_hard_case_build(name, h), 0);
}

/* The pipeline under test (set from the test's state, see main). */
enum { DEFAULTS = 0, PAPER = 1, OCTREE = 2 };
static int mode;

/* The smallest power of two >= every axis of dims. */
static int cube_of(const int dims[3])
{
    int n = 1;
    while (n < dims[0] || n < dims[1] || n < dims[2])
        n *= 2;
    return n;
}

static double total_flux(const lpv_cell *cells, size_t n)
{
    double f[3];
    lpv_grid g = {.dims = {(int)n, 1, 1}, .cell_size = 1.0f};
    lpv_oracle_total_flux(&g, cells, f);
    return f[0] + f[1] + f[2];
}

/* Ticks case h's scene with settings s and checks the accumulated grid and
 * (if with_view, from the case's camera) the frame are finite and c0 >= 0.
 * Returns the last step's energy. */
static double tick_checked(const lpv_hard_scene *h, lpv_settings s, int with_view)
{
    const lpv_scene *scene = &h->scene;
    char err[1024] = "";
    if (mode == PAPER)
        s.lpv.central_transport = s.lpv.normal_bins = s.lpv.far_field = s.scene_surfels = LPV_SWITCH_OFF;
    if (mode == OCTREE) {
        s.technique = LPV_TECHNIQUE_ID_OCTREE;
        s.grid_dims[0] = s.grid_dims[1] = s.grid_dims[2] = cube_of(s.grid_dims);
    }
    if (lpv_engine_set_settings(lpvt_engine, &s, err, sizeof err) != 0 ||
        lpv_engine_set_scene(lpvt_engine, scene, err, sizeof err) != 0)
        fail_msg("%s", err);
    lpv_view view;
    assert_int_equal(lpv_hard_case_view(h, 32, 32, &view), 0);
    assert_int_equal(lpv_engine_set_view(lpvt_engine, with_view ? &view : NULL, err, sizeof err), 0);
    if (lpv_engine_tick(lpvt_engine, err, sizeof err) != 0)
        fail_msg("tick: %s", err);
    const lpv_grid *g = lpv_engine_grid(lpvt_engine);
    const lpv_settings *r = lpv_engine_settings(lpvt_engine);
    if (mode == PAPER)
        assert_true(r->lpv.far_field == LPV_SWITCH_OFF && r->lpv.normal_bins == LPV_SWITCH_OFF);
    else if (mode == OCTREE)
        assert_int_equal(r->technique, LPV_TECHNIQUE_ID_OCTREE);
    else /* the hard cases leave the departures to the defaults: they are checked here */
        assert_true(r->lpv.far_field == LPV_SWITCH_ON && r->lpv.normal_bins == LPV_SWITCH_ON &&
                    r->lpv.central_transport == LPV_SWITCH_ON && r->scene_surfels == LPV_SWITCH_ON);
    /* every cascade (far-field level), each the sum of its normal bins; the
     * octree's merged grid, and its levels' last steps */
    size_t cells = lpv_grid_cell_count(g) * (size_t)lpv_engine_cascade_count(lpvt_engine);
    size_t last_cells = cells;
    if (mode == OCTREE)
        for (size_t n = (size_t)g->dims[0] / 2; n >= 1; n /= 2)
            last_cells += n * n * n;
    lpv_cell *acc = calloc(cells, sizeof *acc), *last = calloc(last_cells, sizeof *last);
    assert_int_equal(lpv_engine_read_grid(lpvt_engine, LPV_GRID_ACCUMULATED, acc, cells), cells);
    if (mode == OCTREE)
        assert_int_equal(lpv_engine_read_volumes(lpvt_engine, LPV_GRID_LAST_STEP, last, last_cells), last_cells);
    else
        assert_int_equal(lpv_engine_read_grid(lpvt_engine, LPV_GRID_LAST_STEP, last, cells), cells);
    for (size_t i = 0; i < cells; ++i) {
        const float *a = (const float *)&acc[i];
        for (int k = 0; k < 12; ++k)
            assert_true(isfinite(a[k]));
        assert_true(acc[i].r[0] >= 0.0f && acc[i].g[0] >= 0.0f && acc[i].b[0] >= 0.0f);
    }
    double e = total_flux(last, last_cells);
    assert_true(isfinite(e));
    if (with_view) {
        float *rgba = calloc((size_t)32 * 32 * 4, sizeof *rgba);
        assert_int_equal(lpv_engine_render(lpvt_engine, LPV_TERMS_FULL, rgba, err, sizeof err), 0);
        for (size_t i = 0; i < (size_t)32 * 32 * 4; ++i)
            assert_true(isfinite(rgba[i]) && rgba[i] >= 0.0f);
        free(rgba);
    }
    free(acc);
    free(last);
    return e;
}

/* Energy of step k's output never exceeds step k-1's. */
static void assert_energy_non_increasing(const lpv_hard_scene *scene, lpv_settings s, int steps)
{
    double prev = INFINITY;
    for (int k = 1; k <= steps; ++k) {
        s.lpv.iterations = k;
        double e = tick_checked(scene, s, 0);
        assert_true(e <= prev * (1.0 + 1e-6) + 1e-30);
        prev = e;
    }
}

static void test_degenerate_normals_and_triangles(void **state)
{
    mode = *(const int *)*state;
    lpv_hard_scene h;
    build("degenerate_geometry", &h);
    double e = tick_checked(&h, h.settings, 1);
    assert_true(e > 0.0); /* light still got in */
    assert_energy_non_increasing(&h, h.settings, 4);
    lpv_hard_scene_free(&h);
}

static void test_light_on_cell_corner(void **state)
{
    mode = *(const int *)*state;
    lpv_hard_scene h;
    build("light_on_cell_corner", &h);
    assert_true(tick_checked(&h, h.settings, 1) > 0.0);
    assert_energy_non_increasing(&h, h.settings, 4);
    lpv_hard_scene_free(&h);
}

static void test_vpls_on_grid_boundary(void **state)
{
    mode = *(const int *)*state;
    lpv_hard_scene h;
    build("vpls_on_grid_boundary", &h);
    tick_checked(&h, h.settings, 1);
    assert_energy_non_increasing(&h, h.settings, 3);
    lpv_hard_scene_free(&h);
}

static void test_dynamic_range_1e6(void **state)
{
    mode = *(const int *)*state;
    lpv_hard_scene h;
    build("dynamic_range_1e6", &h);
    tick_checked(&h, h.settings, 1);
    assert_energy_non_increasing(&h, h.settings, 3);
    lpv_hard_scene_free(&h);
}

static void test_extreme_intensity(void **state)
{
    mode = *(const int *)*state;
    lpv_hard_scene h;
    build("extreme_intensity_1e30", &h);
    tick_checked(&h, h.settings, 1);
    lpv_hard_scene_free(&h);
}

static void test_thin_wall(void **state)
{
    mode = *(const int *)*state;
    lpv_hard_scene h;
    build("thin_wall", &h);
    assert_true(tick_checked(&h, h.settings, 1) > 0.0);
    assert_energy_non_increasing(&h, h.settings, 4);
    lpv_hard_scene_free(&h);
}

static void test_thousand_steps(void **state)
{
    mode = *(const int *)*state;
    lpv_hard_scene h;
    build("steps_1000", &h);
    assert_int_equal(h.settings.lpv.iterations, 1000);
    lpv_settings set = h.settings;
    set.lpv.iterations = 1;
    double first = tick_checked(&h, set, 0);
    set.lpv.iterations = 1000;
    double last = tick_checked(&h, set, 1);
    assert_true(first > 0.0);
    assert_true(last <= first * (1.0 + 1e-6));
    lpv_hard_scene_free(&h);
}

static void test_tiny_and_flat_grids(void **state)
{
    mode = *(const int *)*state;
    lpv_hard_scene one, flat;
    build("one_cell_grid", &one);
    tick_checked(&one, one.settings, 1);
    assert_energy_non_increasing(&one, one.settings, 3);
    build("flat_grid_1x1x64", &flat);
    tick_checked(&flat, flat.settings, 1);
    assert_energy_non_increasing(&flat, flat.settings, 4);
    lpv_hard_scene_free(&one);
    lpv_hard_scene_free(&flat);
}

int main(void)
{
    static int paper = PAPER, defaults = DEFAULTS, octree = OCTREE;
#define EACH(t)                                                                                              \
    cmocka_unit_test_prestate(t, &paper), cmocka_unit_test_prestate(t, &defaults),                          \
        cmocka_unit_test_prestate(t, &octree)
    const struct CMUnitTest tests[] = {
        EACH(test_degenerate_normals_and_triangles),
        EACH(test_light_on_cell_corner),
        EACH(test_vpls_on_grid_boundary),
        EACH(test_dynamic_range_1e6),
        EACH(test_extreme_intensity),
        EACH(test_thin_wall),
        EACH(test_thousand_steps),
        EACH(test_tiny_and_flat_grids),
    };
#undef EACH
    return cmocka_run_group_tests(tests, lpvt_gl_setup, lpvt_gl_teardown);
}
