/*
 * iv_points.h - the point cloud of imperfect volumes (Mavridis &
 * Papaioannou, section 3.1; docs/imperfect-volumes.md): for every triangle,
 * N points uniform over its area by Turk's formula
 *   v = (1 - sqrt(r1)) v1 + (1 - r2) sqrt(r1) v2 + r2 sqrt(r1) v3,
 * each with the triangle's interpolated normal, its material's albedo and
 * emission. Triangles with an edge longer than `split` voxels are first cut
 * in halves across their longest edge (the paper's advice: "tessellate big
 * triangles at load time"), so N points per piece cover a voxel-sized piece.
 *
 * Made on the CPU when the geometry or these knobs change, not per tick: the
 * engine keeps the geometry and re-samples it then (the planner's SAMPLES
 * rule), and the GPU lights the points every tick. The paper's geometry
 * shader generated them per frame; docs/imperfect-volumes.md says why lpvd
 * does not.
 */
#ifndef LPV_IV_POINTS_H
#define LPV_IV_POINTS_H

#include <stddef.h>
#include <stdint.h>

#include "grid.h"
#include "lpv_shared.h"
#include "scene.h"
#include "settings.h"

typedef struct lpv_iv_point_params {
    float voxel;       /* m, the volume's voxel side */
    int points;        /* per triangle (per piece after splitting), >= 1 */
    float split;       /* voxels; > 0 */
    uint32_t seed;
    size_t max_points; /* the budget: fewer points per piece, then coarser splitting, to stay under it */
    int emission;      /* 1: points carry their material's emission; 0: none (area lights carry it) */
    /* Where the volume lies (m), when has_box: pieces wholly outside it get
     * no points and cost none of the budget (a tunnel under a 240 m hill:
     * the hill's faces took the budget down to one point a piece). */
    int has_box;
    float box_min[3], box_max[3];
} lpv_iv_point_params;

typedef struct lpv_iv_point_stats {
    size_t triangles;  /* non-degenerate triangles sampled */
    size_t pieces;     /* after splitting */
    int points_per_piece; /* after the budget */
    float split;       /* voxels, after the budget */
    size_t points;     /* written */
    int budget_cut;    /* 1: the budget lowered points_per_piece or raised split */
} lpv_iv_point_stats;

/* The imperfect volume's voxels for settings s over a scene's bounds
 * [smin, smax] (the settings' bounds when given): lpv_grid_place_cubic at
 * s->iv.resolution voxels along the longest side, or more in a scene whose
 * longest side is more than LPV_IV_LONG_FREE_PATHS free paths long (a
 * tunnel, a corridor: 86 in the 240 m tunnel; rooms and courtyards are 2 to
 * 5, and keep the setting): voxels of
 * free_path / LPV_IV_FREE_PATH_VOXELS (free_path > 0: the scene's mean free
 * path, core/reach.h), as many as keep the grid within the (resolution +
 * 1)^3 voxels of a cube at the setting (the budget core/tick_cost.c
 * counts). The engine's cloud and the technique's volume both place it
 * here. Returns 0 or -1 (lpv_grid_place_cubic's). */
#define LPV_IV_FREE_PATH_VOXELS 4.0
#define LPV_IV_LONG_FREE_PATHS 8.0
int lpv_iv_place(const lpv_settings *s, const float smin[3], const float smax[3], float free_path, lpv_grid *out);

/* The cloud's parameters under settings s for the volume g it is made for:
 * its voxel side and its box (has_box set); emission always carried (the
 * GPU drops it while area lights carry the emitters). */
lpv_iv_point_params lpv_iv_point_params_of(const lpv_settings *s, const lpv_grid *g);

/* The cloud for `scene` under p. *out is malloc'ed (free() it), *count its
 * points. Returns 0, or -1 out of memory (*out NULL, *count 0). Deterministic
 * for a fixed seed: point k of piece i draws r1, r2 from lpv_hash_u32 of the
 * seed, i and k. */
int lpv_iv_points_make(const lpv_scene *scene, const lpv_iv_point_params *p, struct IvPoint **out, size_t *count,
                       lpv_iv_point_stats *stats);

/* The splitting lpv_iv_points_make does to each triangle (a, b, c): cut in
 * halves across the longest edge until every edge is <= limit (m; at most
 * 40 cuts deep). fn (may be NULL) gets each piece's corners in (a, b, c)'s
 * barycentric coordinates, in the order lpv_iv_points_make numbers the
 * pieces (piece i of the scene keys its points with i). Returns the number
 * of pieces. */
typedef void (*lpv_iv_piece_fn)(const double bary[3][3], void *user);
size_t lpv_iv_split_triangle(const float a[3], const float b[3], const float c[3], double limit, lpv_iv_piece_fn fn,
                             void *user);
/* The same, keeping only the pieces that reach into [box_min, box_max] (m;
 * both NULL: every piece): a piece wholly outside is dropped before it is
 * cut further. */
size_t lpv_iv_split_triangle_in(const float a[3], const float b[3], const float c[3], double limit,
                                const float box_min[3], const float box_max[3], lpv_iv_piece_fn fn, void *user);

/* One triangle's points (no splitting), for the voxelization report and the
 * tests: n points on (a, b, c) from `key`, Turk's formula. Writes 3 floats each. */
void lpv_iv_triangle_points(const float a[3], const float b[3], const float c[3], int n, uint32_t seed, uint32_t key,
                            float *out);

#endif /* LPV_IV_POINTS_H */
