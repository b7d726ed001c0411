/*
 * test_downsample.c - the down-sampling of the geometry volume's and the
 * injection's samples (issue 16): the scene surfels grouped on the CPU
 * (core/surfel_groups.h) and the camera's surfels and the RSMs' VPLs and
 * surfels grouped on the GPU (shaders/block_groups.glsl) must give every
 * cell and geometry-volume point what the samples gave it one by one.
 *
 * CPU: the C oracle's GV from grouped surfels equals the GV from the
 * surfels themselves (planes, a 2 cm wall seen from both sides, several
 * cascades, object sizes), with far fewer surfels; area is conserved and
 * hostile surfels are left out.
 * GPU: the built-in Cornell box and the blinds room at the balanced preset,
 * ticked at camera_surfel_step = rsm_vpl_step = 1, again at 4 and 2 (a block
 * of 4 texels has no more groups than the 8 slots) and at auto (which takes
 * the area light samples' VPL-only layers in blocks of 4 x 4 texels,
 * LPV_RSM_AUTO_VPL_STEP, so the Cornell box's ceiling light gives fewer VPLs
 * than at step 2): the injected volumes and the geometry volume read back
 * agree within float rounding (1e-4 of the largest value), with fewer VPLs
 * and camera surfels;
 * the VPLs the injection draws are exactly those that carry light, in order
 * (the compaction of gpu/compact.h).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "context.h"
#include "engine.h"
#include "grid.h"
#include "oracle.h"
#include "scene_load.h"
#include "surfel_groups.h"
#include "test_util.h"
#include "view_choice.h"

/* ---- CPU: lpv_surfels_group against the oracle's GV ------------------------ */

static void push(lpv_surfel *s, size_t *n, float x, float y, float z, float nx, float ny, float nz, float area,
                 float size)
{
    lpv_surfel *o = &s[(*n)++];
    memset(o, 0, sizeof *o);
    o->position[0] = x, o->position[1] = y, o->position[2] = z, o->position[3] = area;
    o->normal[0] = nx, o->normal[1] = ny, o->normal[2] = nz, o->normal[3] = size;
    o->albedo[0] = 0.7f, o->albedo[1] = 0.5f, o->albedo[2] = 0.3f;
}

/* Surfels on a floor, a tilted roof, both faces of a 2 cm wall and a small
 * object, plus hostile ones that must be left out. */
static size_t make_surfels(lpv_surfel *s, size_t max)
{
    uint64_t rng = 12345;
    size_t n = 0;
    for (int i = 0; i < 3000 && n + 8 < max; ++i) {
        float u = (float)lpvt_rand(&rng, -1.0, 1.0), v = (float)lpvt_rand(&rng, -1.0, 1.0);
        float a = (float)lpvt_rand(&rng, 1e-4, 1e-3);
        push(s, &n, u, 0.0f, v, 0.0f, 1.0f, 0.0f, a, 0.0f);                          /* floor */
        push(s, &n, u, 0.5f + 0.3f * v, v, 0.0f, 0.9578f, -0.2873f, a, 0.0f);         /* roof */
        push(s, &n, 0.31f, 0.5f + 0.4f * u, v, 1.0f, 0.0f, 0.0f, a, 0.0f);            /* wall, +x face */
        push(s, &n, 0.29f, 0.5f + 0.4f * u, v, -1.0f, 0.0f, 0.0f, a, 0.0f);           /* wall, -x face */
        push(s, &n, 0.1f * u - 0.5f, 0.2f, 0.1f * v, 0.0f, 0.0f, 1.0f, a, 0.05f);     /* a 5 cm object */
    }
    push(s, &n, NAN, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 1.0f, 0.0f);  /* NaN position */
    push(s, &n, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f); /* no normal */
    push(s, &n, 0.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f, -1.0f, 0.0f); /* negative area */
    push(s, &n, 0.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f, INFINITY, 0.0f);
    return n;
}

static void test_cpu_grouping_keeps_the_gv(void **state)
{
    (void)state;
    enum { MAX = 20000 };
    lpv_surfel *in = calloc(MAX, sizeof *in), *out = calloc(MAX, sizeof *out);
    assert_non_null(in);
    assert_non_null(out);
    size_t n = make_surfels(in, MAX);
    /* two cascades as the far field places them: 8^3 over [-1.1, 1.1]^3
     * and 8^3 of twice the cell around it */
    lpv_grid g[2];
    const int dims[3] = {8, 8, 8};
    assert_int_equal(lpv_grid_place(dims, (float[3]){-1.1f, -1.1f, -1.1f}, (float[3]){1.1f, 1.1f, 1.1f}, &g[0]), 0);
    g[1] = g[0];
    g[1].cell_size = 2.0f * g[0].cell_size;
    lpv_group_grid gg[2];
    for (int k = 0; k < 2; ++k) {
        for (int a = 0; a < 3; ++a)
            gg[k].origin_cells[a] = k == 0 ? g[0].origin[a] / g[0].cell_size
                                           : (g[0].origin[a] / g[0].cell_size - 4.0f) * 0.5f;
        gg[k].cell_size = g[k].cell_size;
        for (int a = 0; a < 3; ++a)
            g[k].origin[a] = gg[k].origin_cells[a] * g[k].cell_size;
    }
    size_t m = lpv_surfels_group(in, n, gg, 2, out);
    printf("%zu surfels -> %zu groups\n", n, m);
    assert_true(m > 0);
    assert_true(m * 10 < n); /* planes over 8^3 points: far fewer */

    double area_in = 0.0, area_out = 0.0;
    for (size_t i = 0; i < n; ++i)
        if (isfinite(in[i].position[0]) && in[i].position[3] > 0.0f && isfinite(in[i].position[3]) &&
            (in[i].normal[0] != 0.0f || in[i].normal[1] != 0.0f || in[i].normal[2] != 0.0f))
            area_in += in[i].position[3];
    for (size_t i = 0; i < m; ++i) {
        area_out += out[i].position[3];
        float len = sqrtf(out[i].normal[0] * out[i].normal[0] + out[i].normal[1] * out[i].normal[1] +
                          out[i].normal[2] * out[i].normal[2]);
        assert_true(len > 0.5f && len <= 1.0f + 1e-6f); /* opposite faces never share a group */
    }
    assert_true(fabs(area_in - area_out) <= 1e-5 * area_in);

    for (int k = 0; k < 2; ++k) {
        size_t np = lpv_grid_gv_count(&g[k]);
        vec4 *a = calloc(np, sizeof *a), *b = calloc(np, sizeof *b);
        assert_non_null(a);
        assert_non_null(b);
        size_t ia = lpv_oracle_inject_surfels(&g[k], in, n, a);
        size_t ib = lpv_oracle_inject_surfels(&g[k], out, m, b);
        assert_true(ia > ib);
        double peak = 0.0;
        for (size_t p = 0; p < np; ++p)
            for (int c = 0; c < 4; ++c)
                peak = fmax(peak, fabs(a[p][c]));
        assert_true(peak > 0.0);
        for (size_t p = 0; p < np; ++p)
            for (int c = 0; c < 4; ++c)
                if (fabs(a[p][c] - b[p][c]) > 1e-5 * peak) {
                    printf("cascade %d point %zu coefficient %d: %g one by one, %g grouped\n", k, p, c, a[p][c],
                           b[p][c]);
                    fail();
                }
        free(a);
        free(b);
    }
    free(in);
    free(out);
}

/* ---- GPU: the engine at step 1 against the down-sampled steps -------------- */

typedef struct snapshot {
    lpv_cell *vol;
    size_t nvol;
    lpv_gv_point *gv;
    size_t ngv;
    size_t vpls, camera; /* VPLs carrying light; camera surfels (stats) */
} snapshot;

static void snap(const lpv_scene *scene, const lpv_view *view, int cam_step, int rsm_step, snapshot *s)
{
    char err[512];
    /* the LPV's volumes are compared (the default technique is auto since issue 30): balanced, 8^3, far field,
     * normal bins, scene surfels */
    lpv_settings st = {.technique = LPV_TECHNIQUE_ID_LPV};
    st.camera_surfel_step = cam_step;
    st.rsm_vpl_step = rsm_step;
    assert_int_equal(lpv_engine_set_settings(lpvt_engine, &st, err, sizeof err), 0);
    assert_int_equal(lpv_engine_set_scene(lpvt_engine, scene, err, sizeof err), 0);
    assert_int_equal(lpv_engine_set_view(lpvt_engine, view, err, sizeof err), 0);
    lpv_engine_invalidate(lpvt_engine);
    assert_int_equal(lpv_engine_tick(lpvt_engine, err, sizeof err), 0);
    const size_t max = 1u << 20;
    s->vol = calloc(max, sizeof *s->vol);
    s->gv = calloc(max, sizeof *s->gv);
    assert_non_null(s->vol);
    assert_non_null(s->gv);
    s->nvol = lpv_engine_read_volumes(lpvt_engine, LPV_GRID_INJECTED, s->vol, max);
    s->ngv = lpv_engine_read_gv(lpvt_engine, s->gv, max);
    const lpv_engine_stats *stats = lpv_engine_last_stats(lpvt_engine);
    lpv_vpl *v = calloc(max, sizeof *v);
    assert_non_null(v);
    size_t nv = lpv_engine_read_vpls(lpvt_engine, v, max);
    s->vpls = 0; /* the VPLs that carry light (a block's unused slots do not) */
    for (size_t i = 0; i < nv; ++i)
        s->vpls += v[i].position[3] != 0.0f;
    /* the injection drew exactly those, in their order, to the bit
     * (gpu/compact.h) */
    lpv_vpl *live = calloc(max, sizeof *live);
    assert_non_null(live);
    size_t nl = lpv_engine_read_injected_vpls(lpvt_engine, live, max);
    assert_int_equal(nl, s->vpls);
    for (size_t i = 0, j = 0; i < nv; ++i)
        if (v[i].position[3] != 0.0f)
            assert_memory_equal(&v[i], &live[j++], sizeof *v);
    free(live);
    free(v);
    s->camera = stats->surfels_camera;
    assert_true(s->nvol > 0);
    assert_true(s->ngv > 0);
}

static void snap_free(snapshot *s)
{
    free(s->vol);
    free(s->gv);
}

static void expect_same(const char *what, const float *a, const float *b, size_t n)
{
    double peak = 0.0;
    for (size_t i = 0; i < n; ++i)
        peak = fmax(peak, fabs(a[i]));
    assert_true(peak > 0.0);
    double worst = 0.0;
    for (size_t i = 0; i < n; ++i)
        worst = fmax(worst, fabs(a[i] - b[i]));
    printf("  %s: largest difference %.3g of the peak %.3g\n", what, worst / peak, peak);
    assert_true(worst <= 1e-4 * peak);
}

static void compare_steps(const lpv_scene *scene)
{
    lpv_view view;
    char err[512];
    assert_int_equal(lpv_view_resolve(&(lpv_view_choice){.width = 128, .height = 128}, scene, &view, err, sizeof err),
                     0);
    snapshot one, four, autos;
    snap(scene, &view, 1, 1, &one);
    snap(scene, &view, 4, 2, &four);
    snap(scene, &view, 0, 0, &autos);
    /* with area lights, auto groups their VPL-only layers further than 2 */
    const lpv_engine_stats *st = lpv_engine_last_stats(lpvt_engine);
    if (st->area_lights > 1)
        assert_true(autos.vpls < four.vpls);
    else
        assert_int_equal(autos.vpls, four.vpls);
    const snapshot *cmp[2] = {&four, &autos};
    for (int c = 0; c < 2; ++c) {
        printf("%s, steps %s: VPLs %zu -> %zu, camera surfels %zu -> %zu\n", scene->source, c ? "auto" : "camera 4, RSM 2",
               one.vpls, cmp[c]->vpls, one.camera, cmp[c]->camera);
        assert_true(cmp[c]->vpls < one.vpls);
        assert_true(cmp[c]->camera < one.camera);
        assert_int_equal(cmp[c]->nvol, one.nvol);
        assert_int_equal(cmp[c]->ngv, one.ngv);
        expect_same("injected volumes", &one.vol[0].r[0], &cmp[c]->vol[0].r[0], one.nvol * 12);
        expect_same("geometry volume", &one.gv[0].blocking[0][0], &cmp[c]->gv[0].blocking[0][0], one.ngv * 12);
    }
    snap_free(&one);
    snap_free(&four);
    snap_free(&autos);
}

static void test_gpu_cornell(void **state)
{
    (void)state;
    lpv_scene scene;
    char err[512];
    assert_int_equal(lpv_scene_load(NULL, &scene, err, sizeof err), 0);
    compare_steps(&scene);
    lpv_scene_free(&scene);
}

static void test_gpu_blinds(void **state)
{
    (void)state;
    char path[1024], err[512];
    snprintf(path, sizeof path, "%s/scenes/blinds.glb", lpvt_source_dir());
    lpv_scene scene;
    assert_int_equal(lpv_scene_load(path, &scene, err, sizeof err), 0);
    compare_steps(&scene);
    lpv_scene_free(&scene);
}

int main(void)
{
    const struct CMUnitTest cpu[] = {cmocka_unit_test(test_cpu_grouping_keeps_the_gv)};
    const struct CMUnitTest gpu[] = {cmocka_unit_test(test_gpu_cornell), cmocka_unit_test(test_gpu_blinds)};
    int rc = cmocka_run_group_tests(cpu, NULL, NULL);
    return rc | cmocka_run_group_tests(gpu, lpvt_gl_setup, lpvt_gl_teardown);
}
