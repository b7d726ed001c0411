/*
 * oracle_inject.c - reference VPL and surfel injection and GV merging
 * (see oracle.h and docs/propagation.md). Literal loops in array order; the
 * injection shaders are checked against these.
 */
#include <math.h>

#include "oracle.h"
#include "sh.h"

static int finite3(const float v[3])
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

static void add_scaled(float dst[4], const float src[4], float scale)
{
    for (int i = 0; i < 4; i++)
        dst[i] += src[i] * scale;
}

/* Whether a VPL is used (valid, finite, a normal with a direction), with
 * its normal as the injection uses it in n. */
static int vpl_usable(const lpv_vpl *v, float n[3])
{
    return v->position[3] != 0.0f && finite3(v->position) && finite3(v->flux) && lpv_mean_direction(v->normal, n);
}

/* One VPL: validated, moved half a cell along its normal (so it lights the
 * cell in front of its surface, not its own), then added as lobe * flux / pi:
 * the lobe integrates to pi, so the cell's intensity integrates to the flux. */
static int inject_vpl(const lpv_grid *g, const lpv_vpl *v, lpv_cell *cells)
{
    float n[3], p[3];
    int cell[3];
    if (!vpl_usable(v, n))
        return 0;
    for (int i = 0; i < 3; i++)
        p[i] = v->position[i] + LPV_VPL_SHIFT_CELLS * g->cell_size * n[i];
    if (!lpv_grid_cell_of(g, p, cell))
        return 0;

    float lobe[4];
    lpv_sh_cosine_lobe(n, lobe);
    for (int i = 0; i < 4; i++)
        lobe[i] /= LPV_PI;
    lpv_cell *c = &cells[lpv_grid_index(g, cell[0], cell[1], cell[2])];
    add_scaled(c->r, lobe, v->flux[0]);
    add_scaled(c->g, lobe, v->flux[1]);
    add_scaled(c->b, lobe, v->flux[2]);
    return 1;
}

/* One VPL spread over its 2 x 2 stencil along its surface (oracle.h). */
static int inject_vpl_spread(const lpv_grid *g, const lpv_vpl *v, lpv_cell *cells)
{
    float n[3], q[3], f[3];
    int b[3];
    if (!vpl_usable(v, n))
        return 0;
    const int ax = lpv_oracle_normal_bin(n) / 2, a0 = ax == 0 ? 1 : 0, a1 = ax == 2 ? 1 : 2;
    for (int i = 0; i < 3; i++) {
        q[i] = (v->position[i] + LPV_VPL_SHIFT_CELLS * g->cell_size * n[i]) / g->cell_size -
               g->origin[i] / g->cell_size; /* as grid.glsl */
        const float lo = floorf(i == ax ? q[i] : q[i] - 0.5f);
        if (!(lo >= -1.0f && lo < (float)g->dims[i])) /* no corner inside (and no int overflow) */
            return 0;
        b[i] = (int)lo;
        f[i] = i == ax ? 0.0f : q[i] - 0.5f - lo;
    }
    float lobe[4];
    lpv_sh_cosine_lobe(n, lobe);
    int given = 0;
    for (int j = 0; j < 4; j++) {
        int c[3] = {b[0], b[1], b[2]};
        c[a0] += j & 1;
        c[a1] += j >> 1;
        const float w = ((j & 1) ? f[a0] : 1.0f - f[a0]) * ((j >> 1) ? f[a1] : 1.0f - f[a1]);
        if (!(w > 0.0f) || c[0] < 0 || c[1] < 0 || c[2] < 0 || c[0] >= g->dims[0] || c[1] >= g->dims[1] ||
            c[2] >= g->dims[2])
            continue;
        lpv_cell *cell = &cells[lpv_grid_index(g, c[0], c[1], c[2])];
        add_scaled(cell->r, lobe, v->flux[0] * w / LPV_PI);
        add_scaled(cell->g, lobe, v->flux[1] * w / LPV_PI);
        add_scaled(cell->b, lobe, v->flux[2] * w / LPV_PI);
        given = 1;
    }
    return given;
}

/* The VPLs one by one, in array order, through one: how many it used. */
static size_t inject_each(const lpv_grid *g, const lpv_vpl *vpls, size_t n, lpv_cell *cells,
                          int (*one)(const lpv_grid *, const lpv_vpl *, lpv_cell *))
{
    size_t injected = 0;
    for (size_t i = 0; i < n; i++)
        injected += (size_t)one(g, &vpls[i], cells);
    return injected;
}

size_t lpv_oracle_inject_vpls_spread(const lpv_grid *g, const lpv_vpl *vpls, size_t n, lpv_cell *cells)
{
    return inject_each(g, vpls, n, cells, inject_vpl_spread);
}

int lpv_oracle_normal_bin(const float n[3])
{
    float a[3] = {fabsf(n[0]), fabsf(n[1]), fabsf(n[2])};
    int axis = (a[0] >= a[1] && a[0] >= a[2]) ? 0 : (a[1] >= a[2] ? 1 : 2);
    return 2 * axis + (n[axis] < 0.0f ? 1 : 0);
}

size_t lpv_oracle_inject_vpls_binned(const lpv_grid *g, const lpv_vpl *vpls, size_t n, lpv_cell *cells)
{
    size_t injected = 0, count = lpv_grid_cell_count(g);
    for (size_t i = 0; i < n; i++) {
        float un[3];
        if (!lpv_mean_direction(vpls[i].normal, un))
            continue;
        injected += (size_t)inject_vpl(g, &vpls[i], cells + (size_t)lpv_oracle_normal_bin(un) * count);
    }
    return injected;
}

size_t lpv_oracle_inject_vpls(const lpv_grid *g, const lpv_vpl *vpls, size_t n, lpv_cell *cells)
{
    return inject_each(g, vpls, n, cells, inject_vpl);
}

/* One surfel: blocking potential B(w) = area / cell_size^2 * max(0, <n, w>)
 * (paper section 3.2) at the nearest GV point (the LPV cell corners). */
static int inject_surfel(const lpv_grid *g, const lpv_surfel *s, vec4 *gv)
{
    float n[3];
    int pt[3];
    float area = s->position[3];
    if (!(area > 0.0f) || !isfinite(area) || !finite3(s->position))
        return 0;
    if (!lpv_mean_direction(s->normal, n))
        return 0;
    float p[3];
    for (int i = 0; i < 3; i++)
        p[i] = s->position[i] + LPV_TIE_CELLS * g->cell_size * n[i]; /* as grid.glsl's gv_point_at */
    if (!lpv_grid_gv_point_of(g, p, pt))
        return 0;

    float lobe[4];
    lpv_sh_cosine_lobe(n, lobe);
    add_scaled(gv[lpv_grid_gv_index(g, pt[0], pt[1], pt[2])], lobe, area / (g->cell_size * g->cell_size));
    return 1;
}

size_t lpv_oracle_inject_surfels(const lpv_grid *g, const lpv_surfel *surfels, size_t n, vec4 *gv)
{
    size_t injected = 0;
    for (size_t i = 0; i < n; i++)
        injected += (size_t)inject_surfel(g, &surfels[i], gv);
    return injected;
}

/* Per GV point and travel direction d keep the larger blocking potential
 * B(-d), towards where the light comes from: a surface seen by the camera and
 * by an RSM must block once, not twice, and a wall seen from inside by a
 * lamp's RSM and from outside by the scene surfels must block both ways (a
 * whole SH vector holds one side's lobe only). A NaN wins and then stays
 * (nothing compares greater), so the transmittance blocks it fully. */
void lpv_oracle_gv_merge(const lpv_grid *g, const vec4 *src, lpv_gv_point *dst)
{
    size_t count = lpv_grid_gv_count(g);
    for (size_t i = 0; i < count; i++) {
        for (int d = 0; d < LPV_DIR_COUNT; d++) {
            float back[3] = {0.0f, 0.0f, 0.0f}, y[4];
            back[d / 2] = (d & 1) ? 1.0f : -1.0f;
            lpv_sh_basis(back, y);
            float b = lpv_sh_dot(src[i], y);
            float *slot = &dst[i].blocking[d / 4][d % 4];
            if (b > *slot || isnan(b))
                *slot = b;
        }
    }
}
