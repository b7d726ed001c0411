/*
 * surfel_groups.h - surfels grouped by the geometry-volume points they snap
 * to, on the CPU: the scene surfels (scene_surfels.h: 65 536 by default, a
 * point each to splat in every cascade) become one surfel per set of GV
 * points (one per cascade), normal bin (so the two faces of a thin wall,
 * whose normals would cancel, stay apart) and object size, carrying the group's total area
 * at its area-weighted centroid with its area-weighted mean normal (length
 * <= 1, lpv_mean_direction) and albedo. The GV every point receives is the
 * one the surfels gave it one by one (exactly on a plane): the GPU's
 * block grouping (shaders/block_groups.glsl) for a list without order.
 */
#ifndef LPV_SURFEL_GROUPS_H
#define LPV_SURFEL_GROUPS_H

#include <stddef.h>

#include "oracle.h"

/* One cascade as the shaders place it: lower corner in its cells, cell (m). */
typedef struct lpv_group_grid {
    float origin_cells[3];
    float cell_size;
    int vpl_spread; /* VPLs key on the 2 x 2 stencil they are spread over (lpv_volume_desc.vpl_spread) */
} lpv_group_grid;

/* Groups n surfels by the GV point each snaps to in each of `levels` grids
 * (floor(x / cell - origin_cells + 0.5), as inject_gv.vert computes it), by
 * normal bin (lpv_oracle_normal_bin) and by object size (normal[3]);
 * surfels with no area or no direction are left out. Writes at most n groups
 * to out (which may not alias in), ordered by their key (deterministic), and
 * returns their count, or 0 when memory runs out. */
size_t lpv_surfels_group(const lpv_surfel *in, size_t n, const lpv_group_grid *grids, int levels, lpv_surfel *out);

#endif
