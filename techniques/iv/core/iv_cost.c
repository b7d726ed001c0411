/*
 * iv_cost.c - the imperfect volume's tick cost bound (core/tick_cost.h).
 */
#include "iv_rules.h"

#include <stdio.h>

/* Imperfect volume: (iv_resolution + 1)^3 voxels at most (cubes along the
 * scene's longest side) x rays x gathers (the bounces, and the AO pass). */
void lpv_iv_tick_cost(const lpv_settings *s, lpv_tick_cost *out)
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
