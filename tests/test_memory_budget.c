/*
 * test_memory_budget.c - storage that does not fit is refused with a message
 * naming the setting and the estimate, never allocated (issue 10, item 4;
 * core/memory_budget.c, docs/shadows.md "Memory"):
 *  1. the estimate and the check on their own, against given limits;
 *  2. through GL: a scene with 8 point lights (48 light faces) and
 *     rsm_size 2048 (a 9.68 GB VPL buffer, which crashed llvmpipe) is
 *     refused, and the same engine then works at a sane size;
 *  3. under LPVD_MEMORY_BUDGET_MB a shadow_size whose maps do not fit is
 *     refused at render time, naming shadow_size and the budget, and
 *     `lpvd render` exits with status 1 and the message instead of crashing;
 *     a shadow_size past the table's range is refused by the flag parser;
 *  4. area light samples are counted: 8 samples of an emitter have 40
 *     shadow-map faces, tiles four to a layer, so 10 layers of shadow_size^2
 *     (4096: 0.67 GB, refused under a 100 MB budget; 256 fits and lights);
 *  5. the probes' own storage is counted (each probe's maps, a batch's ray
 *     results): ray results and distance maps past what one shader storage
 *     buffer holds are refused at their floor, naming the knobs, and
 *     through the engine, which then works at its defaults.
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

#include "commands.h"
#include "context.h"
#include "engine.h"
#include "memory_budget.h"
#include "probes_rules.h"
#include "scene_build.h"
#include "test_util.h"
#include "view.h"

static const lpv_memory_limits LIMITS = {
    .budget = 4000000000ull, .budget_source = "a test's 4 GB", .max_buffer = 2147483647ull,
    .max_texture_size = 16384, .max_layers = 2048};

static lpv_memory_need sane(void)
{
    return (lpv_memory_need){.rsm_size = 128, .rsm_faces = 48, .shadow_size = 1024, .shadow_faces = 48,
                             .cells = 32 * 32 * 32 * 3, .gv_points = 33 * 33 * 33 * 3, .cascades = 3,
                             .grid_dims = {32, 32, 32}, .image_w = 512, .image_h = 512};
}

static void expect_refused(const lpv_memory_need *n, const char *needle1, const char *needle2)
{
    char err[512] = "";
    assert_int_equal(lpv_memory_check(n, &LIMITS, err, sizeof err), -1);
    printf("refused: %s\n", err);
    assert_non_null(strstr(err, needle1));
    assert_non_null(strstr(err, needle2));
}

static void test_estimates_and_check(void **state)
{
    (void)state;
    lpv_memory_need n = sane();
    char err[512] = "";
    assert_int_equal(lpv_memory_check(&n, &LIMITS, err, sizeof err), 0);
    /* the parts, by their formats */
    /* textures per texel; VPLs (and the dense copy of the live ones with
     * their bits and places, 48 + 1 rounded up) and surfels per slot of the
     * down-sampling's blocks, at most (128 + 2)^2 a layer at any step */
    assert_int_equal(lpv_memory_rsm_bytes(&n), 128ull * 128 * 48 * 56 + 130ull * 130 * 48 * (48 + 49 + 48));
    assert_int_equal(lpv_memory_shadow_bytes(&n), 1024ull * 1024 * 48 * 4);
    assert_int_equal(lpv_memory_total_bytes(&n), lpv_memory_rsm_bytes(&n) + lpv_memory_shadow_bytes(&n) +
                                                     lpv_memory_grid_bytes(&n) + lpv_memory_image_bytes(&n));

    n = sane();
    n.rsm_size = 2048; /* 48 x (2048 + 2)^2 x 48 B = 9.68 GB in one buffer */
    expect_refused(&n, "rsm_size 2048 x 48 light faces needs 9.68 GB for one VPL buffer", "2.15 GB");
    n = sane();
    n.rsm_size = 512; /* one VPL buffer of 0.60 GB fits; all RSM storage (1.91 GB) and 8192^2 shadows do not */
    n.shadow_size = 4096; /* 48 x 4096^2 x 4 B = 3.22 GB, the largest part */
    expect_refused(&n, "shadow_size 4096 x 48 shadow-map faces needs 3.22 GB of shadow maps", "a test's 4 GB");
    n = sane();
    n.shadow_size = 20000;
    expect_refused(&n, "shadow_size 20000", "16384");
    n = sane();
    n.cells = (size_t)256 * 256 * 256 * 4;
    n.grid_dims[0] = n.grid_dims[1] = n.grid_dims[2] = 256;
    n.cascades = 4;
    expect_refused(&n, "grid 256x256x256 x 4 cascades needs 3.22 GB for one LPV buffer", "2.15 GB");
    n = sane();
    n.image_w = n.image_h = 16384;
    expect_refused(&n, "image size 16384x16384", "surfel buffer");
    n = sane();
    n.shadow_faces = 4096;
    expect_refused(&n, "4096 shadow-map faces", "2048 array layers");
}

/* A plane under 8 point lights: 48 RSM faces and 48 shadow-map faces. */
static void eight_point_lights(lpv_scene *s)
{
    memset(s, 0, sizeof *s);
    int grey = lpv_scene_add_material(s, "grey", (float[3]){0.5f, 0.5f, 0.5f}, NULL);
    const float plane[4][3] = {{-8, 0, 8}, {8, 0, 8}, {8, 0, -8}, {-8, 0, -8}};
    assert_true(lpv_scene_add_quad(s, grey, plane, NULL) >= 0);
    for (int i = 0; i < 8; ++i)
        assert_non_null(lpv_scene_add_point_light(s, (float[3]){-7.0f + 2.0f * (float)i, 2.0f, 0.0f}, 5.0f));
    lpv_scene_compute_bounds(s);
}

static int run_engine(lpv_engine *e, const lpv_scene *s, const lpv_settings *set, const lpv_view *v, float *rgba,
                      char *err, size_t n)
{
    if (lpv_engine_set_settings(e, set, err, n) != 0 || lpv_engine_set_scene(e, s, err, n) != 0 ||
        lpv_engine_set_view(e, v, err, n) != 0 || lpv_engine_tick(e, err, n) != 0)
        return -1;
    return lpv_engine_render(e, LPV_TERMS_FULL, rgba, err, n);
}

static void test_rsm_size_that_crashed_is_refused(void **state)
{
    (void)state;
    lpv_scene s;
    eight_point_lights(&s);
    lpv_view v;
    assert_int_equal(lpv_view_look_at((float[3]){0, 6, 6}, (float[3]){0, 0, 0}, 1.0f, 32, 32, &v), 0);
    float rgba[32 * 32 * 4];
    char err[1024] = "";
    lpv_settings big = {.grid_dims = {8, 8, 8}, .rsm_size = 2048};
    assert_int_equal(run_engine(lpvt_engine, &s, &big, &v, rgba, err, sizeof err), -1);
    printf("refused: %s\n", err);
    assert_non_null(strstr(err, "rsm_size 2048 x 48 light faces needs 9.68 GB"));
    /* nothing was left half made: the engine works at a size that fits */
    lpv_settings ok = {.grid_dims = {8, 8, 8}, .rsm_size = 32, .shadow_size = 64};
    if (run_engine(lpvt_engine, &s, &ok, &v, rgba, err, sizeof err) != 0)
        fail_msg("after the refusal: %s", err);
    double sum = 0.0;
    for (int i = 0; i < 32 * 32 * 4; i += 4)
        sum += rgba[i + 1];
    assert_true(sum > 0.0);
    lpv_scene_free(&s);
}

static void test_shadow_size_over_the_budget_is_refused(void **state)
{
    (void)state;
    /* A budget of 100 MB (the variable only lowers the detected one); a
     * context and engine of our own read it. 48 faces of 2048^2 shadow maps
     * are 805 MB. */
    assert_int_equal(setenv("LPVD_MEMORY_BUDGET_MB", "100", 1), 0);
    lpv_gl_context *ctx;
    lpv_engine *e;
    assert_int_equal(lpvt_gl_open(&ctx, &e), 0);
    lpv_scene s;
    eight_point_lights(&s);
    lpv_view v;
    assert_int_equal(lpv_view_look_at((float[3]){0, 6, 6}, (float[3]){0, 0, 0}, 1.0f, 32, 32, &v), 0);
    float rgba[32 * 32 * 4];
    char err[1024] = "";
    lpv_settings big = {.grid_dims = {8, 8, 8}, .rsm_size = 32, .shadow_size = 2048};
    assert_int_equal(run_engine(e, &s, &big, &v, rgba, err, sizeof err), -1);
    printf("refused: %s\n", err);
    assert_non_null(strstr(err, "shadow_size 2048 x 48 shadow-map faces needs 0.81 GB"));
    assert_non_null(strstr(err, "LPVD_MEMORY_BUDGET_MB=100"));
    lpv_settings ok = {.grid_dims = {8, 8, 8}, .rsm_size = 32, .shadow_size = 256};
    if (run_engine(e, &s, &ok, &v, rgba, err, sizeof err) != 0)
        fail_msg("after the refusal: %s", err);
    lpvt_gl_close(ctx, e);
    lpv_scene_free(&s);

    /* The command line: a clear message and status 1, not a crash. */
    char out[512];
    snprintf(out, sizeof out, "%s/refused.png", lpvt_tmpdir());
    const char *over[] = {"render", "-o", out, "--size", "32x32", "--grid", "8", "--shadow-size", "8192"};
    assert_int_equal(lpvd_cmd_render(9, (char **)over), 1);
    assert_int_equal(unsetenv("LPVD_MEMORY_BUDGET_MB"), 0);
    const char *absurd[] = {"render", "-o", out, "--shadow-size", "100000"};
    assert_int_equal(lpvd_cmd_render(5, (char **)absurd), 2);
    const char *absurd_rsm[] = {"render", "-o", out, "--rsm-size", "1000000"};
    assert_int_equal(lpvd_cmd_render(5, (char **)absurd_rsm), 2);
}

/* A grey floor under a 0.5 m emitter facing down, no punctual light: its
 * light comes only through the area light samples. */
static void emitter_only(lpv_scene *s)
{
    memset(s, 0, sizeof *s);
    int grey = lpv_scene_add_material(s, "grey", (float[3]){0.5f, 0.5f, 0.5f}, NULL);
    int lamp = lpv_scene_add_material(s, "lamp", (float[3]){0, 0, 0}, (float[3]){2.0f, 2.0f, 2.0f});
    const float plane[4][3] = {{-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, {-4, 0, -4}};
    const float lamp_q[4][3] = {{-0.25f, 1, -0.25f}, {0.25f, 1, -0.25f}, {0.25f, 1, 0.25f}, {-0.25f, 1, 0.25f}};
    assert_true(lpv_scene_add_quad(s, grey, plane, NULL) >= 0);
    assert_true(lpv_scene_add_quad(s, lamp, lamp_q, NULL) >= 0);
    lpv_scene_compute_bounds(s);
}

static void test_area_light_faces_are_counted(void **state)
{
    (void)state;
    assert_int_equal(setenv("LPVD_MEMORY_BUDGET_MB", "100", 1), 0);
    lpv_gl_context *ctx;
    lpv_engine *e;
    assert_int_equal(lpvt_gl_open(&ctx, &e), 0);
    assert_int_equal(unsetenv("LPVD_MEMORY_BUDGET_MB"), 0);
    lpv_scene s;
    emitter_only(&s);
    lpv_view v;
    assert_int_equal(lpv_view_look_at((float[3]){0, 3, 3}, (float[3]){0, 0, 0}, 1.0f, 32, 32, &v), 0);
    float rgba[32 * 32 * 4];
    char err[1024] = "";
    lpv_settings big = {.grid_dims = {8, 8, 8}, .rsm_size = 32, .shadow_size = 4096, .area_light_samples = 8};
    assert_int_equal(run_engine(e, &s, &big, &v, rgba, err, sizeof err), -1);
    printf("refused: %s\n", err);
    /* 8 x 5 faces of 2048^2, four to a 4096^2 layer: 10 layers of 67 MB */
    assert_non_null(strstr(err, "shadow_size 4096 x 10 shadow-map faces needs 0.67 GB"));
    lpv_settings ok = {.grid_dims = {8, 8, 8}, .rsm_size = 32, .shadow_size = 256, .area_light_samples = 8};
    if (run_engine(e, &s, &ok, &v, rgba, err, sizeof err) != 0)
        fail_msg("after the refusal: %s", err);
    double sum = 0.0;
    for (int i = 0; i < 32 * 32 * 4; i += 4)
        sum += rgba[i + 1];
    assert_true(sum > 0.0);
    lpvt_gl_close(ctx, e);
    lpv_scene_free(&s);
}

static lpv_settings probes_settings(int grid, int cascades, int rays, int budget, int oct)
{
    lpv_settings s = {.technique = LPV_TECHNIQUE_ID_PROBES, .grid_dims = {grid, grid, grid}};
    s.lpv.cascades = cascades;
    s.probes.rays = rays;
    s.probes.budget = budget;
    s.probes.oct = oct;
    lpv_settings_resolve(&s);
    return s;
}

static void test_probes_storage_is_counted(void **state)
{
    (void)state;
    /* SH 48 + distances 8 x 8^2 + irradiance 12 x 6^2 + state 32 + list 4,
     * and the scroll's copy of the distances */
    assert_int_equal(lpv_probes_bytes_per_probe(8), 48 + 512 + 432 + 32 + 4 + 512);
    lpv_memory_need n;
    char err[512] = "";
    lpv_settings s = probes_settings(32, 3, 0, 0, 0); /* the knobs' defaults: 64 rays, 1024 probes a tick, 8^2 */
    lpv_memory_need_floor(&s, 1, &n);
    assert_int_equal(lpv_memory_check(&n, &LIMITS, err, sizeof err), 0);
    const uint64_t probes = 3 * 32 * 32 * 32;
    assert_int_equal(n.cells, probes);
    assert_int_equal(n.technique_bytes, probes * (1540 - LPV_MEM_CELL) + 1024ull * 64 * 16);
    /* 64^3 probes x 1024 rays in a batch of all of them: 4.3 GB of ray
     * results in one buffer (it crashed llvmpipe past 2 GiB) */
    s = probes_settings(64, 1, 1024, 1 << 20, 0);
    lpv_memory_need_floor(&s, 1, &n);
    expect_refused(&n, "probes_budget", "probes_rays");
    /* 4 x 64^3 probes with 16^2 distance maps: 2 KiB each, 2 GiB in one buffer */
    s = probes_settings(64, 4, 0, 0, 16);
    lpv_memory_need_floor(&s, 1, &n);
    expect_refused(&n, "distance maps", "probes_oct");

    /* through an engine of its own (the tests before ran lpvd render, which
     * leaves no context current): refused with the message, then the
     * defaults work */
    struct lpv_gl_context *ctx = NULL;
    lpv_engine *e = NULL;
    assert_int_equal(lpvt_gl_open(&ctx, &e), 0);
    lpv_scene scene;
    assert_int_equal(lpv_scene_builtin_cornell(&scene), 0);
    s = probes_settings(64, 1, 1024, 1 << 20, 0);
    if (lpv_engine_set_settings(e, &s, err, sizeof err) == 0 && lpv_engine_set_scene(e, &scene, err, sizeof err) == 0)
        assert_int_not_equal(lpv_engine_tick(e, err, sizeof err), 0);
    printf("engine: %s\n", err);
    assert_non_null(strstr(err, "probes_rays"));
    s = probes_settings(8, 0, 0, 0, 0);
    assert_int_equal(lpv_engine_set_settings(e, &s, err, sizeof err), 0);
    assert_int_equal(lpv_engine_set_scene(e, &scene, err, sizeof err), 0);
    assert_int_equal(lpv_engine_tick(e, err, sizeof err), 0);
    assert_true(lpv_engine_memory_bytes(e) > 8 * 8 * 8 * 1540ull); /* the probes' maps and the BVH */
    lpv_scene_free(&scene);
    lpvt_gl_close(ctx, e);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_estimates_and_check),
        cmocka_unit_test(test_rsm_size_that_crashed_is_refused),
        cmocka_unit_test(test_shadow_size_over_the_budget_is_refused),
        cmocka_unit_test(test_area_light_faces_are_counted),
        cmocka_unit_test(test_probes_storage_is_counted),
    };
    return cmocka_run_group_tests(tests, lpvt_gl_setup, lpvt_gl_teardown);
}
