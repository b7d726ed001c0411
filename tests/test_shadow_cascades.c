/*
 * test_shadow_cascades.c - the cascaded shadow maps of directional lights
 * (core/shadow_cascades.c, docs/shadows.md), without GL:
 *  - a sun over a 64 m level: the cascade nearest the camera has texels of
 *    centimetres at the default shadow_size, coarser cascades coarser ones;
 *  - the splits tile the view depth the scene occupies, and every point of
 *    the view frustum there lies inside a cascade with the border to spare;
 *  - the texel grid is stable: moving or turning the camera does not move a
 *    world point's position within its texel, nor change the texel size.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include <cglm/cglm.h>

#include "lpv_shared.h"
#include "settings.h"
#include "shadow_cascades.h"
#include "view.h"

static const float LEVEL_MIN[3] = {-32.0f, -0.2f, -32.0f}, LEVEL_MAX[3] = {32.0f, 12.0f, 32.0f};
static const float SUN[3] = {0.45f, -0.8f, 0.4f};
#define SHADOW_SIZE 1024 /* texels per cascade (the shadow_size knob's default) */

static lpv_view camera(const float eye[3], const float target[3])
{
    lpv_view v;
    assert_int_equal(lpv_view_look_at(eye, target, 60.0f * (float)M_PI / 180.0f, 640, 480, &v), 0);
    return v;
}

static void fit(const lpv_view *v, lpv_shadow_cascade c[LPV_SHADOW_CASCADES])
{
    assert_int_equal(lpv_shadow_cascades_fit(v, SUN, LEVEL_MIN, LEVEL_MAX, SHADOW_SIZE,
                                             LPV_SHADOW_BORDER_TEXELS, LPV_SHADOW_CASCADES, c),
                     0);
}

/* Clip-space xy of p in cascade c (orthographic: w = 1). */
static void project(const lpv_shadow_cascade *c, const float p[3], float xy[2])
{
    vec4 in = {p[0], p[1], p[2], 1.0f}, out;
    glm_mat4_mulv((vec4 *)c->view_proj, in, out);
    xy[0] = out[0] / out[3];
    xy[1] = out[1] / out[3];
}

static void test_texels_near_the_camera_are_centimetres(void **state)
{
    (void)state;
    lpv_view v = camera((float[3]){0.0f, 1.7f, 28.0f}, (float[3]){0.0f, 0.5f, 0.0f});
    lpv_shadow_cascade c[LPV_SHADOW_CASCADES];
    fit(&v, c);
    for (int k = 0; k < LPV_SHADOW_CASCADES; ++k)
        printf("cascade %d: view depth %.2f .. %.2f m, texel %.2f cm\n", k, (double)c[k].split_near,
               (double)c[k].split_far, 100.0 * c[k].texel);
    /* The level: the old single map had 64 m / 128 texels = 50 cm. */
    assert_true(c[0].texel < 0.02f);
    for (int k = 1; k < LPV_SHADOW_CASCADES; ++k)
        assert_true(c[k].texel > c[k - 1].texel);
    /* No cascade is coarser than one map over the level's bounding sphere
     * (its radius rounded up by at most 1/64, the border added). */
    float radius = 0.5f * sqrtf(64.0f * 64.0f + 12.2f * 12.2f + 64.0f * 64.0f);
    float n = (float)SHADOW_SIZE;
    float whole = 2.0f * radius * (1.0f + 1.0f / 64.0f) / (n - 2.0f * LPV_SHADOW_BORDER_TEXELS);
    for (int k = 0; k < LPV_SHADOW_CASCADES; ++k)
        assert_true(c[k].texel <= whole);
}

static void test_cascades_cover_the_view(void **state)
{
    (void)state;
    lpv_view v = camera((float[3]){-5.0f, 3.0f, 20.0f}, (float[3]){4.0f, 0.0f, -10.0f});
    lpv_shadow_cascade c[LPV_SHADOW_CASCADES];
    fit(&v, c);
    for (int k = 1; k < LPV_SHADOW_CASCADES; ++k)
        assert_float_equal(c[k].split_near, c[k - 1].split_far, 1e-5);
    /* Points across the frustum at depths through every slice: each that
     * lies in the scene lies in the inner square (border kept free) of the
     * cascade of its slice. */
    const float inner = 1.0f - 2.0f * LPV_SHADOW_BORDER_TEXELS / (float)SHADOW_SIZE;
    const float aspect = (float)v.width / (float)v.height, t = tanf(0.5f * v.yfov);
    vec3 fwd = {v.forward[0], v.forward[1], v.forward[2]}, up = {v.up[0], v.up[1], v.up[2]}, right;
    glm_vec3_cross(fwd, up, right);
    glm_vec3_normalize(right);
    glm_vec3_cross(right, fwd, up);
    int checked = 0;
    for (int k = 0; k < LPV_SHADOW_CASCADES; ++k) {
        for (int s = 0; s <= 4; ++s) {
            float z = c[k].split_near + (c[k].split_far - c[k].split_near) * (float)s / 4.0f;
            for (int i = -1; i <= 1; ++i)
                for (int j = -1; j <= 1; ++j) {
                    float p[3], xy[2];
                    for (int a = 0; a < 3; ++a)
                        p[a] = v.eye[a] + fwd[a] * z + right[a] * (float)i * z * t * aspect + up[a] * (float)j * z * t;
                    int in_scene = 1;
                    for (int a = 0; a < 3; ++a)
                        in_scene &= p[a] >= LEVEL_MIN[a] && p[a] <= LEVEL_MAX[a];
                    if (!in_scene)
                        continue;
                    project(&c[k], p, xy);
                    assert_true(fabsf(xy[0]) <= inner && fabsf(xy[1]) <= inner);
                    ++checked;
                }
        }
    }
    printf("%d frustum points in the scene, each inside its cascade\n", checked);
    assert_true(checked > LPV_SHADOW_CASCADES * 5 * 9 / 2);
    /* The slices end where the scene does along the view. */
    assert_true(c[LPV_SHADOW_CASCADES - 1].split_far > 40.0f);
}

/* A world point's position inside its texel (fraction of a texel) in cascade c. */
static void texel_phase(const lpv_shadow_cascade *c, const float p[3], float phase[2])
{
    float xy[2];
    project(c, p, xy);
    for (int a = 0; a < 2; ++a) {
        float u = (xy[a] * 0.5f + 0.5f) * (float)SHADOW_SIZE;
        phase[a] = u - floorf(u);
    }
}

static void test_texel_grid_is_stable(void **state)
{
    (void)state;
    const float target[3] = {0.0f, 0.0f, 0.0f};
    lpv_view a = camera((float[3]){0.0f, 2.0f, 10.0f}, target);
    /* moved by 7 cm and 4 cm; turned by about 1 degree */
    lpv_view b = camera((float[3]){0.07f, 2.0f, 9.96f}, (float[3]){0.07f, 0.0f, -0.04f});
    lpv_view r = camera((float[3]){0.0f, 2.0f, 10.0f}, (float[3]){-0.18f, 0.0f, 0.0f});
    lpv_shadow_cascade ca[LPV_SHADOW_CASCADES], cb[LPV_SHADOW_CASCADES], cr[LPV_SHADOW_CASCADES];
    fit(&a, ca);
    fit(&b, cb);
    fit(&r, cr);
    const float probe[3] = {0.3f, 0.0f, 1.1f};
    for (int k = 0; k < LPV_SHADOW_CASCADES; ++k) {
        /* Same slices, same texel size: the depth range and the radius are
         * rounded outwards. */
        assert_float_equal(cb[k].texel, ca[k].texel, 1e-6 * ca[k].texel);
        assert_float_equal(cr[k].texel, ca[k].texel, 1e-6 * ca[k].texel);
        float pa[2], pb[2], pr[2];
        texel_phase(&ca[k], probe, pa);
        texel_phase(&cb[k], probe, pb);
        texel_phase(&cr[k], probe, pr);
        for (int i = 0; i < 2; ++i) {
            float db = fabsf(pa[i] - pb[i]), dr = fabsf(pa[i] - pr[i]);
            assert_true(fminf(db, 1.0f - db) < 2e-2f);
            assert_true(fminf(dr, 1.0f - dr) < 2e-2f);
        }
    }
}

static void test_degenerate_inputs_are_refused(void **state)
{
    (void)state;
    lpv_view v = camera((float[3]){0.0f, 2.0f, 10.0f}, (float[3]){0.0f, 0.0f, 0.0f});
    lpv_shadow_cascade c[LPV_SHADOW_CASCADES];
    assert_int_equal(lpv_shadow_cascades_fit(&v, (float[3]){0, 0, 0}, LEVEL_MIN, LEVEL_MAX, 1024, 4.0f, 4, c), -1);
    assert_int_equal(lpv_shadow_cascades_fit(&v, (float[3]){NAN, -1, 0}, LEVEL_MIN, LEVEL_MAX, 1024, 4.0f, 4, c), -1);
    assert_int_equal(lpv_shadow_cascades_fit(&v, SUN, LEVEL_MIN, LEVEL_MAX, 8, 4.0f, 4, c), -1); /* all border */
    assert_int_equal(lpv_shadow_cascades_fit(&v, SUN, LEVEL_MIN, LEVEL_MAX, 1024, 4.0f, LPV_SHADOW_CASCADES + 1, c),
                     -1);
    /* A camera that sees none of the scene still gets finite cascades. */
    lpv_view away = camera((float[3]){0.0f, 2.0f, 100.0f}, (float[3]){0.0f, 2.0f, 200.0f});
    assert_int_equal(lpv_shadow_cascades_fit(&away, SUN, LEVEL_MIN, LEVEL_MAX, 1024, 4.0f, 4, c), 0);
    for (int k = 0; k < 4; ++k) {
        assert_true(isfinite(c[k].texel) && c[k].texel > 0.0f);
        for (int i = 0; i < 16; ++i)
            assert_true(isfinite(((float *)c[k].view_proj)[i]));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_texels_near_the_camera_are_centimetres),
        cmocka_unit_test(test_cascades_cover_the_view),
        cmocka_unit_test(test_texel_grid_is_stable),
        cmocka_unit_test(test_degenerate_inputs_are_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
