/*
 * export_result.c - a tick's result read back from the engine on the GL
 * context's thread (sv_result: the accumulated volume of every cascade, the
 * imperfect volume's occupancy, the frames asked for, the stats and plan),
 * what GET_VOLUME, GET_FRAME and the streams encode (export.h). The
 * daemon's GL thread and lpvd batch's volume output take it here. The
 * octree's levels and index (GET_VOLUME content "levels") and the probes'
 * visibility (content "visibility") are read only for a request that asks
 * for them (sv_result_take_content): a tick does not pay for them (issue
 * 33).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "export.h"
#include "probes_record.h" /* a probe's record: its size */

sv_result *sv_result_ref(sv_result *r)
{
    if (r)
        r->refs++;
    return r;
}

static void result_free(sv_result *r)
{
    if (!r)
        return;
    free(r->cells);
    free(r->levels);
    free(r->index);
    free(r->visibility);
    free(r->iv_held);
    for (int i = 0; i < LPVP_TERMS_COUNT; ++i)
        free(r->frames[i]);
    uint64_t counted = 0;
    for (int i = 0; i < 4; ++i) {
        free(r->enc[i / 2][i % 2]);
        counted += r->enc_counted[i / 2][i % 2];
    }
    for (int i = 0; i < SV_SHARED_ENCODINGS; ++i) {
        free(r->shared[i].att);
        counted += r->shared[i].counted;
        sv_blob_unref(r->shared[i].recon);
    }
    if (r->enc_held && counted) /* the encoding caches leave the daemon's count with the result */
        atomic_fetch_sub_explicit(r->enc_held, counted, memory_order_relaxed);
    free(r);
}

void sv_result_unref(sv_result *r)
{
    if (r && --r->refs <= 0)
        result_free(r);
}

/* GET_VOLUME content "levels" (SPEC R5.13): with a technique that has an
 * index volume (the octree), its levels and index, read now on the GL thread.
 * 0, or -1 with err (also for a technique or grid without them). */
static int keep_levels(lpv_engine *e, sv_result *r, char *err, size_t n)
{
    size_t cells0 = lpv_grid_cell_count(&r->grid);
    int count = lpvp_octree_level_count(r->grid.dims[0]);
    const lpv_volume_desc *d = &r->stats.volume;
    if (!d->index_levels || count < 1) {
        snprintf(err, n, "technique \"%s\" has no levels and index volume over its %dx%dx%d grid to send",
                 d->technique ? d->technique : "?", r->grid.dims[0], r->grid.dims[1], r->grid.dims[2]);
        return -1;
    }
    int32_t *index = malloc((cells0 ? cells0 : 1) * sizeof *index);
    if (!index) {
        snprintf(err, n, "out of memory for a %zu-cell index volume", cells0);
        return -1;
    }
    size_t got = lpv_engine_read_index(e, index, cells0);
    lpvp_cascade_info c0 = {.dims = {r->grid.dims[0], r->grid.dims[1], r->grid.dims[2]}, .cells = cells0};
    size_t total = 0;
    for (int i = 0; i < count; ++i) {
        lpvp_cascade_info ci;
        lpvp_octree_level_place(&c0, i, &ci);
        total += (size_t)ci.cells;
    }
    r->levels = malloc((total ? total : 1) * sizeof(lpv_cell));
    r->index = malloc((cells0 ? cells0 : 1) * sizeof *r->index);
    if (!r->levels || !r->index || got != cells0 ||
        lpv_engine_read_volumes(e, LPV_GRID_ACCUMULATED, (lpv_cell *)r->levels, total) != total) {
        snprintf(err, n, "%s", !r->levels || !r->index ? "out of memory for the octree's levels"
                                                       : "the octree's levels or index volume could not be read back");
        free(index);
        return -1;
    }
    for (size_t i = 0; i < cells0; ++i)
        r->index[i] = (uint32_t)index[i];
    free(index);
    r->level_cells = total;
    r->index_count = cells0;
    return 0;
}

/* An iv volume's index (SPEC R5.14): which voxels hold a surface, read now
 * on the GL thread from the voxels (IvVoxel.normal[3], the points that landed
 * in each), and *occupied their count. 0 (nothing kept for a volume that is
 * not an imperfect volume's) or -1 with err. */
static int keep_iv_held(lpv_engine *e, sv_result *r, long long *occupied, char *err, size_t n)
{
    if (lpv_engine_last_stats(e)->volume.kind != LPV_LEVELS_IV_VOXELS)
        return 0;
    size_t cells = lpv_grid_cell_count(&r->grid);
    struct IvVoxel *vox = malloc((cells ? cells : 1) * sizeof *vox);
    r->iv_held = malloc((cells ? cells : 1) * sizeof *r->iv_held);
    if (!vox || !r->iv_held || lpv_engine_read_iv_voxels(e, vox, cells) != cells) {
        snprintf(err, n, "%s", !vox || !r->iv_held ? "out of memory for the imperfect volume's voxels"
                                                    : "the imperfect volume's voxels could not be read back");
        free(vox);
        return -1;
    }
    *occupied = 0;
    for (size_t i = 0; i < cells; ++i) {
        r->iv_held[i] = vox[i].normal[3] > 0.0f; /* lpv_iv_occupied */
        *occupied += r->iv_held[i];
    }
    free(vox);
    r->iv_held_count = cells;
    return 0;
}

/* What every result holds: the grid and cascades, the stats and the plan of
 * the engine's last tick. NULL with err when out of memory. */
static sv_result *result_new(lpv_engine *e, char *err, size_t n)
{
    sv_result *r = calloc(1, sizeof *r);
    if (!r) {
        snprintf(err, n, "out of memory");
        return NULL;
    }
    r->refs = 1;
    r->grid = *lpv_engine_grid(e);
    r->cascade_count = lpv_engine_cascade_count(e);
    if (r->cascade_count < 1)
        r->cascade_count = 1;
    if (r->cascade_count > LPVP_MAX_CASCADES)
        r->cascade_count = LPVP_MAX_CASCADES;
    for (int k = 0; k < r->cascade_count; ++k) {
        const lpv_grid *g = lpv_engine_cascade(e, k);
        r->cascades[k] = g ? *g : r->grid;
    }
    r->stats = *lpv_engine_last_stats(e);
    r->plan = *lpv_engine_last_plan(e);
    return r;
}

/* Every cascade's accumulated cells. 0, or -1 with err. */
static int keep_cells(lpv_engine *e, sv_result *r, char *err, size_t n)
{
    r->cell_count = 0;
    for (int k = 0; k < r->cascade_count; ++k)
        r->cell_count += lpv_grid_cell_count(&r->cascades[k]);
    r->cells = malloc((r->cell_count ? r->cell_count : 1) * sizeof(lpv_cell));
    if (!r->cells) {
        snprintf(err, n, "out of memory for %zu cells", r->cell_count);
        return -1;
    }
    size_t got = lpv_engine_read_grid(e, LPV_GRID_ACCUMULATED, (lpv_cell *)r->cells, r->cell_count);
    if (got < r->cell_count)
        memset(r->cells + got * 12, 0, (r->cell_count - got) * sizeof(lpv_cell));
    return 0;
}

/* GET_VOLUME content "visibility" (SPEC R5.15): the probes' records, a
 * probe per cell kept. 0, or -1 with err (also for a technique without). */
static int keep_visibility(lpv_engine *e, sv_result *r, char *err, size_t n)
{
    const lpv_volume_desc *d = &r->stats.volume;
    if (d->visibility_side <= 0) {
        snprintf(err, n, "technique \"%s\" has no probes' visibility to send", d->technique ? d->technique : "?");
        return -1;
    }
    const size_t per = lpv_probes_record_values(d->irradiance_side, d->visibility_side);
    const size_t want = r->cell_count * per;
    r->visibility = malloc((want ? want : 1) * sizeof *r->visibility);
    if (!r->visibility) {
        snprintf(err, n, "out of memory for the visibility of %zu probes", r->cell_count);
        return -1;
    }
    if (lpv_engine_read_visibility(e, r->visibility, want) != want) {
        snprintf(err, n, "the visibility of %zu probes could not be read back", r->cell_count);
        return -1;
    }
    r->visibility_floats = want;
    return 0;
}

sv_result *sv_result_take(lpv_engine *e, int width, int height, unsigned terms_mask, char *err, size_t n)
{
    sv_result *r = result_new(e, err, n);
    if (!r)
        return NULL;
    if (keep_cells(e, r, err, n) != 0) {
        sv_result_unref(r);
        return NULL;
    }
    long long occupied = -1;
    if (keep_iv_held(e, r, &occupied, err, n) != 0) {
        sv_result_unref(r);
        return NULL;
    }
    r->width = width;
    r->height = height;
    for (int t = 0; t < LPVP_TERMS_COUNT; ++t) {
        if (!(terms_mask & (1u << t)))
            continue;
        size_t px = (size_t)r->width * (size_t)r->height;
        r->frames[t] = malloc(px * 4 * sizeof(float));
        if (!r->frames[t] || lpv_engine_render(e, (lpv_frame_terms)t, r->frames[t], err, n)) {
            free(r->frames[t]);
            r->frames[t] = NULL;
        }
    }
    r->stats = *lpv_engine_last_stats(e); /* again: the frames' render stages join them */
    r->plan = *lpv_engine_last_plan(e);
    if (r->iv_held)
        lpv_stats_put(&r->stats, "occupied", LPV_STAT_INT, (double)occupied, 0, 0); /* from the index it carries */
    return r;
}

sv_result *sv_result_take_content(lpv_engine *e, int content, char *err, size_t n)
{
    sv_result *r = result_new(e, err, n);
    if (!r)
        return NULL;
    int bad;
    if (content == LPVP_CONTENT_LEVELS)
        bad = keep_levels(e, r, err, n); /* no merged cells: it answers content "levels" only */
    else if (content == LPVP_CONTENT_VISIBILITY)
        bad = keep_cells(e, r, err, n) != 0 || keep_visibility(e, r, err, n) != 0;
    else
        bad = snprintf(err, n, "content %d is read with every tick", content) > 0;
    if (bad) {
        sv_result_unref(r);
        return NULL;
    }
    return r;
}
