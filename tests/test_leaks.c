/*
 * test_leaks.c - a lamp inside a closed box must not light the room.
 *
 * A point light stands inside a closed 1 m box on an 8 m floor. Its light
 * reaches only the box's inner faces; the floor outside must get no light,
 * direct (the shadow map) or indirect (the LPV: the inner faces' VPLs must not
 * propagate through the box's walls, which the geometry volume holds from the
 * light's own RSM faces and from the scene surfels). The same lamp without
 * the box lights the floor, so the comparison is about something.
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
#include "scene_build.h"
#include "test_util.h"

enum { RING = 64 };

/* Mean indirect and direct irradiance (W/m^2, luminance-free: the green
 * channel, the light is white) on a ring of floor points 1 to 2.5 m outside
 * the box's walls, with or without the box around the lamp. */
static void floor_light(const lpv_settings *settings, int boxed, float half, double *indirect, double *direct)
{
    lpv_scene s = {0};
    int grey = lpv_scene_add_material(&s, "grey", (float[3]){0.7f, 0.7f, 0.7f}, NULL);
    const float floor_quad[4][3] = {{-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, {-4, 0, -4}};
    assert_true(lpv_scene_add_quad(&s, grey, floor_quad, NULL) >= 0);
    if (boxed)
        assert_true(lpv_scene_add_box(&s, grey, (float[3]){-half, 0.001f, -half}, (float[3]){half, 0.5f + half, half}) >= 0);
    else /* the same lamp and a tiny box under it, so the scene bounds match */
        assert_true(lpv_scene_add_box(&s, grey, (float[3]){-0.05f, 0.001f, -0.05f}, (float[3]){0.05f, 0.1f, 0.05f}) >= 0);
    const float corner[4][3] = {{-4, 2.5f, -4}, {-3.9f, 2.5f, -4}, {-3.9f, 2.5f, -3.9f}, {-4, 2.5f, -3.9f}};
    assert_true(lpv_scene_add_quad(&s, grey, corner, NULL) >= 0); /* bounds reach 2.5 m up either way */
    assert_true(lpv_scene_add_point_light(&s, (float[3]){0.0f, 0.5f, 0.0f}, 10.0f) != NULL);
    lpv_scene_compute_bounds(&s);

    char err[1024] = "";
    lpv_settings lpv = *settings;
    lpv.technique = LPV_TECHNIQUE_ID_LPV; /* the LPV's leaks (the default technique is auto since issue 30) */
    assert_int_equal(lpv_engine_set_settings(lpvt_engine, &lpv, err, sizeof err), 0);
    assert_int_equal(lpv_engine_set_scene(lpvt_engine, &s, err, sizeof err), 0);
    lpv_view view;
    const float eye[3] = {0.0f, 6.0f, 0.01f}, target[3] = {0.0f, 0.0f, 0.0f};
    assert_int_equal(lpv_view_look_at(eye, target, 1.2f, 64, 64, &view), 0);
    assert_int_equal(lpv_engine_set_view(lpvt_engine, &view, err, sizeof err), 0);
    if (lpv_engine_tick(lpvt_engine, err, sizeof err) != 0)
        fail_msg("tick: %s", err);

    float p[RING * 3], n[RING * 3], e[RING * 3];
    for (int i = 0; i < RING; ++i) {
        double a = 2.0 * M_PI * i / RING, r = half + 1.0 + 1.5 * (i % 4) / 3.0;
        p[3 * i] = (float)(r * cos(a));
        p[3 * i + 1] = 0.0f;
        p[3 * i + 2] = (float)(r * sin(a));
        n[3 * i] = n[3 * i + 2] = 0.0f;
        n[3 * i + 1] = 1.0f;
    }
    assert_int_equal(lpv_engine_irradiance(lpvt_engine, p, n, RING, e, err, sizeof err), 0);
    *indirect = 0.0;
    for (int i = 0; i < RING; ++i) {
        assert_true(isfinite(e[3 * i + 1]) && e[3 * i + 1] >= 0.0f);
        *indirect += e[3 * i + 1] / RING;
    }

    /* direct light: the full frame minus the indirect term, seen from above */
    float *full = malloc(64 * 64 * 4 * sizeof *full);
    assert_int_equal(lpv_engine_render(lpvt_engine, LPV_TERMS_DIRECT_ONLY, full, err, sizeof err), 0);
    /* pixels on the floor 1.5 - 3 m from the lamp: the image spans about
     * +-4.1 m at the floor (fov 1.2 rad from 6 m) */
    double sum = 0.0;
    int count = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            double wx = ((x + 0.5) / 64.0 * 2.0 - 1.0) * 6.0 * tan(0.6), wz = ((y + 0.5) / 64.0 * 2.0 - 1.0) * 6.0 * tan(0.6);
            double r = sqrt(wx * wx + wz * wz);
            if (r < half + 1.0 || r > half + 2.5)
                continue;
            sum += full[4 * (y * 64 + x) + 1];
            ++count;
        }
    assert_true(count > 100);
    *direct = sum / count * M_PI / 0.7; /* irradiance, W/m^2: the radiance (albedo / pi x E) back to E */
    free(full);
    lpv_scene_free(&s);
}

/* bound: the largest boxed indirect light allowed, as a fraction of the open
 * floor's direct light. */
static void check(const lpv_settings *s, const char *label, float half, double bound)
{
    double ind_open, dir_open, ind_box, dir_box;
    floor_light(s, 0, half, &ind_open, &dir_open);
    floor_light(s, 1, half, &ind_box, &dir_box);
    printf("%s, box %.2f m: floor 1-2.5 m outside it: indirect %.4g W/m^2 boxed (%.2f %% of the open floor's "
           "direct %.4g W/m^2), %.4g open; direct %.4g boxed\n",
           label, 2.0 * half, ind_box, 100.0 * ind_box / dir_open, dir_open, ind_open, dir_box);
    assert_true(dir_open > 0.01); /* the lamp lights the open floor */
    assert_true(dir_box < 1e-3 * dir_open);
    assert_true(ind_box < bound * dir_open);
}

/* A box of 12 cells (3 m in a 32^3 grid over this 8 m scene) must hold its
 * lamp's light: with the paper's transport under a twentieth of the open
 * floor's direct light (measured 1.3 %), with the default departures and
 * iterations under a tenth (measured 6.9 %: the far field's hand-off sums a
 * coarse cell's eight children, inside and outside a wall that crosses it;
 * 3.1 % with it off). The default grid (8^3, 1.14 m cells) cannot: its walls
 * and its light share cells, and it leaks more than half of the lamp's direct
 * light on the open floor there. That figure is printed, not asserted: the
 * LPV's known limit (docs/propagation.md, "Limits"; LPVT_LEAK_DIAG=1 prints
 * the leak against the box's size in cells). Direct light never leaks (the
 * shadow map). */
static void test_lamp_in_closed_box(void **state)
{
    (void)state;
    /* the paper's transport on a 32^3 grid: 12 cells of box */
    lpv_settings fine = {.grid_dims = {32, 32, 32}, .lpv.iterations = 8, .lpv.central_transport = LPV_SWITCH_OFF,
                         .lpv.far_field = LPV_SWITCH_OFF};
    check(&fine, "32^3, 8 iterations, paper transport, no far field", 1.5f, 0.05);
    /* 8 steps, as the default was before iterations followed the grid: at
     * the default for 32^3 now (32 steps) the volume lets 15.8 % through
     * (printed below, not asserted); frames take the reach mask instead
     * (test_enclosure, docs/propagation.md 6c, 6d) */
    lpv_settings departures = {.grid_dims = {32, 32, 32}, .lpv.iterations = 8};
    check(&departures, "32^3, the default departures, 8 iterations", 1.5f, 0.10);
    lpv_settings grid_steps = {.grid_dims = {32, 32, 32}};
    check(&grid_steps, "32^3, the default departures and iterations (not asserted)", 1.5f, 1.0);
    lpv_settings s = {0};
    for (int k = 0; k < 2; ++k) {
        const float half = k ? 0.5f : 1.5f;
        double ind_open, dir_open, ind_box, dir_box;
        floor_light(&s, 0, half, &ind_open, &dir_open);
        floor_light(&s, 1, half, &ind_box, &dir_box);
        printf("defaults (8^3), box %.2f m (not asserted): indirect on the floor outside it %.4g W/m^2 = %.0f %% "
               "of the open floor's direct %.4g W/m^2; direct with the box %.4g\n",
               2.0 * half, ind_box, 100.0 * ind_box / dir_open, dir_open, dir_box);
        assert_true(dir_box < 1e-3 * dir_open); /* the shadow map holds it at any size */
    }
}

/* The scene surfels add the box's outer sides to the geometry volume, another
 * buffer beside the lamp's RSM that holds the inner sides. Another buffer only
 * adds blocking (the merge keeps the larger per travel direction), so with
 * the surfels on the box must leak no more than with them off; the margin,
 * 5 %, is for the lookup (an L1 field's irradiance at a point need not fall
 * with every face's transmittance). The whole-vector merge this replaced kept
 * each point's larger lobe, the outer side's, and let the lamp's light out:
 * 0.143 W/m^2 with the surfels against 0.0925 without on the 8^3 grid. */
static void test_scene_surfels_do_not_leak(void **state)
{
    (void)state;
    const lpv_switch ON = LPV_SWITCH_ON, OFF = LPV_SWITCH_OFF;
    const lpv_settings grids[2] = {
        {.lpv.central_transport = OFF, .lpv.normal_bins = OFF, .lpv.far_field = OFF, .scene_surfels = OFF},
        {.grid_dims = {32, 32, 32}, .lpv.iterations = 8, .lpv.central_transport = OFF, .lpv.normal_bins = OFF,
         .lpv.far_field = OFF, .scene_surfels = OFF},
    };
    for (int k = 0; k < 2; ++k) {
        lpv_settings off = grids[k], on = grids[k];
        on.scene_surfels = ON;
        double ind_off, ind_on, direct;
        floor_light(&off, 1, 1.5f, &ind_off, &direct);
        floor_light(&on, 1, 1.5f, &ind_on, &direct);
        printf("%s grid, 3 m box: indirect on the floor outside it %.4g W/m^2 with scene surfels, %.4g without\n",
               k ? "32^3" : "8^3", ind_on, ind_off);
        assert_true(ind_off > 0.0); /* the comparison is about something */
        assert_true(ind_on <= 1.05 * ind_off);
    }
}

/* LPVT_LEAK_DIAG=1: the same boxes under variants of the default (printed). */
static void test_leak_diagnosis(void **state)
{
    (void)state;
    if (!getenv("LPVT_LEAK_DIAG"))
        return;
    const lpv_switch ON = LPV_SWITCH_ON, OFF = LPV_SWITCH_OFF;
    lpv_settings v[5] = {
        {.lpv.central_transport = OFF, .lpv.normal_bins = OFF, .lpv.far_field = OFF, .scene_surfels = OFF},
        {.lpv.central_transport = ON, .lpv.normal_bins = OFF, .lpv.far_field = OFF, .scene_surfels = OFF},
        {.lpv.central_transport = OFF, .lpv.normal_bins = ON, .lpv.far_field = OFF, .scene_surfels = OFF},
        {.lpv.central_transport = OFF, .lpv.normal_bins = OFF, .lpv.far_field = ON, .scene_surfels = OFF},
        {.lpv.central_transport = OFF, .lpv.normal_bins = OFF, .lpv.far_field = OFF, .scene_surfels = ON},
    };
    const char *names[5] = {"----", "c---", "-b--", "--f-", "---s"};
    for (int i = 0; i < 5; ++i) {
        double a, b, c, d;
        floor_light(&v[i], 1, 1.5f, &a, &b);
        floor_light(&v[i], 1, 0.5f, &c, &d);
        printf("%s: boxed indirect %.4g (3 m box), %.4g (1 m box)\n", names[i], a, c);
    }
    /* The defaults' departures on finer grids: the leak against the box's
     * size in cells (8 m / (grid - 1) per cell), and what the central
     * transport and the far field add to it (docs/propagation.md, 6c). */
    const int grids[] = {8, 12, 16, 24, 32};
    for (size_t g = 0; g < sizeof grids / sizeof grids[0]; ++g) {
        lpv_settings x = {.grid_dims = {grids[g], grids[g], grids[g]}};
        double ind_open, dir_open, leak, dir, leak_paper, leak_near;
        floor_light(&x, 0, 1.5f, &ind_open, &dir_open);
        floor_light(&x, 1, 1.5f, &leak, &dir);
        x.lpv.central_transport = OFF;
        floor_light(&x, 1, 1.5f, &leak_paper, &dir);
        x.lpv.central_transport = ON;
        x.lpv.far_field = OFF;
        floor_light(&x, 1, 1.5f, &leak_near, &dir);
        printf("defaults on %d^3 (3 m box = %.1f cells): leak %.1f %% of the open floor's direct; central transport "
               "off %.1f %%; far field off %.1f %%\n",
               grids[g], 3.0 * (grids[g] - 1) / 8.0, 100.0 * leak / dir_open, 100.0 * leak_paper / dir_open,
               100.0 * leak_near / dir_open);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_leak_diagnosis),
        cmocka_unit_test(test_lamp_in_closed_box),
        cmocka_unit_test(test_scene_surfels_do_not_leak),
    };
    return cmocka_run_group_tests(tests, lpvt_gl_setup, lpvt_gl_teardown);
}
