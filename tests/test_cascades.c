/*
 * test_cascades.c - cascaded LPVs through the real GL pipeline (llvmpipe in
 * CI): a 20 m room is larger than the finest cascade (8 m), so the planner
 * uses 3 cascades of 16^3 cells (0.5, 1 and 2 m cells). Checks that the
 * engine places them where lpv_cascades_place says, that every cascade's
 * volume is sane, that the irradiance lookup is continuous across cascade
 * borders (the blend of lookup.glsl), and that a small object's light stays
 * out of the coarse cascades (paper section 4).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "cascades.h"
#include "context.h"
#include "engine.h"
#include "oracle.h"
#include "scene_build.h"
#include "test_util.h"

#define DIM 16

static lpv_settings room_settings(void)
{
    lpv_settings s = {0};
    s.technique = LPV_TECHNIQUE_ID_LPV; /* the LPV's cascades (the default is auto since issue 30) */
    s.grid_dims[0] = s.grid_dims[1] = s.grid_dims[2] = DIM;
    s.rsm_size = 64;
    s.lpv.iterations = 4;
    s.lpv.cascade_size = 8.0f; /* explicit: 0.5, 1 and 2 m cells */
    /* the cascaded-LPV paper's cascades: each holds its own injected light and the lookup blends them across
     * borders (far field off), one volume per cascade read with the plain SH lookup (normal bins off) */
    s.lpv.far_field = LPV_SWITCH_OFF;
    s.lpv.normal_bins = LPV_SWITCH_OFF;
    return s; /* cascades 0 = auto: 3, the room (20 m) being larger than 8 m */
}

/* A 20 m x 20 m floor with 4 m walls and two point lights; optionally a box
 * [lo, hi] of albedo box_albedo. */
static void build_room(lpv_scene *s, const float *lo, const float *hi, float box_albedo)
{
    memset(s, 0, sizeof *s);
    int grey = lpv_scene_add_material(s, "grey", (float[3]){0.6f, 0.6f, 0.6f}, NULL);
    int box = lpv_scene_add_material(s, "box", (float[3]){box_albedo, box_albedo, box_albedo}, NULL);
    assert_true(grey >= 0 && box >= 0);
    assert_true(lpv_scene_add_box(s, grey, (float[3]){-10, -0.2f, -10}, (float[3]){10, 0, 10}) >= 0);
    assert_true(lpv_scene_add_box(s, grey, (float[3]){-10.2f, 0, -10}, (float[3]){-10, 4, 10}) >= 0);
    assert_true(lpv_scene_add_box(s, grey, (float[3]){10, 0, -10}, (float[3]){10.2f, 4, 10}) >= 0);
    assert_true(lpv_scene_add_box(s, grey, (float[3]){-10, 0, -10.2f}, (float[3]){10, 4, -10}) >= 0);
    assert_true(lpv_scene_add_box(s, grey, (float[3]){-10, 0, 10}, (float[3]){10, 4, 10.2f}) >= 0);
    if (lo)
        assert_true(lpv_scene_add_box(s, box, lo, hi) >= 0);
    assert_non_null(lpv_scene_add_point_light(s, (float[3]){0, 2, 0}, 100.0f));
    /* a second light near cascade 1's border (x = 8) gives the field a gradient there that the 2 m cells of
     * cascade 2 render differently from cascade 1's 1 m cells */
    assert_non_null(lpv_scene_add_point_light(s, (float[3]){8.25f, 1.5f, 1.0f}, 50.0f));
    lpv_scene_compute_bounds(s);
}

static void load(const lpv_scene *scene, const lpv_settings *s, const lpv_view *v)
{
    char err[1024] = "";
    if (lpv_engine_set_settings(lpvt_engine, s, err, sizeof err) != 0 ||
        lpv_engine_set_scene(lpvt_engine, scene, err, sizeof err) != 0 ||
        lpv_engine_set_view(lpvt_engine, v, err, sizeof err) != 0 || lpv_engine_tick(lpvt_engine, err, sizeof err) != 0)
        fail_msg("%s", err);
}

static lpv_cell *read_all(lpv_grid_which which, size_t *count)
{
    int K = lpv_engine_cascade_count(lpvt_engine);
    size_t n = lpv_grid_cell_count(lpv_engine_cascade(lpvt_engine, 0)) * (size_t)K;
    lpv_cell *c = calloc(n, sizeof *c);
    assert_non_null(c);
    assert_int_equal(lpv_engine_read_grid(lpvt_engine, which, c, n), n);
    *count = n;
    return c;
}

static lpv_view room_view(void)
{
    lpv_view v;
    /* eye.x = 0.1: cascade 0 spans x in [-4, 4], cascade 1 [-8, 8], cascade 2 [-16, 16] */
    assert_int_equal(lpv_view_look_at((float[3]){0.1f, 1.5f, 3.0f}, (float[3]){0.1f, 1.5f, 0.0f}, 1.0f, 32, 32, &v),
                     0);
    return v;
}

/* Placement and volumes with the paper's cascades (departures = 0) and with the defaults' departures on (far
 * field: light handed from each cascade to the next; normal bins: read_grid returns the bins' sum). */
static void check_placement_and_volumes(int departures)
{
    lpv_scene scene;
    build_room(&scene, NULL, NULL, 0);
    lpv_settings s = room_settings();
    if (departures)
        s.lpv.far_field = s.lpv.normal_bins = LPV_SWITCH_DEFAULT;
    lpv_view v = room_view();
    load(&scene, &s, &v);
    assert_int_equal(lpv_engine_cascade_count(lpvt_engine), 3);
    assert_int_equal(lpv_engine_last_plan(lpvt_engine)->cascades, 3);
    lpv_settings r = *lpv_engine_settings(lpvt_engine);
    lpv_cascade_set want;
    assert_int_equal(lpv_cascades_place(&r, 3, scene.bounds_min, scene.bounds_max, v.eye, v.forward, 0.0f, &want), 0);
    for (int k = 0; k < 3; ++k) {
        const lpv_grid *g = lpv_engine_cascade(lpvt_engine, k);
        assert_memory_equal(g->dims, want.grid[k].dims, sizeof g->dims);
        assert_true(g->cell_size == want.grid[k].cell_size);      /* same code, same floats: exact */
        assert_memory_equal(g->origin, want.grid[k].origin, sizeof g->origin);
        assert_float_equal(g->cell_size, 0.5f * (float)(1 << k), 0.0f); /* 8 m / 16 x 2^k, exact in binary */
    }
    assert_memory_equal(lpv_engine_grid(lpvt_engine), lpv_engine_cascade(lpvt_engine, 0), sizeof(lpv_grid));

    size_t n;
    lpv_cell *acc = read_all(LPV_GRID_ACCUMULATED, &n);
    size_t per = n / 3;
    for (int k = 0; k < 3; ++k) {
        double dc = 0.0;
        for (size_t i = k * per; i < (k + 1) * per; ++i) {
            const float *f = (const float *)&acc[i];
            for (int j = 0; j < 12; ++j)
                assert_true(isfinite(f[j]));
            assert_true(acc[i].r[0] >= 0.0f && acc[i].g[0] >= 0.0f && acc[i].b[0] >= 0.0f);
            dc += acc[i].r[0];
        }
        print_message("%s: cascade %d: total red DC %.4g\n", departures ? "defaults" : "paper", k, dc);
        assert_true(dc > 0.0); /* every cascade received light */
    }
    free(acc);
    lpv_scene_free(&scene);
}

static void test_placement_and_volumes(void **state)
{
    (void)state;
    check_placement_and_volumes(0);
    check_placement_and_volumes(1);
    const lpv_settings *r = lpv_engine_settings(lpvt_engine);
    assert_int_equal(r->lpv.far_field, LPV_SWITCH_ON); /* the second run did check the departures */
    assert_int_equal(r->lpv.normal_bins, LPV_SWITCH_ON);
}

/* E (red) at p facing n from cascade k alone, on the CPU (techniques/lpv/core/oracle_lookup.c: the same lookup as lookup.glsl's
 * cascade_irradiance without damping). */
static float cascade_e(const lpv_cell *acc, int k, const float p[3], const float n[3])
{
    const lpv_grid *g = lpv_engine_cascade(lpvt_engine, k);
    float rgb[3];
    lpv_oracle_irradiance(g, acc + (size_t)k * lpv_grid_cell_count(g), p, n, rgb);
    return rgb[0];
}

/* Distance of p to cascade k's border in its cells. */
static float border_cells(int k, const float p[3])
{
    const lpv_grid *g = lpv_engine_cascade(lpvt_engine, k);
    float d = INFINITY;
    for (int i = 0; i < 3; ++i) {
        float q = p[i] / g->cell_size - g->origin[i] / g->cell_size;
        d = fminf(d, fminf(q, (float)g->dims[i] - q));
    }
    return d;
}

static void test_continuity_across_borders(void **state)
{
    (void)state;
    lpv_scene scene;
    build_room(&scene, NULL, NULL, 0);
    lpv_settings s = room_settings();
    lpv_view v = room_view();
    load(&scene, &s, &v);
    size_t n;
    lpv_cell *acc = read_all(LPV_GRID_ACCUMULATED, &n);

    /* A line along x at y = 1 m, z = 1 m (deep inside every cascade along y and z), from the centre of cascade 0
     * (x = 0) past cascade 1's border (x = 8) to x = 12, in steps of 5 cm (a tenth of cascade 0's cell), facing
     * down at the lit floor. */
    enum { N = 241 };
    const float dx = 0.05f;
    float *pts = calloc(N * 3, sizeof *pts), *nrm = calloc(N * 3, sizeof *nrm), *rgb = calloc(N * 3, sizeof *rgb);
    float *hard = calloc(N, sizeof *hard);
    for (int i = 0; i < N; ++i) {
        pts[3 * i] = dx * (float)i;
        pts[3 * i + 1] = 1.0f;
        pts[3 * i + 2] = 1.0f;
        nrm[3 * i + 1] = -1.0f;
    }
    char err[256];
    assert_int_equal(lpv_engine_irradiance(lpvt_engine, pts, nrm, N, rgb, err, sizeof err), 0);

    /* The CPU mirror of lookup.glsl's blend, to check the engine does what we model (1e-4 relative + 1e-6
     * absolute: GPU vs CPU float rounding of the same ~20 multiply-adds), and a hard switch at the middle of each
     * blend zone (the finest cascade where the point is more than 2 of its cells from its border) - what the
     * lookup would give without blending. */
    double max_e = 0.0;
    for (int i = 0; i < N; ++i) {
        const float *p = pts + 3 * i, *nn = nrm + 3 * i;
        float e = 0.0f, remaining = 1.0f;
        int hard_k = 2;
        for (int k = 0; k < 3 && remaining > 0.0f; ++k) {
            float w = k == 2 ? 1.0f : fminf(fmaxf((border_cells(k, p) - 1.0f) * 0.5f, 0.0f), 1.0f);
            if (w > 0.0f)
                e += remaining * w * cascade_e(acc, k, p, nn);
            remaining *= 1.0f - w;
        }
        for (int k = 1; k >= 0; --k)
            if (border_cells(k, p) > 2.0f)
                hard_k = k;
        hard[i] = cascade_e(acc, hard_k, p, nn);
        assert_true(isfinite(rgb[3 * i]) && rgb[3 * i] >= 0.0f);
        assert_float_equal(rgb[3 * i], e, 1e-4f * fabsf(e) + 1e-6f);
        max_e = fmax(max_e, rgb[3 * i]);
    }
    assert_true(max_e > 0.0);

    /* The criterion: second differences (the change of the step from one 5 cm step to the next, d_i - d_(i-1)).
     * Each cascade alone is trilinear, piecewise linear along the line, so its second differences are small: a
     * slope change at a cell centre times the step. The blend w(x) is linear over two cells, so it adds at most
     * (dx / 2 cells) * J = J / 20 at the two ends of the blend zone, J being the two cascades' disagreement;
     * a hard switch puts all of J into one step. Bound per border: the largest second difference of the two
     * cascades' own profiles over the blend zone +- half a cell (the "natural" kinks) plus J / 4 (5x the J / 20 a
     * blend adds). The hard-switch profile computed from the same volumes must break that bound (checked below),
     * so the bound tells a blend from a switch. */
    float *ek[3];
    for (int k = 0; k < 3; ++k) {
        ek[k] = calloc(N, sizeof(float));
        for (int i = 0; i < N; ++i)
            ek[k][i] = cascade_e(acc, k, pts + 3 * i, nrm + 3 * i);
    }
    for (int b = 0; b < 2; ++b) {
        const float xb = b == 0 ? 4.0f : 8.0f; /* cascade b's +x border */
        const float cell = lpv_engine_cascade(lpvt_engine, b)->cell_size;
        const float xs = xb - 2.0f * cell; /* the hard switch: 2 cells inside, the middle of the blend zone */
        double natural = 0.0, blended = 0.0, switched = 0.0, J = 0.0;
        for (int i = 2; i < N; ++i) {
            /* the window: the blend zone (1..3 cells inside) and half a cell either side */
            if (pts[3 * i] < xb - 3.5f * cell || pts[3 * i] > xb - 0.5f * cell)
                continue;
            natural = fmax(natural, fabs((double)ek[b][i] - 2.0 * ek[b][i - 1] + ek[b][i - 2]));
            natural = fmax(natural, fabs((double)ek[b + 1][i] - 2.0 * ek[b + 1][i - 1] + ek[b + 1][i - 2]));
            blended = fmax(blended, fabs((double)rgb[3 * i] - 2.0 * rgb[3 * (i - 1)] + rgb[3 * (i - 2)]));
            switched = fmax(switched, fabs((double)hard[i] - 2.0 * hard[i - 1] + hard[i - 2]));
            if (fabsf(pts[3 * i] - xs) < 0.5f * dx)
                J = fabs((double)ek[b][i] - ek[b + 1][i]);
        }
        const double bound = natural + 0.25 * J;
        print_message("border %d (x = %g): J %.4g, natural %.4g, bound %.4g; blended %.4g, hard switch %.4g\n", b,
                      (double)xb, J, natural, bound, blended, switched);
        assert_true(J > 0.0);
        assert_true(blended <= bound);
        assert_true(switched > bound);
    }
    for (int k = 0; k < 3; ++k)
        free(ek[k]);
    free(pts);
    free(nrm);
    free(rgb);
    free(hard);
    free(acc);
    lpv_scene_free(&scene);
}

/* Injected volume of the room with a box of the given size above the light, lit from below, albedo 1 or 0: the
 * geometry (and so every shadow) is the same, only the box's reflected light differs. */
static lpv_cell *injected_with_box(float half, float albedo, size_t *n)
{
    lpv_scene scene;
    const float lo[3] = {-half, 2.4f, -half}, hi[3] = {half, 2.5f, half};
    build_room(&scene, lo, hi, albedo);
    lpv_settings s = room_settings();
    load(&scene, &s, NULL);
    assert_int_equal(lpv_engine_cascade_count(lpvt_engine), 3);
    lpv_cell *c = read_all(LPV_GRID_INJECTED, n);
    lpv_scene_free(&scene);
    return c;
}

/* Sum over cascade k of |a - b| (all 12 floats) and of |a|. */
static void cascade_diff(const lpv_cell *a, const lpv_cell *b, size_t per, int k, double *diff, double *norm)
{
    *diff = *norm = 0.0;
    const float *fa = (const float *)(a + (size_t)k * per), *fb = (const float *)(b + (size_t)k * per);
    for (size_t i = 0; i < per * 12; ++i) {
        *diff += fabs((double)fa[i] - fb[i]);
        *norm += fabs((double)fa[i]);
    }
}

static void test_small_object_skips_coarse_cascades(void **state)
{
    (void)state;
    size_t n;
    /* 10 cm box: smaller than one cell of cascade 1 (1 m) and 2 (2 m), so weight 0 there */
    lpv_cell *lit = injected_with_box(0.05f, 1.0f, &n), *dark = injected_with_box(0.05f, 0.0f, &n);
    size_t per = n / 3;
    double d[3], norm[3];
    for (int k = 0; k < 3; ++k)
        cascade_diff(lit, dark, per, k, &d[k], &norm[k]);
    print_message("small box: |lit - dark| per cascade %.4g %.4g %.4g (of %.4g %.4g %.4g)\n", d[0], d[1], d[2],
                  norm[0], norm[1], norm[2]);
    /* cascade 0 gets the box's light: more than 1e-4 of the cascade's total, i.e. far above rounding (the box
     * reflects a few % of the light's power; identical inputs give identical sums) */
    assert_true(d[0] > 1e-4 * norm[0]);
    /* cascades 1 and 2 drop it entirely: same inputs otherwise, so bit-identical */
    assert_true(d[1] == 0.0);
    assert_true(d[2] == 0.0);
    free(lit);
    free(dark);

    /* Control: a 6 m slab (3 cells of cascade 2) is kept in every cascade, so the check above is not vacuous. */
    lit = injected_with_box(3.0f, 1.0f, &n);
    dark = injected_with_box(3.0f, 0.0f, &n);
    for (int k = 0; k < 3; ++k)
        cascade_diff(lit, dark, per, k, &d[k], &norm[k]);
    print_message("6 m slab: |lit - dark| per cascade %.4g %.4g %.4g\n", d[0], d[1], d[2]);
    for (int k = 0; k < 3; ++k)
        assert_true(d[k] > 1e-4 * norm[k]);
    free(lit);
    free(dark);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_placement_and_volumes),
        cmocka_unit_test(test_continuity_across_borders),
        cmocka_unit_test(test_small_object_skips_coarse_cascades),
    };
    return cmocka_run_group_tests(tests, lpvt_gl_setup, lpvt_gl_teardown);
}
