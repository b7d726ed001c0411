/*
 * lpv_cost.c - the cascaded LPV's tick cost bound (core/tick_cost.h) and
 * its least storage (core/memory_budget.h).
 */
#include "lpv_rules.h"

#include <stdio.h>

#include "cascades.h"
#include "lpv_shared.h"

/* Cascaded LPV: cells x cascades (auto: the most the planner may place, the
 * far field's levels included) x normal bins x iterations. */
void lpv_lpv_tick_cost(const lpv_settings *s, lpv_tick_cost *out)
{
    int cascades = s->lpv.cascades > 0 ? lpv_cascades_count(s, s->lpv.cascades) : lpv_cascades_count(s, 1);
    if (s->lpv.cascades <= 0 && cascades < LPV_AUTO_CASCADES)
        cascades = LPV_AUTO_CASCADES;
    int bins = s->lpv.normal_bins == LPV_SWITCH_ON ? LPV_NORMAL_BINS : 1;
    out->cell_steps = lpv_settings_grid_cells(s) * cascades * bins * s->lpv.iterations;
    snprintf(out->terms, sizeof out->terms, "grid %dx%dx%d x %d cascade%s x %d normal bin%s x %d iterations",
             s->grid_dims[0], s->grid_dims[1], s->grid_dims[2], cascades, cascades == 1 ? "" : "s", bins,
             bins == 1 ? "" : "s", s->lpv.iterations);
    out->lower = "grid, iterations, cascades or normal_bins";
}

void lpv_lpv_memory_floor(const lpv_settings *s, lpv_memory_need *n)
{
    /* the cascades asked for, and the far field's levels the LPV adds to one */
    const int asked = s->lpv.cascades > 0 ? s->lpv.cascades : 1;
    lpv_memory_need_grid(s, lpv_cascades_count(s, asked), n);
}
