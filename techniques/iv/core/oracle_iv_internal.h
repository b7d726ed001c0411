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
#include <string.h>

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

/* ---- the surfaces around a voxel (iv_surface.glsl's) ------------------------ */

/* 1 when voxel (x, y, z) is inside the grid and holds a surface. */
static inline int occupied_at(const lpv_grid *g, const lpv_iv_voxel *voxels, int x, int y, int z)
{
    return x >= 0 && y >= 0 && z >= 0 && x < g->dims[0] && y < g->dims[1] && z < g->dims[2] &&
           lpv_iv_occupied(&voxels[lpv_grid_index(g, x, y, z)]);
}

/* c's one occupied face neighbour own (and the unit axis side from it to c),
 * if it has exactly one; else own stays c (the march skips own: left at the
 * last of two neighbours, it let an edge voxel's rays through a wall) and
 * side 0. As iv_surface.glsl's surface_beside. */
static inline int surface_beside(const lpv_grid *g, const lpv_iv_voxel *voxels, const int c[3], int own[3],
                                 float side[3])
{
    int n = 0;
    memcpy(own, c, 3 * sizeof *own);
    side[0] = side[1] = side[2] = 0.0f;
    for (int k = 0; k < 3 && n < 2; k++)
        for (int sgn = -1; sgn <= 1; sgn += 2) {
            int q[3] = {c[0], c[1], c[2]};
            q[k] += sgn;
            if (occupied_at(g, voxels, q[0], q[1], q[2]) && ++n == 1) {
                memcpy(own, q, 3 * sizeof *own);
                side[k] = -(float)sgn;
            }
        }
    if (n != 1) {
        memcpy(own, c, 3 * sizeof *own);
        side[0] = side[1] = side[2] = 0.0f;
    }
    return n == 1;
}

/* Whether empty voxel c (inside the grid) gathers on a surface
 * (LPV_IV_SURFACE_GATHER): its one occupied face neighbour own holds a slab
 * across the axis *k between them; side the unit axis from own to c; *plane
 * where the slab's face towards c lies along *k, in voxels. Else own is c,
 * side 0 and *k -1. As iv_surface.glsl's surface_plane. */
static inline int surface_plane(const lpv_grid *g, const lpv_iv_voxel *voxels, const int c[3], int own[3],
                                float side[3], int *k, float *plane)
{
    *k = -1;
    *plane = 0.0f;
    memcpy(own, c, 3 * sizeof *own);
    side[0] = side[1] = side[2] = 0.0f;
    if (occupied_at(g, voxels, c[0], c[1], c[2]) || !surface_beside(g, voxels, c, own, side))
        return 0;
    const int a = side[0] != 0.0f ? 0 : side[1] != 0.0f ? 1 : 2;
    const float *slab = voxels[lpv_grid_index(g, own[0], own[1], own[2])].slab;
    if (slab[0] != (float)a) {
        memcpy(own, c, 3 * sizeof *own);
        side[0] = side[1] = side[2] = 0.0f;
        return 0;
    }
    *k = a;
    *plane = (float)own[a] + (side[a] > 0.0f ? slab[2] : slab[1]);
    return 1;
}

#endif /* LPV_ORACLE_IV_INTERNAL_H */
