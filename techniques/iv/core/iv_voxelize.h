/*
 * iv_voxelize.h - how imperfect the imperfect volume is (Mavridis &
 * Papaioannou 3.1: "there is no guarantee that every voxel containing a
 * triangle will receive a random point"). A conservative voxelization of a
 * triangle, by the separating axis theorem (Akenine-Moller, "Fast 3D
 * triangle-box overlap testing", 2001), is the set of voxels the triangle
 * touches; the point cloud (techniques/iv/core/iv_points.h) marks only the voxels its
 * points land in. The miss fraction is the share of the first that the
 * second lacks. bench/iv_voxelize.c tabulates it over N and triangle size.
 */
#ifndef LPV_IV_VOXELIZE_H
#define LPV_IV_VOXELIZE_H

#include <stddef.h>
#include <stdint.h>

#include "grid.h"

/* Voxels are grown by this many voxels on every side before the overlap
 * test, so a point whose float voxel lookup rounds across a face (about
 * 1e-5 voxels at 64 voxels from the origin) still lands in the set; it adds
 * the voxels a triangle passes within 1e-4 voxels of, which no test or
 * table can tell from the triangle touching them. */
#define LPV_IV_VOXELIZE_EPS 1e-4

/* 1 when triangle tri overlaps the closed box centre +- half (touching
 * counts), by the 13 separating axes: the box's 3 face normals, the
 * triangle's normal and the 9 cross products of the triangle's edges with
 * the box's; 0 when one of them separates. Double throughout; a degenerate
 * triangle (a segment or a point) is handled by the same axes. */
int lpv_iv_tri_box_overlap(const double centre[3], const double half[3], const double tri[3][3]);

/* The conservative voxelization of triangle (a, b, c) in g: every voxel
 * whose box, grown by LPV_IV_VOXELIZE_EPS voxels, the triangle overlaps,
 * in increasing lpv_grid_index order. Writes at most max indices to out
 * (NULL with max 0 only counts) and returns how many there are. A
 * non-finite vertex gives 0. */
size_t lpv_iv_voxelize_triangle(const lpv_grid *g, const float a[3], const float b[3], const float c[3], size_t *out,
                                size_t max);

typedef struct lpv_iv_coverage {
    size_t conservative; /* voxels in the conservative set */
    size_t hit;          /* of those, voxels at least one point landed in */
    size_t points;       /* points made */
    size_t stray;        /* points outside the grid or outside the set (0 unless something is wrong) */
    size_t pieces;       /* pieces sampled (1 without splitting) */
} lpv_iv_coverage;

/* How many voxels of a triangle's conservative set (set, count: as
 * lpv_iv_voxelize_triangle gives it) its points reach. The points are those
 * lpv_iv_points_make would make: the triangle is split with
 * lpv_iv_split_triangle(a, b, c, split * cell_size) (split <= 0: not at
 * all, one piece), and piece i gets lpv_iv_triangle_points(corners, n, seed,
 * key + i). A point's voxel is floor((p - origin) / s) in float, as
 * lpv_iv_create finds it. Returns 0, or -1 out of memory or n < 1 (out
 * zeroed but for conservative). */
int lpv_iv_coverage_of_set(const lpv_grid *g, const size_t *set, size_t count, const float a[3], const float b[3],
                           const float c[3], int n, float split, uint32_t seed, uint32_t key, lpv_iv_coverage *out);

/* Both: the set (lpv_iv_voxelize_triangle) and its coverage. Returns 0 or
 * -1 as lpv_iv_coverage_of_set. */
int lpv_iv_triangle_coverage(const lpv_grid *g, const float a[3], const float b[3], const float c[3], int n,
                             float split, uint32_t seed, uint32_t key, lpv_iv_coverage *out);

#endif /* LPV_IV_VOXELIZE_H */
