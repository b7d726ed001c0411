/*
 * test_octree_gpu.c - the octree technique on the GPU (llvmpipe in CI)
 * against the plain-C octree oracle (techniques/octree/core/oracle_octree.h), the role
 * test_gpu_oracle.c plays for the cascaded LPV.
 *
 * The built-in Cornell box is ticked with technique octree; the VPLs (and,
 * with occlusion, every geometry-volume buffer's surfels) the GPU produced
 * are read back and fed to the oracle, and the GPU's every level, merged
 * volume and index volume must match it: each value within
 * 1e-4 * max|oracle| + 1e-5 * |oracle|, the index exactly. Then the
 * technique's seams: switching lpv -> octree -> lpv gives the cascaded LPV's
 * frame back bit for bit, the plan names the octree's levels, bad grids are
 * refused by name, and hard inputs stay finite with no level gaining energy.
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
#include "oracle_octree.h"
#include "scene.h"
#include "test_util.h"

#define IMG 32

static lpv_scene g_scene;

static int setup(void **state)
{
    if (lpvt_gl_setup(state) != 0)
        return -1;
    return lpv_scene_builtin_cornell(&g_scene);
}

static int teardown(void **state)
{
    lpv_scene_free(&g_scene);
    return lpvt_gl_teardown(state);
}

static lpv_settings octree_settings(int n, int k, lpv_switch occlusion)
{
    lpv_settings s = {.technique = LPV_TECHNIQUE_ID_OCTREE, .grid_dims = {n, n, n}, .rsm_size = 32};
    s.lpv.iterations = k;
    s.lpv.occlusion = occlusion;
    s.lpv.central_transport = LPV_SWITCH_OFF; /* the oracle's transport argument below */
    s.scene_surfels = LPV_SWITCH_OFF;
    return s;
}

static void tick(const lpv_settings *s, int with_view)
{
    char err[1024] = "";
    if (lpv_engine_set_settings(lpvt_engine, s, err, sizeof err) != 0 ||
        lpv_engine_set_scene(lpvt_engine, &g_scene, err, sizeof err) != 0)
        fail_msg("%s", err);
    lpv_view view;
    lpv_view_from_camera(&g_scene.cameras[0], IMG, IMG, &view);
    if (lpv_engine_set_view(lpvt_engine, with_view ? &view : NULL, err, sizeof err) != 0 ||
        lpv_engine_tick(lpvt_engine, err, sizeof err) != 0)
        fail_msg("%s", err);
}

static void assert_close(const char *what, const float *gpu, const float *ref, size_t n)
{
    double max_ref = 0.0;
    for (size_t i = 0; i < n; ++i)
        max_ref = fmax(max_ref, fabs(ref[i]));
    assert_true(max_ref > 0.0); /* the comparison must be about something */
    double worst = 0.0;
    size_t at = 0;
    for (size_t i = 0; i < n; ++i) {
        assert_true(isfinite(gpu[i]));
        double r = fabs((double)gpu[i] - ref[i]) / (1e-4 * max_ref + 1e-5 * fabs(ref[i]));
        if (r > worst) {
            worst = r;
            at = i;
        }
    }
    printf("%s: %zu values, max |ref| %.4g, worst error %.3g of tolerance\n", what, n, max_ref, worst);
    if (worst > 1.0)
        fail_msg("%s differs from the oracle at %zu: gpu %.9g oracle %.9g", what, at, gpu[at], ref[at]);
}

/* The oracle on what the GPU produced: the same grid, VPLs and (occlusion)
 * every GV buffer's surfels in the engine's order. */
static void oracle_from_engine(int k, int occlusion, lpv_octree *o)
{
    char err[256];
    const lpv_grid *g = lpv_engine_grid(lpvt_engine);
    assert_int_equal(lpv_octree_create(g, occlusion, o, err, sizeof err), 0);
    size_t vmax = 32 * 32 * 64;
    lpv_vpl *vpls = calloc(vmax, sizeof *vpls);
    assert_non_null(vpls);
    size_t nv = lpv_engine_read_vpls(lpvt_engine, vpls, vmax);
    assert_true(nv > 1000);
    assert_true(lpv_octree_inject_vpls(o, vpls, nv) > 1000);
    free(vpls);
    if (occlusion) {
        size_t smax = 1 << 20;
        lpv_surfel *surfels = calloc(smax, sizeof *surfels);
        assert_non_null(surfels);
        for (size_t b = 0; b < lpv_engine_gv_buffer_count(lpvt_engine); ++b) {
            size_t n = lpv_engine_read_surfels(lpvt_engine, b, surfels, smax);
            assert_int_equal(lpv_octree_add_surfels(o, surfels, n, NULL), 0);
        }
        free(surfels);
    }
    lpv_octree_downsample(o);
    lpv_octree_propagate(o, k, LPV_TRANSPORT_PAPER);
}

static void compare_with_oracle(int n, int k, int occlusion)
{
    lpv_settings s = octree_settings(n, k, occlusion ? LPV_SWITCH_ON : LPV_SWITCH_OFF);
    tick(&s, occlusion);
    lpv_octree o = {0};
    oracle_from_engine(k, occlusion, &o);
    assert_int_equal(o.levels, lpv_engine_last_stats(lpvt_engine)->cascades);

    if (occlusion) { /* every level's geometry volume, level 0 first */
        size_t ng = 0;
        for (int i = 0; i < o.levels; ++i)
            ng += lpv_grid_gv_count(&o.level[i].grid);
        lpv_gv_point *gg = calloc(ng, sizeof *gg);
        assert_non_null(gg);
        assert_int_equal(lpv_engine_read_gv(lpvt_engine, gg, ng), ng);
        for (int i = 0, at = 0; i < o.levels; at += (int)lpv_grid_gv_count(&o.level[i].grid), ++i) {
            char what[64];
            snprintf(what, sizeof what, "geometry volume level %d (%d^3)", i, n >> i);
            size_t pts = lpv_grid_gv_count(&o.level[i].grid);
            float *bg = calloc(pts * 8, sizeof *bg), *br = calloc(pts * 8, sizeof *br);
            for (size_t p = 0; p < pts; ++p) { /* the blocking; the oracle keeps no albedo */
                memcpy(bg + 8 * p, gg[at + p].blocking, 8 * sizeof(float));
                memcpy(br + 8 * p, o.level[i].gv[p].blocking, 8 * sizeof(float));
            }
            assert_close(what, bg, br, pts * 8);
            free(bg);
            free(br);
        }
        free(gg);
    }
    if (occlusion) { /* every level's transmittances, level 0 first */
        size_t nt = 0;
        for (int i = 0; i < o.levels; ++i)
            nt += lpv_grid_cell_count(&o.level[i].grid) * 6;
        float *tg = calloc(nt, sizeof *tg);
        assert_non_null(tg);
        assert_int_equal(lpv_engine_read_transmittance(lpvt_engine, tg, nt), nt);
        for (int i = 0, at = 0; i < o.levels; at += (int)lpv_grid_cell_count(&o.level[i].grid) * 6, ++i) {
            char what[64];
            snprintf(what, sizeof what, "transmittance level %d (%d^3)", i, n >> i);
            assert_close(what, tg + at, o.level[i].t, lpv_grid_cell_count(&o.level[i].grid) * 6);
        }
        free(tg);
    }
    /* every level's accumulation, level 0 first */
    size_t all = 0;
    for (int i = 0; i < o.levels; ++i)
        all += lpv_grid_cell_count(&o.level[i].grid);
    lpv_cell *gpu = calloc(all, sizeof *gpu), *ref = calloc(all, sizeof *ref);
    assert_non_null(gpu);
    assert_non_null(ref);
    assert_int_equal(lpv_engine_read_volumes(lpvt_engine, LPV_GRID_ACCUMULATED, gpu, all), all);
    for (int i = 0, at = 0; i < o.levels; at += (int)lpv_grid_cell_count(&o.level[i].grid), ++i)
        memcpy(ref + at, o.level[i].acc, lpv_grid_cell_count(&o.level[i].grid) * sizeof *ref);
    char what[64];
    for (int i = 0, at = 0; i < o.levels; at += (int)lpv_grid_cell_count(&o.level[i].grid), ++i) {
        snprintf(what, sizeof what, "level %d (%d^3) k %d occlusion %d", i, n >> i, k, occlusion);
        assert_close(what, (const float *)(gpu + at), (const float *)(ref + at),
                     lpv_grid_cell_count(&o.level[i].grid) * 12);
    }

    /* the merged volume and the index volume */
    const size_t cells = (size_t)n * n * n;
    assert_int_equal(lpv_engine_read_grid(lpvt_engine, LPV_GRID_ACCUMULATED, gpu, cells), cells);
    lpv_octree_merge(&o, ref);
    snprintf(what, sizeof what, "merged %d^3 k %d occlusion %d", n, k, occlusion);
    assert_close(what, (const float *)gpu, (const float *)ref, cells * 12);
    int32_t *index = calloc(cells, sizeof *index);
    assert_non_null(index);
    assert_int_equal(lpv_engine_read_index(lpvt_engine, index, cells), cells);
    int coarse = 0;
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                int want = lpv_octree_index(&o, x, y, z);
                int got = index[x + n * (y + n * z)];
                if (got != want)
                    fail_msg("index at (%d,%d,%d): gpu %d oracle %d", x, y, z, got, want);
                coarse += got > 0;
            }
    printf("index: %d of %zu cells read a coarser level\n", coarse, cells);
    free(index);
    free(gpu);
    free(ref);
    lpv_octree_free(&o);
}

static void test_matches_oracle_without_occlusion(void **state)
{
    (void)state;
    compare_with_oracle(16, 2, 0); /* light has not reached the far cells of level 0 */
    compare_with_oracle(16, 5, 0);
}

static void test_matches_oracle_with_occlusion(void **state)
{
    (void)state;
    compare_with_oracle(16, 4, 1);
}

/* Few iterations on a fine grid: coarse levels must light what level 0 has
 * not reached, which is the technique's point (the thesis' reach). */
static void test_coarse_levels_reach_further(void **state)
{
    (void)state;
    lpv_settings s = octree_settings(32, 2, LPV_SWITCH_ON);
    tick(&s, 1);
    const size_t cells = 32 * 32 * 32;
    int32_t *index = calloc(cells, sizeof *index);
    lpv_cell *merged = calloc(cells, sizeof *merged);
    assert_int_equal(lpv_engine_read_index(lpvt_engine, index, cells), cells);
    assert_int_equal(lpv_engine_read_grid(lpvt_engine, LPV_GRID_ACCUMULATED, merged, cells), cells);
    size_t lit = 0, from_coarse = 0;
    for (size_t i = 0; i < cells; ++i) {
        int nonzero = 0;
        for (int j = 0; j < 4; ++j)
            nonzero |= merged[i].r[j] != 0.0f || merged[i].g[j] != 0.0f || merged[i].b[j] != 0.0f;
        lit += nonzero;
        from_coarse += nonzero && index[i] > 0;
    }
    printf("32^3, 2 iterations: %zu of %zu cells lit, %zu of them from coarser levels\n", lit, cells, from_coarse);
    assert_true(lit == cells);             /* the 1-cell level covers everything */
    assert_true(from_coarse > cells / 4);  /* and level 0 alone would not */
    const lpv_plan *p = lpv_engine_last_plan(lpvt_engine);
    assert_non_null(strstr(p->cascades_reason, "octree: 6 levels (32^3 .. 1^3); 2 iterations cover levels 4..5"));
    free(index);
    free(merged);
}

static float *render(void) { return lpvt_render(IMG, IMG); }

/* Switching techniques rebuilds the lookup passes and the volume; going back
 * gives the cascaded LPV's frame bit for bit, and the octree's differs. */
static void test_switching_techniques(void **state)
{
    (void)state;
    lpv_settings lpv = {.grid_dims = {8, 8, 8}, .rsm_size = 32};
    lpv.lpv.iterations = 4;
    tick(&lpv, 1);
    float *a = render();
    lpv_settings oct = lpv;
    oct.technique = LPV_TECHNIQUE_ID_OCTREE;
    tick(&oct, 1);
    /* the new technique's storage is made anew: nothing of the old volume is served */
    assert_true(lpv_engine_last_plan(lpvt_engine)->recompute);
    assert_non_null(strstr(lpv_engine_last_plan(lpvt_engine)->cascades_reason, "octree: 4 levels"));
    float *b = render();
    tick(&lpv, 1);
    float *c = render();
    assert_memory_equal(a, c, sizeof(float) * IMG * IMG * 4);
    assert_memory_not_equal(a, b, sizeof(float) * IMG * IMG * 4);
    for (size_t i = 0; i < (size_t)IMG * IMG * 4; ++i)
        assert_true(isfinite(b[i]) && b[i] >= 0.0f);
    free(a);
    free(b);
    free(c);
}

static void test_refuses_grids_it_cannot_halve(void **state)
{
    (void)state;
    char err[256] = "";
    const int bad[][3] = {{12, 12, 12}, {16, 16, 8}, {3, 3, 3}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        lpv_settings s = octree_settings(8, 2, LPV_SWITCH_OFF);
        memcpy(s.grid_dims, bad[i], sizeof s.grid_dims);
        assert_int_equal(lpv_engine_set_settings(lpvt_engine, &s, err, sizeof err), -1);
        assert_non_null(strstr(err, "technique octree needs a cubic grid of a power of two"));
    }
}

/* Hard inputs: an extreme light and many steps stay finite, and no level's
 * flux grows from one step to the next (read as the accumulation's growth
 * being at most what was in flight). */
static void test_hard_cases_stay_finite(void **state)
{
    (void)state;
    lpv_scene hot;
    assert_int_equal(lpv_scene_builtin_cornell(&hot), 0);
    for (uint32_t i = 0; i < hot.light_count; ++i)
        hot.lights[i].intensity *= 1e30f;
    char err[512] = "";
    lpv_settings s = octree_settings(16, 64, LPV_SWITCH_ON);
    if (lpv_engine_set_settings(lpvt_engine, &s, err, sizeof err) != 0 ||
        lpv_engine_set_scene(lpvt_engine, &hot, err, sizeof err) != 0 ||
        lpv_engine_set_view(lpvt_engine, NULL, err, sizeof err) != 0 || lpv_engine_tick(lpvt_engine, err, sizeof err) != 0)
        fail_msg("%s", err);
    size_t all = 0;
    for (int n = 16; n >= 1; n /= 2)
        all += (size_t)n * n * n;
    lpv_cell *levels = calloc(all, sizeof *levels), *inj = calloc(all, sizeof *inj);
    assert_int_equal(lpv_engine_read_volumes(lpvt_engine, LPV_GRID_ACCUMULATED, levels, all), all);
    assert_int_equal(lpv_engine_read_volumes(lpvt_engine, LPV_GRID_INJECTED, inj, all), all);
    size_t at = 0;
    for (int n = 16; n >= 1; at += (size_t)n * n * n, n /= 2) {
        double injected = 0.0, accumulated = 0.0;
        for (size_t i = at; i < at + (size_t)n * n * n; ++i) {
            const float *v = (const float *)&levels[i];
            for (int j = 0; j < 12; ++j)
                assert_true(isfinite(v[j]));
            /* c0 >= 0: no negative energy */
            assert_true(levels[i].r[0] >= 0.0f && levels[i].g[0] >= 0.0f && levels[i].b[0] >= 0.0f);
            injected += inj[i].r[0];
            accumulated += levels[i].r[0];
        }
        /* each step sends out at most what it holds, so 64 steps add at most 64 x the injection */
        assert_true(accumulated <= 65.0 * injected * (1.0 + 1e-5));
    }
    free(levels);
    free(inj);
    lpv_scene_free(&hot);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matches_oracle_without_occlusion),
        cmocka_unit_test(test_matches_oracle_with_occlusion),
        cmocka_unit_test(test_coarse_levels_reach_further),
        cmocka_unit_test(test_switching_techniques),
        cmocka_unit_test(test_refuses_grids_it_cannot_halve),
        cmocka_unit_test(test_hard_cases_stay_finite),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
