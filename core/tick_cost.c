/*
 * tick_cost.c - the upper bound of a tick's cost from its settings
 * (tick_cost.h): one function per technique, the dearest for auto.
 */
#include "tick_cost.h"

#include <stdio.h>

#include "cascades.h"
#include "lpv_shared.h"

static double grid_cells(const lpv_settings *s)
{
    return (double)s->grid_dims[0] * (double)s->grid_dims[1] * (double)s->grid_dims[2];
}

/* Cascaded LPV: cells x cascades (auto: the most the planner may place, the
 * far field's levels included) x normal bins x iterations. */
static void cost_lpv(const lpv_settings *s, lpv_tick_cost *out)
{
    int cascades = s->lpv.cascades > 0 ? lpv_cascades_count(s, s->lpv.cascades) : lpv_cascades_count(s, 1);
    if (s->lpv.cascades <= 0 && cascades < LPV_DEFAULT_CASCADES)
        cascades = LPV_DEFAULT_CASCADES;
    int bins = s->lpv.normal_bins == LPV_SWITCH_ON ? LPV_NORMAL_BINS : 1;
    out->cell_steps = grid_cells(s) * cascades * bins * s->lpv.iterations;
    snprintf(out->terms, sizeof out->terms, "grid %dx%dx%d x %d cascade%s x %d normal bin%s x %d iterations",
             s->grid_dims[0], s->grid_dims[1], s->grid_dims[2], cascades, cascades == 1 ? "" : "s", bins,
             bins == 1 ? "" : "s", s->lpv.iterations);
    out->lower = "grid, iterations, cascades or normal_bins";
}

/* Octree: every level propagates; the levels above level 0 add at most 1/7
 * of its cells (each has 1/8 of the one below). No normal bins. */
static void cost_octree(const lpv_settings *s, lpv_tick_cost *out)
{
    out->cell_steps = grid_cells(s) * 8.0 / 7.0 * s->lpv.iterations;
    snprintf(out->terms, sizeof out->terms, "grid %dx%dx%d x 8/7 (its levels) x %d iterations", s->grid_dims[0],
             s->grid_dims[1], s->grid_dims[2], s->lpv.iterations);
    out->lower = "grid or iterations";
}

/* Imperfect volume: (iv_resolution + 1)^3 voxels at most (cubes along the
 * scene's longest side) x rays x gathers (the bounces, and the AO pass). */
static void cost_iv(const lpv_settings *s, lpv_tick_cost *out)
{
    double side = (double)s->iv.resolution + 1.0;
    int gathers = s->iv.bounces + (s->iv.ao == LPV_SWITCH_ON ? 1 : 0);
    out->cell_steps = side * side * side * s->iv.rays * gathers / LPV_TICK_COST_IV_RAYS_PER_STEP;
    snprintf(out->terms, sizeof out->terms,
             "iv_resolution %d: %.0f voxels x %d rays x %d gathers (bounces%s) / %g rays a cell-step",
             s->iv.resolution, side * side * side, s->iv.rays, gathers, s->iv.ao == LPV_SWITCH_ON ? " and AO" : "",
             LPV_TICK_COST_IV_RAYS_PER_STEP);
    out->lower = "iv_resolution, iv_rays or iv_bounces";
}

void lpv_tick_cost_estimate(const lpv_settings *s, lpv_tick_cost *out)
{
    switch (s->technique) {
    case LPV_TECHNIQUE_ID_OCTREE: cost_octree(s, out); return;
    case LPV_TECHNIQUE_ID_IV: cost_iv(s, out); return;
    case LPV_TECHNIQUE_ID_AUTO: { /* the planner chooses lpv or iv from the scene (core/plan.c) */
        lpv_tick_cost iv;
        cost_lpv(s, out);
        cost_iv(s, &iv);
        if (iv.cell_steps > out->cell_steps)
            *out = iv;
        return;
    }
    default: cost_lpv(s, out); return;
    }
}
