/*
 * test_shadows.c - the shadow maps of direct light (issue 10, docs/shadows.md)
 * through real GL, against the geometry's exact answer:
 *
 *  1. A point light over a plane with an occluding square half-way up: the
 *     shadow is the square scaled by 2. lpvd's direct-only frame divided by
 *     the unshadowed I h / r^3 gives each pixel's visibility. Far enough
 *     outside the shadow it is 1 (no acne, no leak of the old 2-texel
 *     offset), far enough inside 0; across the straight edge it ramps
 *     monotonically over the PCF kernel's footprint (2R + 1 texels, 10-90 %
 *     over 80 % of it) and its middle sits on the exact edge within a texel
 *     or two.
 *  2. A sun over a 64 m plane at a grazing angle (16 degrees above the
 *     horizon) and a 20 cm box next to the camera: the box casts its shadow
 *     (the path tracer's shadow-ray test decides every pixel), no lit pixel
 *     anywhere on the plane is darkened (no acne at grazing incidence), with
 *     the cascades' texels (core/shadow_cascades.c) as the tolerance.
 *  3. A spot wider than 45 degrees (a cube of shadow-map faces, of which
 *     shadow_maps.c draws only what the cone reaches: not the face behind
 *     it, a band of each side face) over a plane, with a small box on each
 *     side near the cone's rim and one under the light: every box's shadow
 *     is there and nothing lit is darkened, against the path tracer's direct
 *     irradiance (its spot falloff too).
 *  4. Lights of every kind in any order: the shading loops over the
 *     directional lights, the points and spots, and the area light samples
 *     apart (gpu/light_faces.c puts the directional ones first; a scene
 *     without one gets a frame program without their loop). A point light,
 *     a sun and a spot over a plane with a box, declared in two orders, give
 *     the same frame, and it is the sum of the frames of each light alone
 *     (each kind's own shadows are tests 1 to 3's).
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
#include "lpv_shared.h"
#include "pt.h"
#include "scene_build.h"
#include "settings.h"
#include "shadow_cascades.h"
#include "test_util.h"
#include "view.h"

#define ALBEDO 0.5f

static float *render_direct(const lpv_scene *s, const lpv_settings *set, const lpv_view *view)
{
    char err[1024] = "";
    float *rgba = calloc((size_t)view->width * (size_t)view->height * 4, sizeof *rgba);
    assert_non_null(rgba);
    if (lpv_engine_set_settings(lpvt_engine, set, err, sizeof err) != 0 ||
        lpv_engine_set_scene(lpvt_engine, s, err, sizeof err) != 0 ||
        lpv_engine_set_view(lpvt_engine, view, err, sizeof err) != 0 ||
        lpv_engine_tick(lpvt_engine, err, sizeof err) != 0 ||
        lpv_engine_render(lpvt_engine, LPV_TERMS_DIRECT_ONLY, rgba, err, sizeof err) != 0)
        fail_msg("engine: %s", err);
    return rgba;
}

/* A grey material and the square floor y = 0 of half side `half` (m);
 * returns the material for the test's other geometry. */
static int grey_floor(lpv_scene *s, float half)
{
    int grey = lpv_scene_add_material(s, "grey", (float[3]){ALBEDO, ALBEDO, ALBEDO}, NULL);
    const float plane[4][3] = {{-half, 0, half}, {half, 0, half}, {half, 0, -half}, {-half, 0, -half}};
    assert_true(lpv_scene_add_quad(s, grey, plane, NULL) >= 0);
    return grey;
}

/* The path tracer's view of s, for its direct irradiance. */
static lpv_ref *reference_of(const lpv_scene *s)
{
    lpv_ref *ref = NULL;
    char err[512] = "";
    if (lpv_ref_create(s, NULL, &ref, err, sizeof err) != 0)
        fail_msg("reference: %s", err);
    return ref;
}


/* ---- 1. a point light, an occluding square, a plane --------------------- */

#define LIGHT_I 10.0f /* W/sr */
#define LIGHT_H 2.0f  /* m */
#define SQUARE 0.5f   /* half side of the occluder at height LIGHT_H / 2 */
#define SHADOW_SIZE 64 /* texels: coarse, so the ramp spans many pixels */

typedef struct sample {
    float x, v;
} sample;

static int by_x(const void *a, const void *b)
{
    float d = ((const sample *)a)->x - ((const sample *)b)->x;
    return (d > 0.0f) - (d < 0.0f);
}

static void test_point_light_shadow_edge(void **state)
{
    (void)state;
    lpv_scene s = {0};
    int grey = grey_floor(&s, 4.0f);
    const float h = 0.5f * LIGHT_H, a = SQUARE;
    const float square[4][3] = {{-a, h, -a}, {a, h, -a}, {a, h, a}, {-a, h, a}};
    assert_true(lpv_scene_add_quad(&s, grey, square, NULL) >= 0);
    assert_non_null(lpv_scene_add_point_light(&s, (float[3]){0, LIGHT_H, 0}, LIGHT_I));
    lpv_scene_compute_bounds(&s);

    /* Looking down at the shadow's edge x = 1 (the occluder stays out of
     * every pixel's way: it ends at x = 0.5, the rays pass it further out). */
    enum { W = 128, H = 128 };
    lpv_view view;
    assert_int_equal(lpv_view_look_at((float[3]){1.0f, 2.5f, 0.3f}, (float[3]){1.0f, 0.0f, 0.0f},
                                      30.0f * (float)M_PI / 180.0f, W, H, &view),
                     0);
    lpv_settings set = {.grid_dims = {16, 16, 16}, .shadow_size = SHADOW_SIZE};
    float *rgba = render_direct(&s, &set, &view);

    /* One texel of the cube face looking down, on the plane: the face is
     * widened so its central 90 degrees keep the border free. */
    const float n = (float)SHADOW_SIZE;
    const float T = 2.0f * (n / (n - 2.0f * LPV_SHADOW_BORDER_TEXELS)) * LIGHT_H / n;
    const float edge = 2.0f * SQUARE; /* the exact shadow is |x|, |z| <= 1 */
    const float R = (float)LPV_SHADOW_PCF_RADIUS;

    sample *row = calloc((size_t)W * H, sizeof *row);
    int lit = 0, dark = 0, nrow = 0, acne = 0, leak = 0;
    for (int y = 0; y < H; ++y) {
        for (int x = 0; x < W; ++x) {
            float p[3];
            const float *px = &rgba[4 * ((size_t)y * W + (size_t)x)];
            if (!lpvt_floor_point(&view, x, y, p) || px[3] < 0.5f)
                continue;
            double r2 = (double)p[0] * p[0] + (double)p[2] * p[2] + (double)LIGHT_H * LIGHT_H;
            double unshadowed = ALBEDO / M_PI * LIGHT_I * LIGHT_H / (r2 * sqrt(r2));
            float v = (float)(px[1] / unshadowed);
            /* signed distance to the exact shadow's boundary, m (+ outside) */
            float dx = fabsf(p[0]) - edge, dz = fabsf(p[2]) - edge;
            float out = sqrtf(fmaxf(dx, 0.0f) * fmaxf(dx, 0.0f) + fmaxf(dz, 0.0f) * fmaxf(dz, 0.0f));
            float sd = (dx > 0.0f || dz > 0.0f) ? out : fmaxf(dx, dz);
            if (sd > (R + 2.0f) * T) { /* beyond the kernel's reach and the bias's shift */
                ++lit;
                if (v < 0.995f)
                    ++acne;
            } else if (sd < -(R + 2.0f) * T) {
                ++dark;
                if (v > 0.005f)
                    ++leak;
            }
            if (fabsf(p[2]) < 0.2f && p[0] > edge - 6.0f * T && p[0] < edge + 6.0f * T)
                row[nrow++] = (sample){p[0], v};
        }
    }
    printf("shadow edge: texel %.4f m, %d lit pixels (%d darkened), %d shadowed (%d lit), %d across the edge\n",
           (double)T, lit, acne, dark, leak, nrow);
    assert_true(lit > 1000 && dark > 500);
    assert_int_equal(acne, 0);
    assert_int_equal(leak, 0);

    /* Across the edge x = 1 (|z| < 0.2, far from the corners): visibility
     * as a function of x alone, monotonic, from 0 to 1. */
    assert_true(nrow > 200);
    qsort(row, (size_t)nrow, sizeof *row, by_x);
    float x10 = NAN, x50 = NAN, x90 = NAN;
    for (int i = 0; i < nrow; ++i) {
        if (i > 0 && row[i].x > row[i - 1].x + 1e-4f)
            assert_true(row[i].v >= row[i - 1].v - 2e-3f);
        if (isnan(x10) && row[i].v >= 0.1f)
            x10 = row[i].x;
        if (isnan(x50) && row[i].v >= 0.5f)
            x50 = row[i].x;
        if (isnan(x90) && row[i].v >= 0.9f)
            x90 = row[i].x;
    }
    assert_true(row[0].v < 0.01f && row[nrow - 1].v > 0.99f);
    float width = (x90 - x10) / T, centre = (x50 - edge) / T;
    printf("shadow edge: 10-90 %% ramp %.2f texels (kernel: %.1f), middle %+.2f texels from the exact edge\n",
           (double)width, 0.8 * (2.0 * R + 1.0), (double)centre);
    /* a (2R + 1)-texel tent ramps 10-90 % over 0.8 (2R + 1) texels */
    assert_true(width > 0.6f * (2.0f * R + 1.0f) && width < 1.0f * (2.0f * R + 1.0f));
    assert_true(fabsf(centre) < 1.5f);
    free(row);
    free(rgba);
    lpv_scene_free(&s);
}

/* ---- 2. a low sun over a 64 m plane and a 20 cm box ----------------------- */

#define SUN_E 5.0f /* W/m^2 on a surface facing the sun */

/* Whether the ray from p towards the sun (-d) meets the box [lo, hi]. */
static int box_blocks(const float p[3], const float d[3], const float lo[3], const float hi[3])
{
    float t0 = 0.0f, t1 = INFINITY;
    for (int i = 0; i < 3; ++i) {
        float dir = -d[i];
        if (fabsf(dir) < 1e-12f) {
            if (p[i] < lo[i] || p[i] > hi[i])
                return 0;
            continue;
        }
        float a = (lo[i] - p[i]) / dir, b = (hi[i] - p[i]) / dir;
        t0 = fmaxf(t0, fminf(a, b));
        t1 = fminf(t1, fmaxf(a, b));
    }
    return t1 >= t0;
}

static void test_small_box_under_a_low_sun(void **state)
{
    (void)state;
    lpv_scene s = {0};
    int grey = grey_floor(&s, 32.0f);
    const float lo[3] = {-0.1f, 0.0f, -0.1f}, hi[3] = {0.1f, 0.2f, 0.1f};
    assert_true(lpv_scene_add_box(&s, grey, lo, hi) >= 0);
    float d[3] = {-1.0f, -0.3f, -0.2f}; /* travelling; about 16 degrees above the horizon */
    float len = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int i = 0; i < 3; ++i)
        d[i] /= len;
    assert_non_null(lpv_scene_add_directional_light(&s, d, SUN_E));
    lpv_scene_compute_bounds(&s);

    /* From beside the box, its shadow stretching away towards -x, and the
     * plane out to the horizon. */
    enum { W = 160, H = 120 };
    lpv_view view;
    assert_int_equal(lpv_view_look_at((float[3]){0.3f, 0.45f, 0.9f}, (float[3]){-0.35f, 0.0f, -0.1f},
                                      60.0f * (float)M_PI / 180.0f, W, H, &view),
                     0);
    lpv_settings set = {.grid_dims = {16, 16, 16}};
    float *rgba = render_direct(&s, &set, &view);

    /* The tolerance: three texels of the second cascade (the box and its
     * shadow lie in the first two), as their footprint on the plane: a
     * texel across the light's rays covers T / cos(theta) along them. */
    lpv_shadow_cascade c[LPV_SHADOW_CASCADES];
    lpv_settings resolved = set; /* the shadow map size the engine used */
    lpv_settings_resolve(&resolved);
    assert_int_equal(lpv_shadow_cascades_fit(&view, d, s.bounds_min, s.bounds_max, resolved.shadow_size,
                                             LPV_SHADOW_BORDER_TEXELS, LPV_SHADOW_CASCADES, c),
                     0);
    const int second = LPV_SHADOW_CASCADES > 1 ? 1 : 0;
    for (int k = 0; k < LPV_SHADOW_CASCADES; ++k)
        printf("sun: cascade %d texel %.2f cm\n", k, 100.0 * c[k].texel);
    const float cos_t = -d[1], m_across = 3.0f * c[second].texel, m_along = m_across / cos_t;
    float u[2] = {d[0], d[2]}; /* the sun's direction along the plane, and across it */
    float ul = sqrtf(u[0] * u[0] + u[1] * u[1]);
    u[0] /= ul;
    u[1] /= ul;
    lpv_ref *ref = reference_of(&s);

    const double unshadowed = ALBEDO / M_PI * SUN_E * (double)-d[1];
    int lit = 0, acne = 0, dark = 0, leak = 0, far_lit = 0;
    for (int y = 0; y < H; ++y) {
        for (int x = 0; x < W; ++x) {
            float p[3], org[3], dir[3], tmin, tmax, t, hit[3];
            const float *px = &rgba[4 * ((size_t)y * W + (size_t)x)];
            if (!lpvt_floor_point(&view, x, y, p) || px[3] < 0.5f)
                continue;
            lpv_ref_pixel_ray(&view, x, y, org, dir, &tmin, &tmax);
            if (!lpv_ref_first_hit(ref, org, dir, tmin, tmax, &t, hit) || fabsf(hit[1]) > 1e-4f)
                continue; /* the pixel shows the box, not the plane */
            float v = (float)(px[1] / unshadowed);
            /* the exact answer at p and around it, on an ellipse of the
             * tolerance in eight directions */
            int inside = 0, outside = 0;
            for (int k = 0; k < 9; ++k) {
                float q[3] = {p[0], 0.0f, p[2]};
                if (k < 8) {
                    float a = m_along * cosf((float)k * (float)M_PI / 4.0f);
                    float b = m_across * sinf((float)k * (float)M_PI / 4.0f);
                    q[0] += a * u[0] - b * u[1];
                    q[2] += a * u[1] + b * u[0];
                }
                if (box_blocks(q, d, lo, hi))
                    ++inside;
                else
                    ++outside;
            }
            if (inside != 9 && outside != 9)
                continue; /* within the tolerance of the shadow's boundary */
            float e[3]; /* the path tracer's shadow ray agrees with the slab test */
            lpv_ref_direct_irradiance(ref, (float[3]){p[0], 1e-4f, p[2]}, (float[3]){0, 1, 0}, e);
            assert_true((e[1] > 0.0f) == (outside == 9));
            if (outside == 9) {
                ++lit;
                if (p[0] * p[0] + p[2] * p[2] > 25.0f)
                    ++far_lit;
                if (v < 0.99f)
                    ++acne;
            } else if (inside == 9) {
                ++dark;
                if (v > 0.01f)
                    ++leak;
            }
        }
    }
    printf("sun: %d lit plane pixels (%d beyond 5 m; %d darkened), %d in the box's shadow (%d lit)\n", lit, far_lit,
           acne, dark, leak);
    assert_true(dark > 100);  /* the 20 cm box casts a shadow */
    assert_true(far_lit > 500); /* the plane is seen far out */
    assert_int_equal(acne, 0);
    assert_int_equal(leak, 0);
    lpv_ref_destroy(ref);
    free(rgba);
    lpv_scene_free(&s);
}

/* ---- 3. a wide spot: boxes near its rim ----------------------------------- */

#define SPOT_I 20.0f /* W/sr on the axis */
#define SPOT_H 2.0f  /* m */
#define SPOT_SIZE 512 /* texels per cube face */

static void test_wide_spot_rim_shadows(void **state)
{
    (void)state;
    lpv_scene s = {0};
    int grey = grey_floor(&s, 8.0f);
    /* four boxes 2.3 m out along +-x and +-z (their shadows 50-58 degrees off
     * the axis, in the cube's side faces, inside the 62-degree cone) and one
     * under the light (the face below) */
    enum { BOXES = 5 };
    const float centre[BOXES][2] = {{2.3f, 0.0f}, {-2.3f, 0.0f}, {0.0f, 2.3f}, {0.0f, -2.3f}, {0.6f, 0.4f}};
    float lo[BOXES][3], hi[BOXES][3];
    for (int b = 0; b < BOXES; ++b) {
        const float r = 0.25f, h = b < 4 ? 0.3f : 1.0f;
        lo[b][0] = centre[b][0] - r, lo[b][1] = 0.0f, lo[b][2] = centre[b][1] - r;
        hi[b][0] = centre[b][0] + r, hi[b][1] = h, hi[b][2] = centre[b][1] + r;
        assert_true(lpv_scene_add_box(&s, grey, lo[b], hi[b]) >= 0);
    }
    lpv_light *spot = lpv_scene_add_point_light(&s, (float[3]){0, SPOT_H, 0}, SPOT_I);
    assert_non_null(spot);
    spot->type = LPV_LIGHT_SPOT;
    spot->direction[0] = spot->direction[2] = 0.0f, spot->direction[1] = -1.0f;
    spot->inner_cone = 40.0f * (float)M_PI / 180.0f;
    spot->outer_cone = 62.0f * (float)M_PI / 180.0f;
    lpv_scene_compute_bounds(&s);

    enum { W = 192, H = 192 };
    lpv_view view;
    assert_int_equal(lpv_view_look_at((float[3]){0.0f, 9.0f, 0.01f}, (float[3]){0.0f, 0.0f, 0.0f},
                                      50.0f * (float)M_PI / 180.0f, W, H, &view),
                     0);
    lpv_settings set = {.grid_dims = {16, 16, 16}, .shadow_size = SPOT_SIZE};
    float *rgba = render_direct(&s, &set, &view);
    lpv_ref *ref = reference_of(&s);

    /* Tolerance around the shadows' edges: three texels of a cube face at the
     * rim's distance, spread along the floor at the rim's incidence. */
    const float rim = SPOT_H / cosf(spot->outer_cone);
    const float tol = 3.0f * 2.0f * rim / (float)SPOT_SIZE / cosf(spot->outer_cone);
    const float up[3] = {0.0f, 1.0f, 0.0f};
    int lit = 0, acne = 0, dark[BOXES] = {0}, leak = 0;
    for (int y = 0; y < H; ++y) {
        for (int x = 0; x < W; ++x) {
            float p[3];
            const float *px = &rgba[4 * ((size_t)y * W + (size_t)x)];
            if (!lpvt_floor_point(&view, x, y, p) || px[3] < 0.5f)
                continue;
            int on_box = 0, near_edge = 0, shadowed = -1;
            for (int b = 0; b < BOXES; ++b) {
                /* the box's footprint and the contact around it, where the
                 * receiver offsets let light in (docs/shadows.md) */
                on_box |= p[0] > lo[b][0] - tol && p[0] < hi[b][0] + tol && p[2] > lo[b][2] - tol &&
                          p[2] < hi[b][2] + tol;
                int in = 0;
                for (int k = 0; k < 9; ++k) { /* p and eight points around it at the tolerance */
                    float q[3] = {p[0], 0.0f, p[2]};
                    if (k < 8) {
                        q[0] += tol * cosf((float)k * (float)M_PI / 4.0f);
                        q[2] += tol * sinf((float)k * (float)M_PI / 4.0f);
                    }
                    float d[3] = {q[0], q[1] - SPOT_H, q[2]}; /* travelling from the light */
                    in += box_blocks(q, d, lo[b], hi[b]);
                }
                near_edge |= in > 0 && in < 9;
                if (in == 9)
                    shadowed = b;
            }
            if (on_box || near_edge)
                continue;
            float e[3];
            lpv_ref_direct_irradiance(ref, (float[3]){p[0], 1e-4f, p[2]}, up, e);
            const double want = ALBEDO / M_PI * (double)e[1];
            if (shadowed >= 0) {
                ++dark[shadowed];
                if (px[1] > 1e-3 * ALBEDO / M_PI * SPOT_I / (SPOT_H * SPOT_H))
                    ++leak;
            } else if (e[1] > 0.05f * SPOT_I / (SPOT_H * SPOT_H)) {
                ++lit;
                if (fabs(px[1] / want - 1.0) > 0.02)
                    ++acne;
            }
        }
    }
    printf("wide spot: %d lit plane pixels (%d off by more than 2 %%), shadows of the boxes %d %d %d %d %d pixels "
           "(%d lit)\n",
           lit, acne, dark[0], dark[1], dark[2], dark[3], dark[4], leak);
    assert_true(lit > 2000);
    for (int b = 0; b < BOXES; ++b)
        assert_true(dark[b] > 10); /* every box casts its shadow, the rim's too */
    assert_int_equal(acne, 0);
    assert_int_equal(leak, 0);
    lpv_ref_destroy(ref);
    free(rgba);
    lpv_scene_free(&s);
}

/* ---- 4. lights of every kind, in any order ------------------------------- */

/* The plane and box of test 4 with the lights of `which` (bits: 1 point, 2
 * sun, 4 spot), declared in that order or reversed. */
static void mixed_scene(lpv_scene *s, int which, int reversed)
{
    memset(s, 0, sizeof *s);
    int grey = grey_floor(s, 4.0f);
    assert_true(lpv_scene_add_box(s, grey, (float[3]){-0.3f, 0.0f, -0.3f}, (float[3]){0.3f, 0.6f, 0.3f}) >= 0);
    for (int i = 0; i < 3; ++i) {
        const int k = reversed ? 2 - i : i;
        if (!(which & (1 << k)))
            continue;
        if (k == 0)
            assert_non_null(lpv_scene_add_point_light(s, (float[3]){1.0f, 2.0f, 0.5f}, LIGHT_I));
        else if (k == 1)
            assert_non_null(lpv_scene_add_directional_light(s, (float[3]){-0.5f, -0.8f, -0.33f}, SUN_E));
        else {
            lpv_light *spot = lpv_scene_add_point_light(s, (float[3]){-1.0f, 2.0f, -0.5f}, SPOT_I);
            assert_non_null(spot);
            spot->type = LPV_LIGHT_SPOT;
            spot->direction[0] = 0.3f, spot->direction[1] = -1.0f, spot->direction[2] = 0.2f;
            spot->inner_cone = 0.4f;
            spot->outer_cone = 0.6f;
        }
    }
    lpv_scene_compute_bounds(s);
}

static void test_lights_in_any_order(void **state)
{
    (void)state;
    enum { W = 96, H = 72 };
    lpv_view view;
    assert_int_equal(lpv_view_look_at((float[3]){2.5f, 2.5f, 3.0f}, (float[3]){0.0f, 0.0f, 0.0f},
                                      60.0f * (float)M_PI / 180.0f, W, H, &view),
                     0);
    lpv_settings set = {.grid_dims = {8, 8, 8}};
    lpv_scene s;
    float *all[2], *alone[3];
    for (int r = 0; r < 2; ++r) {
        mixed_scene(&s, 7, r);
        all[r] = render_direct(&s, &set, &view);
        lpv_scene_free(&s);
    }
    for (int k = 0; k < 3; ++k) {
        mixed_scene(&s, 1 << k, 0);
        alone[k] = render_direct(&s, &set, &view);
        lpv_scene_free(&s);
    }
    double peak = 0.0, order = 0.0, sum = 0.0;
    int lit[3] = {0, 0, 0};
    for (size_t i = 0; i < (size_t)W * H * 4; ++i) {
        if (i % 4 == 3)
            continue;
        peak = fmax(peak, all[0][i]);
        order = fmax(order, fabs((double)all[0][i] - all[1][i]));
        sum = fmax(sum, fabs((double)all[0][i] - alone[0][i] - alone[1][i] - alone[2][i]));
        for (int k = 0; k < 3; ++k)
            lit[k] += alone[k][i] > 0.0f;
    }
    printf("lights in any order: peak %.4g, the two orders differ by %.3g, the sum of the lights alone by %.3g; "
           "lit values %d / %d / %d\n",
           peak, order, sum, lit[0], lit[1], lit[2]);
    assert_true(peak > 0.0);
    for (int k = 0; k < 3; ++k)
        assert_true(lit[k] > 1000); /* every light lights the plane */
    assert_true(order <= 1e-5 * peak);
    assert_true(sum <= 1e-5 * peak);
    for (int k = 0; k < 3; ++k)
        free(alone[k]);
    free(all[0]);
    free(all[1]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_point_light_shadow_edge),
        cmocka_unit_test(test_small_box_under_a_low_sun),
        cmocka_unit_test(test_wide_spot_rim_shadows),
        cmocka_unit_test(test_lights_in_any_order),
    };
    return cmocka_run_group_tests(tests, lpvt_gl_setup, lpvt_gl_teardown);
}
