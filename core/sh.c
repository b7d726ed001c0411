/*
 * sh.c - two-band real SH with the conventions of shaders/lpv_shared.h:
 * no Condon-Shortley phase, coefficient order (Y00, Y1-1, Y10, Y11), i.e. the
 * shapes (1, y, z, x). The GLSL uses the same constants, so the C and GPU
 * sides cannot disagree on a sign.
 */
#include "sh.h"

#include <math.h>

#include "lpv_shared.h"

/* sqrt(4 pi): the integral of the constant basis shape 1 / C0 over the sphere. */
#define LPV_SQRT_4PI 3.54490770181103205f

void lpv_sh_basis(const float d[3], float out[4])
{
    out[0] = LPV_SH_C0;
    out[1] = LPV_SH_C1 * d[1];
    out[2] = LPV_SH_C1 * d[2];
    out[3] = LPV_SH_C1 * d[0];
}

/* The zonal coefficients of max(0, cos) are (sqrt(pi)/2, sqrt(pi/3)); rotating
 * them to n multiplies band l by sqrt(4 pi / (2l + 1)) Y_lm(n), which for this
 * basis gives (LOBE0, LOBE1 n.y, LOBE1 n.z, LOBE1 n.x). tests/test_sh.c checks
 * it against quadrature. */
void lpv_sh_cosine_lobe(const float n[3], float out[4])
{
    out[0] = LPV_SH_LOBE0;
    out[1] = LPV_SH_LOBE1 * n[1];
    out[2] = LPV_SH_LOBE1 * n[2];
    out[3] = LPV_SH_LOBE1 * n[0];
}

float lpv_sh_eval(const float c[4], const float d[3])
{
    float y[4];
    lpv_sh_basis(d, y);
    return lpv_sh_dot(c, y);
}

/* Only Y00 has a non-zero integral (the band-1 shapes are odd). */
float lpv_sh_integral(const float c[4])
{
    return c[0] * LPV_SQRT_4PI;
}

/* The basis is orthonormal, so the integral of a product is the dot product. */
float lpv_sh_dot(const float a[4], const float b[4])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
}

/* in / len, or in / max(len, 1) (keep_short): 0 for a non-finite or nearly
 * zero vector. */
static int direction(const float in[3], float out[3], int keep_short)
{
    if (!isfinite(in[0]) || !isfinite(in[1]) || !isfinite(in[2]))
        return 0;
    float len = sqrtf(in[0] * in[0] + in[1] * in[1] + in[2] * in[2]);
    if (!(len > 1e-8f) || !isfinite(len))
        return 0;
    float d = keep_short && len < 1.0f ? 1.0f : len;
    for (int i = 0; i < 3; i++)
        out[i] = in[i] / d;
    return 1;
}

int lpv_mean_direction(const float in[3], float out[3]) { return direction(in, out, 1); }

int lpv_unit_direction(const float in[3], float out[3]) { return direction(in, out, 0); }
