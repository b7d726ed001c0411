/*
 * test_bounces.c - multiple bounces (settings.lpv.bounces, paper section 7)
 * through the real GL pipeline (llvmpipe in CI): a closed 2 m box lit from
 * inside by a point light (whose RSM gives the geometry volume its blockers
 * and their albedo) and an emissive panel (light that does not depend on the
 * walls' albedo). Energy, as in test_gpu_stability.c, is the total flux of a
 * propagation step's output (sum of c0 * sqrt(4 pi) per channel); with
 * walls of albedo <= 1 a bounce only redirects what a blocker stopped, so it
 * must never grow from one step to the next.
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
#include "scene_build.h"
#include "test_util.h"

#define DIM 16

/* The closed box: six 10 cm slabs of albedo a around [-1, 1] x [0, 2] x [-1, 1]. */
static void build_box(lpv_scene *s, float a)
{
    memset(s, 0, sizeof *s);
    int wall = lpv_scene_add_material(s, "wall", (float[3]){a, a, a}, NULL);
    int lamp = lpv_scene_add_material(s, "lamp", (float[3]){0, 0, 0}, (float[3]){3.0f, 3.0f, 3.0f});
    assert_true(wall >= 0 && lamp >= 0);
    const float t = 0.1f;
    assert_true(lpv_scene_add_box(s, wall, (float[3]){-1 - t, -t, -1 - t}, (float[3]){1 + t, 0, 1 + t}) >= 0);
    assert_true(lpv_scene_add_box(s, wall, (float[3]){-1 - t, 2, -1 - t}, (float[3]){1 + t, 2 + t, 1 + t}) >= 0);
    assert_true(lpv_scene_add_box(s, wall, (float[3]){-1 - t, 0, -1 - t}, (float[3]){-1, 2, 1 + t}) >= 0);
    assert_true(lpv_scene_add_box(s, wall, (float[3]){1, 0, -1 - t}, (float[3]){1 + t, 2, 1 + t}) >= 0);
    assert_true(lpv_scene_add_box(s, wall, (float[3]){-1, 0, -1 - t}, (float[3]){1, 2, -1}) >= 0);
    assert_true(lpv_scene_add_box(s, wall, (float[3]){-1, 0, 1}, (float[3]){1, 2, 1 + t}) >= 0);
    /* a panel 1 cm under the ceiling, facing down */
    const float q[4][3] = {{-0.3f, 1.99f, -0.3f}, {0.3f, 1.99f, -0.3f}, {0.3f, 1.99f, 0.3f}, {-0.3f, 1.99f, 0.3f}};
    assert_true(lpv_scene_add_quad(s, lamp, q, NULL) >= 0);
    assert_non_null(lpv_scene_add_point_light(s, (float[3]){0.13f, 1.07f, -0.21f}, 10.0f));
    lpv_scene_compute_bounds(s);
}

static lpv_settings box_settings(int iterations, lpv_switch bounces, float intensity)
{
    lpv_settings s = {.technique = LPV_TECHNIQUE_ID_LPV};
    s.grid_dims[0] = s.grid_dims[1] = s.grid_dims[2] = DIM;
    s.rsm_size = 32;
    s.lpv.iterations = iterations;
    s.lpv.occlusion = LPV_SWITCH_ON;
    s.lpv.bounces = bounces;
    s.lpv.bounce_intensity = intensity;
    /* The panel's light must enter the LPV itself (as VPLs) for these tests,
     * which watch what the propagation does with it; with area lights on it
     * would light the box directly and only the walls' reflection would. */
    s.area_lights = LPV_SWITCH_OFF;
    return s;
}

static double total_flux(const lpv_cell *cells, size_t n)
{
    double f[3];
    lpv_grid g = {.dims = {(int)n, 1, 1}, .cell_size = 1.0f};
    lpv_oracle_total_flux(&g, cells, f);
    return f[0] + f[1] + f[2];
}

/* Ticks and returns the energy of the last step's output and (if acc) the accumulated volume's total flux;
 * checks every accumulated coefficient is finite and every DC >= 0. */
static double run(const lpv_scene *scene, lpv_settings s, double *acc_flux)
{
    char err[1024] = "";
    if (lpv_engine_set_settings(lpvt_engine, &s, err, sizeof err) != 0 ||
        lpv_engine_set_scene(lpvt_engine, scene, err, sizeof err) != 0 ||
        lpv_engine_set_view(lpvt_engine, NULL, err, sizeof err) != 0 || lpv_engine_tick(lpvt_engine, err, sizeof err) != 0)
        fail_msg("%s", err);
    const lpv_plan *p = lpv_engine_last_plan(lpvt_engine);
    assert_true(p->pass[LPV_PASS_GV].run);
    assert_int_equal(p->pass[LPV_PASS_BOUNCE].run, s.lpv.bounces == LPV_SWITCH_ON);
    size_t n = lpv_grid_cell_count(lpv_engine_grid(lpvt_engine)) * (size_t)lpv_engine_cascade_count(lpvt_engine);
    lpv_cell *acc = calloc(n, sizeof *acc), *last = calloc(n, sizeof *last);
    assert_int_equal(lpv_engine_read_grid(lpvt_engine, LPV_GRID_ACCUMULATED, acc, n), n);
    assert_int_equal(lpv_engine_read_grid(lpvt_engine, LPV_GRID_LAST_STEP, last, n), n);
    for (size_t i = 0; i < n; ++i) {
        const float *a = (const float *)&acc[i], *l = (const float *)&last[i];
        for (int k = 0; k < 12; ++k)
            assert_true(isfinite(a[k]) && isfinite(l[k]));
        assert_true(acc[i].r[0] >= 0.0f && acc[i].g[0] >= 0.0f && acc[i].b[0] >= 0.0f);
    }
    double e = total_flux(last, n);
    if (acc_flux)
        *acc_flux = total_flux(acc, n);
    free(acc);
    free(last);
    return e;
}

/* Step k's output (iterations = k) never carries more energy than step k - 1's: 1e-6 relative slack for float
 * rounding of the ~10^4 cell sums, as in test_gpu_stability.c. */
static void assert_non_increasing(float albedo, int steps)
{
    lpv_scene scene;
    build_box(&scene, albedo);
    double prev = INFINITY, first = 0.0, last = 0.0;
    for (int k = 1; k <= steps; ++k) {
        double e = run(&scene, box_settings(k, LPV_SWITCH_ON, 1.0f), NULL);
        assert_true(isfinite(e));
        if (!(e <= prev * (1.0 + 1e-6) + 1e-30))
            fail_msg("albedo %g: step %d carries %.9g W, step %d %.9g W", (double)albedo, k, e, k - 1, prev);
        if (k == 1)
            first = e;
        last = e;
        prev = e;
    }
    print_message("albedo %g, bounces on: step 1 %.5g W, step %d %.5g W\n", (double)albedo, first, steps, last);
    assert_true(first > 0.0);
    lpv_scene_free(&scene);
}

static void test_energy_bounded_albedo_1(void **state)
{
    (void)state;
    assert_non_increasing(1.0f, 64);
}

static void test_energy_bounded_albedo_half(void **state)
{
    (void)state;
    assert_non_increasing(0.5f, 32);
}

static void test_bounces_add_light(void **state)
{
    (void)state;
    enum { STEPS = 16 };
    lpv_scene white, black;
    build_box(&white, 1.0f);
    build_box(&black, 0.0f);
    double off, on, half;
    run(&white, box_settings(STEPS, LPV_SWITCH_OFF, 1.0f), &off);
    run(&white, box_settings(STEPS, LPV_SWITCH_ON, 1.0f), &on);
    run(&white, box_settings(STEPS, LPV_SWITCH_ON, 0.5f), &half);
    print_message("white walls, accumulated flux: bounces off %.5g, intensity 0.5 %.5g, on %.5g W\n", off, half, on);
    /* bounces add light: more than 1% more (a white closed box reflects a large share of what its walls block;
     * 1% is far above rounding yet far below the measured gain) */
    assert_true(on > off * 1.01);
    /* intensity 0.5 lies strictly between (same 1% margin on both sides) */
    assert_true(half > off * 1.01);
    assert_true(half < on / 1.01);

    /* black walls: nothing to reflect, so bounces change nothing (bit-identical: a zero reflectance is skipped) */
    double black_off, black_on;
    run(&black, box_settings(STEPS, LPV_SWITCH_OFF, 1.0f), &black_off);
    run(&black, box_settings(STEPS, LPV_SWITCH_ON, 1.0f), &black_on);
    print_message("black walls, accumulated flux: bounces off %.9g, on %.9g W\n", black_off, black_on);
    assert_true(black_off > 0.0); /* the panel's light is there */
    assert_true(black_on == black_off);
    lpv_scene_free(&white);
    lpv_scene_free(&black);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_energy_bounded_albedo_1),
        cmocka_unit_test(test_energy_bounded_albedo_half),
        cmocka_unit_test(test_bounces_add_light),
    };
    return cmocka_run_group_tests(tests, lpvt_gl_setup, lpvt_gl_teardown);
}
