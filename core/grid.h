/*
 * grid.h - placement of a light propagation volume in the world.
 *
 * Cells are cubes of side cell_size. A grid over bounds [min, max] with dims
 * cells per axis uses cell_size = max_i (max_i - min_i) / max(dims_i - 1, 1),
 * so every axis keeps at least half a cell of margin on each side, and is
 * centred on the bounds. Degenerate (zero or non-finite) extents give
 * cell_size 1. Cell (i, j, k) spans origin + [i, i+1) * cell_size, its centre
 * is at origin + (i + 0.5) * cell_size. The geometry volume (GV) has
 * dims + 1 points per axis, point (i, j, k) at origin + (i, j, k) * cell_size:
 * on the LPV's cell corners (the paper's half-cell shift).
 */
#ifndef LPV_GRID_H
#define LPV_GRID_H

#include <stddef.h>

typedef struct lpv_grid {
    int dims[3];
    float origin[3];  /* world position of the lower corner, m */
    float cell_size;  /* m */
} lpv_grid;

/* Cell sizes a grid may have (m): the oracle divides by cell_size^2, which must
 * stay a normal, finite float. A grid over bounds whose cells would fall
 * outside (a scene collapsed to a point) gets cells of 1 m instead; bounds a
 * user gives are refused instead (lpv_settings_validate). */
#define LPV_MIN_CELL_SIZE 1e-18
#define LPV_MAX_CELL_SIZE 1e18

/* The cell size lpv_grid_place gives dims cells over [bmin, bmax] before that
 * fallback: the longest extent_i / max(dims_i - 1, 1), so every axis keeps at
 * least half a cell of margin on each side. In double, so that huge finite
 * bounds do not overflow before the division. */
double lpv_grid_cell_size_over(const int dims[3], const float bmin[3], const float bmax[3]);

/* Places a grid of dims cells over [bmin, bmax]. Returns 0, or -1 when a bound
 * is not finite or when a
 * dimension is outside 1..LPV_MAX_GRID_DIM. */
int lpv_grid_place(const int dims[3], const float bmin[3], const float bmax[3], lpv_grid *out);

/* The box [bmin, bmax]'s sides (m), shortest first: sides[1] is its middle
 * axis (a tunnel's cross-section), sides[2] its longest. */
void lpv_box_sides(const float bmin[3], const float bmax[3], float sides[3]);

/* Places cubic voxels over [bmin, bmax] for the imperfect volume:
 * `resolution` voxels of side longest / resolution span the longest side,
 * the other axes as many as they need; one more voxel per axis puts the
 * bounds on voxel centres, so a surface on the bounds (a room's wall) lies
 * inside a voxel rather than on a face. Axes are capped at LPV_MAX_GRID_DIM. Returns 0, or -1
 * when a bound is not finite or resolution < 1. */
int lpv_grid_place_cubic(int resolution, const float bmin[3], const float bmax[3], lpv_grid *out);

size_t lpv_grid_cell_count(const lpv_grid *g);
size_t lpv_grid_gv_count(const lpv_grid *g); /* (dims+1) product */

static inline size_t lpv_grid_index(const lpv_grid *g, int x, int y, int z)
{
    return (size_t)x + (size_t)g->dims[0] * ((size_t)y + (size_t)g->dims[1] * (size_t)z);
}

static inline size_t lpv_grid_gv_index(const lpv_grid *g, int x, int y, int z)
{
    return (size_t)x + (size_t)(g->dims[0] + 1) * ((size_t)y + (size_t)(g->dims[1] + 1) * (size_t)z);
}

/* Cell containing p (floor). Returns 1 if inside the grid, 0 otherwise
 * (including non-finite p). */
int lpv_grid_cell_of(const lpv_grid *g, const float p[3], int cell[3]);

/* Nearest GV point to p (round). Returns 1 if inside 0..dims, 0 otherwise. */
int lpv_grid_gv_point_of(const lpv_grid *g, const float p[3], int point[3]);

#endif /* LPV_GRID_H */
