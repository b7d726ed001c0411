/*
 * octree_cost.c - the octree LPV's tick cost bound (core/tick_cost.h) and
 * its least storage (core/memory_budget.h).
 */
#include "octree_rules.h"

#include <stdio.h>

/* Octree: every level propagates; the levels above level 0 add at most 1/7
 * of its cells (each has 1/8 of the one below). No normal bins. */
void lpv_octree_tick_cost(const lpv_settings *s, lpv_tick_cost *out)
{
    out->cell_steps = lpv_settings_grid_cells(s) * 8.0 / 7.0 * s->lpv.iterations;
    snprintf(out->terms, sizeof out->terms, "grid %dx%dx%d x 8/7 (its levels) x %d iterations", s->grid_dims[0],
             s->grid_dims[1], s->grid_dims[2], s->lpv.iterations);
    out->lower = "grid or iterations";
}

void lpv_octree_memory_floor(const lpv_settings *s, lpv_memory_need *n)
{
    lpv_memory_need_grid(s, 1, n);
}
