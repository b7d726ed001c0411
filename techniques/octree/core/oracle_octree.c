/*
 * oracle_octree.c - reference octree light propagation volumes (see
 * oracle_octree.h and docs/octree.md). Each level is an ordinary LPV handed
 * to the cascaded oracle's functions; what is here is only the octree's own
 * bookkeeping, in literal loops.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "oracle_octree.h"

_Static_assert((1 << (LPV_OCTREE_MAX_LEVELS - 1)) == LPV_MAX_GRID_DIM,
               "LPV_OCTREE_MAX_LEVELS must be log2(LPV_MAX_GRID_DIM) + 1");

static int cell_nonzero(const lpv_cell *c)
{
    for (int k = 0; k < 4; k++) {
        if (c->r[k] != 0.0f || c->g[k] != 0.0f || c->b[k] != 0.0f)
            return 1;
    }
    return 0;
}

static size_t level_cells(const lpv_octree_level *lv) { return lpv_grid_cell_count(&lv->grid); }

/* ---- Creation ------------------------------------------------------------ */

static int power_of_two_dim(int n) { return n >= 1 && n <= LPV_MAX_GRID_DIM && (n & (n - 1)) == 0; }

static int log2_int(int n)
{
    int l = 0;
    while ((1 << l) < n)
        l++;
    return l;
}

void lpv_octree_free(lpv_octree *o)
{
    for (int i = 0; i < LPV_OCTREE_MAX_LEVELS; i++) {
        lpv_octree_level *lv = &o->level[i];
        free(lv->src);
        free(lv->cur);
        free(lv->acc);
        free(lv->index);
        free(lv->gv);
        free(lv->t);
    }
    free(o->scratch);
    memset(o, 0, sizeof *o);
}

void lpv_octree_clear(lpv_octree *o)
{
    for (int i = 0; i < o->levels; i++) {
        lpv_octree_level *lv = &o->level[i];
        size_t cells = level_cells(lv);
        memset(lv->src, 0, cells * sizeof *lv->src);
        memset(lv->cur, 0, cells * sizeof *lv->cur);
        memset(lv->acc, 0, cells * sizeof *lv->acc);
        /* Thesis 4.2: every element points at the last (coarsest) level until
         * light says otherwise. */
        memset(lv->index, o->levels - 1, cells);
        if (lv->gv)
            memset(lv->gv, 0, lpv_grid_gv_count(&lv->grid) * sizeof *lv->gv);
        if (lv->t)
            memset(lv->t, 0, cells * LPV_DIR_COUNT * sizeof *lv->t);
    }
    o->steps = 0;
}

int lpv_octree_create(const lpv_grid *g, int occlusion, lpv_octree *o, char *err, size_t err_size)
{
    memset(o, 0, sizeof *o);
    int n = g->dims[0];
    if (g->dims[1] != n || g->dims[2] != n)
        return lpv_error(err, err_size, "octree: the grid must be n x n x n, got %d x %d x %d", g->dims[0],
                         g->dims[1], g->dims[2]);
    if (!power_of_two_dim(n))
        return lpv_error(err, err_size, "octree: n = %d is not a power of two in 1..%d", n, LPV_MAX_GRID_DIM);
    if (!(g->cell_size > 0.0f) || !isfinite(g->cell_size) || !isfinite(g->origin[0]) ||
        !isfinite(g->origin[1]) || !isfinite(g->origin[2]))
        return lpv_error(err, err_size, "octree: the grid's origin and cell size must be finite (cell size > 0)");

    o->n = n;
    o->levels = log2_int(n) + 1;
    o->occlusion = occlusion ? 1 : 0;
    for (int i = 0; i < o->levels; i++) {
        lpv_octree_level *lv = &o->level[i];
        int m = n >> i;
        lv->grid = *g;
        lv->grid.dims[0] = lv->grid.dims[1] = lv->grid.dims[2] = m;
        /* A power of two: exact, so level i's cells tile level i-1's 2 x 2 x 2. */
        lv->grid.cell_size = ldexpf(g->cell_size, i);
        size_t cells = lpv_grid_cell_count(&lv->grid);
        lv->src = malloc(cells * sizeof *lv->src);
        lv->cur = malloc(cells * sizeof *lv->cur);
        lv->acc = malloc(cells * sizeof *lv->acc);
        lv->index = malloc(cells);
        int ok = lv->src && lv->cur && lv->acc && lv->index;
        if (ok && o->occlusion) {
            lv->gv = malloc(lpv_grid_gv_count(&lv->grid) * sizeof *lv->gv);
            lv->t = malloc(cells * LPV_DIR_COUNT * sizeof *lv->t);
            ok = lv->gv && lv->t;
        }
        if (!ok) {
            lpv_octree_free(o);
            return lpv_error(err, err_size, "octree: out of memory for level %d (%d^3 cells)", i, m);
        }
    }
    o->scratch = malloc(lpv_grid_cell_count(g) * sizeof *o->scratch);
    if (!o->scratch) {
        lpv_octree_free(o);
        return lpv_error(err, err_size, "octree: out of memory for the step buffer");
    }
    lpv_octree_clear(o);
    return 0;
}

/* ---- Injection ----------------------------------------------------------- */

size_t lpv_octree_inject_vpls(lpv_octree *o, const lpv_vpl *vpls, size_t n)
{
    lpv_octree_level *l0 = &o->level[0];
    size_t injected = lpv_oracle_inject_vpls(&l0->grid, vpls, n, l0->src);
    /* Thesis 4.2: a level-0 element holding light is next to lit geometry and
     * nothing finer exists, so it is sampled from level 0. Marked from the
     * cell's value (not per VPL), as the thesis sums it up: after injection
     * I is 0 exactly where O_0 != 0. */
    size_t cells = level_cells(l0);
    for (size_t c = 0; c < cells; c++) {
        if (cell_nonzero(&l0->src[c]))
            l0->index[c] = 0;
    }
    return injected;
}

int lpv_octree_add_surfels(lpv_octree *o, const lpv_surfel *surfels, size_t n, size_t *injected)
{
    if (injected)
        *injected = 0;
    if (!o->occlusion)
        return 0;
    /* One per-buffer SH GV, sized for level 0 and reused by the coarser
     * levels (each needs fewer points). */
    size_t points0 = lpv_grid_gv_count(&o->level[0].grid);
    vec4 *buffer = malloc(points0 * sizeof *buffer);
    if (!buffer)
        return -1;
    for (int i = 0; i < o->levels; i++) {
        lpv_octree_level *lv = &o->level[i];
        memset(buffer, 0, lpv_grid_gv_count(&lv->grid) * sizeof *buffer);
        /* Each level injects the surfels itself (docs/octree.md), as a
         * cascade of the cascaded LPV does: the blocking potential
         * area / s_i^2 is the fraction of a level-i face a surface covers (a
         * density per face area), so a wall that closes level 0's faces
         * closes every level's. The thesis' build downsamples the GV with
         * eq. 11 instead; a wall lies in one plane of GV points, which is
         * one of two fine planes a coarse element covers along its normal,
         * so the mean halves its blocking at each level (1 / 2^i of it is
         * left where the wall is on a plane of level i) and a closed wall
         * leaks on the coarse levels. */
        size_t took = lpv_oracle_inject_surfels(&lv->grid, surfels, n, buffer);
        if (i == 0 && injected)
            *injected = took;
        lpv_oracle_gv_merge(&lv->grid, buffer, lv->gv);
    }
    free(buffer);
    return 0;
}

/* ---- Downsampling (eq. 11) ----------------------------------------------- */

/* coarse(x) = mean of fine's 8 children of x. The sum runs in double so no
 * finite input overflows (8 floats near FLT_MAX); the mean of finite values
 * is within their range, so the one rounding to float stays finite. The
 * metric's Ô uses this same function, so it equals O_i bit for bit right
 * after downsampling. */
static void mean_of_children(const lpv_grid *fine, const lpv_cell *fcells, int x, int y, int z, lpv_cell *out)
{
    double sum[3][4] = {{0.0}};
    for (int dz = 0; dz < 2; dz++) {
        for (int dy = 0; dy < 2; dy++) {
            for (int dx = 0; dx < 2; dx++) {
                const lpv_cell *c = &fcells[lpv_grid_index(fine, 2 * x + dx, 2 * y + dy, 2 * z + dz)];
                for (int k = 0; k < 4; k++) {
                    sum[0][k] += (double)c->r[k];
                    sum[1][k] += (double)c->g[k];
                    sum[2][k] += (double)c->b[k];
                }
            }
        }
    }
    for (int k = 0; k < 4; k++) {
        out->r[k] = (float)(sum[0][k] / 8.0);
        out->g[k] = (float)(sum[1][k] / 8.0);
        out->b[k] = (float)(sum[2][k] / 8.0);
    }
}

void lpv_octree_downsample(lpv_octree *o)
{
    for (int i = 1; i < o->levels; i++) {
        lpv_octree_level *fine = &o->level[i - 1], *lv = &o->level[i];
        int m = lv->grid.dims[0];
        for (int z = 0; z < m; z++) {
            for (int y = 0; y < m; y++) {
                for (int x = 0; x < m; x++) {
                    size_t c = lpv_grid_index(&lv->grid, x, y, z);
                    mean_of_children(&fine->grid, fine->src, x, y, z, &lv->src[c]);
                    /* Thesis 4.2: an element given light by the downsampling
                     * is sampled from its own level unless a finer one has it. */
                    if (cell_nonzero(&lv->src[c]))
                        lv->index[c] = (uint8_t)i;
                }
            }
        }
    }
}

/* ---- Propagation --------------------------------------------------------- */

void lpv_octree_propagate_begin(lpv_octree *o)
{
    for (int i = 0; i < o->levels; i++) {
        lpv_octree_level *lv = &o->level[i];
        size_t bytes = level_cells(lv) * sizeof *lv->src;
        memcpy(lv->cur, lv->src, bytes);
        memcpy(lv->acc, lv->src, bytes);
        if (o->occlusion)
            lpv_oracle_transmittance(&lv->grid, lv->gv, lv->t);
    }
    o->steps = 0;
}

void lpv_octree_propagate_step(lpv_octree *o, int transport)
{
    for (int i = 0; i < o->levels; i++) {
        lpv_octree_level *lv = &o->level[i];
        /* The level is its own LPV (thesis 4.2) and takes the cascaded
         * oracle's step unchanged; no occlusion on the first step, as
         * lpv_oracle_propagate_with (a VPL's own surface would shadow it). */
        const float *t = o->occlusion && o->steps > 0 ? lv->t : NULL;
        lpv_oracle_propagate_step_with(&lv->grid, lv->cur, t, transport, o->scratch);
        size_t cells = level_cells(lv);
        for (size_t c = 0; c < cells; c++) {
            const lpv_cell *s = &o->scratch[c];
            /* p = 1: the step's output is added as it is. */
            for (int k = 0; k < 4; k++) {
                lv->acc[c].r[k] += s->r[k];
                lv->acc[c].g[k] += s->g[k];
                lv->acc[c].b[k] += s->b[k];
            }
            /* Thesis 4.2: a non-zero contribution to O_i(x) sets I_i(x) = i. */
            if (cell_nonzero(s))
                lv->index[c] = (uint8_t)i;
        }
        memcpy(lv->cur, o->scratch, cells * sizeof *lv->cur);
    }
    o->steps++;
}

void lpv_octree_propagate(lpv_octree *o, int iterations, int transport)
{
    lpv_octree_propagate_begin(o);
    for (int k = 0; k < iterations; k++)
        lpv_octree_propagate_step(o, transport);
}

/* ---- Index lookup and merge (eq. 10) ------------------------------------- */

int lpv_octree_index(const lpv_octree *o, int x, int y, int z)
{
    int best = o->levels - 1;
    for (int i = 0; i < o->levels; i++) {
        const lpv_octree_level *lv = &o->level[i];
        int v = lv->index[lpv_grid_index(&lv->grid, x >> i, y >> i, z >> i)];
        if (v < best)
            best = v;
    }
    return best;
}

void lpv_octree_merge(const lpv_octree *o, lpv_cell *merged)
{
    const lpv_grid *g0 = &o->level[0].grid;
    for (int z = 0; z < o->n; z++) {
        for (int y = 0; y < o->n; y++) {
            for (int x = 0; x < o->n; x++) {
                int i = lpv_octree_index(o, x, y, z);
                const lpv_octree_level *lv = &o->level[i];
                merged[lpv_grid_index(g0, x, y, z)] = lv->acc[lpv_grid_index(&lv->grid, x >> i, y >> i, z >> i)];
            }
        }
    }
}

/* ---- The metric (thesis 6.2) --------------------------------------------- */

/* max |v_k| over the 12 values (the thesis writes max_k v_k; a norm needs
 * the absolute value, and SH coefficients are signed). */
static double inf_norm(const lpv_cell *c)
{
    double m = 0.0;
    for (int k = 0; k < 4; k++) {
        m = fmax(m, fabs((double)c->r[k]));
        m = fmax(m, fabs((double)c->g[k]));
        m = fmax(m, fabs((double)c->b[k]));
    }
    return m;
}

static double inf_norm_diff(const lpv_cell *a, const lpv_cell *b)
{
    double m = 0.0;
    for (int k = 0; k < 4; k++) {
        m = fmax(m, fabs((double)a->r[k] - (double)b->r[k]));
        m = fmax(m, fabs((double)a->g[k] - (double)b->g[k]));
        m = fmax(m, fabs((double)a->b[k] - (double)b->b[k]));
    }
    return m;
}

void lpv_octree_measure(const lpv_octree *o, lpv_octree_error *out)
{
    memset(out, 0, sizeof *out);
    double sum_abs = 0.0, sum_rel = 0.0;
    for (int i = 1; i < o->levels; i++) {
        const lpv_octree_level *fine = &o->level[i - 1], *lv = &o->level[i];
        int m = lv->grid.dims[0];
        for (int z = 0; z < m; z++) {
            for (int y = 0; y < m; y++) {
                for (int x = 0; x < m; x++) {
                    lpv_cell ideal;
                    mean_of_children(&fine->grid, fine->acc, x, y, z, &ideal);
                    const lpv_cell *c = &lv->acc[lpv_grid_index(&lv->grid, x, y, z)];
                    double d = inf_norm_diff(c, &ideal), norm = inf_norm(c);
                    sum_abs += d;
                    if (norm > 0.0)
                        sum_rel += d / norm;
                    else if (d > 0.0)
                        out->rel_undefined++; /* counts 0: see oracle_octree.h */
                    out->elements++;
                }
            }
        }
    }
    if (o->levels < 2)
        return; /* no level above 0: nothing to compare, both errors 0 */
    /* The thesis' 7 / (8^l - 8), in double: 8^9 is far from overflowing. */
    double thesis = 7.0 / (ldexp(1.0, 3 * o->levels) - 8.0);
    out->e_abs = thesis * sum_abs;
    out->e_rel = thesis * sum_rel;
    out->mean_abs = sum_abs / (double)out->elements;
    out->mean_rel = sum_rel / (double)out->elements;
}

/* ---- The whole pipeline -------------------------------------------------- */

int lpv_octree_run(const lpv_octree_desc *desc, lpv_octree *o, lpv_cell *merged, char *err, size_t err_size)
{
    memset(o, 0, sizeof *o);
    if (desc->iterations < 0 || desc->iterations > LPV_MAX_ITERATIONS)
        return lpv_error(err, err_size, "octree: iterations %d outside 0..%d", desc->iterations,
                         LPV_MAX_ITERATIONS);
    if (desc->transport != LPV_TRANSPORT_PAPER && desc->transport != LPV_TRANSPORT_CENTRAL)
        return lpv_error(err, err_size, "octree: unknown transport %d", desc->transport);
    if (desc->vpl_count > 0 && !desc->vpls)
        return lpv_error(err, err_size, "octree: %zu VPLs but no array", desc->vpl_count);
    if (lpv_octree_create(&desc->grid, desc->surfels != NULL, o, err, err_size) != 0)
        return -1;
    if (desc->vpl_count > 0)
        lpv_octree_inject_vpls(o, desc->vpls, desc->vpl_count);
    if (desc->surfels && lpv_octree_add_surfels(o, desc->surfels, desc->surfel_count, NULL) != 0) {
        lpv_octree_free(o);
        return lpv_error(err, err_size, "octree: out of memory for the geometry volume");
    }
    lpv_octree_downsample(o);
    lpv_octree_propagate(o, desc->iterations, desc->transport);
    if (merged)
        lpv_octree_merge(o, merged);
    return 0;
}
