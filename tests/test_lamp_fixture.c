/*
 * test_lamp_fixture.c - a lamp in a small closed fixture in a large scene
 * stays enclosed in direct light (issue 30, docs/shadows.md "Near planes").
 *
 * The lights' shadow maps clipped everything closer to the light than their
 * near plane, which was 1e-3 x the scene's bounding radius: on a 400 m
 * floor (radius 283 m) 0.28 m, more than the walls of a 20 cm box around
 * the lamp are from it, so the lamp lit the floor around the box as if the
 * box were not there. The near plane now comes from the geometry around
 * each light (gpu/light_faces.c). On a 400 m floor:
 *   1. a point light in a closed 0.2 m box;
 *   2. an emissive 10 cm panel facing down in a closed 0.3 m box, 5 cm
 *      under its lid;
 * the direct-only frame of the floor 0.5 to 1.5 m from the box must be at
 * most 1e-3 of the same lamp's without the box (the default technique,
 * then octree and iv).
 *   3. A point light 2 m over the same floor, 1 mm from a small cube (so
 *      its shadow-map faces' near planes are 0.5 mm), lights a wall at 63
 *      degrees to its face's axis 10, 40 and 150 m away without acne (with
 *      the standard depth mapping a near plane that small loses the depth
 *      precision at such distances; the shadow maps hold reversed depth,
 *      shadow_maps.c): the direct frame over I cos / r^2 is 1.
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
#include "pt.h"
#include "scene_build.h"
#include "settings.h"
#include "test_util.h"
#include "view.h"

#define ALBEDO 0.5f
#define HALF 200.0f /* m: half the floor's side */

enum { W = 96, H = 96 };

/* The 400 m floor y = 0; returns its grey material. */
static int big_floor(lpv_scene *s)
{
    int grey = lpv_scene_add_material(s, "grey", (float[3]){ALBEDO, ALBEDO, ALBEDO}, NULL);
    const float plane[4][3] = {{-HALF, 0, HALF}, {HALF, 0, HALF}, {HALF, 0, -HALF}, {-HALF, 0, -HALF}};
    assert_true(lpv_scene_add_quad(s, grey, plane, NULL) >= 0);
    return grey;
}

/* The technique of the frames (the default unless a test sets another). */
static lpv_technique_id technique = LPV_TECHNIQUE_ID_DEFAULT;

/* The direct-only frame of s (default settings but the technique) from eye
 * looking at target. */
static float *render_direct(lpv_scene *s, const float eye[3], const float target[3], lpv_view *view)
{
    char err[1024] = "";
    lpv_scene_compute_bounds(s);
    lpv_settings set = {0};
    set.technique = technique;
    lpv_settings_resolve(&set);
    assert_int_equal(lpv_view_look_at(eye, target, 1.0f, W, H, view), 0);
    float *rgba = calloc((size_t)W * H * 4, sizeof *rgba);
    assert_non_null(rgba);
    if (lpv_engine_set_settings(lpvt_engine, &set, err, sizeof err) != 0 ||
        lpv_engine_set_scene(lpvt_engine, s, err, sizeof err) != 0 ||
        lpv_engine_set_view(lpvt_engine, view, err, sizeof err) != 0 ||
        lpv_engine_tick(lpvt_engine, err, sizeof err) != 0 ||
        lpv_engine_render(lpvt_engine, LPV_TERMS_DIRECT_ONLY, rgba, err, sizeof err) != 0)
        fail_msg("engine: %s", err);
    return rgba;
}


/* Mean direct radiance (rgb averaged) of the floor pixels 0.5 to 1.5 m from
 * the vertical axis through the origin, seen from 3 m up. */
static double ring_direct(lpv_scene *s)
{
    const float eye[3] = {0.0f, 3.0f, 0.01f}, target[3] = {0.0f, 0.0f, 0.0f};
    lpv_view view;
    float *rgba = render_direct(s, eye, target, &view);
    double sum = 0.0;
    int n = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            float p[3];
            if (!lpvt_floor_point(&view, x, y, p))
                continue;
            const float r = hypotf(p[0], p[2]);
            if (r < 0.5f || r > 1.5f)
                continue;
            const float *c = rgba + 4 * ((size_t)y * W + (size_t)x);
            for (int k = 0; k < 3; ++k)
                assert_true(isfinite(c[k]) && c[k] >= 0.0f);
            sum += (c[0] + c[1] + c[2]) / 3.0;
            ++n;
        }
    free(rgba);
    assert_true(n > 1000);
    return sum / n;
}

/* 1. a point light 10 cm over the floor, in a closed 0.2 m box or not */
static double point_lamp(int boxed)
{
    lpv_scene s = {0};
    int grey = big_floor(&s);
    if (boxed)
        assert_true(lpv_scene_add_box(&s, grey, (float[3]){-0.1f, 0.001f, -0.1f}, (float[3]){0.1f, 0.201f, 0.1f}) >= 0);
    assert_non_null(lpv_scene_add_point_light(&s, (float[3]){0.0f, 0.101f, 0.0f}, 10.0f));
    const double v = ring_direct(&s);
    lpv_scene_free(&s);
    return v;
}

/* 2. an emissive 10 cm panel facing down 25 cm over the floor, in a closed
 * 0.3 m box or not */
static double panel_lamp(int boxed)
{
    lpv_scene s = {0};
    int grey = big_floor(&s);
    if (boxed)
        assert_true(lpv_scene_add_box(&s, grey, (float[3]){-0.15f, 0.001f, -0.15f}, (float[3]){0.15f, 0.301f, 0.15f}) >=
                    0);
    int lamp = lpv_scene_add_material(&s, "lamp", (float[3]){0.0f, 0.0f, 0.0f}, (float[3]){1000.0f, 1000.0f, 1000.0f});
    assert_true(lamp >= 0);
    const float a = 0.05f, h = 0.25f;
    const float panel[4][3] = {{-a, h, -a}, {a, h, -a}, {a, h, a}, {-a, h, a}}; /* counter-clockwise from below */
    assert_true(lpv_scene_add_quad(&s, lamp, panel, NULL) >= 0);
    const double v = ring_direct(&s);
    lpv_scene_free(&s);
    return v;
}

/* The direct light is the shadow maps' for every technique: each one named
 * (the default, auto, is one of them on any scene). */
static const lpv_technique_id TECHNIQUES[] = {LPV_TECHNIQUE_ID_LPV, LPV_TECHNIQUE_ID_OCTREE, LPV_TECHNIQUE_ID_IV};

static void test_point_light_in_small_box(void **state)
{
    (void)state;
    for (size_t t = 0; t < sizeof TECHNIQUES / sizeof TECHNIQUES[0]; ++t) {
        technique = TECHNIQUES[t];
        const double open = point_lamp(0), closed = point_lamp(1);
        print_message("technique %d, point light: open %.4g, in a 0.2 m box %.4g W/(m^2 sr): %.3g of the open\n",
                      (int)technique, open, closed, closed / open);
        assert_true(open > 0.0);
        assert_true(closed <= 1e-3 * open);
    }
    technique = LPV_TECHNIQUE_ID_DEFAULT;
}

static void test_panel_in_small_box(void **state)
{
    (void)state;
    for (size_t t = 0; t < sizeof TECHNIQUES / sizeof TECHNIQUES[0]; ++t) {
        technique = TECHNIQUES[t];
        const double open = panel_lamp(0), closed = panel_lamp(1);
        print_message("technique %d, emissive panel: open %.4g, in a 0.3 m box %.4g W/(m^2 sr): %.3g of the open\n",
                      (int)technique, open, closed, closed / open);
        assert_true(open > 0.0);
        assert_true(closed <= 1e-3 * open);
    }
    technique = LPV_TECHNIQUE_ID_DEFAULT;
}

/* The point where pixel (x, y)'s ray meets the plane through o with normal
 * n (facing the camera), or -1. */
static int plane_point(const lpv_view *v, int x, int y, const double o[3], const double n[3], float p[3])
{
    float org[3], dir[3], tmin, tmax;
    lpv_ref_pixel_ray(v, x, y, org, dir, &tmin, &tmax);
    const double dn = dir[0] * n[0] + dir[1] * n[1] + dir[2] * n[2];
    if (!(dn < 0.0))
        return -1;
    const double t = ((o[0] - org[0]) * n[0] + (o[1] - org[1]) * n[1] + (o[2] - org[2]) * n[2]) / dn;
    for (int i = 0; i < 3; ++i)
        p[i] = (float)(org[i] + t * dir[i]);
    return 0;
}

/* 3. no acne on a wall facing the lamp 10, 40 and 150 m away (facing it, the
 * receiver's bias is its smallest, half a texel): direct / (albedo / pi x
 * I cos / r^2) */
static void test_far_wall_lit(void **state)
{
    (void)state;
    const float I = 10.0f, h = 2.0f, walls[3] = {10.0f, 40.0f, 150.0f};
    for (int k = 0; k < 3; ++k) {
        const float D = walls[k];
        lpv_scene s = {0};
        int grey = big_floor(&s);
        /* a 10 cm cube 1 mm behind the lamp: its shadow-map faces' near
         * planes are 0.5 mm */
        assert_true(lpv_scene_add_box(&s, grey, (float[3]){-0.101f, h - 0.05f, -0.05f}, (float[3]){-0.001f, h + 0.05f, 0.05f}) >=
                    0);
        /* the wall x = D + z / 2 (its depth varies across the face that sees
         * it), facing the lamp */
        const float wall[4][3] = {{D - 5, 0, -10}, {D + 5, 0, 10}, {D + 5, 20, 10}, {D - 5, 20, -10}};
        assert_true(lpv_scene_add_quad(&s, grey, wall, NULL) >= 0);
        const double o[3] = {D, 0.0, 0.0}, nw[3] = {-2.0 / sqrt(5.0), 0.0, 1.0 / sqrt(5.0)};
        assert_non_null(lpv_scene_add_point_light(&s, (float[3]){0.0f, h, 0.0f}, I));
        const float eye[3] = {D - 6.0f, h, 3.0f}, target[3] = {D, h, 0.0f};
        lpv_view view;
        float *rgba = render_direct(&s, eye, target, &view);
        double sum = 0.0, lo = 1e30;
        int n = 0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                float p[3];
                if (plane_point(&view, x, y, o, nw, p) != 0 || p[1] < 0.5f || p[1] > 19.5f || fabsf(p[2]) > 9.5f)
                    continue;
                const double l[3] = {0.0 - p[0], h - p[1], 0.0 - p[2]};
                const double r = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
                const double exact = ALBEDO / M_PI * I * (l[0] * nw[0] + l[1] * nw[1] + l[2] * nw[2]) / (r * r * r);
                const double v = rgba[4 * ((size_t)y * W + (size_t)x) + 1] / exact;
                sum += v;
                lo = v < lo ? v : lo;
                ++n;
            }
        free(rgba);
        lpv_scene_free(&s);
        assert_true(n > W * H / 2);
        print_message("wall %.0f m from the lamp: visibility mean %.4f, min %.4f\n", (double)D, sum / n, lo);
        assert_true(sum / n > 0.99 && sum / n < 1.01);
        assert_true(lo > 0.9); /* 0.92 at a few pixels at 10 m, on the old near planes too */
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_point_light_in_small_box),
        cmocka_unit_test(test_panel_in_small_box),
        cmocka_unit_test(test_far_wall_lit),
    };
    return cmocka_run_group_tests(tests, lpvt_gl_setup, lpvt_gl_teardown);
}
