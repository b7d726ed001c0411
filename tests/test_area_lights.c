/*
 * test_area_lights.c - emissive surfaces as direct area lights (issue 10,
 * docs/area-lights.md), through the real GL pipeline and the reference:
 *
 *  1. An emissive-only room is lit: a square emitter facing down over a
 *     grey floor. lpvd's direct irradiance on the floor matches the analytic
 *     form factor of the square within a few percent (and closer with more
 *     samples); the reference's emitter irradiance and its full frame agree
 *     with the same formula.
 *  2. Shadows: an opaque plate between the emitter and the floor darkens the
 *     floor under it to (nearly) nothing, in lpvd and in the reference.
 *  3. Energy: the samples carry exactly pi L A; the floor's RSM VPLs carry
 *     rho x the part of it that reaches the floor; the emitter injects nothing
 *     of its own (no double count), and with area lights off it injects
 *     exactly pi L A as VPLs instead.
 *  4. The plan says what ran and why.
 *  5. The area shadow step (docs/area-lights.md): the samples' visibility
 *     once per 2 x 2 or 4 x 4 block gives the every-pixel frame's penumbra
 *     within a few percent, leaves the floor's direct light no further from
 *     the numerically integrated shadowed irradiance than step 1's frame
 *     (beyond a small margin), and changes nothing where there is no area light;
 *     a surface thinner than the blocks takes its light from the second pass.
 *  6. A double-sided emitter (glTF doubleSided, issue 30) emits from its back
 *     as from its front, in lpvd (every technique) and the reference; a
 *     single-sided one leaves what lies behind it dark.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "area_lights.h"
#include "engine.h"
#include "oracle.h"
#include "pt.h"
#include "scene_build.h"
#include "test_util.h"
#include "view.h"

#define LE 2.0f        /* W/(m^2 sr), the emitter's radiance */
#define HALF 0.25f     /* m, half the emitter's side */
#define HEIGHT 1.0f    /* m, the emitter above the floor */
#define FLOOR_HALF 4.0f
#define RHO 0.5f
#define SAMPLES 8 /* the area_light_samples knob's default */

/* A grey floor (y = 0) under a black square emitter facing down; with plate,
 * an opaque 0.8 m plate at y = 0.5 between them. */
static void build(lpv_scene *s, int plate, float floor_half)
{
    memset(s, 0, sizeof *s);
    int grey = lpv_scene_add_material(s, "floor", (float[3]){RHO, RHO, RHO}, NULL);
    int lamp = lpv_scene_add_material(s, "lamp", (float[3]){0, 0, 0}, (float[3]){LE, LE, LE});
    const float f = floor_half, h = HALF, y = HEIGHT;
    const float floor_q[4][3] = {{-f, 0, f}, {f, 0, f}, {f, 0, -f}, {-f, 0, -f}};
    const float lamp_q[4][3] = {{-h, y, -h}, {h, y, -h}, {h, y, h}, {-h, y, h}}; /* counter-clockwise from below */
    assert_true(lpv_scene_add_quad(s, grey, floor_q, NULL) >= 0);
    assert_true(lpv_scene_add_quad(s, lamp, lamp_q, NULL) >= 0);
    if (plate) {
        int black = lpv_scene_add_material(s, "plate", (float[3]){0, 0, 0}, NULL);
        assert_true(lpv_scene_add_box(s, black, (float[3]){-0.4f, 0.49f, -0.4f}, (float[3]){0.4f, 0.51f, 0.4f}) >= 0);
    }
    lpv_scene_compute_bounds(s);
}

/* E / L at (x, 0, z) from the emitter: the differential-area-to-parallel-
 * rectangle form factor (times pi) by corner rectangles with signs. */
static double corner(double a, double b, double c)
{
    double A = a / c, B = b / c, sa = sqrt(1.0 + A * A), sb = sqrt(1.0 + B * B);
    return 0.5 * (A / sa * atan(B / sa) + B / sb * atan(A / sb));
}

static double signed_corner(double u, double v)
{
    return (u < 0 ? -1.0 : 1.0) * (v < 0 ? -1.0 : 1.0) * corner(fabs(u), fabs(v), HEIGHT);
}

static double analytic_e(double x, double z)
{
    double x0 = -HALF - x, x1 = HALF - x, z0 = -HALF - z, z1 = HALF - z;
    return LE * (signed_corner(x1, z1) - signed_corner(x0, z1) - signed_corner(x1, z0) + signed_corner(x0, z0));
}

static void run(const lpv_scene *s, lpv_settings set, const lpv_view *view)
{
    char err[1024] = "";
    if (lpv_engine_set_settings(lpvt_engine, &set, err, sizeof err) != 0 ||
        lpv_engine_set_scene(lpvt_engine, s, err, sizeof err) != 0 ||
        lpv_engine_set_view(lpvt_engine, view, err, sizeof err) != 0 || lpv_engine_tick(lpvt_engine, err, sizeof err))
        fail_msg("engine: %s", err);
}

enum { W = 64, H = 64 };

static lpv_view floor_view(void)
{
    lpv_view v;
    /* above and to the side: the emitter (at y = 1, |x|, |z| <= 0.25) hides no floor near its foot */
    assert_int_equal(lpv_view_look_at((float[3]){1.6f, 2.2f, 1.6f}, (float[3]){0, 0, 0}, 0.9f, W, H, &v), 0);
    return v;
}


/* lpvd's direct irradiance (from the direct-only frame) against the analytic
 * one over the floor within 1 m of the emitter's foot: the mean and the
 * largest relative error, and the value right under the emitter's centre. */
static void direct_error(int samples, double *mean_err, double *max_err, double *centre_ratio)
{
    lpv_scene s;
    build(&s, 0, FLOOR_HALF);
    lpv_view v = floor_view();
    lpv_settings set = {.grid_dims = {16, 16, 16}, .rsm_size = 128, .area_light_samples = samples};
    run(&s, set, &v);
    float *rgba = calloc((size_t)W * H * 4, sizeof *rgba);
    char err[512] = "";
    if (lpv_engine_render(lpvt_engine, LPV_TERMS_DIRECT_ONLY, rgba, err, sizeof err) != 0)
        fail_msg("render: %s", err);
    double sum = 0.0, worst = 0.0, best_d = 1e9;
    int n = 0;
    *centre_ratio = NAN;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            float p[3];
            const float *px = &rgba[4 * ((size_t)y * W + x)];
            if (!lpvt_floor_point(&v, x, y, p) || px[3] < 0.5f || hypotf(p[0], p[2]) > 1.0f)
                continue;
            double want = analytic_e(p[0], p[2]), got = px[1] * M_PI / RHO;
            double e = fabs(got - want) / want;
            sum += e;
            worst = fmax(worst, e);
            n++;
            double d = hypot(p[0], p[2]);
            if (d < best_d) {
                best_d = d;
                *centre_ratio = got / want;
            }
        }
    assert_true(n > 200);
    *mean_err = sum / n;
    *max_err = worst;
    free(rgba);
    lpv_scene_free(&s);
}

static void test_direct_matches_form_factor(void **state)
{
    (void)state;
    double mean8, max8, c8, mean64, max64, c64;
    direct_error(8, &mean8, &max8, &c8);
    direct_error(64, &mean64, &max64, &c64);
    printf("area lights: floor within 1 m of a %.1f m square emitter %.1f m above it, direct E vs the form factor: "
           "8 samples mean %.2f%% max %.2f%% (under the centre x%.4f); 64 samples mean %.2f%% max %.2f%% (x%.4f)\n",
           2.0 * HALF, (double)HEIGHT, 100 * mean8, 100 * max8, c8, 100 * mean64, 100 * max64, c64);
    /* right under the emitter, on average and everywhere: within a few
     * percent (measured: 0.2 %, 0.6 %, 1.6 %) */
    assert_true(fabs(c8 - 1.0) < 0.02);
    assert_true(mean8 < 0.02);
    assert_true(max8 < 0.05);
    /* more samples: closer */
    assert_true(fabs(c64 - 1.0) < 0.01);
    assert_true(mean64 < mean8);
}

/* The reference computes the same irradiance (next-event estimation on the
 * emitter) and its full frame shows rho / pi x it on the floor. */
static void test_reference_agrees(void **state)
{
    (void)state;
    lpv_scene s;
    build(&s, 0, FLOOR_HALF);
    lpv_ref *ref = NULL;
    char err[512] = "";
    if (lpv_ref_create(&s, &(lpv_ref_desc){.emitters_are_lights = 1}, &ref, err, sizeof err) != 0)
        fail_msg("%s", err);
    const float pts[3][3] = {{0, 0, 0}, {0.3f, 0, 0.1f}, {0.8f, 0, -0.5f}}, up[3][3] = {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}};
    float e[9], se[9];
    assert_int_equal(lpv_ref_emitter_irradiance(ref, &pts[0][0], &up[0][0], 3, 16384, e, se), 0);
    for (int i = 0; i < 3; ++i) {
        double want = analytic_e(pts[i][0], pts[i][2]);
        printf("area lights: reference E at (%.1f, 0, %.1f) = %.5f +- %.5f, analytic %.5f\n", (double)pts[i][0],
               (double)pts[i][2], (double)e[3 * i + 1], (double)se[3 * i + 1], want);
        assert_true(se[3 * i + 1] > 0.0f && se[3 * i + 1] < 0.01 * want);
        assert_true(fabs(e[3 * i + 1] - want) < 3.0 * se[3 * i + 1]);
    }
    /* the full frame: nothing but the floor reflects (the lamp is black), so
     * a floor pixel is rho / pi x the direct irradiance, one bounce or none */
    lpv_view v = floor_view();
    float *full = calloc((size_t)W * H * 4, sizeof *full), *fse = calloc((size_t)W * H * 4, sizeof *fse);
    assert_int_equal(lpv_ref_render_full(ref, &v, 1, 256, full, fse), 0);
    int checked = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            float p[3];
            const float *px = &full[4 * ((size_t)y * W + x)];
            if (!lpvt_floor_point(&v, x, y, p) || hypotf(p[0], p[2]) > 1.0f || px[1] > 0.5f * LE)
                continue;
            double want = RHO / M_PI * analytic_e(p[0], p[2]);
            assert_true(fabs(px[1] - want) < 4.0 * fse[4 * ((size_t)y * W + x) + 1] + 1e-6);
            checked++;
        }
    assert_true(checked > 200);
    free(full);
    free(fse);
    lpv_ref_destroy(ref);
    lpv_scene_free(&s);
}

/* The square turned to face up (its front towards +y, away from the floor);
 * double_sided as glTF's doubleSided: then its back emits too. */
static void build_facing_up(lpv_scene *s, int double_sided)
{
    memset(s, 0, sizeof *s);
    int grey = lpv_scene_add_material(s, "floor", (float[3]){RHO, RHO, RHO}, NULL);
    int lamp = lpv_scene_add_material(s, "lamp", (float[3]){0, 0, 0}, (float[3]){LE, LE, LE});
    s->materials[lamp].double_sided = double_sided;
    const float f = FLOOR_HALF, h = HALF, y = HEIGHT;
    const float floor_q[4][3] = {{-f, 0, f}, {f, 0, f}, {f, 0, -f}, {-f, 0, -f}};
    const float lamp_q[4][3] = {{-h, y, h}, {h, y, h}, {h, y, -h}, {-h, y, -h}}; /* counter-clockwise from above */
    assert_true(lpv_scene_add_quad(s, grey, floor_q, NULL) >= 0);
    assert_true(lpv_scene_add_quad(s, lamp, lamp_q, NULL) >= 0);
    lpv_scene_compute_bounds(s);
}

/* The mean of lpvd's direct irradiance over the analytic one (the square's
 * form factor, as if it faced down) on the floor within 1 m of its foot. */
static double direct_ratio_facing_up(int double_sided, lpv_technique_id technique)
{
    lpv_scene s;
    build_facing_up(&s, double_sided);
    lpv_view v = floor_view();
    lpv_settings set = {.grid_dims = {16, 16, 16}, .rsm_size = 128, .technique = technique};
    run(&s, set, &v);
    float *rgba = calloc((size_t)W * H * 4, sizeof *rgba);
    char err[512] = "";
    if (lpv_engine_render(lpvt_engine, LPV_TERMS_DIRECT_ONLY, rgba, err, sizeof err) != 0)
        fail_msg("render: %s", err);
    double got = 0.0, want = 0.0;
    int n = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            float p[3];
            const float *px = &rgba[4 * ((size_t)y * W + x)];
            if (!lpvt_floor_point(&v, x, y, p) || px[3] < 0.5f || hypotf(p[0], p[2]) > 1.0f)
                continue;
            got += px[1] * M_PI / RHO;
            want += analytic_e(p[0], p[2]);
            n++;
        }
    assert_true(n > 200);
    free(rgba);
    lpv_scene_free(&s);
    return got / want;
}

/* Issue 30: a double-sided emitter emits from both sides, as glTF viewers
 * light it. Facing up over the floor, the square lights the floor with its
 * back as it does facing down (each technique: they share the area light
 * samples), the reference agrees, and twice the flux goes out; single-sided,
 * the floor behind it stays dark. */
static void test_double_sided_emits_both_ways(void **state)
{
    (void)state;
    const lpv_technique_id techs[3] = {LPV_TECHNIQUE_ID_LPV, LPV_TECHNIQUE_ID_OCTREE, LPV_TECHNIQUE_ID_IV};
    for (int t = 0; t < 3; ++t) {
        double two = direct_ratio_facing_up(1, techs[t]), one = direct_ratio_facing_up(0, techs[t]);
        printf("area lights: a square facing up over the floor (technique %d): floor E / form factor %.4f "
               "double-sided, %.5f single-sided\n",
               (int)techs[t], two, one);
        assert_true(fabs(two - 1.0) < 0.03);
        assert_true(one < 1e-3);
    }
    /* the samples: pi L A from each side, half of them facing down */
    lpv_scene s;
    build_facing_up(&s, 1);
    lpv_emitter_list l;
    assert_int_equal(lpv_emitters_collect(&s, &l), 0);
    assert_int_equal(l.count, 4);
    assert_int_equal(l.surfaces, 1);
    lpv_area_sample smp[SAMPLES];
    assert_int_equal(lpv_area_lights_sample(&l, SAMPLES, smp), SAMPLES);
    double up = 0.0, down = 0.0;
    for (int k = 0; k < SAMPLES; ++k)
        *(smp[k].normal[1] > 0.99f ? &up : &down) += M_PI * smp[k].intensity[1];
    const double side_flux = M_PI * LE * 4.0 * HALF * HALF;
    assert_true(fabs(up - side_flux) < 1e-5 * side_flux);
    assert_true(fabs(down - side_flux) < 1e-5 * side_flux);
    lpv_emitters_free(&l);
    /* the reference: the analytic irradiance below; single-sided none */
    const float pts[2][3] = {{0, 0, 0}, {0.3f, 0, 0.1f}}, nrm[2][3] = {{0, 1, 0}, {0, 1, 0}};
    for (int ds = 1; ds >= 0; --ds) {
        s.materials[1].double_sided = ds;
        lpv_ref *ref = NULL;
        char err[512] = "";
        if (lpv_ref_create(&s, &(lpv_ref_desc){.emitters_are_lights = 1}, &ref, err, sizeof err) != 0)
            fail_msg("%s", err);
        float e[6], se[6];
        assert_int_equal(lpv_ref_emitter_irradiance(ref, &pts[0][0], &nrm[0][0], 2, 16384, e, se), 0);
        for (int i = 0; i < 2; ++i) {
            double want = analytic_e(pts[i][0], pts[i][2]);
            printf("area lights: reference E under a square facing up (%s) at (%.1f, 0, %.1f) = %.5f +- %.5f, "
                   "analytic from its back %.5f\n",
                   ds ? "double-sided" : "single-sided", (double)pts[i][0], (double)pts[i][2], (double)e[3 * i + 1],
                   (double)se[3 * i + 1], want);
            if (ds)
                assert_true(fabs(e[3 * i + 1] - want) < 3.0 * se[3 * i + 1] && se[3 * i + 1] < 0.01 * want);
            else
                assert_true(e[3 * i + 1] == 0.0f);
        }
        lpv_ref_destroy(ref);
    }
    lpv_scene_free(&s);
}

static void test_occluder_casts_shadow(void **state)
{
    (void)state;
    lpv_scene s;
    build(&s, 1, FLOOR_HALF);
    /* low, looking under the plate at the emitter's foot */
    lpv_view v;
    assert_int_equal(lpv_view_look_at((float[3]){2.5f, 0.3f, 0.3f}, (float[3]){0, 0, 0}, 0.9f, W, H, &v), 0);
    lpv_settings set = {.grid_dims = {16, 16, 16}, .rsm_size = 128};
    run(&s, set, &v);
    float *rgba = calloc((size_t)W * H * 4, sizeof *rgba);
    char err[512] = "";
    if (lpv_engine_render(lpvt_engine, LPV_TERMS_DIRECT_ONLY, rgba, err, sizeof err) != 0)
        fail_msg("render: %s", err);
    /* the 0.8 m plate halfway hides the whole 0.5 m emitter from the floor
     * within 0.55 m of the foot (umbra) and none of it beyond 1.05 m */
    double shadow = 0.0, lit = 0.0, lit_want = 0.0;
    int ns = 0, nl = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            float p[3];
            const float *px = &rgba[4 * ((size_t)y * W + x)];
            if (!lpvt_floor_point(&v, x, y, p) || px[3] < 0.5f)
                continue;
            double d = fmax(fabsf(p[0]), fabsf(p[2]));
            if (d < 0.3) {
                shadow += px[1] * M_PI / RHO;
                ns++;
            } else if (d > 1.15 && d < 1.5) {
                lit += px[1] * M_PI / RHO;
                lit_want += analytic_e(p[0], p[2]);
                nl++;
            }
        }
    assert_true(ns > 10 && nl > 10);
    shadow /= ns;
    lit /= nl;
    lit_want /= nl;
    lpv_ref *ref = NULL;
    if (lpv_ref_create(&s, &(lpv_ref_desc){.emitters_are_lights = 1}, &ref, err, sizeof err) != 0)
        fail_msg("%s", err);
    float pts[6] = {0.1f, 0, -0.2f, 1.3f, 0, 0.2f}, nrm[6] = {0, 1, 0, 0, 1, 0}, e[6], se[6];
    assert_int_equal(lpv_ref_emitter_irradiance(ref, pts, nrm, 2, 4096, e, se), 0);
    printf("area lights: floor under the plate E = %.5f W/m^2 (%zu px; reference %.5f), beyond its shadow %.5f "
           "(%zu px; unshadowed %.5f; reference at 1.3 m %.5f vs %.5f); unshadowed at the foot %.5f\n",
           shadow, (size_t)ns, (double)e[1], lit, (size_t)nl, lit_want, (double)e[4], analytic_e(1.3, 0.2),
           analytic_e(0, 0));
    assert_true(e[1] == 0.0f);                     /* the reference: full shadow */
    assert_true(fabs(e[4] - analytic_e(1.3, 0.2)) < 3.0 * se[4]); /* and no shadow out there */
    assert_true(shadow < 0.02 * analytic_e(0, 0)); /* lpvd: dark where it would be brightest */
    assert_true(fabs(lit - lit_want) < 0.05 * lit_want); /* and lit as without the plate beyond */
    free(rgba);
    lpv_ref_destroy(ref);
    lpv_scene_free(&s);
}

/* Total flux of the last tick's injected LPV (W, green). */
static double injected_flux(void)
{
    const lpv_grid *g = lpv_engine_grid(lpvt_engine);
    size_t count = lpv_grid_cell_count(g);
    lpv_cell *inj = calloc(count, sizeof *inj);
    assert_int_equal(lpv_engine_read_grid(lpvt_engine, LPV_GRID_INJECTED, inj, count), count);
    double flux[3];
    lpv_oracle_total_flux(g, inj, flux);
    free(inj);
    return flux[1];
}

static void test_energy_no_double_count(void **state)
{
    (void)state;
    lpv_scene s;
    const float big = 10.0f; /* the floor catches all but 0.3 % of the emitter's light */
    build(&s, 0, big);
    const double emitted = M_PI * LE * 4.0 * HALF * HALF;
    /* the samples: exactly pi L A */
    lpv_emitter_list l;
    assert_int_equal(lpv_emitters_collect(&s, &l), 0);
    lpv_area_sample smp[SAMPLES];
    assert_int_equal(lpv_area_lights_sample(&l, SAMPLES, smp), SAMPLES);
    double sum = 0.0;
    for (int k = 0; k < SAMPLES; ++k)
        sum += M_PI * smp[k].intensity[1];
    assert_true(fabs(sum - emitted) < 1e-6 * emitted);
    lpv_emitters_free(&l);

    /* area lights on: what enters the LPV is the floor's reflection, rho x
     * what reaches it (the point-to-square form factor of a 20 m floor 1 m
     * below: 0.9969), and nothing from the emitter itself */
    const double caught = 4.0 * corner(big, big, HEIGHT) / M_PI;
    lpv_settings set = {.technique = LPV_TECHNIQUE_ID_LPV, .grid_dims = {16, 16, 16}, .rsm_size = 256, .lpv.cascades = 1}; /* all of it in one grid */
    run(&s, set, NULL);
    double on = injected_flux();
    const lpv_plan *p = lpv_engine_last_plan(lpvt_engine);
    printf("area lights: emitted pi L A = %.4f W; floor caught %.4f; injected with area lights on %.4f W (rho x "
           "caught x emitted = %.4f)\n",
           emitted, caught, on, RHO * caught * emitted);
    /* (measured -0.5 %: each sample falls off as a disc of its area, not a point) */
    assert_true(fabs(on - RHO * caught * emitted) < 0.01 * RHO * emitted);
    assert_false(p->pass[LPV_PASS_EMISSIVE].run);
    assert_int_equal(lpv_engine_last_stats(lpvt_engine)->vpls_emissive, 0);

    /* black floor: nothing reflects, and the emitter injects nothing itself */
    s.materials[0].base_color[0] = s.materials[0].base_color[1] = s.materials[0].base_color[2] = 0.0f;
    run(&s, set, NULL);
    double black = injected_flux();
    printf("area lights: black floor, injected %.3g W\n", black);
    assert_true(black == 0.0);

    /* area lights off: the emitter's own VPLs carry exactly pi L A */
    set.area_lights = LPV_SWITCH_OFF;
    run(&s, set, NULL);
    double off = injected_flux();
    printf("area lights off, black floor: injected %.4f W (the emitter's VPLs)\n", off);
    assert_true(fabs(off - emitted) < 1e-4 * emitted);
    lpv_scene_free(&s);
}

static void test_plan_says_why(void **state)
{
    (void)state;
    lpv_scene s;
    build(&s, 0, FLOOR_HALF);
    lpv_settings set = {.technique = LPV_TECHNIQUE_ID_LPV, .grid_dims = {8, 8, 8}, .rsm_size = 32, .area_light_samples = 12};
    run(&s, set, NULL);
    const lpv_plan *p = lpv_engine_last_plan(lpvt_engine);
    print_message("rsm: %s\nemissive: %s\n", p->pass[LPV_PASS_RSM].reason, p->pass[LPV_PASS_EMISSIVE].reason);
    assert_true(p->pass[LPV_PASS_RSM].run);
    assert_non_null(strstr(p->pass[LPV_PASS_RSM].reason, "area lights: 1 emissive surfaces -> 12 samples"));
    assert_false(p->pass[LPV_PASS_EMISSIVE].run);
    assert_non_null(strstr(p->pass[LPV_PASS_EMISSIVE].reason, "light the scene directly"));
    const lpv_engine_stats *st = lpv_engine_last_stats(lpvt_engine);
    assert_int_equal(st->area_lights, 12);
    assert_int_equal(st->lights, 0);
    assert_int_equal(st->rsm_faces, 12 * 5);
    /* with the planner off the emitter still does not enter the LPV twice */
    set.planner = LPV_SWITCH_OFF;
    run(&s, set, NULL);
    assert_false(lpv_engine_last_plan(lpvt_engine)->pass[LPV_PASS_EMISSIVE].run);
    /* area lights off: no RSM (no punctual light), the emissive VPLs instead */
    set.planner = LPV_SWITCH_DEFAULT;
    set.area_lights = LPV_SWITCH_OFF;
    run(&s, set, NULL);
    p = lpv_engine_last_plan(lpvt_engine);
    assert_false(p->pass[LPV_PASS_RSM].run);
    assert_true(p->pass[LPV_PASS_EMISSIVE].run);
    assert_non_null(strstr(p->pass[LPV_PASS_EMISSIVE].reason, "(area lights off)"));
    assert_int_equal(lpv_engine_last_stats(lpvt_engine)->area_lights, 0);
    lpv_scene_free(&s);
}

/* Whether pixel (x, y)'s ray meets the box [lo, hi] before the floor. */
static int ray_hits_box(const lpv_view *v, int x, int y, const float lo[3], const float hi[3])
{
    float org[3], dir[3], tmin, tmax;
    lpv_ref_pixel_ray(v, x, y, org, dir, &tmin, &tmax);
    double t0 = 0.0, t1 = dir[1] < 0.0f ? -org[1] / dir[1] : 1e30;
    for (int a = 0; a < 3; ++a) {
        if (fabsf(dir[a]) < 1e-12f) {
            if (org[a] < lo[a] || org[a] > hi[a])
                return 0;
            continue;
        }
        double ta = (lo[a] - org[a]) / dir[a], tb = (hi[a] - org[a]) / dir[a];
        t0 = fmax(t0, fmin(ta, tb));
        t1 = fmin(t1, fmax(ta, tb));
    }
    return t0 < t1;
}

/* E at (x, 0, z) from the emitter with the plate box [lo, hi] in the way,
 * integrated numerically: the emitter (Lambertian, radiance LE) as a 40 x 40
 * grid of cells, each adding LE cos_floor cos_lamp / d^2 dA unless the
 * segment from the floor point to the cell's centre crosses the box. */
static double shadowed_e(double x, double z, const float lo[3], const float hi[3])
{
    enum { N = 40 };
    const double cell = 2.0 * HALF / N, da = cell * cell;
    double e = 0.0;
    for (int j = 0; j < N; ++j)
        for (int i = 0; i < N; ++i) {
            const double q[3] = {-HALF + (i + 0.5) * cell, HEIGHT, -HALF + (j + 0.5) * cell};
            const double o[3] = {x, 0.0, z}, d[3] = {q[0] - x, q[1], q[2] - z};
            double t0 = 0.0, t1 = 1.0;
            for (int a = 0; a < 3 && t0 < t1; ++a) {
                if (fabs(d[a]) < 1e-12) {
                    if (o[a] < lo[a] || o[a] > hi[a])
                        t1 = -1.0;
                    continue;
                }
                const double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
                t0 = fmax(t0, fmin(ta, tb));
                t1 = fmin(t1, fmax(ta, tb));
            }
            if (t0 < t1)
                continue; /* the plate hides this cell */
            const double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], c = HEIGHT / sqrt(d2); /* both cosines */
            e += LE * c * c / d2 * da;
        }
    return e;
}

/* The frame of `terms` at area shadow step `step` (s, v, set as given). */
static float *frame_at_step(const lpv_scene *s, lpv_settings set, const lpv_view *v, int step, lpv_frame_terms terms)
{
    set.area_shadow_step = step;
    run(s, set, v);
    float *rgba = calloc((size_t)W * H * 4, sizeof *rgba);
    char err[512] = "";
    if (lpv_engine_render(lpvt_engine, terms, rgba, err, sizeof err) != 0)
        fail_msg("render: %s", err);
    return rgba;
}

static void test_area_shadow_step_keeps_penumbra(void **state)
{
    (void)state;
    lpv_scene s;
    build(&s, 1, FLOOR_HALF);
    lpv_view v = floor_view(); /* from above: the plate, the floor, the plate's penumbra on it */
    const lpv_settings set = {.grid_dims = {16, 16, 16}, .rsm_size = 128};
    const float plate_lo[3] = {-0.4f, 0.49f, -0.4f}, plate_hi[3] = {0.4f, 0.51f, 0.4f};
    float *every = frame_at_step(&s, set, &v, 1, LPV_TERMS_DIRECT_ONLY);
    assert_false(lpvt_stage("area_shadow", NULL, NULL));
    for (int step = 2; step <= 4; step += 2) {
        float *blocks = frame_at_step(&s, set, &v, step, LPV_TERMS_DIRECT_ONLY);
        assert_true(lpvt_stage("area_shadow", NULL, NULL));
        /* over the floor: the frames' difference against the mean, and each
         * frame's error against the integrated shadowed irradiance; in the
         * penumbra (0.6 to 1.0 m from the foot, where the plate hides part
         * of the emitter) the mean of each, against the unshadowed light */
        double diff2 = 0.0, sum = 0.0, pen_every = 0.0, pen_blocks = 0.0, pen_open = 0.0;
        double err2_every = 0.0, err2_blocks = 0.0, sum_true = 0.0;
        int n = 0, np = 0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const size_t i = 4 * ((size_t)y * W + x);
                assert_true(isfinite(blocks[i]) && isfinite(blocks[i + 1]) && isfinite(blocks[i + 2]));
                float p[3];
                if (!lpvt_floor_point(&v, x, y, p) || every[i + 3] < 0.5f || ray_hits_box(&v, x, y, plate_lo, plate_hi))
                    continue; /* not the floor, or the plate in front of it */
                const double a = every[i + 1] * M_PI / RHO, b = blocks[i + 1] * M_PI / RHO;
                diff2 += (a - b) * (a - b);
                sum += a;
                const double t = shadowed_e(p[0], p[2], plate_lo, plate_hi);
                err2_every += (a - t) * (a - t);
                err2_blocks += (b - t) * (b - t);
                sum_true += t;
                n++;
                const double d = fmax(fabsf(p[0]), fabsf(p[2]));
                if (d > 0.6 && d < 1.0) {
                    pen_every += a;
                    pen_blocks += b;
                    pen_open += analytic_e(p[0], p[2]);
                    np++;
                }
            }
        assert_true(n > 1000 && np > 50);
        const double rel_rmse = sqrt(diff2 / n) / (sum / n);
        const double err_every = sqrt(err2_every / n) / (sum_true / n);
        const double err_blocks = sqrt(err2_blocks / n) / (sum_true / n);
        print_message("area shadow step %d: floor rel. RMS error vs the integrated shadowed E %.4f (step 1: %.4f), "
                      "difference %.4f to step 1 (%d px); penumbra mean E %.5f vs %.5f W/m^2 (%d px, unshadowed "
                      "%.5f)\n",
                      step, err_blocks, err_every, rel_rmse, n, pen_blocks / np, pen_every / np, np, pen_open / np);
        assert_true(pen_every > 0.1 * pen_open && pen_every < 0.9 * pen_open); /* a real penumbra */
        assert_true(fabs(pen_blocks - pen_every) < 0.03 * pen_every);
        /* the blocks never make the direct light worse than the every-pixel
         * shadow lookup, beyond a small margin */
        assert_true(err_blocks <= 1.1 * err_every + 0.01);
        free(blocks);
    }
    free(every);
    /* without area light samples the frame is the same at every step, and
     * the pass does not run */
    lpv_settings off = set;
    off.area_lights = LPV_SWITCH_OFF;
    float *a = frame_at_step(&s, off, &v, 1, LPV_TERMS_FULL), *b = frame_at_step(&s, off, &v, 2, LPV_TERMS_FULL);
    assert_false(lpvt_stage("area_shadow", NULL, NULL));
    assert_memory_equal(a, b, (size_t)W * H * 4 * sizeof *a);
    free(a);
    free(b);
    lpv_scene_free(&s);
}

/* A white pole 3 cm thick in the plate's penumbra, about a pixel wide in the
 * view: no 4 x 4 block lies on its faces, so the frame lists its lit pixels
 * and a second pass gives them their area light through every sample's
 * shadow map, as at step 1 (the blocks around are the floor's, whose
 * visibility differs from the pole's). */
static void test_area_shadow_step_thin_surfaces(void **state)
{
    (void)state;
    lpv_scene s;
    build(&s, 1, FLOOR_HALF);
    const float lo[3] = {0.785f, 0.0f, -0.015f}, hi[3] = {0.815f, 0.45f, 0.015f};
    int white = lpv_scene_add_material(&s, "pole", (float[3]){0.8f, 0.8f, 0.8f}, NULL);
    assert_true(lpv_scene_add_box(&s, white, lo, hi) >= 0);
    lpv_scene_compute_bounds(&s);
    lpv_view v = floor_view();
    const lpv_settings set = {.grid_dims = {16, 16, 16}, .rsm_size = 128};
    float *every = frame_at_step(&s, set, &v, 1, LPV_TERMS_DIRECT_ONLY);
    assert_int_equal(lpv_engine_last_stats(lpvt_engine)->frame_area_shadow_pixels, 0);
    float *blocks = frame_at_step(&s, set, &v, 4, LPV_TERMS_DIRECT_ONLY);
    const size_t listed = lpv_engine_last_stats(lpvt_engine)->frame_area_shadow_pixels;
    double sum_every = 0.0, sum_blocks = 0.0, worst = 0.0;
    int n = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const size_t i = 4 * ((size_t)y * W + x);
            if (!ray_hits_box(&v, x, y, lo, hi) || every[i + 3] < 0.5f || !(every[i + 1] > 0.0f))
                continue;
            sum_every += every[i + 1];
            sum_blocks += blocks[i + 1];
            worst = fmax(worst, fabs(blocks[i + 1] - every[i + 1]) / every[i + 1]);
            n++;
        }
    print_message("area shadow step 4, a 3 cm pole: %zu pixels listed for the second pass; the pole's %d lit "
                  "pixels %.5f vs %.5f at step 1 (mean), worst %.2f %%\n",
                  listed, n, sum_blocks / fmax(n, 1), sum_every / fmax(n, 1), 100.0 * worst);
    assert_true(n >= 3);
    assert_true(listed > 0);
    assert_true(fabs(sum_blocks - sum_every) < 0.02 * sum_every);
    free(every);
    free(blocks);
    lpv_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_direct_matches_form_factor), cmocka_unit_test(test_reference_agrees),
        cmocka_unit_test(test_occluder_casts_shadow),      cmocka_unit_test(test_energy_no_double_count),
        cmocka_unit_test(test_plan_says_why),              cmocka_unit_test(test_area_shadow_step_keeps_penumbra),
        cmocka_unit_test(test_area_shadow_step_thin_surfaces), cmocka_unit_test(test_double_sided_emits_both_ways),
    };
    return cmocka_run_group_tests(tests, lpvt_gl_setup, lpvt_gl_teardown);
}
