/*
 * test_render.c - whole frames: the Cornell box's indirect light bleeds the
 * walls' colours onto the floor; the shared glTF Cornell box renders like the
 * built-in one; `lpvd render` writes PNG and EXR files and rejects bad input.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "commands.h"
#include "context.h"
#include "engine.h"
#include "image_io.h"
#include "lpv_shared.h"
#include "scene.h"
#include "scene_load.h"
#include "test_util.h"
#include "view_choice.h"

enum { W = 96, H = 96 };

/* The frame `terms` of the scene's first camera at w x h with settings s. */
static void render_with(const lpv_scene *scene, const lpv_settings *s, lpv_frame_terms terms, int w, int h,
                        lpv_view *view, float *rgba)
{
    char err[1024] = "";
    lpv_view_from_camera(&scene->cameras[0], w, h, view);
    if (lpv_engine_set_settings(lpvt_engine, s, err, sizeof err) ||
        lpv_engine_set_scene(lpvt_engine, scene, err, sizeof err) ||
        lpv_engine_set_view(lpvt_engine, view, err, sizeof err) || lpv_engine_tick(lpvt_engine, err, sizeof err) ||
        lpv_engine_render(lpvt_engine, terms, rgba, err, sizeof err))
        fail_msg("%s", err);
}

static void render_damped(const lpv_scene *scene, lpv_frame_terms terms, float damping, lpv_view *view, float *rgba)
{
    /* Issue 2's configuration (32^3, 8 iterations, RSM 256^2), not the
     * default preset: at balanced's 4 steps light from the green wall barely
     * reaches the floor 2.3 cells away, and the warm spot keeps red ahead
     * of green there (docs/accuracy.md, "Presets"). The LPV named: its
     * propagation and damping are tested (the default is auto since issue 30). */
    const lpv_settings s = {
        .technique = LPV_TECHNIQUE_ID_LPV, .lpv.iterations = 8, .rsm_size = 256, .lpv.damping = damping};
    render_with(scene, &s, terms, W, H, view, rgba);
}

static void render(const lpv_scene *scene, lpv_frame_terms terms, lpv_view *view, float *rgba)
{
    render_damped(scene, terms, 0.0f, view, rgba);
}

/* Mean radiance over the 5x5 pixels around world point p (test_util). */
static void patch(const lpv_view *v, const float *rgba, const float p[3], double out[3])
{
    lpvt_patch(v, rgba, W, H, p, 2, out);
}

static void test_cornell_colour_bleeding(void **state)
{
    (void)state;
    lpv_scene scene;
    assert_int_equal(lpv_scene_builtin_cornell(&scene), 0);
    float *ind = calloc((size_t)W * H * 4, sizeof *ind), *dir = calloc((size_t)W * H * 4, sizeof *dir);
    lpv_view view;
    render(&scene, LPV_TERMS_INDIRECT_ONLY, &view, ind);
    render(&scene, LPV_TERMS_DIRECT_ONLY, &view, dir);
    const float near_red[3] = {-0.85f, 0.0f, 0.5f}, near_green[3] = {0.85f, 0.0f, 0.5f};
    double ir[3], ig[3], dr[3], dg[3];
    patch(&view, ind, near_red, ir);
    patch(&view, ind, near_green, ig);
    patch(&view, dir, near_red, dr);
    patch(&view, dir, near_green, dg);
    printf("direct near red wall %.4g %.4g %.4g, near green wall %.4g %.4g %.4g\n", dr[0], dr[1], dr[2], dg[0], dg[1],
           dg[2]);
    printf("indirect near red wall %.4g %.4g %.4g, near green wall %.4g %.4g %.4g\n", ir[0], ir[1], ir[2], ig[0], ig[1],
           ig[2]);
    assert_true(ir[0] > 0.0 && ig[1] > 0.0);
    /* The criterion, literally. */
    assert_true(ir[0] > ir[1]);
    assert_true(ig[1] > ig[0]);
    /* And relative to the (warm, white-ish) direct light on the same floor,
     * so the warm spot colour alone cannot pass it. The floor point near the
     * green wall lies in the short box's shadow (the path tracer agrees:
     * docs/shadows.md), so the floor's lit colour is read near the red wall
     * for both. */
    assert_true(dr[0] > 0.0 && dr[1] > 0.0);
    assert_true(ir[0] / ir[1] > dr[0] / dr[1]);
    assert_true(ig[1] / ig[0] > dr[1] / dr[0]);
    free(ind);
    free(dir);
    lpv_scene_free(&scene);
}

/* Damping (lookup.glsl; the engine shades with a program compiled without
 * it unless it is on) only ever removes indirect light, and on the Cornell
 * box it removes some: the damped frame is another program's, and must
 * differ where light grows toward a surface. */
static void test_damping_only_darkens(void **state)
{
    (void)state;
    lpv_scene scene;
    assert_int_equal(lpv_scene_builtin_cornell(&scene), 0);
    float *plain = calloc((size_t)W * H * 4, sizeof *plain), *damped = calloc((size_t)W * H * 4, sizeof *damped);
    lpv_view view;
    render_damped(&scene, LPV_TERMS_INDIRECT_ONLY, 0.0f, &view, plain);
    render_damped(&scene, LPV_TERMS_INDIRECT_ONLY, 1.0f, &view, damped);
    double sum_plain = 0.0, sum_damped = 0.0;
    for (size_t i = 0; i < (size_t)W * H; ++i)
        for (int c = 0; c < 3; ++c) {
            const float a = plain[4 * i + (size_t)c], b = damped[4 * i + (size_t)c];
            assert_true(isfinite(b));
            if (b > a * (1.0f + 1e-5f) + 1e-7f)
                fail_msg("pixel %zu channel %d: damped %g > undamped %g", i, c, (double)b, (double)a);
            sum_plain += a;
            sum_damped += b;
        }
    print_message("indirect light summed over the frame: undamped %.6g, damping 1 %.6g\n", sum_plain, sum_damped);
    assert_true(sum_damped < 0.999 * sum_plain);
    free(plain);
    free(damped);
    lpv_scene_free(&scene);
}

/* The Cornell box's indirect-only frame at lookup step `step`, w x h. */
static void render_step(const lpv_scene *scene, int step, int w, int h, float *rgba)
{
    /* the LPV's lookup (the default technique is auto since issue 30) */
    const lpv_settings s = {
        .technique = LPV_TECHNIQUE_ID_LPV, .lpv.iterations = 8, .rsm_size = 256, .lookup_step = step};
    lpv_view view;
    render_with(scene, &s, LPV_TERMS_INDIRECT_ONLY, w, h, &view, rgba);
}

/* The lookup step (shading.glsl, lookup_blocks.comp): looking the
 * irradiance up once per block of 2 x 2 or 4 x 4 pixels and spreading it
 * along planes gives the every-pixel frame back closely, edges included (a
 * plain bilinear upsampling carries a wall's light onto the surface beside
 * it and fails step 2's bounds), on an image whose size the blocks do not
 * divide. */
static void test_lookup_step_follows_planes(void **state)
{
    (void)state;
    enum { SW = 191, SH = 155 };
    lpv_scene scene;
    assert_int_equal(lpv_scene_builtin_cornell(&scene), 0);
    float *every = calloc((size_t)SW * SH * 4, sizeof *every), *blocks = calloc((size_t)SW * SH * 4, sizeof *blocks);
    render_step(&scene, 1, SW, SH, every);
    double mean = 0.0;
    size_t covered = 0;
    for (size_t i = 0; i < (size_t)SW * SH; ++i)
        if (every[4 * i + 3] > 0.5f) {
            mean += (every[4 * i] + every[4 * i + 1] + every[4 * i + 2]) / 3.0;
            ++covered;
        }
    assert_true(covered > 0);
    mean /= (double)covered;
    /* measured: step 2 1896 of 68376 values (2.8 %) off by > 10 %, worst
     * 0.95, sum +0.3 %; step 4 8.4 %, 2.39, +1.3 %. A plain bilinear
     * upsampling: step 2 4.8 %, worst 1.92 */
    const struct {
        int step;
        double far, worst, sum;
    } steps[] = {{2, 0.035, 1.2, 0.01}, {4, 0.10, 2.5, 0.02}};
    for (size_t k = 0; k < sizeof steps / sizeof steps[0]; ++k) {
        render_step(&scene, steps[k].step, SW, SH, blocks);
        double sum_every = 0.0, sum_blocks = 0.0, worst = 0.0;
        size_t far = 0;
        for (size_t i = 0; i < (size_t)SW * SH; ++i) {
            assert_true(blocks[4 * i + 3] == every[4 * i + 3]);
            for (int c = 0; c < 3; ++c) {
                const double a = every[4 * i + (size_t)c], b = blocks[4 * i + (size_t)c];
                assert_true(isfinite(b) && b >= 0.0);
                const double rel = fabs(b - a) / fmax(a, 0.1 * mean);
                worst = fmax(worst, rel);
                far += rel > 0.1;
                sum_every += a;
                sum_blocks += b;
            }
        }
        print_message("lookup step %d: frame sum %.6g against %.6g at step 1, %zu of %zu values off by > 10 %%, "
                      "worst %.3f\n",
                      steps[k].step, sum_blocks, sum_every, far, 3 * covered, worst);
        assert_true(fabs(sum_blocks - sum_every) < steps[k].sum * sum_every);
        assert_true((double)far < steps[k].far * (double)(3 * covered));
        assert_true(worst < steps[k].worst);
    }
    free(every);
    free(blocks);
    lpv_scene_free(&scene);
}

/* The frame in two passes (shading.glsl, LPV_LOOKUP_SPLIT): every pixel of
 * the built-in box faces an axis or one of its flat surfaces' normals
 * (core/scene_planes.c), so the second pass has none to look up; with every
 * vertex normal turned by about a milliradian no pixel does, and the second
 * pass looks up all of them. The two indirect-only frames agree to what the
 * turn changes (measured: worst value 0.25 % apart). */
/* The frame in two passes at w x h: the built-in box with every vertex
 * normal turned by a milliradian sends every covered pixel through the
 * second pass (frame_full_lookups), whose light must be the first pass's
 * of the flat box. Returns the covered pixels. */
static size_t check_second_pass(int w, int h)
{
    lpv_scene flat, turned;
    assert_int_equal(lpv_scene_builtin_cornell(&flat), 0);
    assert_int_equal(lpv_scene_builtin_cornell(&turned), 0);
    for (uint32_t i = 0; i < turned.vertex_count; ++i) {
        float *n = turned.vertices[i].normal;
        const float d[3] = {sinf(1.3f * (float)i), cosf(2.1f * (float)i), sinf(0.7f * (float)i + 1.0f)};
        float len = 0.0f;
        for (int k = 0; k < 3; ++k) {
            n[k] += 1e-3f * d[k];
            len += n[k] * n[k];
        }
        for (int k = 0; k < 3; ++k)
            n[k] /= sqrtf(len);
    }
    /* the LPV at the default preset: normal bins, two cascades (lpv named: the default technique is auto since
     * issue 30, and the two passes are the LPV's lookup) */
    const lpv_settings s = {.technique = LPV_TECHNIQUE_ID_LPV};
    lpv_view view;
    const size_t pixels = (size_t)w * (size_t)h;
    float *a = calloc(pixels * 4, sizeof *a), *b = calloc(pixels * 4, sizeof *b);
    assert_non_null(a);
    assert_non_null(b);
    render_with(&flat, &s, LPV_TERMS_INDIRECT_ONLY, w, h, &view, a);
    assert_int_equal(lpv_engine_last_stats(lpvt_engine)->frame_full_lookups, 0);
    render_with(&turned, &s, LPV_TERMS_INDIRECT_ONLY, w, h, &view, b);
    size_t covered = 0;
    double mean = 0.0;
    for (size_t i = 0; i < pixels; ++i)
        if (a[4 * i + 3] > 0.5f) {
            ++covered;
            mean += (a[4 * i] + a[4 * i + 1] + a[4 * i + 2]) / 3.0;
        }
    assert_true(covered > pixels / 2);
    mean /= (double)covered;
    assert_int_equal(lpv_engine_last_stats(lpvt_engine)->frame_full_lookups, covered);
    double worst = 0.0, sum_a = 0.0, sum_b = 0.0;
    size_t unlit = 0; /* covered pixels the second pass left black */
    for (size_t i = 0; i < pixels; ++i) {
        assert_true(a[4 * i + 3] == b[4 * i + 3]);
        if (a[4 * i + 3] > 0.5f && a[4 * i] + a[4 * i + 1] + a[4 * i + 2] > 0.0f && b[4 * i] + b[4 * i + 1] + b[4 * i + 2] == 0.0f)
            ++unlit;
        for (int c = 0; c < 3; ++c) {
            const double x = a[4 * i + (size_t)c], y = b[4 * i + (size_t)c];
            assert_true(isfinite(y) && y >= 0.0);
            worst = fmax(worst, fabs(x - y) / fmax(x, 0.1 * mean));
            sum_a += x;
            sum_b += y;
        }
    }
    print_message("second pass at %dx%d: %zu pixels, %zu left unlit, worst value %.4f apart, sums %.6g and %.6g\n",
                  w, h, covered, unlit, worst, sum_a, sum_b);
    assert_int_equal(unlit, 0);
    assert_true(worst < 0.02);
    assert_true(fabs(sum_b - sum_a) < 0.002 * sum_a);
    free(a);
    free(b);
    lpv_scene_free(&flat);
    lpv_scene_free(&turned);
    return covered;
}

static void test_frame_second_pass(void **state)
{
    (void)state;
    check_second_pass(W, H);
}

/* Past LPV_SHADE_REST_MAX_GROUPS workgroups of LPV_SHADE_REST_WG listed
 * pixels (4 194 240) each invocation of the second pass takes several:
 * 2200 x 2200 lists about 4.56 M. */
static void test_frame_second_pass_strided(void **state)
{
    (void)state;
    const size_t covered = check_second_pass(2200, 2200);
    assert_true(covered > (size_t)LPV_SHADE_REST_WG * LPV_SHADE_REST_MAX_GROUPS);
}

static void test_shared_glb_matches_builtin(void **state)
{
    (void)state;
    const char *shared = lpvt_shared_dir();
    if (!shared) {
        skip();
        return;
    }
    char path[1024], err[1024];
    snprintf(path, sizeof path, "%s/scenes/cornell-box.glb", shared);
    lpv_scene glb, builtin;
    if (lpv_scene_load(path, &glb, err, sizeof err) != 0)
        fail_msg("%s", err);
    assert_int_equal(lpv_scene_builtin_cornell(&builtin), 0);
    float *a = calloc((size_t)W * H * 4, sizeof *a), *b = calloc((size_t)W * H * 4, sizeof *b);
    lpv_view va, vb;
    render(&glb, LPV_TERMS_FULL, &va, a);
    render(&builtin, LPV_TERMS_FULL, &vb, b);
    double diff = 0.0, sum = 0.0;
    for (size_t i = 0; i < (size_t)W * H * 4; i += 4)
        for (int c = 0; c < 3; ++c) {
            diff += fabs((double)a[i + (size_t)c] - b[i + (size_t)c]);
            sum += b[i + (size_t)c];
        }
    printf("glb vs built-in: relative L1 difference %.4f\n", diff / sum);
    assert_true(sum > 0.0);
    assert_true(diff / sum < 0.03);
    free(a);
    free(b);
    lpv_scene_free(&glb);
    lpv_scene_free(&builtin);
}

static int run(int argc, const char **argv)
{
    return lpvd_cmd_render(argc, (char **)argv);
}

static void test_render_command_files(void **state)
{
    (void)state;
    char png[512], exr[512], err[512];
    snprintf(png, sizeof png, "%s/cb.png", lpvt_tmpdir());
    snprintf(exr, sizeof exr, "%s/cb.exr", lpvt_tmpdir());
    const char *a1[] = {"render", "-o", png, "--size", "64x48", "--grid", "16", "--iterations", "4"};
    assert_int_equal(run(9, a1), 0);
    const char *a2[] = {"render", "-o", exr, "--size", "64x48", "--grid", "16", "--indirect-only", "--stats"};
    assert_int_equal(run(9, a2), 0);
    int w, h;
    float *px = NULL;
    assert_int_equal(lpv_image_read_f32(png, 4, &w, &h, &px, err, sizeof err), 0);
    assert_int_equal(w, 64);
    assert_int_equal(h, 48);
    double sum = 0.0;
    for (int i = 0; i < w * h * 4; i += 4)
        sum += px[i] + px[i + 1] + px[i + 2];
    assert_true(sum > 0.0);
    free(px);
    assert_int_equal(lpv_image_read_f32(exr, 4, &w, &h, &px, err, sizeof err), 0);
    float mx = 0.0f;
    for (int i = 0; i < w * h * 4; ++i) {
        assert_true(isfinite(px[i]));
        if (i % 4 != 3 && px[i] > mx)
            mx = px[i];
    }
    assert_true(mx > 0.0f); /* linear radiance, not tone-mapped */
    free(px);
}

static void test_render_command_rejects_bad_input(void **state)
{
    (void)state;
    const char *bad_flag[] = {"render", "--no-such-flag"};
    assert_int_equal(run(2, bad_flag), 2);
    const char *bad_grid[] = {"render", "--grid", "0"};
    assert_int_equal(run(3, bad_grid), 2);
    const char *bad_size[] = {"render", "--size", "12"};
    assert_int_equal(run(3, bad_size), 2);
    const char *missing[] = {"render", "/nonexistent/scene.glb"};
    assert_int_equal(run(2, missing), 1);
    const char *bad_camera[] = {"render", "--camera", "NoSuchCamera"};
    assert_int_equal(run(3, bad_camera), 2);
    char out[512];
    snprintf(out, sizeof out, "%s/no/such/folder/x.png", lpvt_tmpdir());
    const char *bad_out[] = {"render", "--size", "16x16", "--grid", "8", "-o", out};
    assert_int_equal(run(7, bad_out), 1);
}

/* --time and --animation (issue 32): a triangle that its animation moves
 * 4 m along +x in 1 s, seen by a camera looking at where it starts. At
 * --time 0 it fills the view's middle, at --time 1 it has left: the frames
 * differ. --animation without --time, a negative time and an animation the
 * file lacks are refused. */
static const char *SLIDE_GLTF =
        "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":68,\"uri\":\"data:application/"
        "octet-stream;base64,AACAvwAAgL8AAAAAAACAPwAAgL8AAAAAAAAAAAAAgD8AAAAAAAAAAAAAgD8AAAAAAAAAAAAAAAAAAIBAAAAA"
        "AAAAAAA=\"}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,"
        "\"byteLength\":8},{\"buffer\":0,\"byteOffset\":44,\"byteLength\":24}],\"accessors\":[{\"bufferView\":0,"
        "\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[-1,-1,0],\"max\":[1,1,0]},{\"bufferView\":1,"
        "\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\",\"min\":[0],\"max\":[1]},{\"bufferView\":2,"
        "\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"}],\"meshes\":[{\"primitives\":[{\"attributes\":"
        "{\"POSITION\":0}}]}],\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],\"scene\":0,\"animations\":"
        "[{\"name\":\"slide\",\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}}],"
        "\"samplers\":[{\"input\":1,\"output\":2}]}]}";

static void test_render_command_time(void **state)
{
    (void)state;
    const char *path = lpvt_write_file(lpvt_tmpdir(), "slide.gltf", SLIDE_GLTF, strlen(SLIDE_GLTF));
    char scene[512], a_out[512], b_out[512], err[512];
    snprintf(scene, sizeof scene, "%s", path);
    snprintf(a_out, sizeof a_out, "%s/t0.exr", lpvt_tmpdir());
    snprintf(b_out, sizeof b_out, "%s/t1.exr", lpvt_tmpdir());
    const char *a[] = {"render", scene, "-o", a_out, "--size", "32x32", "--eye", "0,0,4", "--target", "0,0,0",
                       "--time", "0", "--animation", "slide"};
    assert_int_equal(run(14, a), 0);
    const char *b[] = {"render", scene, "-o", b_out, "--size", "32x32", "--eye", "0,0,4", "--target", "0,0,0",
                       "--time", "1"};
    assert_int_equal(run(12, b), 0);
    int w, h;
    float *pa = NULL, *pb = NULL;
    assert_int_equal(lpv_image_read_f32(a_out, 4, &w, &h, &pa, err, sizeof err), 0);
    assert_int_equal(lpv_image_read_f32(b_out, 4, &w, &h, &pb, err, sizeof err), 0);
    const size_t centre = 4 * ((size_t)(h / 2) * (size_t)w + (size_t)(w / 2));
    printf("centre pixel at t = 0: %g (alpha %g); at t = 1: %g (alpha %g)\n", pa[centre], pa[centre + 3],
           pb[centre], pb[centre + 3]);
    assert_true(pa[centre + 3] > 0.5f); /* the triangle covers the centre at t = 0 */
    assert_true(pb[centre + 3] < 0.5f); /* and has left it at t = 1 */
    free(pa);
    free(pb);
    const char *no_time[] = {"render", scene, "--animation", "slide"};
    assert_int_equal(run(4, no_time), 2);
    const char *negative[] = {"render", scene, "--time", "-1"};
    assert_int_equal(run(4, negative), 2);
    const char *unknown[] = {"render", scene, "-o", a_out, "--size", "16x16", "--time", "0.5", "--animation", "walk"};
    assert_int_equal(run(10, unknown), 1);
}

/* A posed scene is sent to the GPU again only when the pose changed its
 * geometry (issue 32): the triangle at 1 s and at 2 s (after the last
 * keyframe: the same place) is one upload; at 0.5 s another. */
static void test_pose_uploads_only_when_geometry_moves(void **state)
{
    (void)state;
    const char *path = lpvt_write_file(lpvt_tmpdir(), "slide-uploads.gltf", SLIDE_GLTF, strlen(SLIDE_GLTF));
    char p[512], err[512];
    snprintf(p, sizeof p, "%s", path);
    const double times[3] = {1.0, 2.0, 0.5};
    unsigned long uploads[3];
    lpv_settings st = {.technique = LPV_TECHNIQUE_ID_LPV, .grid_dims = {8, 8, 8}};
    assert_int_equal(lpv_engine_set_settings(lpvt_engine, &st, err, sizeof err), 0);
    for (int i = 0; i < 3; ++i) {
        lpv_gltf_animation_time at = {"slide", times[i]};
        lpv_scene s;
        assert_int_equal(lpv_scene_load_user(p, &at, &s, err, sizeof err), 0);
        lpv_view v;
        lpv_view_choice choice = {.width = 16, .height = 16};
        assert_int_equal(lpv_view_resolve(&choice, &s, &v, err, sizeof err), 0);
        if (lpv_engine_set_scene(lpvt_engine, &s, err, sizeof err) != 0 ||
            lpv_engine_set_view(lpvt_engine, &v, err, sizeof err) != 0 || lpv_engine_tick(lpvt_engine, err, sizeof err))
            fail_msg("%s", err);
        uploads[i] = lpv_engine_get_counters(lpvt_engine).scene_uploads;
        lpv_scene_free(&s);
    }
    printf("uploads after 1 s, 2 s, 0.5 s: %lu, %lu, %lu\n", uploads[0], uploads[1], uploads[2]);
    assert_int_equal(uploads[1], uploads[0]);
    assert_int_equal(uploads[2], uploads[1] + 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cornell_colour_bleeding),
        cmocka_unit_test(test_damping_only_darkens),
        cmocka_unit_test(test_lookup_step_follows_planes),
        cmocka_unit_test(test_frame_second_pass),
        cmocka_unit_test(test_frame_second_pass_strided),
        cmocka_unit_test(test_shared_glb_matches_builtin),
        cmocka_unit_test(test_render_command_files),
        cmocka_unit_test(test_render_command_rejects_bad_input),
        cmocka_unit_test(test_render_command_time),
        cmocka_unit_test(test_pose_uploads_only_when_geometry_moves),
    };
    return cmocka_run_group_tests(tests, lpvt_gl_setup, lpvt_gl_teardown);
}
