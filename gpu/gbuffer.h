/*
 * gbuffer.h - the camera's G-buffer as an object: its targets, the buffer
 * of the camera's surfels and the translucent layer, allocated for a size,
 * and the scene drawn into them from explicit inputs (the scene on the GPU,
 * the view block, the programs), and its pixels turned into surfels
 * grouped by the cascades given. Knows no engine: pass_camera.c gives it
 * the inputs and shades the frame (frame.h) from it.
 */
#ifndef LPV_GBUFFER_H
#define LPV_GBUFFER_H

#include <stddef.h>

#include "gl.h"
#include "lpv_shared.h"
#include "scene_gpu.h"
#include "surfel_groups.h"
#include "timer.h"

/* The G-buffer's targets (gbuffer.frag): position, normal, albedo,
 * emission, occlusion. */
#define LPV_GBUF_TARGETS 5

/* The camera's G-buffer, its surfels for the geometry volume and the
 * translucent layer: what gbuffer.c allocates and draws and pass_camera.c gives
 * the technique (camera surfels) and the frame (the targets). */
typedef struct lpv_gbuffer {
    int w, h;
    /* the camera's surfels: blocks of camera_surfel_step pixels, surfel_slots surfels each */
    int surfel_w, surfel_h, surfel_slots;
    GLuint tex[LPV_GBUF_TARGETS], depth, fbo, surfels;
    /* The translucent layer (scenes with BLEND draws, LPV_PASS_TRANSLUCENT):
     * the nearest BLEND surface in front of the G-buffer's, in a G-buffer of
     * its own (the same targets, then its coverage: alpha) sharing the
     * G-buffer's depth, shaded into layer_frame_tex and laid over the frame. */
    GLuint layer_tex[LPV_GBUF_TARGETS + 1], layer_fbo, layer_frame_tex;
    int layer_w, layer_h;
    int stale;           /* the G-buffer does not show the current view and scene */
} lpv_gbuffer;

/* Deletes the targets, the surfels and the translucent layer (a partly
 * failed allocation too): the one list of them. */
void lpv_gbuffer_free(lpv_gbuffer *g);

/* (Re)allocates the targets and the camera's surfels for w x h pixels
 * unless they have that size. Returns 0, or -1 with err. */
int lpv_gbuffer_ensure(lpv_gbuffer *g, int w, int h, char *err, size_t err_size);

/* What the G-buffer is drawn with: the scene, the camera's view block
 * (build_view_block) and its image size and projection, the G-buffer
 * programs (full and plain materials), whether the translucent layer is
 * drawn too (scenes with BLEND draws whose plan runs it), the timer whose
 * current stage counts the draws. */
typedef struct lpv_gbuffer_draw {
    const lpv_scene_gpu *geo;
    const struct LpvViewBlock *view;
    int width, height, orthographic;
    GLuint prog, prog_plain;
    int translucent;
    lpv_timer *timer;
} lpv_gbuffer_draw;

/* Draws the opaque draws and the wires into the targets and, when asked,
 * the BLEND draws into the translucent layer (allocated here). Returns 0,
 * or -1 with err (the layer could not be allocated). */
int lpv_gbuffer_draw_scene(lpv_gbuffer *g, const lpv_gbuffer_draw *d, char *err, size_t err_size);

/* What the camera's surfels are made with: camera_surfels.comp, the block
 * side in pixels (lpv_settings_camera_surfel_step), the cascades whose
 * cells and GV points group them (block_groups.h; 0 levels: one group per
 * block), the timer whose current stage counts the dispatch. */
typedef struct lpv_gbuffer_surfels {
    GLuint prog;
    int step;
    const lpv_group_grid *groups;
    int group_levels;
    lpv_timer *timer;
} lpv_gbuffer_surfels;

/* Turns the targets' blocks of d->step pixels into the surfels buffer
 * (surfel_w x surfel_h blocks, surfel_slots each). */
void lpv_gbuffer_extract_surfels(lpv_gbuffer *g, const lpv_gbuffer_surfels *d);

#endif
