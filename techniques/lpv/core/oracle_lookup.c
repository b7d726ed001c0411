/*
 * oracle_lookup.c - reference irradiance lookup (see oracle.h and
 * docs/propagation.md). Mirrors a 3D-texture fetch with linear filtering and
 * GL_CLAMP_TO_EDGE: trilinear between cell centres, clamped at the edge.
 */
#include <math.h>
#include <string.h>

#include "oracle.h"
#include "sh.h"

/* Per axis: the two cells to blend and the weight of the upper one. The
 * position in cell units is clamped to [0.5, dims - 0.5] (the outermost cell
 * centres), so points outside the grid take the edge value. Returns 0 for a
 * NaN coordinate; +-Inf clamps like any other far point. */
static int axis_lerp(const lpv_grid *g, int axis, float p, int *i0, int *i1, float *f)
{
    float u = p / g->cell_size - g->origin[axis] / g->cell_size; /* as grid.glsl */
    if (isnan(u))
        return 0;
    float hi = (float)g->dims[axis] - 0.5f;
    u = fminf(fmaxf(u, 0.5f), hi) - 0.5f; /* now in [0, dims - 1] */
    float base = floorf(u);
    if (base > (float)(g->dims[axis] - 2))
        base = (float)(g->dims[axis] - 2);
    if (base < 0.0f)
        base = 0.0f; /* a 1-cell axis */
    *i0 = (int)base;
    *i1 = *i0 + 1 < g->dims[axis] ? *i0 + 1 : *i0;
    *f = u - base;
    return 1;
}

/* Trilinear blend of the cells' coefficients. Zero-weight corners are
 * skipped so a far, non-finite cell cannot turn 0 * Inf into NaN. */
static void interpolate(const lpv_grid *g, const lpv_cell *cells, const int i0[3], const int i1[3],
                        const float f[3], lpv_cell *out)
{
    memset(out, 0, sizeof *out);
    for (int corner = 0; corner < 8; corner++) {
        int idx[3];
        float w = 1.0f;
        for (int a = 0; a < 3; a++) {
            int upper = (corner >> a) & 1;
            idx[a] = upper ? i1[a] : i0[a];
            w *= upper ? f[a] : 1.0f - f[a];
        }
        if (w == 0.0f)
            continue;
        const lpv_cell *c = &cells[lpv_grid_index(g, idx[0], idx[1], idx[2])];
        for (int k = 0; k < 4; k++) {
            out->r[k] += w * c->r[k];
            out->g[k] += w * c->g[k];
            out->b[k] += w * c->b[k];
        }
    }
}

/* E(n) = max(0, <c, lobe(-n)>) / s^2: the cell stores intensity (W/sr); the
 * intensity seen through the surface's hemisphere, per projected cell area,
 * gives irradiance (docs/propagation.md, "Lookup"). */
/* The lookup point half a cell in front of the surface (the mirror of the
 * injection's half-cell offset: the cells behind a surface hold light that
 * cannot reach it, and a wall's own cells are half empty), as the two cells
 * and the weight per axis. 0 for a degenerate normal or a NaN point. */
static int lookup_point(const lpv_grid *g, const float p[3], const float n[3], float un[3], int i0[3], int i1[3],
                        float f[3])
{
    if (!lpv_unit_direction(n, un))
        return 0;
    for (int a = 0; a < 3; a++) {
        if (!axis_lerp(g, a, p[a] + 0.5f * g->cell_size * un[a], &i0[a], &i1[a], &f[a]))
            return 0;
    }
    return 1;
}

static void project(const lpv_cell *c, const float w[4], float scale, float rgb[3])
{
    rgb[0] += lpv_sh_dot(c->r, w) * scale;
    rgb[1] += lpv_sh_dot(c->g, w) * scale;
    rgb[2] += lpv_sh_dot(c->b, w) * scale;
}

void lpv_oracle_irradiance(const lpv_grid *g, const lpv_cell *acc, const float p[3], const float n[3], float rgb[3])
{
    float un[3], f[3];
    int i0[3], i1[3];
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    if (!lookup_point(g, p, n, un, i0, i1, f))
        return;
    lpv_cell c;
    interpolate(g, acc, i0, i1, f, &c);
    float back[3] = {-un[0], -un[1], -un[2]};
    float lobe[4];
    lpv_sh_cosine_lobe(back, lobe);
    project(&c, lobe, 1.0f / (g->cell_size * g->cell_size), rgb); /* as lookup.glsl */
    for (int k = 0; k < 3; k++)
        rgb[k] = fmaxf(0.0f, rgb[k]);
}

/* docs/propagation.md section 6b. Light of bin b travels into the half-space
 * H = {w : <w, e> > 0}; its intensity is reconstructed on H as a + <bv, w>
 * with the stored band-0/1 moments and integrated against max(0, <m, w>),
 * m = -n, over H:
 *   K0 = int_H max(0, <m,w>) dw   = pi (1 + cos t) / 2
 *   K1 = int_H max(0, <m,w>) w dw = 2/3 ((pi - t) m + sin t e),  cos t = <m, e>
 *   a  = (2/pi) (c0 / C0 - 1.5 <cv, e> / C1),  bv = 3/(2 pi) (cv / C1 - pi a e)
 *   E  = a K0 + <bv, K1> = a (K0 - 1.5 <e, K1>) + 3/(2 pi C1) <cv, K1>. */
void lpv_oracle_bin_weights(int b, const float n[3], float w[4])
{
    double e[3] = {0.0, 0.0, 0.0}, m[3] = {-n[0], -n[1], -n[2]}, k1[3];
    e[b / 2] = (b & 1) ? -1.0 : 1.0;
    double ct = m[0] * e[0] + m[1] * e[1] + m[2] * e[2];
    ct = ct < -1.0 ? -1.0 : (ct > 1.0 ? 1.0 : ct);
    double t = acos(ct), pi = 3.14159265358979324;
    double k0 = pi * (1.0 + ct) * 0.5;
    for (int i = 0; i < 3; i++)
        k1[i] = (2.0 / 3.0) * ((pi - t) * m[i] + sin(t) * e[i]);
    double ek1 = e[0] * k1[0] + e[1] * k1[1] + e[2] * k1[2];
    double wa = k0 - 1.5 * ek1;
    double wv[3];
    for (int i = 0; i < 3; i++)
        wv[i] = -(2.0 / pi) * 1.5 / LPV_SH_C1 * wa * e[i] + 1.5 / (pi * LPV_SH_C1) * k1[i];
    w[0] = (float)((2.0 / pi) / LPV_SH_C0 * wa);
    w[1] = (float)wv[1]; /* slot order (1, y, z, x) */
    w[2] = (float)wv[2];
    w[3] = (float)wv[0];
}

void lpv_oracle_irradiance_binned(const lpv_grid *g, const lpv_cell *acc, const float p[3], const float n[3],
                                  float rgb[3])
{
    float un[3], f[3];
    int i0[3], i1[3];
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    if (!lookup_point(g, p, n, un, i0, i1, f))
        return;
    const size_t count = lpv_grid_cell_count(g);
    const float inv_area = 1.0f / (g->cell_size * g->cell_size);
    for (int b = 0; b < LPV_NORMAL_BINS; b++) {
        float w[4];
        lpv_oracle_bin_weights(b, un, w);
        if (w[0] == 0.0f && w[1] == 0.0f && w[2] == 0.0f && w[3] == 0.0f)
            continue;
        lpv_cell c;
        interpolate(g, acc + (size_t)b * count, i0, i1, f, &c);
        project(&c, w, inv_area, rgb);
    }
    for (int k = 0; k < 3; k++)
        rgb[k] = fmaxf(0.0f, rgb[k]);
}
