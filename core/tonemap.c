/* tonemap.c - see tonemap.h. */
#include "tonemap.h"

#include <math.h>

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
    return (uint8_t)lrintf(v * 255.0f);
}

void lpv_tonemap_rgba8(const float *rgba, size_t n, float exposure, uint8_t *out)
{
    for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) {
            float x = rgba[i * 4 + (size_t)c] * exposure;
            x = isfinite(x) && x > 0.0f ? x / (1.0f + x) : 0.0f;
            out[i * 4 + (size_t)c] = to_u8(lpv_srgb_encode(x));
        }
        float a = rgba[i * 4 + 3];
        out[i * 4 + 3] = to_u8(isfinite(a) ? fminf(fmaxf(a, 0.0f), 1.0f) : 0.0f);
    }
}
