/* metrics.c - see metrics.h and docs/accuracy.md. */
#include "metrics.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "image_io.h"

static int seen(const float *px)
{
    return px[3] > 0.5f;
}

int lpv_acc_compare(const float *lpv, const float *ref, const float *ref_stderr, int width, int height,
                    lpv_acc_metrics *out)
{
    memset(out, 0, sizeof *out);
    size_t n = (width > 0 && height > 0) ? (size_t)width * (size_t)height : 0;
    double sum_l = 0.0, sum_r = 0.0, sum_d2 = 0.0, sum_s2 = 0.0, sum_ad = 0.0;
    size_t count = 0;
    for (size_t i = 0; i < n; ++i) {
        const float *l = lpv + 4 * i, *r = ref + 4 * i;
        if (!seen(l) || !seen(r))
            continue;
        ++count;
        for (int c = 0; c < 3; ++c) {
            double d = (double)l[c] - (double)r[c];
            sum_l += l[c];
            sum_r += r[c];
            sum_d2 += d * d;
            sum_ad += fabs(d);
            if (ref_stderr) {
                double s = ref_stderr[4 * i + (size_t)c];
                sum_s2 += s * s;
            }
        }
    }
    out->pixels = count;
    out->rel_rmse = out->rel_bias = out->ref_noise = out->rel_rmse_excess = out->rel_mae = NAN;
    if (count == 0) {
        out->mean_lpv = out->mean_ref = NAN;
        return -1;
    }
    double k = 3.0 * (double)count;
    out->mean_lpv = sum_l / k;
    out->mean_ref = sum_r / k;
    if (!(out->mean_ref > 0.0))
        return -1;
    double mse = sum_d2 / k, ms2 = sum_s2 / k;
    out->rel_rmse = sqrt(mse) / out->mean_ref;
    out->rel_bias = (out->mean_lpv - out->mean_ref) / out->mean_ref;
    out->ref_noise = sqrt(ms2) / out->mean_ref;
    out->rel_rmse_excess = sqrt(mse > ms2 ? mse - ms2 : 0.0) / out->mean_ref;
    out->rel_mae = sum_ad / k / out->mean_ref;
    return 0;
}

void lpv_acc_baselines(const float *lpv, const float *ref, int width, int height, double *black, double *constant)
{
    size_t n = (width > 0 && height > 0) ? (size_t)width * (size_t)height : 0, count = 0;
    double sum = 0.0, sum2 = 0.0;
    for (size_t i = 0; i < n; ++i) {
        if (!seen(lpv + 4 * i) || !seen(ref + 4 * i))
            continue;
        ++count;
        for (int c = 0; c < 3; ++c) {
            sum += ref[4 * i + (size_t)c];
            sum2 += (double)ref[4 * i + (size_t)c] * ref[4 * i + (size_t)c];
        }
    }
    *black = *constant = NAN;
    double k = 3.0 * (double)count, mean = count ? sum / k : 0.0;
    if (!(mean > 0.0))
        return;
    *black = sqrt(sum2 / k) / mean;
    double var = sum2 / k - mean * mean;
    *constant = sqrt(var > 0.0 ? var : 0.0) / mean;
}

int lpv_acc_region_of(const float n[3])
{
    return n[1] > 0.7f ? LPV_ACC_REGION_FLOOR : (n[1] < -0.7f ? LPV_ACC_REGION_CEILING : LPV_ACC_REGION_WALLS);
}

void lpv_acc_region_errors(const float *lpv, const float *ref, const uint8_t *region, int width, int height,
                           double share[LPV_ACC_REGIONS], double rmse[LPV_ACC_REGIONS],
                           double ratio[LPV_ACC_REGIONS])
{
    size_t n = (width > 0 && height > 0) ? (size_t)width * (size_t)height : 0, count = 0;
    double d2[LPV_ACC_REGIONS] = {0}, sl[LPV_ACC_REGIONS] = {0}, sr[LPV_ACC_REGIONS] = {0}, total_d2 = 0.0,
           total_r = 0.0;
    size_t px[LPV_ACC_REGIONS] = {0};
    for (size_t i = 0; i < n; ++i) {
        const float *l = lpv + 4 * i, *r = ref + 4 * i;
        if (!seen(l) || !seen(r))
            continue;
        ++count;
        int g = region[i] < LPV_ACC_REGIONS ? region[i] : -1;
        for (int c = 0; c < 3; ++c) {
            double d = (double)l[c] - (double)r[c];
            total_d2 += d * d;
            total_r += r[c];
            if (g >= 0) {
                d2[g] += d * d;
                sl[g] += l[c];
                sr[g] += r[c];
            }
        }
        if (g >= 0)
            ++px[g];
    }
    double mean = count ? total_r / (3.0 * (double)count) : 0.0;
    for (int g = 0; g < LPV_ACC_REGIONS; ++g) {
        share[g] = rmse[g] = ratio[g] = NAN;
        if (!px[g] || !(mean > 0.0))
            continue;
        share[g] = total_d2 > 0.0 ? d2[g] / total_d2 : 0.0;
        rmse[g] = sqrt(d2[g] / (3.0 * (double)px[g])) / mean;
        ratio[g] = sr[g] > 0.0 ? sl[g] / sr[g] : NAN;
    }
}

double lpv_acc_pixel_error(const float *lpv_px, const float *ref_px, double mean_ref)
{
    double l = ((double)lpv_px[0] + lpv_px[1] + lpv_px[2]) / 3.0;
    double r = ((double)ref_px[0] + ref_px[1] + ref_px[2]) / 3.0;
    double floor_v = LPV_ACC_ERROR_FLOOR * mean_ref;
    double den = r > floor_v ? r : floor_v;
    if (!(den > 0.0))
        return (l == r) ? 0.0 : NAN;
    return (l - r) / den;
}

static uint8_t to_u8(double v)
{
    v = v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v);
    return (uint8_t)lround(v * 255.0);
}

void lpv_acc_error_colour(double e, uint8_t rgb[3])
{
    if (isnan(e)) {
        rgb[0] = rgb[1] = rgb[2] = 0;
        return;
    }
    if (e > 1.0)
        e = 1.0;
    if (e < -1.0)
        e = -1.0;
    if (e >= 0.0) { /* white -> red */
        rgb[0] = 255;
        rgb[1] = rgb[2] = to_u8(1.0 - e);
    } else { /* white -> blue */
        rgb[0] = rgb[1] = to_u8(1.0 + e);
        rgb[2] = 255;
    }
}

void lpv_acc_error_image(const float *lpv, const float *ref, int width, int height, double mean_ref,
                         uint8_t *rgb)
{
    size_t n = (width > 0 && height > 0) ? (size_t)width * (size_t)height : 0;
    for (size_t i = 0; i < n; ++i) {
        const float *l = lpv + 4 * i, *r = ref + 4 * i;
        if (!seen(l) || !seen(r)) {
            rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = 0;
            continue;
        }
        lpv_acc_error_colour(lpv_acc_pixel_error(l, r, mean_ref), rgb + 3 * i);
    }
}

int lpv_acc_write_error_png(const char *path, const float *lpv, const float *ref, int width, int height,
                            double mean_ref, char *err, size_t err_size)
{
    uint8_t *rgb = malloc((size_t)width * (size_t)height * 3 + 1);
    if (!rgb) {
        if (err_size)
            err[0] = '\0';
        return -1;
    }
    lpv_acc_error_image(lpv, ref, width, height, mean_ref, rgb);
    int rc = lpv_image_write_u8(path, width, height, 3, rgb, err, err_size);
    free(rgb);
    return rc;
}

size_t lpv_acc_pareto(const double *cost, const double *error, size_t n, int *front)
{
    size_t count = 0;
    for (size_t i = 0; i < n; ++i) {
        front[i] = !(isnan(cost[i]) || isnan(error[i]));
        for (size_t j = 0; j < n && front[i]; ++j) {
            if (j == i || isnan(cost[j]) || isnan(error[j]))
                continue;
            if (cost[j] <= cost[i] && error[j] <= error[i] && (cost[j] < cost[i] || error[j] < error[i]))
                front[i] = 0;
        }
        count += (size_t)front[i];
    }
    return count;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double lpv_acc_median(const double *v, size_t n)
{
    if (n == 0)
        return NAN;
    double *c = malloc(n * sizeof *c);
    if (!c)
        return NAN;
    memcpy(c, v, n * sizeof *c);
    qsort(c, n, sizeof *c, cmp_double);
    double m = n % 2 ? c[n / 2] : 0.5 * (c[n / 2 - 1] + c[n / 2]);
    free(c);
    return m;
}
