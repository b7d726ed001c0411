/*
 * oracle_propagate.c - reference transmittance, flux-limited propagation and
 * accumulation (see oracle.h; docs/propagation.md derives every constant and
 * explains the flux limiter). The propagation shader is a gather over the
 * same loops: per destination cell, per direction, per channel.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "oracle.h"

/* Directions in the order +x -x +y -y +z -z: axis d / 2, sign + for even d. */
static const int lpv_dir[LPV_DIR_COUNT][3] = {
    {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1},
};

/* Coefficient slot of each axis in the (c0, y, z, x) order. */
static const int lpv_axis_slot[3] = {3, 1, 2};

static int dir_axis(int d) { return d / 2; }
static float dir_sign(int d) { return (d & 1) ? -1.0f : 1.0f; }

static const float *channel(const lpv_cell *c, int ch)
{
    return ch == 0 ? c->r : ch == 1 ? c->g : c->b;
}

static float *channel_mut(lpv_cell *c, int ch)
{
    return ch == 0 ? c->r : ch == 1 ? c->g : c->b;
}

/* ---- Transmittance ------------------------------------------------------ */

/* The total's blocking for travel direction d averaged over the four corners
 * of the face of cell c through which light travelling along d enters: the
 * face at centre - 0.5 dir_d, i.e. the lower face on axis k for a positive
 * direction, the upper for negative. e1, e2 are the other two axes in x, y, z
 * order; the corners are summed in the order base, +e1, +e2, +e1+e2 (as
 * transmit.comp does). */
static float face_blocking(const lpv_grid *g, const lpv_gv_point *gv, const int c[3], int d)
{
    int k = dir_axis(d);
    int e1 = k == 0 ? 1 : 0, e2 = k == 2 ? 1 : 2;
    int base[3] = {c[0], c[1], c[2]};
    if (d & 1)
        base[k] += 1;
    static const int steps[4][2] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
    float sum = 0.0f;
    for (int corner = 0; corner < 4; corner++) {
        int p[3] = {base[0], base[1], base[2]};
        p[e1] += steps[corner][0];
        p[e2] += steps[corner][1];
        sum += gv[lpv_grid_gv_index(g, p[0], p[1], p[2])].blocking[d / 4][d % 4];
    }
    return 0.25f * sum;
}

/* 1 - clamp(B / peak, 0, 1): B is the blocking towards where the light comes
 * from (lpv_oracle_gv_merge), so a surface facing the light blocks it,
 * normalised by the L1 lobe's peak (LPV_GV_PEAK) so a covered face blocks all
 * of it. A non-finite B blocks completely: NaN must never reach the
 * propagation. */
static float face_transmittance(float b)
{
    if (!isfinite(b))
        return 0.0f;
    return 1.0f - fminf(fmaxf(b / LPV_GV_PEAK, 0.0f), 1.0f);
}

void lpv_oracle_transmittance(const lpv_grid *g, const lpv_gv_point *gv, float *t)
{
    int cell[3];
    for (cell[2] = 0; cell[2] < g->dims[2]; cell[2]++) {
        for (cell[1] = 0; cell[1] < g->dims[1]; cell[1]++) {
            for (cell[0] = 0; cell[0] < g->dims[0]; cell[0]++) {
                size_t idx = lpv_grid_index(g, cell[0], cell[1], cell[2]);
                for (int d = 0; d < LPV_DIR_COUNT; d++) {
                    t[idx * LPV_DIR_COUNT + d] = face_transmittance(face_blocking(g, gv, cell, d));
                }
            }
        }
    }
}

/* ---- One step ----------------------------------------------------------- */

/* Flux (per sqrt(4 pi)) that the linear scheme sends towards the neighbour
 * along d: row 0 of M_d applied to c. Sum over the six d is 6 A c0 = c0. */
static float face_flux(const float c[4], int d)
{
    return LPV_PROP_A * c[0] + dir_sign(d) * LPV_PROP_B * c[lpv_axis_slot[dir_axis(d)]];
}

/* Flux limiter sigma_d for one source channel: the positive face fluxes are
 * scaled to sum to c0 and the negative ones dropped, so the source never
 * sends out more than it holds and never sends negative flux. A channel that
 * is not strictly positive or not finite sends nothing. */
static float flux_limit(const float c[4], int d)
{
    if (!(c[0] > 0.0f) || !isfinite(c[0]) || !isfinite(c[1]) || !isfinite(c[2]) || !isfinite(c[3]))
        return 0.0f;
    float p = 0.0f;
    for (int e = 0; e < LPV_DIR_COUNT; e++) {
        float f = face_flux(c, e);
        if (f > 0.0f)
            p += f;
    }
    if (!(p > 0.0f) || !isfinite(p))
        return 0.0f;
    return face_flux(c, d) > 0.0f ? c[0] / p : 0.0f;
}

/* The band-1 rows (E, F, G) of a transport (lpv_shared.h). */
static void transport_rows(int transport, float efg[3])
{
    int central = transport == LPV_TRANSPORT_CENTRAL;
    efg[0] = central ? LPV_PROP_CENTRAL_E : LPV_PROP_E;
    efg[1] = central ? LPV_PROP_CENTRAL_F : LPV_PROP_F;
    efg[2] = central ? LPV_PROP_CENTRAL_G : LPV_PROP_G;
}

/* out += w * M_d c with the sparse matrix of lpv_shared.h:
 * out0 = A c0 + s B ck, outk = s E c0 + F ck, outj = G cj (j != k). */
static void add_transfer(const float c[4], int d, float w, const float efg[3], float out[4])
{
    float s = dir_sign(d);
    int k = lpv_axis_slot[dir_axis(d)];
    out[0] += w * face_flux(c, d);
    for (int j = 1; j < 4; j++) {
        float m = j == k ? s * efg[0] * c[0] + efg[1] * c[k] : efg[2] * c[j];
        out[j] += w * m;
    }
}

static int inside(const lpv_grid *g, const int p[3])
{
    return p[0] >= 0 && p[0] < g->dims[0] && p[1] >= 0 && p[1] < g->dims[1] && p[2] >= 0 && p[2] < g->dims[2];
}

/* Gathers into destination cell x from its (up to) six neighbours. Terms with
 * zero weight are skipped, not multiplied: 0 * Inf would be a NaN. */
static void gather(const lpv_grid *g, const lpv_cell *in, const float *t, const float efg[3], const int x[3],
                   lpv_cell *dst)
{
    size_t dst_idx = lpv_grid_index(g, x[0], x[1], x[2]);
    memset(dst, 0, sizeof *dst);
    for (int d = 0; d < LPV_DIR_COUNT; d++) {
        int src[3] = {x[0] - lpv_dir[d][0], x[1] - lpv_dir[d][1], x[2] - lpv_dir[d][2]};
        if (!inside(g, src))
            continue;
        float tr = t ? t[dst_idx * LPV_DIR_COUNT + d] : 1.0f;
        const lpv_cell *sc = &in[lpv_grid_index(g, src[0], src[1], src[2])];
        for (int ch = 0; ch < 3; ch++) {
            const float *c = channel(sc, ch);
            float w = tr * flux_limit(c, d);
            if (!(w > 0.0f))
                continue;
            add_transfer(c, d, w, efg, channel_mut(dst, ch));
        }
    }
}

void lpv_oracle_propagate_step(const lpv_grid *g, const lpv_cell *in, const float *t, lpv_cell *out)
{
    lpv_oracle_propagate_step_with(g, in, t, LPV_TRANSPORT_PAPER, out);
}

void lpv_oracle_propagate_step_with(const lpv_grid *g, const lpv_cell *in, const float *t, int transport,
                                    lpv_cell *out)
{
    float efg[3];
    transport_rows(transport, efg);
    int x[3];
    for (x[2] = 0; x[2] < g->dims[2]; x[2]++) {
        for (x[1] = 0; x[1] < g->dims[1]; x[1]++) {
            for (x[0] = 0; x[0] < g->dims[0]; x[0]++)
                gather(g, in, t, efg, x, &out[lpv_grid_index(g, x[0], x[1], x[2])]);
        }
    }
}

/* ---- Whole propagation -------------------------------------------------- */

static void accumulate(size_t count, const lpv_cell *src, lpv_cell *acc)
{
    for (size_t i = 0; i < count; i++) {
        for (int k = 0; k < 4; k++) {
            acc[i].r[k] += src[i].r[k];
            acc[i].g[k] += src[i].g[k];
            acc[i].b[k] += src[i].b[k];
        }
    }
}

int lpv_oracle_propagate(const lpv_grid *g, const lpv_cell *injected, const float *t, int iterations,
                         lpv_cell *acc)
{
    return lpv_oracle_propagate_with(g, injected, t, iterations, LPV_TRANSPORT_PAPER, acc);
}

static void transport_step(const lpv_grid *g, const lpv_cell *in, const float *t, void *ctx, lpv_cell *out)
{
    lpv_oracle_propagate_step_with(g, in, t, *(const int *)ctx, out);
}

int lpv_oracle_propagate_with(const lpv_grid *g, const lpv_cell *injected, const float *t, int iterations,
                              int transport, lpv_cell *acc)
{
    return lpv_oracle_propagate_steps(g, injected, t, iterations, transport_step, &transport, acc);
}

int lpv_oracle_propagate_steps(const lpv_grid *g, const lpv_cell *injected, const float *t, int iterations,
                               lpv_oracle_step_fn step, void *ctx, lpv_cell *acc)
{
    size_t count = lpv_grid_cell_count(g);
    size_t bytes = count * sizeof(lpv_cell);
    lpv_cell *cur = NULL, *next = NULL;
    if (iterations > 0) {
        cur = malloc(bytes);
        next = malloc(bytes);
        if (!cur || !next) {
            free(cur);
            free(next);
            return -1;
        }
        memcpy(cur, injected, bytes);
    }
    if (acc != injected)
        memmove(acc, injected, bytes);

    for (int i = 0; i < iterations; i++) {
        /* No occlusion on the first step: a VPL's own surface would shadow it. */
        step(g, cur, i == 0 ? NULL : t, ctx, next);
        accumulate(count, next, acc);
        lpv_cell *tmp = cur;
        cur = next;
        next = tmp;
    }
    free(cur);
    free(next);
    return 0;
}

void lpv_oracle_total_flux(const lpv_grid *g, const lpv_cell *cells, double flux[3])
{
    const double sqrt_4pi = 3.5449077018110318;
    size_t count = lpv_grid_cell_count(g);
    flux[0] = flux[1] = flux[2] = 0.0;
    for (size_t i = 0; i < count; i++) {
        flux[0] += (double)cells[i].r[0];
        flux[1] += (double)cells[i].g[0];
        flux[2] += (double)cells[i].b[0];
    }
    for (int ch = 0; ch < 3; ch++)
        flux[ch] *= sqrt_4pi;
}
