/*
 * oracle_octree.h - the plain-C reference of octree light propagation
 * volumes (Olovsson's thesis, seed 003, sections 4.2, 5.2 and 6.2;
 * docs/octree.md). It plays for a GPU octree technique the role techniques/lpv/core/oracle.h
 * plays for the cascaded LPV: literal loops the shaders can be checked
 * against. Every LPV operation (injection, GV, transmittance, one
 * propagation step, flux) is the cascaded oracle's own; this file adds only
 * the octree: the levels, the downsampling (eq. 11), the index volume, the
 * merge (eq. 10) and the thesis' error metric.
 *
 * The pipeline, in order:
 *   lpv_octree_create     levels and index volume, I_i = l - 1 everywhere
 *   lpv_octree_inject_vpls    into level 0; I_0 = 0 where O_0 != 0
 *   lpv_octree_add_surfels    (occlusion only) each level's GV, one buffer
 *   lpv_octree_downsample     O_i = mean of 8 children of O_{i-1}; I_i = i
 *   lpv_octree_propagate      k steps on every level (or _begin + _step)
 *   lpv_octree_merge          M(x) = S(x) into one n^3 volume
 * or lpv_octree_run for all of it. lpv_octree_measure gives e_abs, e_rel.
 */
#ifndef LPV_ORACLE_OCTREE_H
#define LPV_ORACLE_OCTREE_H

#include <stddef.h>
#include <stdint.h>

#include "grid.h"
#include "oracle.h"

/* log2(LPV_MAX_GRID_DIM) + 1: the levels of the largest octree. */
#define LPV_OCTREE_MAX_LEVELS 9

/* One level i: a standalone LPV of (n / 2^i)^3 cells of side cell_size * 2^i
 * over the level-0 grid's origin (so it covers the same box). Arrays are in
 * lpv_grid_index order (x fastest). */
typedef struct lpv_octree_level {
    lpv_grid grid;
    lpv_cell *src;    /* O_i after injection (i = 0) or downsampling (i > 0):
                         the propagation's source, kept as it was */
    lpv_cell *cur;    /* the light in flight: the last step's output (src
                         after lpv_octree_propagate_begin) */
    lpv_cell *acc;    /* the accumulated O_i: src + every step's output */
    uint8_t *index;   /* I_i, one per cell, in 0..l-1 */
    lpv_gv_point *gv; /* occlusion only: the level's GV total, lpv_grid_gv_count points */
    float *t;         /* occlusion only: the level's transmittances, 6 per cell */
} lpv_octree_level;

/* Zero-initialise, then lpv_octree_create; lpv_octree_free zeroes it again. */
typedef struct lpv_octree {
    int n;         /* cells per axis of level 0, a power of two */
    int levels;    /* l = log2(n) + 1 */
    int occlusion; /* 1: levels have gv and t */
    int steps;     /* propagation steps taken since lpv_octree_propagate_begin */
    lpv_octree_level level[LPV_OCTREE_MAX_LEVELS];
    lpv_cell *scratch; /* one step's output, sized for level 0 */
} lpv_octree;

/* Allocates the octree over g, which must have dims n x n x n with n a power
 * of two in 1..LPV_MAX_GRID_DIM, a finite origin and a finite cell size > 0.
 * Everything starts at zero and I_i = l - 1 (thesis 4.2). Returns 0, or -1
 * with a message in err (o is left zeroed). */
int lpv_octree_create(const lpv_grid *g, int occlusion, lpv_octree *o, char *err, size_t err_size);
void lpv_octree_free(lpv_octree *o);

/* Back to the state lpv_octree_create leaves (the thesis' clear step). */
void lpv_octree_clear(lpv_octree *o);

/* lpv_oracle_inject_vpls into level 0's src, then I_0 = 0 at every cell of
 * O_0 that is non-zero (any of its 12 coefficients). Returns the number of
 * VPLs injected. Call before lpv_octree_downsample. */
size_t lpv_octree_inject_vpls(lpv_octree *o, const lpv_vpl *vpls, size_t n);

/* Occlusion only (no-op otherwise): one GV buffer of surfels, injected into
 * every level at that level's resolution (lpv_oracle_inject_surfels on the
 * level's grid, so a surfel blocks area / (cell_size * 2^i)^2 of a level-i
 * face) and merged into the level's total with lpv_oracle_gv_merge
 * (docs/octree.md says why this and not eq. 11 for the GV). Returns 0, or
 * -1 on allocation failure; *injected (if not NULL) gets the number of
 * surfels level 0 took. */
int lpv_octree_add_surfels(lpv_octree *o, const lpv_surfel *surfels, size_t n, size_t *injected);

/* Eq. 11: for i = 1..l-1, src_i(x) = the mean of the 8 cells
 * src_{i-1}([2x, 2x+1], [2y, 2y+1], [2z, 2z+1]) (summed in double, children
 * in lpv_grid_index order, / 8, rounded to float once), and I_i(x) = i where
 * the result is non-zero. */
void lpv_octree_downsample(lpv_octree *o);

/* Propagation with propagation factor p = 1 (the thesis' O_i = p P; p = 3 in
 * its real-time build is a gain, left to the caller, as indirect_gain is for
 * the cascaded LPV). _begin computes the transmittances (occlusion) and sets
 * acc = cur = src on every level. Each _step does one iteration on every
 * level as its own LPV: lpv_oracle_propagate_step_with with the level's
 * transmittances (none on the first step, as lpv_oracle_propagate_with),
 * acc += the output, and I_i = i wherever the output is non-zero. transport
 * is LPV_TRANSPORT_PAPER or LPV_TRANSPORT_CENTRAL. _propagate is _begin and
 * iterations steps. */
void lpv_octree_propagate_begin(lpv_octree *o);
void lpv_octree_propagate_step(lpv_octree *o, int transport);
void lpv_octree_propagate(lpv_octree *o, int iterations, int transport);

/* I(x, y, z) = min_i I_i(x / 2^i, y / 2^i, z / 2^i), x, y, z in 0..n-1. */
int lpv_octree_index(const lpv_octree *o, int x, int y, int z);

/* Eq. 10 and the merge step: merged (n^3 cells, level 0's layout) gets
 * M(x) = acc_{I(x)}(x / 2^I(x)). Read it with lpv_oracle_irradiance on
 * level 0's grid. Valid after lpv_octree_propagate (iterations >= 0). */
void lpv_octree_merge(const lpv_octree *o, lpv_cell *merged);

/* The thesis' correctness metric (6.2) on the accumulated levels: for every
 * element p of O_i, i = 1..l-1, d(p) = ||O_i(p) - Ô_i(p)||_inf over the 12
 * values, Ô_i the eq. 11 mean of acc_{i-1}'s 8 children (computed exactly as
 * lpv_octree_downsample does, so it is 0 right after downsampling). */
typedef struct lpv_octree_error {
    double e_abs;         /* 7 / (8^l - 8) * sum of d(p)            (the thesis' formula) */
    double e_rel;         /* 7 / (8^l - 8) * sum of d(p) / ||O_i(p)||_inf */
    double mean_abs;      /* sum of d(p) / elements: the per-element mean; the thesis'
                             factor is 1 / (8 elements) (docs/octree.md) */
    double mean_rel;      /* sum of relative terms / elements */
    size_t elements;      /* elements of O_1..O_{l-1}: (8^(l-1) - 1) / 7 */
    size_t rel_undefined; /* elements with ||O_i(p)||_inf = 0 but d(p) > 0: their
                             relative term is undefined and counts as 0 (an element
                             with both 0 has no error and counts 0 too) */
} lpv_octree_error;
void lpv_octree_measure(const lpv_octree *o, lpv_octree_error *out);

/* The whole pipeline. */
typedef struct lpv_octree_desc {
    lpv_grid grid;                 /* level 0: n x n x n, n a power of two */
    const lpv_vpl *vpls;
    size_t vpl_count;
    const lpv_surfel *surfels;     /* NULL: no occlusion; else one GV buffer (may be empty) */
    size_t surfel_count;
    int iterations;                /* k, 0..LPV_MAX_ITERATIONS */
    int transport;                 /* LPV_TRANSPORT_PAPER (0) or LPV_TRANSPORT_CENTRAL */
} lpv_octree_desc;

/* Creates o (zeroed on entry) from desc, injects, adds the surfels,
 * downsamples, propagates desc->iterations steps and, if merged is not
 * NULL, merges into it (n^3 cells). Returns 0, or -1 with a message in err
 * and o zeroed. The caller frees o with lpv_octree_free. */
int lpv_octree_run(const lpv_octree_desc *desc, lpv_octree *o, lpv_cell *merged, char *err, size_t err_size);

#endif /* LPV_ORACLE_OCTREE_H */
