/*
 * lpv_rules.h - the cascaded LPV's CPU half beside its oracle (oracle.h):
 * its plan and its tick cost bound, which techniques/registry.c lists.
 */
#ifndef LPV_LPV_RULES_H
#define LPV_LPV_RULES_H

#include "memory_budget.h"
#include "plan.h"
#include "tick_cost.h"

/* The plan of one tick of the cascaded LPV (the octree's too): the shared
 * producers it reads and its passes, each with its reason. s resolved. */
void lpv_plan_make_lpv(const lpv_settings *s, const lpv_plan_facts *f, lpv_plan *out);

/* The LPV's own (not the octree's) warning for a grid finer than
 * LPV_GRID_REACH_CELLS on every axis: appended to out's iterations_reason,
 * with iterations_warning set. Its transport spreads light sideways at each
 * step, so light crosses fewer metres the finer the cells, and against
 * converged light every scene of the accuracy set is worse at 32^3 than at
 * 16^3 (docs/accuracy.md, "Knobs that never make it worse"). */
#define LPV_GRID_REACH_CELLS 16
void lpv_plan_grid_reach_note(const lpv_settings *s, lpv_plan *out);

/* Cells x cascades (auto: the most the planner may place, the far field's
 * levels included) x normal bins x iterations. */
void lpv_lpv_tick_cost(const lpv_settings *s, lpv_tick_cost *out);

/* Its least storage whatever the scene: the grid at the cascades asked for
 * (at least one) and the far field's levels. */
void lpv_lpv_memory_floor(const lpv_settings *s, lpv_memory_need *n);

#endif /* LPV_LPV_RULES_H */
