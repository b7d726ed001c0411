/*
 * cascades.h - placement of the cascaded light propagation volumes
 * (cascaded-LPV paper section 4; docs/cascades.md).
 *
 * One cascade is the classic single grid over the scene (or the settings'
 * bounds): lpv_grid_place. Several cascades share the settings' grid_dims;
 * cascade k's cells measure finest / max(dims) * cascade_ratio^k, with finest
 * = lpv_cascade_finest_size (cascade_size, or a quarter of the scene's longest
 * side when it is 0). Each is centred ahead of the camera, at
 * anchor + forward * cascade_offset * extent_k, where the anchor is the eye
 * (inside the scene's bounds), the point where the view ray enters the bounds
 * (outside), else the point of the bounds nearest the eye (the scene's centre
 * without a camera); the centre is then kept over the scene (the scene's
 * centre along an axis the cascade spans, else at most half the cascade's
 * extent inside the bounds), and snapped: its lower
 * corner sits on a whole multiple of its own cell size,
 *   origin_cells = floor(centre / cell) - floor(dims / 2),
 * so a camera moving by less than a cell leaves a cascade where it is (unless
 * the centre crosses a cell boundary) and moving by one cell shifts it by
 * exactly one cell.
 */
#ifndef LPV_CASCADES_H
#define LPV_CASCADES_H

#include "grid.h"
#include "settings.h"

typedef struct lpv_cascade_set {
    int count;
    lpv_grid grid[4];             /* LPV_MAX_CASCADES; cascade 0 the finest */
    float origin_cells[4][3];     /* each grid's origin / cell_size; whole numbers when snapped */
    int snapped;                  /* 1: camera-following, snapped cascades; 0: one grid over bounds */
    int handoff;                  /* 1: far field (settings.lpv.far_field on): cascade k + 1 carries on the
                                     light of cascade k; every cascade's cells are unions of 2^3 of
                                     the next finer one's */
} lpv_cascade_set;

/* Places `count` (1..LPV_MAX_CASCADES) cascades for resolved settings s over
 * the scene bounds [bmin, bmax]; eye and forward (unit) may be NULL (no
 * camera); view_chord as lpv_cascade_finest_size's. Returns 0, or -1 when a grid cannot be placed (non-finite input,
 * dims out of range).
 *
 * Far field (s->lpv.far_field on, L = s->lpv.far_field_levels): one grid over the bounds gets L coarser
 * levels around it, level k with cells 2^k times the grid's and the same
 * dims, its origin (o_{k-1} - floor(dims / 2)) / 2 in its own cells so its
 * cells are unions of 2^3 cells of level k - 1 (at most LPV_MAX_CASCADES in
 * all); camera-following cascades hand off when their ratio is 2. */
int lpv_cascades_place(const lpv_settings *s, int count, const float bmin[3], const float bmax[3], const float *eye,
                       const float *forward, float view_chord, lpv_cascade_set *out);

/* A snapped cascade's origin is a whole number of its cells held in a float:
 * exact up to 2^24, and 1e7 leaves room for the grid's own cells. */
#define LPV_CASCADE_MAX_ORIGIN_CELLS 1e7

/* 1 when snapped cascades of settings s (more than one; their finest cell:
 * lpv_cascade_finest_size(s, bmin, bmax, view_chord) / the longest grid side) can be placed wherever
 * the camera stands over the scene bounds [bmin, bmax]: the finest cascade's
 * origin, counted in its cells, stays within LPV_CASCADE_MAX_ORIGIN_CELLS.
 * Else 0, with the reason in why: the cell size, how far from the origin
 * the scene reaches, and the smallest cascade_size that fits. */
int lpv_cascades_fit(const lpv_settings *s, const float bmin[3], const float bmax[3], float view_chord, char *why,
                     size_t n);

/* The grid block the shaders read (lpv_shared.h's LpvGridParams, grid.glsl)
 * for the cascades `set`: dims, cell count, cascade count (info.x) and each
 * cascade's origin in cells and cell size; the rest zero, the technique's
 * own to fill. */
struct LpvGridParams;
void lpv_cascades_grid_params(const lpv_cascade_set *set, struct LpvGridParams *out);

/* How many grids lpv_cascades_place(s, count, ...) places: count, or for one
 * grid over the bounds with the far field on 1 + far_field_levels (at most
 * LPV_MAX_CASCADES). */
int lpv_cascades_count(const lpv_settings *s, int count);

/* The finest cascade's extent (m): cascade_size, or with cascade_size 0
 * (auto) LPV_CASCADE_AUTO_FRACTION x the longest side of [bmin, bmax]
 * (1 when that is empty), made smaller where the space around the camera
 * is: view_chord (m, lpv_reach_view_chord at the eye; 0 = not measured,
 * INFINITY = open) gives cells of about LPV_VIEW_ACROSS x it, the
 * quarter divided by the nearest whole power of sqrt(2) (never more than
 * the quarter). Not measured, a long scene (lpv_cascade_cross_section) gets
 * the grid's longest axis x LPV_CASCADE_LONG_CELL x its cross-section
 * from its bounds (docs/cascades.md, "Long scenes and narrow spaces"). */
float lpv_cascade_finest_size(const lpv_settings *s, const float bmin[3], const float bmax[3], float view_chord);

/* A long scene's cross-section (m): the second-longest side of [bmin, bmax]
 * when the longest is at least LPV_CASCADE_LONG_RATIO x it (a tunnel, a
 * corridor, a street), else 0. */
float lpv_cascade_cross_section(const float bmin[3], const float bmax[3]);

/* 1 when p lies in the box [bmin, bmax] (faces included). */
int lpv_point_in_bounds(const float p[3], const float bmin[3], const float bmax[3]);

/* 1 when both sets place the same grids (count, dims, origins, cell sizes). */
int lpv_cascades_equal(const lpv_cascade_set *a, const lpv_cascade_set *b);

#endif /* LPV_CASCADES_H */
