/* test_metrics.c - bench/accuracy/metrics.h: relative RMSE, bias, the
 * reference's noise level, masking, the error image's colours and the
 * Pareto front (docs/accuracy.md). Plain C, no GL. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image_io.h"
#include "metrics.h"
#include "overall.h"
#include "test_util.h"

enum { W = 8, H = 6, N = W * H };

/* A varied reference: positive colours, every pixel seen. */
static void make_ref(float *ref)
{
    for (int i = 0; i < N; ++i) {
        ref[4 * i + 0] = 0.1f + 0.05f * (float)(i % 7);
        ref[4 * i + 1] = 0.2f + 0.03f * (float)(i % 5);
        ref[4 * i + 2] = 0.05f + 0.02f * (float)(i % 11);
        ref[4 * i + 3] = 1.0f;
    }
}

static void test_identical(void **state)
{
    (void)state;
    float ref[4 * N], se[4 * N] = {0};
    make_ref(ref);
    lpv_acc_metrics m;
    assert_int_equal(lpv_acc_compare(ref, ref, se, W, H, &m), 0);
    assert_int_equal(m.pixels, N);
    assert_true(m.rel_rmse == 0.0);
    assert_true(m.rel_bias == 0.0);
    assert_true(m.ref_noise == 0.0);
    assert_true(m.rel_rmse_excess == 0.0);
    assert_true(m.rel_mae == 0.0);
    assert_true(m.mean_ref > 0.0);
}

static void test_constant_factor(void **state)
{
    (void)state;
    const float ks[] = {0.5f, 0.9f, 1.0f, 1.25f, 3.0f};
    float ref[4 * N], lpv[4 * N];
    make_ref(ref);
    for (size_t j = 0; j < sizeof ks / sizeof ks[0]; ++j) {
        float k = ks[j];
        for (int i = 0; i < 4 * N; ++i)
            lpv[i] = (i % 4 == 3) ? 1.0f : k * ref[i];
        lpv_acc_metrics m;
        assert_int_equal(lpv_acc_compare(lpv, ref, NULL, W, H, &m), 0);
        /* mean(L) = k mean(R), and |L - R| = |k - 1| R, but the RMSE of |k-1| R
         * over mean(R) is |k-1| * rms(R) / mean(R): check both exactly. */
        assert_float_equal(m.rel_bias, k - 1.0, 1e-6);
        assert_float_equal(m.rel_mae, fabs(k - 1.0), 1e-6); /* mean |k-1| R / mean R */
        double s1 = 0.0, s2 = 0.0;
        for (int i = 0; i < N; ++i)
            for (int c = 0; c < 3; ++c) {
                s1 += ref[4 * i + c];
                s2 += (double)ref[4 * i + c] * ref[4 * i + c];
            }
        double rms_over_mean = sqrt(s2 / (3.0 * N)) / (s1 / (3.0 * N));
        assert_float_equal(m.rel_rmse, fabs(k - 1.0) * rms_over_mean, 1e-6);
        assert_true(m.ref_noise == 0.0);
    }
    /* On a constant reference rms(R) = mean(R): rel_rmse is exactly |k - 1|. */
    for (int i = 0; i < N; ++i) {
        ref[4 * i] = ref[4 * i + 1] = ref[4 * i + 2] = 0.3f;
        ref[4 * i + 3] = 1.0f;
    }
    for (size_t j = 0; j < sizeof ks / sizeof ks[0]; ++j) {
        for (int i = 0; i < 4 * N; ++i)
            lpv[i] = (i % 4 == 3) ? 1.0f : ks[j] * ref[i];
        lpv_acc_metrics m;
        assert_int_equal(lpv_acc_compare(lpv, ref, NULL, W, H, &m), 0);
        assert_float_equal(m.rel_rmse, fabs(ks[j] - 1.0), 1e-6);
        assert_float_equal(m.rel_bias, ks[j] - 1.0, 1e-6);
        assert_float_equal(m.rel_mae, fabs(ks[j] - 1.0), 1e-6);
    }
}

static void test_masked_pixels_ignored(void **state)
{
    (void)state;
    float ref[4 * N], lpv[4 * N];
    make_ref(ref);
    memcpy(lpv, ref, sizeof lpv);
    /* Garbage where either image has alpha <= 0.5: must not count. */
    lpv[4 * 3 + 0] = 1e6f;
    lpv[4 * 3 + 3] = 0.0f; /* lpvd sees nothing here */
    ref[4 * 7 + 1] = -5e5f;
    ref[4 * 7 + 3] = 0.5f; /* the reference sees nothing here (not > 0.5) */
    lpv[4 * 9 + 2] = NAN;
    lpv[4 * 9 + 3] = 0.25f;
    lpv_acc_metrics m;
    assert_int_equal(lpv_acc_compare(lpv, ref, NULL, W, H, &m), 0);
    assert_int_equal(m.pixels, N - 3);
    assert_true(m.rel_rmse == 0.0);
    assert_true(m.rel_bias == 0.0);

    /* Nothing seen by both: -1 and NaN metrics. */
    for (int i = 0; i < N; ++i)
        lpv[4 * i + 3] = 0.0f;
    assert_int_equal(lpv_acc_compare(lpv, ref, NULL, W, H, &m), -1);
    assert_int_equal(m.pixels, 0);
    assert_true(isnan(m.rel_rmse));
}

static void test_noise_level(void **state)
{
    (void)state;
    float ref[4 * N], se[4 * N], lpv[4 * N];
    for (int i = 0; i < N; ++i) {
        for (int c = 0; c < 3; ++c) {
            ref[4 * i + c] = 2.0f;
            se[4 * i + c] = 0.2f; /* 10 % of the mean */
            /* +-0.2 alternating: an error exactly at the noise level, no bias */
            lpv[4 * i + c] = 2.0f + ((i + c) % 2 ? 0.2f : -0.2f);
        }
        ref[4 * i + 3] = lpv[4 * i + 3] = se[4 * i + 3] = 1.0f;
    }
    lpv_acc_metrics m;
    assert_int_equal(lpv_acc_compare(lpv, ref, se, W, H, &m), 0);
    assert_float_equal(m.ref_noise, 0.1, 1e-6);
    assert_float_equal(m.rel_rmse, 0.1, 1e-6);
    assert_float_equal(m.rel_bias, 0.0, 1e-6);
    assert_float_equal(m.rel_rmse_excess, 0.0, 1e-3);
    assert_float_equal(m.rel_mae, 0.1, 1e-6);
}

static void test_error_colours(void **state)
{
    (void)state;
    uint8_t c[3];
    lpv_acc_error_colour(0.0, c);
    assert_true(c[0] == 255 && c[1] == 255 && c[2] == 255); /* white: exact */
    lpv_acc_error_colour(1.0, c);
    assert_true(c[0] == 255 && c[1] == 0 && c[2] == 0); /* red: too bright */
    lpv_acc_error_colour(5.0, c);
    assert_true(c[0] == 255 && c[1] == 0 && c[2] == 0); /* clamped at +100 % */
    lpv_acc_error_colour(-1.0, c);
    assert_true(c[0] == 0 && c[1] == 0 && c[2] == 255); /* blue: too dark */
    lpv_acc_error_colour(-7.0, c);
    assert_true(c[0] == 0 && c[1] == 0 && c[2] == 255);
    lpv_acc_error_colour(0.5, c);
    assert_true(c[0] == 255 && c[1] == 128 && c[2] == 128);
    lpv_acc_error_colour(-0.5, c);
    assert_true(c[0] == 128 && c[1] == 128 && c[2] == 255);
    lpv_acc_error_colour(NAN, c);
    assert_true(c[0] == 0 && c[1] == 0 && c[2] == 0);

    /* The image: a 4x1 strip, exact / twice too bright / half as bright / masked. */
    float ref[16], lpv[16];
    for (int i = 0; i < 4; ++i) {
        for (int ch = 0; ch < 3; ++ch)
            ref[4 * i + ch] = 1.0f;
        ref[4 * i + 3] = lpv[4 * i + 3] = 1.0f;
    }
    const float f[4] = {1.0f, 2.0f, 0.5f, 1.0f};
    for (int i = 0; i < 4; ++i)
        for (int ch = 0; ch < 3; ++ch)
            lpv[4 * i + ch] = f[i];
    lpv[4 * 3 + 3] = 0.0f;
    lpv_acc_metrics m;
    assert_int_equal(lpv_acc_compare(lpv, ref, NULL, 4, 1, &m), 0);
    uint8_t img[12];
    lpv_acc_error_image(lpv, ref, 4, 1, m.mean_ref, img);
    const uint8_t want[12] = {255, 255, 255, 255, 0, 0, 128, 128, 255, 0, 0, 0};
    assert_memory_equal(img, want, sizeof want);

    /* Dark reference pixels are measured against 10 % of mean(R), not 0. */
    const float l_px[4] = {0.05f, 0.05f, 0.05f, 1}, r_px[4] = {0, 0, 0, 1};
    assert_float_equal(lpv_acc_pixel_error(l_px, r_px, 1.0), 0.5, 1e-6);

    /* And it is written as a PNG that reads back with those colours. */
    char path[512], err[512] = "";
    snprintf(path, sizeof path, "%s/err.png", lpvt_tmpdir());
    assert_int_equal(lpv_acc_write_error_png(path, lpv, ref, 4, 1, m.mean_ref, err, sizeof err), 0);
    int w = 0, h = 0;
    float *back = NULL;
    assert_int_equal(lpv_image_read_f32(path, 3, &w, &h, &back, err, sizeof err), 0);
    assert_int_equal(w, 4);
    assert_int_equal(h, 1);
    for (int i = 0; i < 12; ++i)
        assert_float_equal(back[i], want[i] / 255.0f, 1e-3);
    free(back);
}

static void test_pareto(void **state)
{
    (void)state;
    /*            0    1    2    3    4    5 (NaN)  6 (duplicate of 0) */
    double ms[] = {1.0, 2.0, 3.0, 2.5, 10.0, 0.5, 1.0};
    double er[] = {0.9, 0.5, 0.6, 0.4, 0.1, NAN, 0.9};
    int front[7];
    size_t n = lpv_acc_pareto(ms, er, 7, front);
    const int want[7] = {1, 1, 0, 1, 1, 0, 1};
    for (int i = 0; i < 7; ++i)
        assert_int_equal(front[i], want[i]);
    assert_int_equal(n, 5);
    const double v[] = {5, 1, 3, 2, 4};
    assert_float_equal(lpv_acc_median(v, 5), 3.0, 0);
    assert_float_equal(lpv_acc_median(v, 4), 2.5, 0); /* 5 1 3 2 -> (2 + 3) / 2 */
    assert_true(isnan(lpv_acc_median(v, 0)));
}

/* The overall front: means over scenes, errors normalised by each scene's
 * best; a point missing on one scene is left out. */
static void test_overall_front(void **state)
{
    (void)state;
    const lpv_acc_row rows[] = {
        {0, {1, 0, 0, 0}, 10.0, 2.0}, {1, {1, 0, 0, 0}, 20.0, 8.0},  /* A: ms 15, (2/1 + 8/4)/2 = 2 */
        {0, {2, 0, 0, 0}, 30.0, 1.0}, {1, {2, 0, 0, 0}, 50.0, 4.0},  /* B: ms 40, (1 + 1)/2 = 1 */
        {0, {3, 0, 0, 0}, 40.0, 1.5}, {1, {3, 0, 0, 0}, 60.0, 16.0}, /* C: ms 50, (1.5 + 4)/2 = 2.75: dominated */
        {0, {4, 0, 0, 0}, 1.0, 0.5},                                  /* D: scene 1 missing */
    };
    lpv_acc_overall o[8];
    size_t n = lpv_acc_overall_front(rows, sizeof rows / sizeof rows[0], 2, o, 8);
    assert_int_equal(n, 3);
    assert_int_equal(o[0].key[0], 1);
    assert_float_equal(o[0].ms, 15.0, 1e-12);
    /* scene 0's best is D's 0.5 (any measured point counts) */
    assert_float_equal(o[0].norm_rmse, (2.0 / 0.5 + 8.0 / 4.0) / 2.0, 1e-12);
    assert_float_equal(o[1].norm_rmse, (1.0 / 0.5 + 1.0) / 2.0, 1e-12);
    assert_float_equal(o[1].rel_rmse[1], 4.0, 0.0);
    assert_int_equal(o[0].pareto, 1);
    assert_int_equal(o[1].pareto, 1);
    assert_int_equal(o[2].pareto, 0);
    assert_int_equal(lpv_acc_overall_front(rows, 7, 0, o, 8), 0);
    assert_int_equal(lpv_acc_overall_front(rows, 7, 2, o, 1), 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_identical),        cmocka_unit_test(test_constant_factor),
        cmocka_unit_test(test_masked_pixels_ignored), cmocka_unit_test(test_noise_level),
        cmocka_unit_test(test_error_colours),    cmocka_unit_test(test_pareto), cmocka_unit_test(test_overall_front),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
