/*
 * shadow_maps.h - the shadow maps of direct light (docs/shadows.md), an
 * object of their own: the engine hands them the faces to draw
 * (lpv_shadow_faces_build), the scene on the GPU, the lights and the
 * programs, and the frame binds what they hold (lpv_shadow_maps_bind). They
 * know nothing else of the engine; the engine checks its memory budget
 * before they allocate.
 */
#ifndef LPV_SHADOW_MAPS_H
#define LPV_SHADOW_MAPS_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "gl.h"
#include "lpv_shared.h"
#include "scene_gpu.h"
#include "timer.h"

typedef struct lpv_shadow_maps {
    struct LpvShadowBlock block; /* the faces the maps hold */
    GLuint ubo, tex, fbo;        /* the block's buffer; the DEPTH32F array and its framebuffer */
    /* the maps' transmission (scenes with BLEND draws,
     * LPV_TEX_SHADOW_TRANSMIT): an RGBA16F array like tex, drawn through
     * transmit_fbo over tex's depth */
    GLuint transmit_tex, transmit_fbo;
    int alloc_size, alloc_faces;
    int valid;                   /* 0: the maps must be redrawn (scene, settings, invalidate) */
} lpv_shadow_maps;

/* What a redraw draws with: the scene, the lights the faces belong to (a
 * spot's cone and an area light sample's half-space bound what a face
 * needs), the shadow programs (full and plain materials), the timer whose
 * "shadow" stage it records. */
typedef struct lpv_shadow_draw {
    const lpv_scene_gpu *geo;
    const struct LpvLightGpu *lights;
    GLuint prog, prog_plain;
    lpv_timer *timer;
} lpv_shadow_draw;

/* A spot's outer cone half angle (rad) from its GPU record (cos stored in
 * cone_faces[1]): what its shadow faces cover and what it lights. */
static inline float lpv_spot_outer_angle(const struct LpvLightGpu *g)
{
    return acosf(fminf(fmaxf(g->cone_faces[1], -1.0f), 1.0f));
}

/* The faces' buffer made, no maps yet; destroy frees everything. */
void lpv_shadow_maps_create(lpv_shadow_maps *sm);
void lpv_shadow_maps_destroy(lpv_shadow_maps *sm);

/* Whether the maps as allocated hold `layers` layers of size^2 texels, with
 * transmission maps when translucent. */
int lpv_shadow_maps_fit(const lpv_shadow_maps *sm, int size, int layers, int translucent);
/* (Re)allocates them; bytes, what they take (lpv_memory_shadow_bytes), only
 * names the size in the error. Returns 0, or -1 with err. */
int lpv_shadow_maps_allocate(lpv_shadow_maps *sm, int size, int layers, int translucent, uint64_t bytes, char *err,
                             size_t err_size);

/* Draws the faces of block b, unless the maps already hold exactly them. */
void lpv_shadow_maps_draw(lpv_shadow_maps *sm, const struct LpvShadowBlock *b, const lpv_shadow_draw *d);

/* Binds the maps, their transmission and the faces' block for the frame
 * (shadow.glsl). */
void lpv_shadow_maps_bind(const lpv_shadow_maps *sm);

#endif
