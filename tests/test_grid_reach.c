/*
 * test_grid_reach.c - issue 30: a finer grid must not darken the frame. The
 * light moves about a cell per propagation step, so a fixed step count at a
 * finer grid stops short of the far walls (`--grid 64` kept the preset's 8
 * steps and a dining room went half black). The built-in Cornell box's
 * indirect-only frame at grid 16, 32 and 64, iterations unset: where the
 * grid-16 frame is lit, at most half the pixels may go black, and the mean
 * may not fall under 0.7 x grid 16's. Without occlusion the scaled step
 * count keeps the mean within 10 % at every grid (the propagation alone
 * neither gains nor loses light with the cell count); with it (the
 * default) grid 64 still loses more: the geometry volume's fuzzy occlusion
 * takes more from light that crosses 64 cells than 16 (docs/propagation.md,
 * "Iterations follow the grid"), so the test asks 0.65 x at grid 32 (0.70 measured) and 0.3 x at 64, three
 * times what a fixed 8 steps gave (0.10 x).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "engine.h"
#include "scene.h"
#include "test_util.h"

enum { W = 48, H = 48 };

static float luminance(const float *p) { return 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2]; }

/* The Cornell box's indirect-only frame at grid n^3, every other knob unset
 * but occlusion. */
static void render_grid(const lpv_scene *scene, int n, lpv_switch occlusion, float *rgba)
{
    char err[1024] = "";
    lpv_view view;
    lpv_view_from_camera(&scene->cameras[0], W, H, &view);
    /* the LPV's grid and propagation (the default technique is auto since issue 30) */
    const lpv_settings s = {.technique = LPV_TECHNIQUE_ID_LPV, .grid_dims = {n, n, n}, .lpv.occlusion = occlusion};
    if (lpv_engine_set_settings(lpvt_engine, &s, err, sizeof err) ||
        lpv_engine_set_scene(lpvt_engine, scene, err, sizeof err) ||
        lpv_engine_set_view(lpvt_engine, &view, err, sizeof err) || lpv_engine_tick(lpvt_engine, err, sizeof err) ||
        lpv_engine_render(lpvt_engine, LPV_TERMS_INDIRECT_ONLY, rgba, err, sizeof err))
        fail_msg("%s", err);
    const lpv_plan *p = lpv_engine_last_plan(lpvt_engine);
    print_message("grid %d, occlusion %s: %s\n", n, occlusion == LPV_SWITCH_OFF ? "off" : "on",
                  p ? p->iterations_reason : "(no plan)");
}

/* min_mean[k]: the least mean over grid 16's for grids 32 and 64. */
static void check_grids(lpv_switch occlusion, const double min_mean[2])
{
    lpv_scene scene;
    assert_int_equal(lpv_scene_builtin_cornell(&scene), 0);
    const size_t px = (size_t)W * H;
    float *ref = calloc(px * 4, sizeof *ref), *img = calloc(px * 4, sizeof *img);
    assert_non_null(ref);
    assert_non_null(img);
    render_grid(&scene, 16, occlusion, ref);
    double ref_sum = 0.0;
    size_t lit = 0;
    for (size_t i = 0; i < px; ++i)
        ref_sum += luminance(ref + 4 * i);
    const double ref_mean = ref_sum / (double)px;
    assert_true(ref_mean > 0.0);
    /* lit: over a tenth of the frame's mean; black: under a hundredth of it */
    for (size_t i = 0; i < px; ++i)
        lit += luminance(ref + 4 * i) > 0.1 * ref_mean;
    assert_true(lit > px / 4);
    const int grids[] = {32, 64};
    for (size_t g = 0; g < sizeof grids / sizeof grids[0]; ++g) {
        render_grid(&scene, grids[g], occlusion, img);
        double sum = 0.0;
        size_t black = 0;
        for (size_t i = 0; i < px; ++i) {
            const float y = luminance(img + 4 * i);
            sum += y;
            black += luminance(ref + 4 * i) > 0.1 * ref_mean && y < 0.01 * ref_mean;
        }
        const double mean = sum / (double)px, black_share = (double)black / (double)lit;
        print_message("grid %d: mean %.4g (grid 16: %.4g, ratio %.3f), black where grid 16 is lit: %.1f %%\n",
                      grids[g], mean, ref_mean, mean / ref_mean, 100.0 * black_share);
        assert_true(black_share <= 0.5);
        assert_true(mean >= min_mean[g] * ref_mean);
    }
    free(ref);
    free(img);
    lpv_scene_free(&scene);
}

/* The default settings (occlusion on). */
static void test_finer_grids_stay_lit(void **state)
{
    (void)state;
    const double min_mean[2] = {0.65, 0.3}; /* measured 0.70 and 0.35 */
    check_grids(LPV_SWITCH_DEFAULT, min_mean);
}

/* The propagation alone: the light's total does not depend on the grid. */
static void test_finer_grids_keep_the_light_without_occlusion(void **state)
{
    (void)state;
    const double min_mean[2] = {0.9, 0.9};
    check_grids(LPV_SWITCH_OFF, min_mean);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_finer_grids_stay_lit),
        cmocka_unit_test(test_finer_grids_keep_the_light_without_occlusion),
    };
    return cmocka_run_group_tests(tests, lpvt_gl_setup, lpvt_gl_teardown);
}
