/*
 * oracle_iv.c - reference imperfect volumes (see oracle_iv.h): literal loops
 * over voxels, rays and corners, sums in double. This file holds the entry
 * points (lpv_iv_run, lpv_iv_run_ao: checks, then creation and the bounces)
 * and the tail after the last bounce; the steps live beside it:
 * oracle_iv_create.c, oracle_iv_emit.c, oracle_iv_gather.c,
 * oracle_iv_filter.c and oracle_iv_reconstruct.c, sharing
 * oracle_iv_internal.h.
 */
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "oracle_iv_internal.h"

/* ---- Entry points ------------------------------------------------------------ */

static int check(const lpv_iv_desc *d, int need_bounces, char *err, size_t err_size)
{
    const lpv_grid *g = &d->grid;
    for (int a = 0; a < 3; a++)
        if (g->dims[a] < 1 || g->dims[a] > LPV_MAX_GRID_DIM)
            return lpv_error(err, err_size, "iv: grid dims %d x %d x %d outside 1..%d", g->dims[0], g->dims[1],
                             g->dims[2], LPV_MAX_GRID_DIM);
    if (!finite3(g->origin) || !isfinite(g->cell_size) || !(g->cell_size > 0.0f))
        return lpv_error(err, err_size, "iv: the grid's origin and cell size must be finite (cell size > 0)");
    if (d->point_count > 0 && !d->points)
        return lpv_error(err, err_size, "iv: %zu points but no point array", d->point_count);
    if (d->rays < 1)
        return lpv_error(err, err_size, "iv: rays = %d, need >= 1", d->rays);
    if (need_bounces && d->bounces < 1)
        return lpv_error(err, err_size, "iv: bounces = %d, need >= 1", d->bounces);
    if (need_bounces && (d->neighbours < 1 || d->neighbours > 8))
        return lpv_error(err, err_size, "iv: neighbours = %d, need 1..8", d->neighbours);
    return 0;
}

void lpv_iv_total(size_t cells, const lpv_cell *incoming, double total[3])
{
    total[0] = total[1] = total[2] = 0.0;
    for (size_t i = 0; i < cells; i++) {
        total[0] += incoming[i].r[0];
        total[1] += incoming[i].g[0];
        total[2] += incoming[i].b[0];
    }
}

void lpv_iv_tail_share(const double (*totals)[3], int K, float q[3])
{
    const double most = (double)LPV_IV_TAIL_MAX_RATIO * (double)LPV_IV_TAIL_MAX_RATIO;
    for (int ch = 0; ch < 3; ch++) {
        q[ch] = 0.0f;
        if (K < 3)
            continue;
        const double d0 = totals[K - 2][ch] - (K >= 4 ? totals[K - 3][ch] : 0.0);
        const double d1 = totals[K][ch] - totals[K - 1][ch];
        if (!(d0 > 0.0) || !(d1 > 0.0))
            continue;
        const double v = d1 / d0;
        q[ch] = (float)(v < most ? v : most);
    }
}

void lpv_iv_add_tail(size_t cells, const lpv_cell *base, const float q[3], lpv_cell *last)
{
    for (size_t i = 0; i < cells; i++)
        for (int ch = 0; ch < 3; ch++) {
            float *a = channel(&last[i], ch);
            const float *b = cchannel(&base[i], ch);
            if (!(q[ch] > 0.0f) || !(a[0] - b[0] > 0.0f)) /* no light from the last two bounces here: no tail */
                continue;
            const float f = q[ch] / (1.0f - q[ch]);
            for (int k = 0; k < 4; k++)
                a[k] += (a[k] - b[k]) * f;
        }
}

int lpv_iv_run(const lpv_iv_desc *d, lpv_iv_voxel *voxels, lpv_cell *incoming, char *err, size_t err_size)
{
    if (check(d, 1, err, err_size) != 0)
        return -1;
    const lpv_grid *g = &d->grid;
    size_t cells = lpv_grid_cell_count(g);
    lpv_iv_voxel *own = voxels ? NULL : malloc(cells * sizeof *own);
    lpv_cell *emit = malloc(cells * sizeof *emit);
    lpv_cell *prev = malloc(cells * sizeof *prev);
    lpv_cell *base = d->tail ? malloc(cells * sizeof *base) : NULL; /* I_{K-2} */
    int rc = -1;
    if ((!voxels && !own) || !emit || !prev || (d->tail && !base)) {
        lpv_error(err, err_size, "iv: out of memory for %zu voxels", cells);
        goto done;
    }
    lpv_iv_voxel *vox = voxels ? voxels : own;
    if (lpv_iv_create(g, d->points, d->radiosity, d->point_count, vox, NULL) != 0) {
        lpv_error(err, err_size, "iv: out of memory creating the volume");
        goto done;
    }
    memset(incoming, 0, cells * sizeof *incoming); /* I_0 */
    double totals[LPV_IV_TAIL_SLOTS][3] = {{0.0}};
    for (int k = 1; k <= d->bounces; k++) {
        if (base && k == d->bounces && k >= 3)
            memcpy(base, prev, cells * sizeof *base); /* prev still holds I_{k-2} */
        memcpy(prev, incoming, cells * sizeof *prev);
        lpv_iv_emit(g, vox, prev, k, d->neighbours, emit);
        lpv_iv_gather(g, vox, emit, d->seed, d->rays, incoming);
        if (base && k >= d->bounces - 3 && k < LPV_IV_TAIL_SLOTS) /* the tail's four totals */
            lpv_iv_total(cells, incoming, totals[k]);
    }
    if (base && d->bounces >= 3 && d->bounces < LPV_IV_TAIL_SLOTS) {
        float q[3];
        lpv_iv_tail_share((const double(*)[3])totals, d->bounces, q);
        lpv_iv_add_tail(cells, base, q, incoming);
    }
    if (d->filter) { /* prev is free now */
        memcpy(prev, incoming, cells * sizeof *prev);
        lpv_iv_filter(g, vox, prev, incoming);
    }
    rc = 0;
done:
    free(own);
    free(emit);
    free(prev);
    free(base);
    return rc;
}

int lpv_iv_run_ao(const lpv_iv_desc *d, float reach, lpv_iv_voxel *voxels, vec4 *ao, char *err, size_t err_size)
{
    if (check(d, 0, err, err_size) != 0)
        return -1;
    const lpv_grid *g = &d->grid;
    size_t cells = lpv_grid_cell_count(g);
    lpv_iv_voxel *own = voxels ? NULL : malloc(cells * sizeof *own);
    lpv_iv_voxel *vox = voxels ? voxels : own;
    if (!vox)
        return lpv_error(err, err_size, "iv: out of memory for %zu voxels", cells);
    int rc = lpv_iv_create(g, d->points, d->radiosity, d->point_count, vox, NULL);
    if (rc != 0)
        lpv_error(err, err_size, "iv: out of memory creating the volume");
    else
        lpv_iv_gather_ao(g, vox, d->seed, d->rays, reach, ao);
    free(own);
    return rc;
}
