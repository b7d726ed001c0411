/*
 * rsm_maps.h - the lights' reflective shadow maps as an object: their
 * textures and the VPL and surfel buffers made from them, allocated for a
 * size and a layer count, and the light views drawn into them from explicit
 * inputs (the faces, the scene on the GPU, the light block's buffer, the
 * programs), and their texels turned into VPLs and surfels grouped by the
 * cascades given. Knows no engine: pass_rsm.c lays out the faces, checks
 * the memory budget before they allocate and chooses each layer's step.
 */
#ifndef LPV_RSM_MAPS_H
#define LPV_RSM_MAPS_H

#include <stddef.h>
#include <stdint.h>

#include "gl.h"
#include "lpv_shared.h"
#include "scene_gpu.h"
#include "surfel_groups.h"
#include "timer.h"

/* The lights' reflective shadow maps and what pass_rsm.c makes of them:
 * the VPLs the technique injects and the surfels of the geometry volume
 * (lpv_technique_inputs takes them). Faces are laid out by light_faces.c. */
typedef struct lpv_rsms {
    int size, face_count, alloc_size, alloc_faces;
    int punctual_faces;   /* faces (= layers) of the punctual lights; area faces follow */
    int layers;           /* layers in use: punctual faces + those the area faces' tiles fill */
    int area_face_side;   /* texels of an area light face's tile */
    GLuint position, normal, flux, albedo, depth, fbo;
    GLuint vpls, surfels; /* blocks of RSM texels, lpv_block_slots each (vpl_blocks.comp; vpl_extract.comp at step 1) */
    /* the VPLs that carry light, in order, and their draw command (compact.h):
     * the injection draws only them */
    GLuint vpls_live, vpls_draw;
    /* VPLs (and surfels) per layer, blocks^2 x slots: the punctual lights',
     * the area lights' layers whose surfels the GV takes
     * (lpv_engine_area_gv_layers), the other area layers' (pass_rsm.c) */
    size_t per_layer[3];
    size_t vpl_count; /* the three kinds of layers x their per_layer */
} lpv_rsms;

/* Deletes the textures and buffers (a partly failed allocation too): the one
 * list of them. */
void lpv_rsms_free(lpv_rsms *r);

/* Whether they are allocated for layers of size^2 texels. */
int lpv_rsms_fit(const lpv_rsms *r, int size, int layers);
/* (Re)allocates them: the four targets and depth, `layers` deep, and the
 * VPL, surfel, live-VPL and draw buffers for the most VPLs any step makes.
 * bytes (lpv_memory_rsm_bytes) only names the size in the error. Returns 0,
 * or -1 with err. */
int lpv_rsms_allocate(lpv_rsms *r, int size, int layers, uint64_t bytes, char *err, size_t err_size);

/* What the light views are drawn with: the scene, the light block's faces
 * (faces[0 .. r->face_count): a face's view-projection and its tile) and the
 * buffer shaders read it from, the RSM programs (full and plain materials),
 * the timer whose "rsm" stage it records. */
typedef struct lpv_rsm_draw {
    const lpv_scene_gpu *geo;
    const struct LpvLightBlock *lights;
    GLuint light_ubo;
    GLuint prog, prog_plain;
    lpv_timer *timer;
} lpv_rsm_draw;

/* Draws every face into its layer (or tile): position, normal, flux and
 * albedo, cleared once per layer. */
void lpv_rsms_draw(lpv_rsms *r, const lpv_rsm_draw *d);

/* What the VPLs and surfels of layers [first, first + count) are made
 * with: blocks of step x step texels (the step divides the faces' side;
 * lpv_block_slots samples each), written from element `base` on, by prog
 * (vpl_extract.comp at step 1, a vpl_blocks.comp variant above), grouped by
 * the cells (VPLs) and GV points (surfels) of `group_levels` cascades
 * (block_groups.h), the timer's current stage counting the dispatch. */
typedef struct lpv_rsm_extract {
    int first, count, step;
    size_t base;
    GLuint prog;
    const lpv_group_grid *groups;
    int group_levels;
    lpv_timer *timer;
} lpv_rsm_extract;

/* Makes those VPLs and surfels (nothing when count is 0). Returns the
 * elements per layer: blocks^2 x slots. */
size_t lpv_rsms_extract(lpv_rsms *r, const lpv_rsm_extract *d);

#endif
