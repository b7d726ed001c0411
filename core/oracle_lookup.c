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
void lpv_oracle_irradiance(const lpv_grid *g, const lpv_cell *acc, const float p[3], const float n[3], float rgb[3])
{
    float un[3];
    int i0[3], i1[3];
    float f[3];
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    if (!lpv_unit_direction(n, un))
        return;
    /* Sample half a cell in front of the surface, the mirror of the
     * injection's half-cell offset: the cells behind a surface hold light
     * that cannot reach it (and a wall's own cells are half empty). */
    for (int a = 0; a < 3; a++) {
        if (!axis_lerp(g, a, p[a] + 0.5f * g->cell_size * un[a], &i0[a], &i1[a], &f[a]))
            return;
    }

    lpv_cell c;
    interpolate(g, acc, i0, i1, f, &c);
    float back[3] = {-un[0], -un[1], -un[2]};
    float lobe[4];
    lpv_sh_cosine_lobe(back, lobe);
    float inv_area = 1.0f / (g->cell_size * g->cell_size); /* as lookup.glsl */
    rgb[0] = fmaxf(0.0f, lpv_sh_dot(c.r, lobe) * inv_area);
    rgb[1] = fmaxf(0.0f, lpv_sh_dot(c.g, lobe) * inv_area);
    rgb[2] = fmaxf(0.0f, lpv_sh_dot(c.b, lobe) * inv_area);
}
