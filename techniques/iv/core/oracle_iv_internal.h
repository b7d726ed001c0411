/*
 * oracle_iv_internal.h - the small helpers the imperfect-volumes oracle's
 * files share (oracle_iv_create.c: points to voxels; oracle_iv_reconstruct.c:
 * the lookup; oracle_iv_emit.c: what voxels send out; oracle_iv_gather.c:
 * the march; oracle_iv.c: the whole run). static inline, so every file
 * computes with the same code. Not seen outside techniques/iv/core/:
 * oracle_iv.h is the interface.
 */
#ifndef LPV_ORACLE_IV_INTERNAL_H
#define LPV_ORACLE_IV_INTERNAL_H

#include <math.h>

#include "oracle_iv.h"

/* ---- small helpers --------------------------------------------------------- */

static inline void hemi(const float n[3], float h[4])
{
    h[0] = LPV_IV_HEMI0;
    h[1] = LPV_IV_HEMI1 * n[1];
    h[2] = LPV_IV_HEMI1 * n[2];
    h[3] = LPV_IV_HEMI1 * n[0];
}

static inline float *channel(lpv_cell *c, int ch) { return ch == 0 ? c->r : ch == 1 ? c->g : c->b; }

static inline const float *cchannel(const lpv_cell *c, int ch) { return ch == 0 ? c->r : ch == 1 ? c->g : c->b; }

static inline int finite3(const float *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

/* The centre of voxel v along one axis, in float. */
static inline float centre_of(const lpv_grid *g, int axis, int v)
{
    return g->origin[axis] + ((float)v + 0.5f) * g->cell_size;
}

#endif /* LPV_ORACLE_IV_INTERNAL_H */
