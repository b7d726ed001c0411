/* tonemap.c - see tonemap.h. */
#include "tonemap.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene.h" /* LPV_LUMENS_PER_WATT */

float lpv_srgb_encode(float x)
{
    if (!(x > 0.0f))
        return 0.0f;
    if (x >= 1.0f)
        return 1.0f;
    return x <= 0.0031308f ? 12.92f * x : 1.055f * powf(x, 1.0f / 2.4f) - 0.055f;
}

float lpv_srgb_decode(float c)
{
    return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
}

static uint8_t to_u8(float v)
{
    return (uint8_t)lrintf(fminf(fmaxf(v, 0.0f), 1.0f) * 255.0f);
}

static float reinhard(float x)
{
    return isfinite(x) && x > 0.0f ? x / (1.0f + x) : 0.0f;
}

void lpv_tonemap_rgba8(const float *rgba, size_t n, float factor, uint8_t *out)
{
    for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c)
            out[i * 4 + (size_t)c] = to_u8(lpv_srgb_encode(reinhard(rgba[i * 4 + (size_t)c] * factor)));
        float a = rgba[i * 4 + 3];
        out[i * 4 + 3] = to_u8(isfinite(a) ? a : 0.0f);
    }
}

void lpv_display_default(lpv_display *d)
{
    memset(d, 0, sizeof *d);
    d->exposure_auto = 1;
    d->background[0] = d->background[1] = d->background[2] = LPV_BACKGROUND_SRGB;
}

int lpv_exposure_parse(const char *v, lpv_display *d, char *err, size_t n)
{
    if (v && strcmp(v, "auto") == 0) {
        d->exposure_auto = 1;
        return 0;
    }
    char *end = NULL;
    double ev = v ? strtod(v, &end) : NAN;
    if (!v || end == v || *end || !isfinite(ev) || ev < -64.0 || ev > 64.0) {
        snprintf(err, n, "exposure %s: expected \"auto\" or an EV, a number in -64..64 (the image shows "
                         "683 lm/W x radiance x 2^EV)", v ? v : "(none)");
        return -1;
    }
    d->exposure_auto = 0;
    d->exposure_ev = (float)ev;
    return 0;
}

static float luminance(const float *p)
{
    return 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2];
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

float lpv_exposure_meter_ev(const float *rgba, size_t n)
{
    float *y = malloc((n ? n : 1) * sizeof *y);
    if (!y)
        return 0.0f;
    size_t m = 0;
    for (size_t i = 0; i < n; ++i) {
        const float *p = rgba + i * 4;
        if (!(p[3] > 0.5f))
            continue;
        float l = luminance(p);
        y[m++] = isfinite(l) && l > 0.0f ? l : 0.0f;
    }
    float ev = 0.0f;
    if (m > 0) {
        qsort(y, m, sizeof *y, cmp_float);
        size_t k = (size_t)floor((double)LPV_METER_PERCENTILE * (double)(m - 1) + 0.5);
        double hi = y[k];
        if (hi > 0.0 && isfinite(hi)) {
            double lo = hi * exp2(-(double)LPV_METER_STOPS), sum = 0.0;
            for (size_t i = 0; i < m; ++i)
                sum += log2(fmin(fmax((double)y[i], lo), hi));
            double key = exp2(sum / (double)m);
            ev = (float)log2((double)LPV_MIDDLE_GREY / ((double)LPV_LUMENS_PER_WATT * key));
        }
    }
    free(y);
    return ev;
}

float lpv_display_rgba8(const float *rgba, size_t n, const lpv_display *d, uint8_t *out)
{
    float ev = d->exposure_auto ? lpv_exposure_meter_ev(rgba, n) : d->exposure_ev;
    float s = LPV_LUMENS_PER_WATT * exp2f(ev);
    float bg[3];
    for (int c = 0; c < 3; ++c)
        bg[c] = lpv_srgb_decode(fminf(fmaxf(d->background[c], 0.0f), 1.0f));
    for (size_t i = 0; i < n; ++i) {
        float a = rgba[i * 4 + 3];
        a = isfinite(a) ? fminf(fmaxf(a, 0.0f), 1.0f) : 0.0f;
        for (int c = 0; c < 3; ++c) {
            float x = reinhard(rgba[i * 4 + (size_t)c] * s);
            if (!d->transparent)
                x += (1.0f - a) * bg[c];
            out[i * 4 + (size_t)c] = to_u8(lpv_srgb_encode(x));
        }
        out[i * 4 + 3] = d->transparent ? to_u8(a) : 255;
    }
    return ev;
}

void lpv_fraction_gray8(const float *rgba, size_t n, uint8_t *out)
{
    for (size_t i = 0; i < n; ++i) {
        float v = rgba[4 * i];
        uint8_t b = (uint8_t)lrintf(255.0f * (v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f));
        out[4 * i] = out[4 * i + 1] = out[4 * i + 2] = b;
        out[4 * i + 3] = 255;
    }
}
