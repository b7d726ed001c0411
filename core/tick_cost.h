/*
 * tick_cost.h - an upper bound of what one tick costs, from the settings
 * alone (issue 14, item 2), so a server can refuse at CONFIG a configuration
 * whose tick would hold its one GL thread for long, before running it.
 *
 * The unit is the cell-step: one cell of one LPV volume advanced by one
 * propagation step, the unit of the tick stats' counts.cell_steps. Every
 * multiplier is taken at the most the settings allow (cascades "auto" as the
 * most the planner may use, normal bins as all of them), so the bound never
 * depends on the scene. The imperfect volume's gather is converted at the
 * rate measured on llvmpipe (LPV_TICK_COST_IV_RAYS_PER_STEP). The shared
 * passes (RSMs, shadow maps) are bounded by the texture limits instead.
 * Pure arithmetic, no GL.
 */
#ifndef LPV_TICK_COST_H
#define LPV_TICK_COST_H

#include "settings.h"

/* iv_gather marches about 4 voxel-rays in the time the LPV takes for one
 * cell-step (llvmpipe, 2 cores: 33^3 voxels x 1024 rays x 8 bounces in 8 s,
 * 33^3 LPV cells x 6 bins x 2 levels x 64 steps in 2 s). */
#define LPV_TICK_COST_IV_RAYS_PER_STEP 4.0

/* The probes trace about as many rays in the time as iv marches (one
 * traversal of the BVH against one march through the voxels); a first
 * figure until the front measures it (techniques/probes/README.md). */
#define LPV_TICK_COST_PROBES_RAYS_PER_STEP 4.0

typedef struct lpv_tick_cost {
    double cell_steps;  /* the bound */
    char terms[224];    /* how it is made, e.g. "grid 64x64x64 x 3 cascades x 6 normal bins x 16 iterations" */
    const char *lower;  /* the CONFIG knobs that lower it, e.g. "grid, iterations, cascades or normal_bins" */
} lpv_tick_cost;


/* The bound for resolved settings s (lpv_settings_resolve); technique auto
 * takes the dearest of the techniques the planner may choose. */
void lpv_tick_cost_estimate(const lpv_settings *s, lpv_tick_cost *out);

#endif /* LPV_TICK_COST_H */
