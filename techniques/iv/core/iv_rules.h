/*
 * iv_rules.h - the imperfect volume's CPU half beside its oracle
 * (oracle_iv.h), point cloud (iv_points.h) and voxelizer (iv_voxelize.h):
 * its plan, its tick cost bound and its knob rows, which
 * techniques/registry.c lists.
 */
#ifndef LPV_IV_RULES_H
#define LPV_IV_RULES_H

#include "iv_points.h"
#include "plan.h"
#include "settings_fields.h"
#include "tick_cost.h"

/* The imperfect volume's plan: the shared producers it reads (the RSMs for
 * shadows, the G-buffer for reprojection) and its passes. s resolved;
 * cloud: the point cloud it sampled (lpv_iv_points_make's stats; points 0:
 * none). */
void lpv_plan_make_iv(const lpv_settings *s, const lpv_plan_facts *f, const lpv_iv_point_stats *cloud,
                      lpv_plan *out);

/* (iv_resolution + 1)^3 voxels at most x rays x gathers (the bounces, and
 * the AO pass), at LPV_TICK_COST_IV_RAYS_PER_STEP rays a cell-step. */
void lpv_iv_tick_cost(const lpv_settings *s, lpv_tick_cost *out);

/* Its knob rows (iv_fields.c), *count of them. */
const lpv_field *lpv_iv_fields(size_t *count);

#endif /* LPV_IV_RULES_H */
