/*
 * reach.h - where the scene's light can go: the connected air spaces of the
 * scene and which of them hold a light (issue 30, docs/propagation.md
 * "Enclosed lights").
 *
 * Every technique carries its light in cells or voxels much larger than a
 * wall is thick, so light put into a closed box, or into one of two rooms
 * that share a wall, spreads through the wall: a lamp in a closed 0.6 m box
 * lit the room outside it at 34 % of the unenclosed lamp's indirect light
 * (lpv; octree 37 %, iv 2.7 %). The path tracer says 0: no path leaves a
 * closed surface. This module finds the closed spaces exactly enough to
 * tell: the scene's opaque triangles are voxelized conservatively (every
 * voxel a triangle touches is solid, techniques/iv/core/iv_voxelize.h's overlap test) on a
 * fine grid of cubic voxels, the air between them is split into its
 * 6-connected components, and a component is lit when a light can put light
 * into it: a point or spot light's voxel, both sides of an emissive
 * triangle, the air outside the scene for a directional light or a light
 * outside the bounds. A conservative voxelization of a closed surface
 * separates 6-connected air, so no component crosses a closed wall.
 *
 * The frame, the queries and the glossy and media passes multiply the
 * technique's irradiance at a surface by lpv_reach_at's answer (reach.glsl
 * on the GPU): 0 where the air in front of the surface is a component no
 * light reaches, else 1. The answer is 1 (nothing is removed) wherever it is
 * unsure: a surface in a gap narrower than the voxels, a light inside a
 * solid voxel with no air around it. Gaps narrower than a voxel close, so
 * light through a crack thinner than the voxel size is taken away; the
 * voxel size is reported with the plan.
 */
#ifndef LPV_REACH_H
#define LPV_REACH_H

#include <stddef.h>
#include <stdint.h>

#include "lpv_shared.h" /* LPV_REACH_SOLID, _DARK, _LIT: a voxel's state in mask and on the GPU */
#include "scene.h"

/* The voxel budget of lpv_reach_build when the caller gives 0, and the most
 * voxels along one axis (GL's 3D textures are at least 2048 on the
 * implementations lpvd runs on; 1024 keeps the texture small). */
#define LPV_REACH_DEFAULT_VOXELS (2u << 20)
#define LPV_REACH_MAX_DIM 1024
/* Voxels of air around the scene's bounds: the air outside the scene is one
 * component however the scene touches its bounds. */
#define LPV_REACH_MARGIN 2

typedef struct lpv_reach {
    int dims[3];
    float origin[3];   /* world position of voxel (0, 0, 0)'s lower corner, m */
    float voxel;       /* side, m */
    uint32_t *label;   /* per voxel (x fastest): 0 solid, else its air component 1..components */
    uint32_t components;
    uint8_t *mask;     /* per voxel: LPV_REACH_SOLID / DARK / LIT (lpv_reach_light) */
    /* Emissive triangles' seeds: each triangle's centroid and front
     * normal, and again with the normal turned round. */
    float *emitter_seeds; /* 6 floats each: point, direction */
    size_t emitter_seed_count;
    /* The scene's mean free path, m: 4 V / S (the mean chord of an
     * enclosure, Kosten's room-acoustics formula) with V the air inside the
     * bounds and S the opaque surfaces' area (both sides of a thin wall
     * count once each side it has): 2.8 m in a 240 m x 3 m tunnel, 2.4 m in
     * a 4 x 3 x 4 m room, tens of m in an open courtyard. The free distance
     * lpvd sizes iv's voxels from in long scenes; 0 without surfaces. */
    float free_path;
    int all_opaque;    /* 1: every material of the scene is opaque, so the voxels hold every surface
                          (cut-out and blended ones are not voxelized but still cast shadows) */
    /* lpv_reach_light's result: */
    int unsure;        /* 1: a light's seed had no air around it; every voxel reads lit */
    size_t solid_voxels, dark_voxels, lit_voxels;
    uint32_t lit_components;
    unsigned char *lit;   /* per component 0..components: lit by the last lpv_reach_light (NULL before) */
    /* The box of the lit air, grown by one voxel so it holds the surfaces
     * around it (world, m), and that air's free path 4 V / S (V its voxels,
     * S the faces between them and solid voxels): where light can go, and
     * how far it runs there, for a volume that need cover no more (the
     * imperfect volume: a lit tunnel under a 240 m hill is 3 m across, not
     * 240 m). lit_box 0 when unsure or nothing is lit. */
    int lit_box;
    float lit_min[3], lit_max[3];
    float lit_free_path;
} lpv_reach;
/* A volume covers the lit box instead of the scene's bounds where the box
 * (within the bounds) holds at most this share of their volume
 * (lpv_engine_lit_region). */
#define LPV_REACH_LIT_BOX_SHARE 0.5

/* Voxelizes the scene's opaque triangles (alpha mode OPAQUE; cut-out and
 * blended surfaces let light through) over its bounds grown by
 * LPV_REACH_MARGIN voxels, with cubic voxels as small as max_voxels (0 =
 * LPV_REACH_DEFAULT_VOXELS) and LPV_REACH_MAX_DIM allow, labels the air's
 * components and records the emitters' seeds. The mask is all lit until
 * lpv_reach_light. Returns 0, or -1 with a message (out of memory, no
 * bounds). r is zeroed first; free it with lpv_reach_free either way. */
int lpv_reach_build(lpv_reach *r, const lpv_scene *scene, size_t max_voxels, char *err, size_t err_size);

/* The mask for these punctual lights and the emitters recorded by build:
 * the components holding a light are lit, the rest of the air dark. A
 * light in a solid voxel (a lamp close under a ceiling) lights the
 * components its air reaches in a closer look at the scene's surfaces
 * around it, LPV_REACH_CLOSER times finer (scene: the one built from; NULL:
 * every air voxel around it; one pass over the scene's triangles for each
 * such light, every call). Returns 1 when the mask changed, 0 when the
 * lights light the same spaces as at the last call (a light moved within
 * its room: the daemon's common LIGHT_SET), so the caller need not send it
 * again. */
#define LPV_REACH_CLOSER 8
int lpv_reach_light(lpv_reach *r, const lpv_scene *scene, const lpv_light *lights, size_t light_count);

/* 1 when light can reach the air in front of a surface at p facing n (unit),
 * 0 when that air is a component no light reaches: the first non-solid voxel
 * at 0.75, 1.5, 2.5 and 3.5 voxels along n decides; when all are solid (a
 * surface in a corner, the steps running along the other surface's voxels)
 * the 27 voxels around 2 voxels along n do: any lit gives 1, else any dark
 * 0. A point outside the grid, no air around or an unsure mask give 1. The
 * GPU's reach.glsl is the same rule. */
float lpv_reach_at(const lpv_reach *r, const float p[3], const float n[3]);

/* 1 when p lies in air a light reaches (and the mask is sure), else 0 (dark
 * air, a solid voxel, or an unsure mask); a point outside the grid lies in
 * the outside air, which the margin's voxels hold. A camera there
 * sees only surfaces that face that air, so its frame need not read the
 * mask per pixel (gpu/reach_volume.c). */
int lpv_reach_lit_at(const lpv_reach *r, const float p[3]);

/* 1 when a solid voxel lies within `within` (m) of p, or when there are no
 * voxels or the voxels are much finer than `within` (more than
 * LPV_REACH_SEARCH_MAX each side: the caller must look at the triangles); 0
 * when the air around p is clear that far. Every opaque surface lies in a
 * solid voxel, so 0 means no opaque surface is that near. */
#define LPV_REACH_SEARCH_MAX 32
int lpv_reach_solid_within(const lpv_reach *r, const float p[3], float within);
/* How wide the space around a point is (m; issue 30, docs/cascades.md
 * "Long scenes and narrow spaces"): the median length of the chords through p along
 * LPV_REACH_VIEW_RAYS stratified directions (lpv_iv_ray's, a fixed seed),
 * each from the first solid voxel behind p to the first ahead, by a 3-D DDA
 * through the voxels; a chord that leaves the grid on either side is open
 * and counts as infinitely long. The local counterpart of the free path (a
 * convex room's mean chord is 4 V / S), whatever the scene's bounds and
 * wherever in the space p stands: 3.4 m in a 3 m x 2.6 m tunnel however
 * long it is or whatever ground lies over it, 4.4 m in panel-room's 4.2 m x
 * 2.8 m x 4.2 m room seen from near a corner. INFINITY where more than half
 * the chords are open (a courtyard under the sky); 0 when it cannot tell
 * (no voxels, p outside the grid or in a solid voxel). */
#define LPV_REACH_VIEW_RAYS 128
float lpv_reach_view_chord(const lpv_reach *r, const float p[3]);

void lpv_reach_free(lpv_reach *r);

#endif /* LPV_REACH_H */
