/*
 * test_gpu_oracle.c - the GPU pipeline against the plain-C oracle.
 *
 * The built-in Cornell box is ticked on the GPU (llvmpipe in CI); the VPLs
 * and surfels the GPU produced are read back and fed to the oracle, and each
 * grid the GPU built (injected LPV, geometry volume, transmittances,
 * accumulated LPV) must match the oracle's within a stated tolerance:
 * |gpu - oracle| <= 1e-4 * max|oracle| + 1e-5 * |oracle| per value.
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
#include "scene_planes.h"
#include "scene.h"
#include "test_util.h"

typedef struct fixture {
    lpv_gl_context *ctx;
    lpv_engine *engine;
    lpv_scene scene;
} fixture;

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    *state = f;
    if (lpvt_gl_open(&f->ctx, &f->engine) != 0)
        return -1;
    return lpv_scene_builtin_cornell(&f->scene);
}

static int teardown(void **state)
{
    fixture *f = *state;
    lpvt_gl_close(f->ctx, f->engine);
    lpv_scene_free(&f->scene);
    free(f);
    return 0;
}

/* The oracle follows the paper's pipeline; a test that wants a departure
 * (central transport, normal bins) sets it, the rest stay off here. */
static lpv_settings paper_unless_set(const lpv_settings *in)
{
    lpv_settings s = *in;
    lpv_switch *sw[] = {&s.lpv.central_transport, &s.lpv.normal_bins, &s.lpv.far_field, &s.scene_surfels};
    for (size_t i = 0; i < sizeof sw / sizeof sw[0]; ++i)
        if (*sw[i] == LPV_SWITCH_DEFAULT)
            *sw[i] = LPV_SWITCH_OFF;
    return s;
}

static void tick(fixture *f, const lpv_settings *in, int with_view)
{
    char err[1024] = "";
    lpv_settings s0 = paper_unless_set(in);
    const lpv_settings *s = &s0;
    assert_int_equal(lpv_engine_set_settings(f->engine, s, err, sizeof err), 0);
    assert_int_equal(lpv_engine_set_scene(f->engine, &f->scene, err, sizeof err), 0);
    lpv_view view;
    lpv_view_from_camera(&f->scene.cameras[0], 48, 48, &view);
    assert_int_equal(lpv_engine_set_view(f->engine, with_view ? &view : NULL, err, sizeof err), 0);
    if (lpv_engine_tick(f->engine, err, sizeof err) != 0)
        fail_msg("tick: %s", err);
}

/* Compares n floats; returns the worst error relative to the tolerance. */
static void assert_close(const char *what, const float *gpu, const float *ref, size_t n)
{
    double max_ref = 0.0;
    for (size_t i = 0; i < n; ++i)
        if (fabs(ref[i]) > max_ref)
            max_ref = fabs(ref[i]);
    assert_true(max_ref > 0.0); /* the comparison must be about something */
    size_t worst = 0;
    double worst_ratio = 0.0;
    for (size_t i = 0; i < n; ++i) {
        assert_true(isfinite(gpu[i]));
        double tol = 1e-4 * max_ref + 1e-5 * fabs(ref[i]);
        double ratio = fabs((double)gpu[i] - ref[i]) / tol;
        if (ratio > worst_ratio) {
            worst_ratio = ratio;
            worst = i;
        }
    }
    printf("%s: %zu values, max |ref| %.4g, worst error %.3g of tolerance (at %zu: gpu %.6g ref %.6g)\n", what, n,
           max_ref, worst_ratio, worst, gpu[worst], ref[worst]);
    if (worst_ratio > 1.0)
        fail_msg("%s differs from the oracle at %zu: gpu %.9g oracle %.9g", what, worst, gpu[worst], ref[worst]);
}

/* A tick of the built-in box at 16^3 without occlusion (smooth: the
 * setting smooth_injection), its VPLs (at most vmax) and its injected
 * grid read back; the VPL count in *nv, the grid's cells in *cells. */
static void injected_tick(fixture *f, int smooth, lpv_vpl **vpls, size_t vmax, size_t *nv, lpv_cell **gpu,
                          size_t *cells)
{
    lpv_settings s = {.technique = LPV_TECHNIQUE_ID_LPV, .grid_dims = {16, 16, 16}, .rsm_size = 64,
                      .lpv.iterations = 4, .lpv.occlusion = LPV_SWITCH_OFF,
                      .lpv.smooth_injection = smooth ? LPV_SWITCH_ON : LPV_SWITCH_OFF};
    tick(f, &s, 0);
    *cells = lpv_grid_cell_count(lpv_engine_grid(f->engine));
    *vpls = calloc(vmax, sizeof **vpls);
    *nv = lpv_engine_read_vpls(f->engine, *vpls, vmax);
    *gpu = calloc(*cells, sizeof **gpu);
    assert_int_equal(lpv_engine_read_grid(f->engine, LPV_GRID_INJECTED, *gpu, *cells), *cells);
}

static void test_injection_matches_oracle(void **state)
{
    fixture *f = *state;
    /* the spot's RSM layer and the 8 area light samples' 40 faces as 32^2
     * tiles, 4 to a layer (docs/area-lights.md): 11 layers of 64^2; a slot
     * per texel in the spot's layer and the 2 holding the first sample's
     * faces (blocks of 2 x 2 texels, 4 slots), half that in the other 8,
     * which give VPLs only (blocks of 4 x 4, 8 slots: LPV_RSM_AUTO_VPL_STEP) */
    lpv_vpl *vpls;
    lpv_cell *gpu;
    size_t nv, cells;
    injected_tick(f, 0, &vpls, 64 * 64 * 16, &nv, &gpu, &cells);
    const lpv_grid *g = lpv_engine_grid(f->engine);
    assert_int_equal(lpv_engine_last_stats(f->engine)->area_lights, 8);
    assert_int_equal(nv, 64 * 64 * 3 + 64 * 64 * 8 / 2);
    lpv_cell *ref = calloc(cells, sizeof *ref);
    size_t injected = lpv_oracle_inject_vpls(g, vpls, nv, ref);
    assert_true(injected > 1000);
    assert_close("injected LPV", (const float *)gpu, (const float *)ref, cells * 12);
    free(vpls);
    free(gpu);
    free(ref);
}

/* Smooth injection (settings lpv.smooth_injection): the GPU's four points
 * a VPL against the oracle's bilinear stencil, on the same VPLs (the RSMs'
 * groups, keyed by the stencil); and not the point splat's volume. */
static void test_smooth_injection_matches_oracle(void **state)
{
    fixture *f = *state;
    lpv_vpl *vpls;
    lpv_cell *gpu;
    size_t nv, cells;
    injected_tick(f, 1, &vpls, 64 * 64 * 16, &nv, &gpu, &cells);
    const lpv_grid *g = lpv_engine_grid(f->engine);
    assert_true(nv > 1000);
    lpv_cell *ref = calloc(cells, sizeof *ref), *point = calloc(cells, sizeof *point);
    assert_true(lpv_oracle_inject_vpls_spread(g, vpls, nv, ref) > 1000);
    assert_close("injected LPV, smooth injection", (const float *)gpu, (const float *)ref, cells * 12);
    /* the same VPLs as point splats differ by much more than the tolerance */
    lpv_oracle_inject_vpls(g, vpls, nv, point);
    double diff = 0.0, top = 0.0;
    for (size_t i = 0; i < cells * 12; ++i) {
        diff = fmax(diff, fabs((double)((const float *)point)[i] - ((const float *)ref)[i]));
        top = fmax(top, fabs((double)((const float *)ref)[i]));
    }
    printf("point splats against the smooth injection: largest difference %.3g of the largest value\n", diff / top);
    assert_true(diff > 0.05 * top);
    free(vpls);
    free(gpu);
    free(ref);
    free(point);
}

/* The blocking of n GV points, LPV_DIR_COUNT floats each. */
static float *blocking_of(const lpv_gv_point *gv, size_t n)
{
    float *b = calloc(n * LPV_DIR_COUNT, sizeof *b);
    for (size_t i = 0; i < n; ++i)
        for (int d = 0; d < LPV_DIR_COUNT; ++d)
            b[i * LPV_DIR_COUNT + d] = gv[i].blocking[d / 4][d % 4];
    return b;
}

static void test_geometry_volume_matches_oracle(void **state)
{
    fixture *f = *state;
    lpv_settings s = {.technique = LPV_TECHNIQUE_ID_LPV, .grid_dims = {16, 16, 16}, .rsm_size = 64, .lpv.iterations = 4, .lpv.occlusion = LPV_SWITCH_ON};
    tick(f, &s, 1);
    const lpv_grid *g = lpv_engine_grid(f->engine);
    size_t gv_n = lpv_grid_gv_count(g), cells = lpv_grid_cell_count(g);
    lpv_gv_point *ref = calloc(gv_n, sizeof *ref), *gpu = calloc(gv_n, sizeof *gpu);
    vec4 *tmp = calloc(gv_n, sizeof *tmp);
    float *dc = calloc(gv_n, sizeof *dc); /* the largest DC term of any buffer: the albedo's owner */
    size_t smax = 64 * 64 * 16;
    lpv_surfel *surfels = calloc(smax, sizeof *surfels);
    size_t buffers = lpv_engine_gv_buffer_count(f->engine);
    assert_int_equal(buffers, 3); /* the spot light's RSM, the area light samples' RSMs and the camera */
    for (size_t b = 0; b < buffers; ++b) {
        size_t n = lpv_engine_read_surfels(f->engine, b, surfels, smax);
        assert_true(n > 0);
        memset(tmp, 0, gv_n * sizeof *tmp);
        assert_true(lpv_oracle_inject_surfels(g, surfels, n, tmp) > 100);
        lpv_oracle_gv_merge(g, tmp, ref);
        for (size_t i = 0; i < gv_n; ++i)
            dc[i] = fmaxf(dc[i], tmp[i][0]);
    }
    assert_int_equal(lpv_engine_read_gv(f->engine, gpu, gv_n), gv_n);
    float *b_gpu = blocking_of(gpu, gv_n), *b_ref = blocking_of(ref, gv_n), *dc_gpu = calloc(gv_n, sizeof *dc_gpu);
    assert_close("geometry volume blocking", b_gpu, b_ref, gv_n * LPV_DIR_COUNT);
    size_t surfaced = 0;
    for (size_t i = 0; i < gv_n; ++i) {
        dc_gpu[i] = gpu[i].albedo[3];
        for (int k = 0; k < 3; ++k)
            assert_true(gpu[i].albedo[k] >= 0.0f && gpu[i].albedo[k] <= 1.0f);
        surfaced += gpu[i].albedo[3] > 0.0f && gpu[i].albedo[1] > 0.0f;
    }
    assert_close("geometry volume albedo's DC term", dc_gpu, dc, gv_n);
    assert_true(surfaced > 100); /* the walls' albedo is there for the bounces */

    /* Transmittances from the GPU's GV: only the arithmetic is compared. */
    float *t_gpu = calloc(cells * 6, sizeof *t_gpu), *t_ref = calloc(cells * 6, sizeof *t_ref);
    assert_int_equal(lpv_engine_read_transmittance(f->engine, t_gpu, cells * 6), cells * 6);
    lpv_oracle_transmittance(g, gpu, t_ref);
    size_t blocked = 0;
    for (size_t i = 0; i < cells * 6; ++i) {
        assert_true(t_gpu[i] >= 0.0f && t_gpu[i] <= 1.0f);
        assert_true(fabsf(t_gpu[i] - t_ref[i]) <= 1e-5f);
        blocked += t_ref[i] < 0.5f;
    }
    assert_true(blocked > 50); /* the box's walls do block */
    free(ref);
    free(tmp);
    free(gpu);
    free(dc);
    free(dc_gpu);
    free(b_gpu);
    free(b_ref);
    free(surfels);
    free(t_gpu);
    free(t_ref);
}

static void check_propagation(fixture *f, lpv_switch occlusion, int iterations)
{
    lpv_settings s = {.technique = LPV_TECHNIQUE_ID_LPV, .grid_dims = {16, 16, 16}, .rsm_size = 64, .lpv.iterations = iterations,
                      .lpv.occlusion = occlusion};
    tick(f, &s, 1);
    const lpv_grid *g = lpv_engine_grid(f->engine);
    size_t cells = lpv_grid_cell_count(g);
    lpv_cell *inj = calloc(cells, sizeof *inj), *gpu = calloc(cells, sizeof *gpu), *ref = calloc(cells, sizeof *ref);
    float *t = NULL;
    assert_int_equal(lpv_engine_read_grid(f->engine, LPV_GRID_INJECTED, inj, cells), cells);
    assert_int_equal(lpv_engine_read_grid(f->engine, LPV_GRID_ACCUMULATED, gpu, cells), cells);
    if (occlusion == LPV_SWITCH_ON) {
        t = calloc(cells * 6, sizeof *t);
        assert_int_equal(lpv_engine_read_transmittance(f->engine, t, cells * 6), cells * 6);
    }
    assert_int_equal(lpv_oracle_propagate(g, inj, t, iterations, ref), 0);
    char what[64];
    snprintf(what, sizeof what, "accumulated LPV (%d steps, occlusion %s)", iterations,
             occlusion == LPV_SWITCH_ON ? "on" : "off");
    assert_close(what, (const float *)gpu, (const float *)ref, cells * 12);
    free(inj);
    free(gpu);
    free(ref);
    free(t);
}

static void test_propagation_matches_oracle(void **state)
{
    check_propagation(*state, LPV_SWITCH_OFF, 8);
    check_propagation(*state, LPV_SWITCH_ON, 8);
    check_propagation(*state, LPV_SWITCH_ON, 1);
}

/* The lookup: GPU irradiance queries against lpv_oracle_irradiance on the
 * GPU's own accumulated grid, at points inside, on the edge and outside the
 * grid, with axis-aligned, oblique and degenerate normals. */
static void test_lookup_matches_oracle(void **state)
{
    fixture *f = *state;
    lpv_settings s = {.technique = LPV_TECHNIQUE_ID_LPV, .grid_dims = {16, 16, 16}, .rsm_size = 64, .lpv.iterations = 8};
    tick(f, &s, 1);
    const lpv_grid *g = lpv_engine_grid(f->engine);
    size_t cells = lpv_grid_cell_count(g);
    lpv_cell *acc = calloc(cells, sizeof *acc);
    assert_int_equal(lpv_engine_read_grid(f->engine, LPV_GRID_ACCUMULATED, acc, cells), cells);
    enum { N = 500 };
    float p[N * 3], n[N * 3], gpu[N * 3], ref[N * 3];
    unsigned seed = 12345;
    for (int i = 0; i < N; ++i) {
        for (int k = 0; k < 3; ++k) {
            seed = seed * 1664525u + 1013904223u;
            float u = (float)(seed >> 8) / 16777216.0f;
            p[i * 3 + k] = -1.3f + 3.6f * u; /* the box spans about -1..1 x 0..2 x -1..1 */
            seed = seed * 1664525u + 1013904223u;
            n[i * 3 + k] = (float)(seed >> 8) / 8388608.0f - 1.0f;
        }
        if (i % 7 == 0) { /* the six axis normals (lookup.glsl's u_lpv_normals), some not of unit length */
            n[i * 3] = n[i * 3 + 1] = n[i * 3 + 2] = 0.0f;
            n[i * 3 + (i / 7) % 3] = ((i / 21) % 2 == 0 ? 1.0f : -1.0f) * (i % 4 == 0 ? 2.5f : 1.0f);
        }
        if (i == 3)
            n[9] = n[10] = n[11] = 0.0f; /* degenerate normal: 0 */
    }
    char err[256];
    assert_int_equal(lpv_engine_irradiance(f->engine, p, n, N, gpu, err, sizeof err), 0);
    for (int i = 0; i < N; ++i)
        lpv_oracle_irradiance(g, acc, &p[i * 3], &n[i * 3], &ref[i * 3]);
    assert_true(gpu[9] == 0.0f && gpu[10] == 0.0f && gpu[11] == 0.0f);
    assert_close("irradiance lookup", gpu, ref, N * 3);
    free(acc);
}

/* Central transport (docs/propagation.md section 4b): the GPU's steps with
 * the central band-1 rows against the oracle's, with and without occlusion;
 * and they must differ from the paper's (the setting reaches the shader). */
static void test_central_transport_matches_oracle(void **state)
{
    fixture *f = *state;
    for (int occ = 0; occ < 2; ++occ) {
        lpv_settings s = {.technique = LPV_TECHNIQUE_ID_LPV, .grid_dims = {16, 16, 16}, .rsm_size = 64, .lpv.iterations = 6,
                          .lpv.occlusion = occ ? LPV_SWITCH_ON : LPV_SWITCH_OFF,
                          .lpv.central_transport = LPV_SWITCH_ON};
        tick(f, &s, 1);
        const lpv_grid *g = lpv_engine_grid(f->engine);
        size_t cells = lpv_grid_cell_count(g);
        lpv_cell *inj = calloc(cells, sizeof *inj), *gpu = calloc(cells, sizeof *gpu),
                 *ref = calloc(cells, sizeof *ref), *paper = calloc(cells, sizeof *paper);
        float *t = occ ? calloc(cells * 6, sizeof *t) : NULL;
        assert_int_equal(lpv_engine_read_grid(f->engine, LPV_GRID_INJECTED, inj, cells), cells);
        assert_int_equal(lpv_engine_read_grid(f->engine, LPV_GRID_ACCUMULATED, gpu, cells), cells);
        if (t)
            assert_int_equal(lpv_engine_read_transmittance(f->engine, t, cells * 6), cells * 6);
        assert_int_equal(lpv_oracle_propagate_with(g, inj, t, 6, LPV_TRANSPORT_CENTRAL, ref), 0);
        assert_int_equal(lpv_oracle_propagate_with(g, inj, t, 6, LPV_TRANSPORT_PAPER, paper), 0);
        assert_close(occ ? "accumulated LPV, central transport, occlusion on"
                         : "accumulated LPV, central transport, occlusion off",
                     (const float *)gpu, (const float *)ref, cells * 12);
        double diff = 0.0;
        for (size_t i = 0; i < cells * 12; ++i)
            diff += fabs((double)((const float *)paper)[i] - ((const float *)gpu)[i]);
        assert_true(diff > 1e-3); /* not the paper's transport */
        free(inj);
        free(gpu);
        free(ref);
        free(paper);
        free(t);
    }
}

/* Normal bins (docs/propagation.md section 6b): each bin's injected and
 * accumulated volume against the oracle's binned injection and propagation,
 * read_grid is their sum, and GPU irradiance queries against
 * lpv_oracle_irradiance_binned. */
static void test_normal_bins_match_oracle(void **state)
{
    fixture *f = *state;
    lpv_settings s = {.technique = LPV_TECHNIQUE_ID_LPV, .grid_dims = {12, 12, 12}, .rsm_size = 64, .lpv.iterations = 5,
                      .lpv.occlusion = LPV_SWITCH_ON,
                      .lpv.normal_bins = LPV_SWITCH_ON, .lpv.central_transport = LPV_SWITCH_ON};
    tick(f, &s, 1);
    assert_int_equal(lpv_engine_bins(f->engine), LPV_NORMAL_BINS);
    const lpv_grid *g = lpv_engine_grid(f->engine);
    const size_t cells = lpv_grid_cell_count(g), all = cells * LPV_NORMAL_BINS;
    size_t vmax = 64 * 64 * 16;
    lpv_vpl *vpls = calloc(vmax, sizeof *vpls);
    size_t nv = lpv_engine_read_vpls(f->engine, vpls, vmax);
    lpv_cell *gpu = calloc(all, sizeof *gpu), *ref = calloc(all, sizeof *ref), *acc = calloc(all, sizeof *acc),
             *sum = calloc(cells, sizeof *sum);
    float *t = calloc(cells * 6, sizeof *t);
    assert_int_equal(lpv_engine_read_volumes(f->engine, LPV_GRID_INJECTED, gpu, all), all);
    assert_true(lpv_oracle_inject_vpls_binned(g, vpls, nv, ref) > 1000);
    assert_close("injected LPV, 6 normal bins", (const float *)gpu, (const float *)ref, all * 12);
    int used = 0; /* the box's walls face five ways: five bins hold light */
    for (int b = 0; b < LPV_NORMAL_BINS; ++b) {
        double flux[3];
        lpv_oracle_total_flux(g, ref + (size_t)b * cells, flux);
        used += flux[0] > 0.0;
    }
    assert_true(used >= 4);

    assert_int_equal(lpv_engine_read_transmittance(f->engine, t, cells * 6), cells * 6);
    for (int b = 0; b < LPV_NORMAL_BINS; ++b)
        assert_int_equal(lpv_oracle_propagate_with(g, ref + (size_t)b * cells, t, 5, LPV_TRANSPORT_CENTRAL,
                                                   ref + (size_t)b * cells),
                         0);
    assert_int_equal(lpv_engine_read_volumes(f->engine, LPV_GRID_ACCUMULATED, acc, all), all);
    assert_close("accumulated LPV, 6 normal bins", (const float *)acc, (const float *)ref, all * 12);

    /* read_grid returns the physical field: the sum of the bins */
    assert_int_equal(lpv_engine_read_grid(f->engine, LPV_GRID_ACCUMULATED, sum, cells), cells);
    for (size_t i = 0; i < cells; ++i)
        for (int k = 0; k < 4; ++k) {
            double want = 0.0;
            for (int b = 0; b < LPV_NORMAL_BINS; ++b)
                want += acc[(size_t)b * cells + i].r[k];
            assert_true(fabs(sum[i].r[k] - want) <= 1e-5 * (fabs(want) + 1e-3));
        }

    /* the box's slanted walls and block sides: the lookup's plane normals
     * (core/scene_planes.h), read from their own irradiance volumes */
    float planes[LPV_MAX_LOOKUP_PLANES][3];
    const int plane_count = lpv_scene_plane_normals(&f->scene, planes, LPV_MAX_LOOKUP_PLANES);
    assert_int_equal(plane_count, 14);
    enum { N = 400 };
    float p[N * 3], n[N * 3], gq[N * 3], rq[N * 3];
    unsigned seed = 777;
    for (int i = 0; i < N; ++i) {
        for (int k = 0; k < 3; ++k) {
            seed = seed * 1664525u + 1013904223u;
            p[i * 3 + k] = -1.0f + 2.0f * (float)(seed >> 8) / 16777216.0f + (k == 1 ? 1.0f : 0.0f);
            seed = seed * 1664525u + 1013904223u;
            n[i * 3 + k] = (float)(seed >> 8) / 8388608.0f - 1.0f;
        }
        if (i % 5 == 0) { /* the walls' own normals, where the bins matter most */
            n[i * 3] = n[i * 3 + 1] = n[i * 3 + 2] = 0.0f;
            n[i * 3 + (i / 5) % 3] = (i % 10 == 0) ? 1.0f : -1.0f;
        }
        if (i % 5 == 1)
            memcpy(&n[i * 3], planes[(i / 5) % plane_count], sizeof planes[0]);
    }
    char err[256];
    assert_int_equal(lpv_engine_irradiance(f->engine, p, n, N, gq, err, sizeof err), 0);
    for (int i = 0; i < N; ++i)
        lpv_oracle_irradiance_binned(g, acc, &p[i * 3], &n[i * 3], &rq[i * 3]);
    assert_close("irradiance lookup, 6 normal bins", gq, rq, N * 3);
    free(vpls);
    free(gpu);
    free(ref);
    free(acc);
    free(sum);
    free(t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_injection_matches_oracle),
        cmocka_unit_test(test_smooth_injection_matches_oracle),
        cmocka_unit_test(test_geometry_volume_matches_oracle),
        cmocka_unit_test(test_propagation_matches_oracle),
        cmocka_unit_test(test_lookup_matches_oracle),
        cmocka_unit_test(test_central_transport_matches_oracle),
        cmocka_unit_test(test_normal_bins_match_oracle),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
