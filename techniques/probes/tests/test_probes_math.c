/*
 * test_probes_math.c - the probes' ray set, rotation, octahedral map, SH
 * irradiance and Chebyshev weight (techniques/probes/core/probes_math.h).
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
#include "probes_table.h"
#include "probes_update.h"

static float dot3(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static double urand(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return (double)(*s >> 11) / 9007199254740992.0;
}

static void random_dir(uint64_t *s, float d[3])
{
    const double z = 2.0 * urand(s) - 1.0, phi = 2.0 * LPV_PI * urand(s), r = sqrt(1.0 - z * z);
    d[0] = (float)(r * cos(phi));
    d[1] = (float)(r * sin(phi));
    d[2] = (float)z;
}

/* Unit, balanced, and covering: no direction is farther from the set than
 * about the spacing of n equal areas. */
static void test_fibonacci_covers_the_sphere(void **state)
{
    (void)state;
    const uint32_t n = 256;
    float set[256][3], mean[3] = {0, 0, 0};
    for (uint32_t i = 0; i < n; ++i) {
        lpv_probes_fibonacci(i, n, set[i]);
        assert_float_equal(dot3(set[i], set[i]), 1.0f, 1e-5f);
        for (int k = 0; k < 3; ++k)
            mean[k] += set[i][k] / (float)n;
    }
    assert_true(sqrtf(dot3(mean, mean)) < 0.01f);
    /* the spacing of n equal areas: a cap of 4 pi / n sr has angle acos(1 - 2 / n) */
    const float cap = acosf(1.0f - 2.0f / (float)n);
    uint64_t rng = 7;
    float worst = 0.0f;
    for (int t = 0; t < 20000; ++t) {
        float d[3], best = -1.0f;
        random_dir(&rng, d);
        for (uint32_t i = 0; i < n; ++i)
            best = fmaxf(best, dot3(d, set[i]));
        worst = fmaxf(worst, acosf(fminf(best, 1.0f)));
    }
    assert_true(worst < 2.0f * cap);
}

static void test_rotation_is_a_rotation(void **state)
{
    (void)state;
    float m[9], m2[9], m3[9];
    for (uint32_t tick = 0; tick < 200; ++tick) {
        lpv_probes_rotation(tick, 1, m);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) {
                const float d = m[3 * r] * m[3 * c] + m[3 * r + 1] * m[3 * c + 1] + m[3 * r + 2] * m[3 * c + 2];
                assert_float_equal(d, r == c ? 1.0f : 0.0f, 1e-5f);
            }
        const float det = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
                          m[2] * (m[3] * m[7] - m[4] * m[6]);
        assert_float_equal(det, 1.0f, 1e-5f);
    }
    lpv_probes_rotation(5, 1, m);
    lpv_probes_rotation(5, 1, m2);
    lpv_probes_rotation(6, 1, m3);
    int same = 1, differ = 0;
    for (int k = 0; k < 9; ++k) {
        same &= m[k] == m2[k];
        differ |= fabsf(m[k] - m3[k]) > 1e-3f;
    }
    assert_true(same);   /* a tick's rotation is the same every time */
    assert_true(differ); /* the next tick's is another */
}

/* Over many ticks the rotated rays of a probe cover the sphere evenly: the
 * share landing in each octant is an eighth. */
static void test_rotated_rays_are_uniform(void **state)
{
    (void)state;
    int octant[8] = {0};
    const uint32_t n = 16, ticks = 4000;
    for (uint32_t tick = 0; tick < ticks; ++tick) {
        float m[9], d[3];
        lpv_probes_rotation(tick, 3, m);
        for (uint32_t i = 0; i < n; ++i) {
            lpv_probes_ray(i, n, m, d);
            assert_float_equal(dot3(d, d), 1.0f, 1e-5f);
            octant[(d[0] > 0) | (d[1] > 0) << 1 | (d[2] > 0) << 2]++;
        }
    }
    for (int k = 0; k < 8; ++k)
        assert_true(fabs(octant[k] / (double)(n * ticks) - 0.125) < 0.005);
}

static void test_octahedral_round_trip(void **state)
{
    (void)state;
    uint64_t rng = 11;
    for (int t = 0; t < 100000; ++t) {
        float d[3], uv[2], back[3];
        random_dir(&rng, d);
        lpv_probes_oct_encode(d, uv);
        assert_true(fabsf(uv[0]) <= 1.0f && fabsf(uv[1]) <= 1.0f);
        lpv_probes_oct_decode(uv, back);
        assert_true(dot3(d, back) > 1.0f - 1e-6f);
    }
    /* the poles and the equator's axes, where the fold meets */
    const float axes[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int a = 0; a < 6; ++a) {
        float uv[2], back[3];
        lpv_probes_oct_encode(axes[a], uv);
        lpv_probes_oct_decode(uv, back);
        assert_true(dot3(axes[a], back) > 1.0f - 1e-6f);
    }
}

/* Radiance of bands 0 and 1, L(w) = a + b w.z, projected from the ray set
 * and read back as irradiance: pi a + (2 pi / 3) b n.z, exact up to the
 * quadrature of 256 rays. A constant sky gives pi L on every normal. */
static void test_sh_irradiance(void **state)
{
    (void)state;
    const uint32_t n = 256;
    const float a = 2.0f, b = 1.5f;
    float sh[3][4] = {{0}};
    float m[9];
    lpv_probes_rotation(9, 1, m);
    for (uint32_t i = 0; i < n; ++i) {
        float d[3];
        lpv_probes_ray(i, n, m, d);
        const float l[3] = {a + b * d[2], a, 0.0f};
        lpv_probes_sh_add(sh, d, l, n);
    }
    uint64_t rng = 13;
    for (int t = 0; t < 1000; ++t) {
        float nrm[3], e[3];
        random_dir(&rng, nrm);
        lpv_probes_sh_irradiance(sh, nrm, e);
        assert_float_equal(e[0], LPV_PI * a + 2.0f * LPV_PI / 3.0f * b * nrm[2], 0.01f * LPV_PI * a);
        assert_float_equal(e[1], LPV_PI * a, 0.01f * LPV_PI * a);
        assert_float_equal(e[2], 0.0f, 1e-6f);
    }
}

static void test_chebyshev(void **state)
{
    (void)state;
    /* in front of the mean: trusted */
    assert_float_equal(lpv_probes_chebyshev(2.0f, 4.5f, 1.0f, 1e-4f), 1.0f, 0.0f);
    assert_float_equal(lpv_probes_chebyshev(2.0f, 4.5f, 2.0f, 1e-4f), 1.0f, 0.0f);
    /* behind it: less the farther, var = 0.5 */
    float last = 1.0f;
    for (float d = 2.1f; d < 6.0f; d += 0.1f) {
        const float w = lpv_probes_chebyshev(2.0f, 4.5f, d, 1e-4f);
        assert_true(w < last && w >= 0.0f);
        last = w;
    }
    const float w3 = lpv_probes_chebyshev(2.0f, 4.5f, 3.0f, 1e-4f), base = 0.5f / (0.5f + 1.0f);
    assert_float_equal(w3, base * base * base, 1e-6f);
    /* a wall: every ray stopped at 1 m, var 0 (rounding: negative) -> the floor */
    assert_true(lpv_probes_chebyshev(1.0f, 0.999999f, 1.5f, 1e-4f) < 1e-6f);
    /* bad input */
    assert_float_equal(lpv_probes_chebyshev(NAN, 1.0f, 1.0f, 1e-4f), 0.0f, 0.0f);
    assert_float_equal(lpv_probes_chebyshev(1.0f, INFINITY, 2.0f, 1e-4f), 0.0f, 0.0f);
}

/* The batch's ray table: its directions are lpv_probes_ray's; every
 * distance texel's weights sum to 1 and keep to its direction; every
 * irradiance texel's sum to pi (uniform radiance L gives pi L) and weigh
 * its hemisphere as the cosine does (their mean cosine is 2/3). */
static void test_ray_table(void **state)
{
    (void)state;
    lpv_probes_table t = {0};
    const int oct = 8, irr = 6;
    const uint32_t rays = 256;
    assert_int_equal(lpv_probes_table_make(&t, 3, 7, rays, oct, 50.0f, irr), 0);
    float m[9], d[3];
    lpv_probes_rotation(3, 7, m);
    for (uint32_t i = 0; i < rays; ++i) {
        lpv_probes_ray(i, rays, m, d);
        for (int k = 0; k < 3; ++k)
            assert_float_equal(t.dirs[4 * i + k], d[k], 1e-7);
    }
    const size_t texels = (size_t)(oct * oct + irr * irr);
    for (size_t k = 0; k < texels; ++k) {
        const int is_irr = k >= (size_t)(oct * oct);
        const int side = is_irr ? irr : oct, j = (int)(is_irr ? k - (size_t)(oct * oct) : k);
        float td[3];
        lpv_probes_texel_dir(j % side, j / side, side, td);
        const uint32_t first = t.taps[2 * k], count = t.taps[2 * k + 1];
        assert_true(count >= 1 && count <= rays);
        double sum = 0.0, cos_mean = 0.0;
        for (uint32_t q = first; q < first + count; ++q) {
            float w;
            memcpy(&w, &t.taps[2 * q + 1], sizeof w);
            const float *r = t.dirs + 4 * t.taps[2 * q];
            assert_true(w > 0.0f);
            sum += w;
            cos_mean += w * (td[0] * r[0] + td[1] * r[1] + td[2] * r[2]);
        }
        assert_float_equal(sum, is_irr ? LPV_PI : 1.0, 1e-4);
        if (!is_irr) /* the paper's sharpness: the rays within ~37 degrees, a tenth of them */
            assert_true(count <= rays / 8 && cos_mean > 0.9);
        else /* int cos^2 / int cos over the hemisphere = 2/3 */
            assert_true(cos_mean / LPV_PI > 0.6 && cos_mean / LPV_PI < 0.72);
    }
    lpv_probes_table_free(&t);
    assert_null(t.dirs);
    assert_int_equal(lpv_probes_table_make(&t, 0, 0, 0, oct, 50.0f, irr), -1);
    assert_int_equal(lpv_probes_table_make(&t, 0, 0, rays, 0, 50.0f, irr), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fibonacci_covers_the_sphere),
        cmocka_unit_test(test_rotation_is_a_rotation),
        cmocka_unit_test(test_rotated_rays_are_uniform),
        cmocka_unit_test(test_octahedral_round_trip),
        cmocka_unit_test(test_sh_irradiance),
        cmocka_unit_test(test_chebyshev),
        cmocka_unit_test(test_ray_table),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
