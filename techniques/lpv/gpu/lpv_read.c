/*
 * lpv_read.c - the LPV's read-backs for the tests and the daemon: the light
 * (injected, accumulated or the last step's; per cascade summed over the
 * normal bins, or every volume as stored), the geometry volume and the
 * transmittances. What exists depends on the plan the volume was computed
 * (or last served) under.
 */
#include <stdlib.h>

#include "lpv_internal.h"

/* The buffer holding the chosen grid of every LPV volume. */
static GLuint grid_buffer(const lpv_cascaded *c, const lpv_plan *last, lpv_grid_which which)
{
    const int steps = last->pass[LPV_PASS_PROPAGATE].run ? c->settings.lpv.iterations : 0;
    if (which == LPV_GRID_INJECTED || (which == LPV_GRID_LAST_STEP && steps == 0))
        return c->lpv_injected;
    if (which == LPV_GRID_LAST_STEP)
        return c->lpv_last;
    return c->lpv_acc;
}

static size_t read_summed(lpv_cascaded *c, GLuint b, lpv_cell *out, size_t max)
{
    if (c->bins <= 1)
        return lpv_gl_read_buffer(b, sizeof(lpv_cell), lpv_all_cells(c), out, max);
    /* Normal bins: the physical field of a cascade is the sum of its bins. */
    const size_t per = lpv_cascade_cells(c), all = lpv_volume_cells(c);
    lpv_cell *raw = malloc(all * sizeof *raw);
    if (!raw)
        return 0;
    lpv_gl_read_buffer(b, sizeof(lpv_cell), all, raw, all);
    size_t n = lpv_all_cells(c) < max ? lpv_all_cells(c) : max;
    for (size_t i = 0; i < n; ++i) {
        size_t k = i / per, cell = i % per;
        lpv_cell sum = raw[k * (size_t)c->bins * per + cell];
        for (int bin = 1; bin < c->bins; ++bin) {
            const lpv_cell *x = &raw[(k * (size_t)c->bins + (size_t)bin) * per + cell];
            for (int j = 0; j < 4; ++j) {
                sum.r[j] += x->r[j];
                sum.g[j] += x->g[j];
                sum.b[j] += x->b[j];
            }
        }
        out[i] = sum;
    }
    free(raw);
    return n;
}

size_t lpv_cascaded_read(lpv_cascaded *c, const lpv_plan *last, lpv_volume_part part, lpv_grid_which which,
                         void *out, size_t max)
{
    switch (part) {
    case LPV_VOLUME_SUMMED:
        return read_summed(c, grid_buffer(c, last, which), out, max);
    case LPV_VOLUME_STORED:
        return lpv_gl_read_buffer(grid_buffer(c, last, which), sizeof(lpv_cell), lpv_volume_cells(c), out, max);
    case LPV_VOLUME_GEOMETRY:
        if (!last->pass[LPV_PASS_GV].run)
            return 0;
        return lpv_gl_read_buffer(c->gv_total, sizeof(lpv_gv_point),
                                  lpv_grid_gv_count(&c->grid) * (size_t)c->cascades.count, out, max);
    case LPV_VOLUME_TRANSMIT:
        if (!last->pass[LPV_PASS_GV].run)
            return 0;
        return lpv_gl_read_buffer(c->transmit, sizeof(float), lpv_all_cells(c) * LPV_DIR_COUNT, out, max);
    case LPV_VOLUME_INDEX: /* one grid per cascade: no index volume */
    case LPV_VOLUME_IV_VOXELS:
    case LPV_VOLUME_AO:
    case LPV_VOLUME_VISIBILITY:
        return 0;
    }
    return 0;
}
