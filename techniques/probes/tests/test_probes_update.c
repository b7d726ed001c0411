/*
 * test_probes_update.c - one tick of the probes on the CPU
 * (techniques/probes/core/probes_update.h): irradiance, distance moments
 * and back-face share against what closed boxes make exact.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "lpv_shared.h"
#include "probes_math.h"
#include "probes_update.h"

/* An axis-aligned box from lo to hi as 12 triangles whose winding's normals
 * face inward (inward != 0) or outward. */
static void box(const float lo[3], const float hi[3], int inward, float pos[8 * 3], uint32_t idx[36])
{
    for (int c = 0; c < 8; ++c)
        for (int k = 0; k < 3; ++k)
            pos[3 * c + k] = (c >> k) & 1 ? hi[k] : lo[k];
    /* each face as two triangles wound outward (seen from outside: counter-clockwise) */
    static const uint32_t out[36] = {0, 4, 6, 0, 6, 2,  /* -x */ 1, 3, 7, 1, 7, 5, /* +x */
                                     0, 1, 5, 0, 5, 4,  /* -y */ 2, 6, 7, 2, 7, 3, /* +y */
                                     0, 2, 3, 0, 3, 1,  /* -z */ 4, 5, 7, 4, 7, 6 /* +z */};
    for (int t = 0; t < 12; ++t) {
        idx[3 * t] = out[3 * t];
        idx[3 * t + 1] = inward ? out[3 * t + 2] : out[3 * t + 1];
        idx[3 * t + 2] = inward ? out[3 * t + 1] : out[3 * t + 2];
    }
}

typedef struct emitter {
    const lpv_probes_bvh *bvh;
    float l[3];
} emitter;

/* The walls emit l from their front (the side their winding faces) only. */
static void shade_front(void *ctx, uint32_t tri, const float p[3], const float d[3], float t, float l[3])
{
    (void)p;
    (void)t;
    const emitter *e = ctx;
    const float *v = e->bvh->vertices + 12 * (size_t)tri;
    const float e1[3] = {v[4] - v[0], v[5] - v[1], v[6] - v[2]}, e2[3] = {v[8] - v[0], v[9] - v[1], v[10] - v[2]};
    const float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const int front = n[0] * d[0] + n[1] * d[1] + n[2] * d[2] < 0.0f;
    for (int c = 0; c < 3; ++c)
        l[c] = front ? e->l[c] : 0.0f;
}

/* The BVH of the box from (-1, -1, -1) to (1, 1, 1), walls facing in or out. */
static void unit_box(int inward, lpv_probes_bvh *b)
{
    float pos[24];
    uint32_t idx[36];
    box((float[3]){-1, -1, -1}, (float[3]){1, 1, 1}, inward, pos, idx);
    char err[128];
    assert_int_equal(lpv_probes_bvh_build(b, pos, 8, idx, 12, err, sizeof err), 0);
}

static lpv_probes_update_desc desc_for(const lpv_probes_bvh *b, const float *probes, size_t n, emitter *e)
{
    return (lpv_probes_update_desc){.bvh = b, .positions = probes, .probe_count = n, .rays = 2048, .tick = 1,
                                    .seed = 1, .max_distance = 100.0f, .oct_size = 8, .sharpness = 50.0f,
                                    .shade = shade_front, .ctx = e};
}

/* Inside a closed box whose walls all emit L: the irradiance is pi L on
 * every normal, no ray meets a back face, and each texel's mean distance is
 * the distance to the wall in its direction (1 / the largest component, in
 * a 2 m cube seen from its centre), blurred by the moments' cone. */
static void test_inside_a_glowing_box(void **state)
{
    (void)state;
    lpv_probes_bvh b;
    unit_box(1, &b);
    emitter e = {&b, {1.0f, 0.5f, 0.25f}};
    const float probe[3] = {0.0f, 0.0f, 0.0f};
    float moments[2 * 64];
    lpv_probe_result r = {.moments = moments};
    const lpv_probes_update_desc d = desc_for(&b, probe, 1, &e);
    assert_int_equal(lpv_probes_update_cpu(&d, &r), 0);
    assert_float_equal(r.backface_share, 0.0f, 0.0f);
    const float normals[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int k = 0; k < 6; ++k) {
        float irr[3];
        lpv_probes_sh_irradiance(r.sh, normals[k], irr);
        for (int c = 0; c < 3; ++c)
            assert_float_equal(irr[c], LPV_PI * e.l[c], 0.01f * LPV_PI * e.l[c]);
    }
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            float td[3];
            lpv_probes_texel_dir(x, y, 8, td);
            const float wall = 1.0f / fmaxf(fabsf(td[0]), fmaxf(fabsf(td[1]), fabsf(td[2])));
            const float mean = moments[2 * (y * 8 + x)], mean2 = moments[2 * (y * 8 + x) + 1];
            assert_float_equal(mean, wall, 0.1f * wall);
            assert_true(mean2 >= mean * mean * 0.999f); /* a variance is never negative beyond rounding */
        }
    lpv_probes_bvh_free(&b);
}

/* Outside that box (lit inside only): no light reaches the probe, the rays
 * that meet the box meet its backs, and their share is the box's solid
 * angle; the texels facing the box hold its distance, the others the miss
 * distance. A probe inside a solid block (outward walls) sees only backs. */
static void test_outside_and_inside_a_wall(void **state)
{
    (void)state;
    lpv_probes_bvh b;
    unit_box(1, &b);
    emitter e = {&b, {1.0f, 1.0f, 1.0f}};
    const float probe[3] = {3.0f, 0.0f, 0.0f};
    float moments[2 * 64];
    lpv_probe_result r = {.moments = moments};
    /* rays stop at twice the distance to the box, as a probe's stop near its
     * spacing: a texel's cone of weights reaches past the box's silhouette,
     * and a miss counted 100 m away moved the mean toward the box from 2 m
     * to 3.2 m (DDGI keeps the reach near the probes' spacing for that) */
    lpv_probes_update_desc d = desc_for(&b, probe, 1, &e);
    d.max_distance = 4.0f;
    assert_int_equal(lpv_probes_update_cpu(&d, &r), 0);
    for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 4; ++k)
            assert_float_equal(r.sh[c][k], 0.0f, 0.0f);
    /* the rays that meet the box meet its +x face, 2 m away: the solid angle
     * of a square of half-side a at distance h is 4 atan(a^2 / (h sqrt(2 a^2
     * + h^2))), here 4 atan(1 / (2 sqrt 6)), as a share of 4 pi */
    const float share = 4.0f * atanf(1.0f / (2.0f * sqrtf(6.0f))) / (4.0f * LPV_PI);
    assert_float_equal(r.backface_share, share, 0.15f * share);
    /* toward the box (-x) the mean distance is 2 m, away from it the misses' 4 m */
    float uv_dir[3];
    int toward = -1, away = -1;
    for (int k = 0; k < 64; ++k) {
        lpv_probes_texel_dir(k % 8, k / 8, 8, uv_dir);
        if (uv_dir[0] < -0.97f)
            toward = k;
        if (uv_dir[0] > 0.97f)
            away = k;
    }
    assert_true(toward >= 0 && away >= 0);
    assert_float_equal(moments[2 * toward], 2.0f, 0.1f);
    assert_float_equal(moments[2 * away], 4.0f, 1e-4f);
    lpv_probes_bvh_free(&b);

    /* a solid block: its walls face out, a probe inside it sees their backs */
    unit_box(0, &b);
    e.bvh = &b;
    const float inside[3] = {0.2f, -0.1f, 0.3f};
    const lpv_probes_update_desc d2 = desc_for(&b, inside, 1, &e);
    assert_int_equal(lpv_probes_update_cpu(&d2, &r), 0);
    assert_float_equal(r.backface_share, 1.0f, 0.0f);
    lpv_probes_bvh_free(&b);
}

/* No geometry: every ray sees the sky, pi sky on every normal, every texel
 * at the miss distance. A description it cannot run is refused. */
static void test_sky_and_bad_input(void **state)
{
    (void)state;
    lpv_probes_bvh b;
    char err[128];
    assert_int_equal(lpv_probes_bvh_build(&b, NULL, 0, NULL, 0, err, sizeof err), 0);
    const float sky[3] = {0.2f, 0.3f, 0.4f}, probe[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    float moments[2 * 16];
    lpv_probe_result r = {.moments = moments};
    lpv_probes_update_desc d = {.bvh = &b, .positions = probe, .probe_count = 1, .rays = 256, .max_distance = 10.0f,
                                .oct_size = 4, .sharpness = 50.0f, .sky = sky};
    assert_int_equal(lpv_probes_update_cpu(&d, &r), 0);
    float irr[3];
    lpv_probes_sh_irradiance(r.sh, up, irr);
    for (int c = 0; c < 3; ++c)
        assert_float_equal(irr[c], LPV_PI * sky[c], 0.01f * LPV_PI * sky[c]);
    for (int k = 0; k < 16; ++k) {
        assert_float_equal(moments[2 * k], 10.0f, 1e-4f);
        assert_float_equal(moments[2 * k + 1], 100.0f, 1e-2f);
    }
    lpv_probes_update_desc bad = d;
    bad.rays = 0;
    assert_int_equal(lpv_probes_update_cpu(&bad, &r), -1);
    bad = d;
    bad.oct_size = LPV_PROBES_OCT_MAX + 1;
    assert_int_equal(lpv_probes_update_cpu(&bad, &r), -1);
    bad = d;
    bad.max_distance = NAN;
    assert_int_equal(lpv_probes_update_cpu(&bad, &r), -1);
    bad = d;
    bad.bvh = NULL;
    assert_int_equal(lpv_probes_update_cpu(&bad, &r), -1);
    lpv_probes_bvh_free(&b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_inside_a_glowing_box),
        cmocka_unit_test(test_outside_and_inside_a_wall),
        cmocka_unit_test(test_sky_and_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
