/* probes_math.c - see probes_math.h. */
#include "probes_math.h"

#include <math.h>

#include "lpv_shared.h"
#include "sh.h"

void lpv_probes_fibonacci(uint32_t i, uint32_t n, float out[3])
{
    /* the golden angle's fraction of a turn, (3 - sqrt 5) / 2 */
    const double golden = 0.3819660112501051;
    const double z = 1.0 - (2.0 * (double)i + 1.0) / (double)(n ? n : 1);
    const double r = sqrt(fmax(0.0, 1.0 - z * z));
    double turns = golden * (double)i;
    turns -= floor(turns); /* keeps the angle's precision for large i */
    const double phi = 2.0 * 3.14159265358979324 * turns;
    out[0] = (float)(r * cos(phi));
    out[1] = (float)(r * sin(phi));
    out[2] = (float)z;
}

/* A 32-bit integer hash (Wang's), for uniform numbers from a tick. */
static uint32_t hash32(uint32_t x)
{
    x = (x ^ 61u) ^ (x >> 16);
    x *= 9u;
    x ^= x >> 4;
    x *= 0x27d4eb2du;
    x ^= x >> 15;
    return x;
}

void lpv_probes_rotation(uint32_t tick, uint32_t seed, float m[9])
{
    /* three uniform numbers in [0, 1) from (tick, seed) */
    uint32_t h = hash32(tick * 0x9e3779b9u ^ hash32(seed));
    double u[3];
    for (int k = 0; k < 3; ++k) {
        h = hash32(h + (uint32_t)k * 0x85ebca6bu);
        u[k] = (double)h / 4294967296.0;
    }
    /* Shoemake, "Uniform random rotations" (Graphics Gems III) */
    const double a = sqrt(1.0 - u[0]), b = sqrt(u[0]);
    const double t1 = 2.0 * 3.14159265358979324 * u[1], t2 = 2.0 * 3.14159265358979324 * u[2];
    const double x = a * sin(t1), y = a * cos(t1), z = b * sin(t2), w = b * cos(t2);
    const double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w),     2 * (x * z + y * w),
                         2 * (x * y + z * w),     1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
                         2 * (x * z - y * w),     2 * (y * z + x * w),     1 - 2 * (x * x + y * y)};
    for (int k = 0; k < 9; ++k)
        m[k] = (float)r[k];
}

void lpv_probes_ray(uint32_t i, uint32_t n, const float m[9], float out[3])
{
    float d[3];
    lpv_probes_fibonacci(i, n, d);
    for (int r = 0; r < 3; ++r)
        out[r] = m[3 * r] * d[0] + m[3 * r + 1] * d[1] + m[3 * r + 2] * d[2];
}

static float sign_not_zero(float v) { return v >= 0.0f ? 1.0f : -1.0f; }

void lpv_probes_oct_encode(const float d[3], float uv[2])
{
    const float l1 = fabsf(d[0]) + fabsf(d[1]) + fabsf(d[2]);
    if (!(l1 > 0.0f)) {
        uv[0] = uv[1] = 0.0f;
        return;
    }
    float u = d[0] / l1, v = d[1] / l1;
    if (d[2] < 0.0f) {
        const float fu = (1.0f - fabsf(v)) * sign_not_zero(u), fv = (1.0f - fabsf(u)) * sign_not_zero(v);
        u = fu;
        v = fv;
    }
    uv[0] = u;
    uv[1] = v;
}

void lpv_probes_oct_decode(const float uv[2], float d[3])
{
    float x = uv[0], y = uv[1];
    const float z = 1.0f - fabsf(x) - fabsf(y);
    if (z < 0.0f) {
        const float fx = (1.0f - fabsf(y)) * sign_not_zero(x), fy = (1.0f - fabsf(x)) * sign_not_zero(y);
        x = fx;
        y = fy;
    }
    const float len = sqrtf(x * x + y * y + z * z);
    d[0] = x / len;
    d[1] = y / len;
    d[2] = z / len;
}

void lpv_probes_sh_add(float sh[3][4], const float d[3], const float l[3], uint32_t n)
{
    float y[4];
    lpv_sh_basis(d, y);
    const float w = 4.0f * LPV_PI / (float)(n ? n : 1);
    for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 4; ++k)
            sh[c][k] += w * l[c] * y[k];
}

void lpv_probes_sh_irradiance(const float sh[3][4], const float nrm[3], float e[3])
{
    float lobe[4];
    lpv_sh_cosine_lobe(nrm, lobe);
    for (int c = 0; c < 3; ++c)
        e[c] = lpv_sh_dot(sh[c], lobe);
}

float lpv_probes_chebyshev(float mean, float mean2, float d, float min_var)
{
    if (!isfinite(mean) || !isfinite(mean2) || !isfinite(d))
        return 0.0f;
    if (d <= mean)
        return 1.0f;
    const float var = fmaxf(mean2 - mean * mean, min_var), dd = d - mean;
    const float w = var / (var + dd * dd);
    return w * w * w;
}
