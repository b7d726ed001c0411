/*
 * frame.h - the shaded frame as an object: its linear-radiance target, the
 * lists of pixels left to second passes and the textures of the passes per
 * block of pixels (the lookup step's, the area shadow step's), allocated
 * for a size, and a G-buffer shaded into it from explicit inputs: the
 * G-buffer's targets, the programs of the variant the engine chose, the
 * technique's lookup as a binding call, the shadow maps, the light and
 * view blocks' buffers. Knows no engine: pass_camera.c chooses the variant
 * and the passes from the settings, the plan, the lights and the technique.
 */
#ifndef LPV_FRAME_H
#define LPV_FRAME_H

#include <stddef.h>

#include "gl.h"
#include "shadow_maps.h"
#include "timer.h"

/* Textures of a pass per block of the frame's pixels: a value and a plane
 * per block, w x h blocks of step x step pixels; empty until a step above 1. */
typedef struct lpv_frame_blocks {
    GLuint tex[2];
    int w, h, step;
} lpv_frame_blocks;

typedef struct lpv_frame {
    int w, h;
    GLuint tex, fbo;   /* RGBA32F, linear radiance (W/(m^2 sr)) */
    GLuint shade_rest; /* the pixels left for shade_rest.comp (a uvec4 head, then an ivec2 per pixel) */
    GLuint area_rest;  /* the pixels left for area_shadow_rest.comp (the same layout) */
    int shade_split;   /* the last shading ran in two passes */
    int shade_area_blocks; /* the last shading took the area light's shadows from the area shadow step's blocks */
    /* the lookup step's irradiance and planes per block (lookup_blocks.comp)
     * and the area shadow step's visibility and planes per block
     * (area_shadow_blocks.comp) */
    lpv_frame_blocks lookup_blocks, area_shadow_blocks;
} lpv_frame;

/* Deletes the target, the lists and the blocks' textures (a partly failed
 * allocation too): the one list of them. */
void lpv_frame_free(lpv_frame *f);

/* (Re)allocates the target and the lists for w x h pixels unless they have
 * that size. Returns 0, or -1 with err. */
int lpv_frame_ensure(lpv_frame *f, int w, int h, char *err, size_t err_size);

/* The technique's lookup bound to a program in use (its volume, its
 * uniforms): the engine's, through ctx. */
typedef struct lpv_frame_lookup {
    void (*bind)(void *ctx, GLuint prog);
    void *ctx;
} lpv_frame_lookup;

/* One shading of a G-buffer into a texture (shading.glsl as a compute pass). */
typedef struct lpv_frame_shading {
    const GLuint *gbuf; /* the G-buffer's LPV_GBUF_TARGETS textures (the camera's or the translucent layer's) */
    GLuint target;      /* the texture written: the frame's or the translucent layer's frame */
    int rect[4];        /* the pixels shaded: x, y, w, h */
    const char *stage;  /* the timer's stage */
    /* the passes: the lookup step's blocks first, the area shadow step's
     * blocks first, the technique's second lookup pass over listed pixels */
    int blocks, area_blocks, split;
    int lookup_step, area_shadow_step;
    float glossy_roughness; /* u_glossy_roughness: 0 where the glossy pass adds nothing */
    GLuint prog;            /* the frame program of the variant (shade.comp) */
    GLuint prog_rest, prog_area_rest, prog_lookup_blocks, prog_area_shadow_blocks;
    lpv_frame_lookup lookup;
    const lpv_shadow_maps *shadows;
    GLuint light_ubo, view_ubo;
    lpv_timer *timer;
} lpv_frame_shading;

/* Shades s->rect of s->gbuf into s->target, the passes per block before and
 * the listed pixels' second passes after, in bands with a yield point
 * between them. */
void lpv_frame_shade(lpv_frame *f, const lpv_frame_shading *s);

/* Pixels of the last shading looked up in full by its second pass
 * (shade_rest.comp), and those whose area light area_shadow_rest.comp
 * added: read back, so call them after the frame. */
size_t lpv_frame_full_lookups(const lpv_frame *f);
size_t lpv_frame_area_rest_pixels(const lpv_frame *f);

/* Lays a shaded layer (its frame, its coverage) over rect of the frame
 * with prog (translucent.comp), in the timer's current stage. */
void lpv_frame_overlay(lpv_frame *f, GLuint prog, GLuint layer_frame, GLuint layer_alpha, const int rect[4],
                       lpv_timer *timer);

/* Reads the frame back as w x h RGBA floats, top row first. */
void lpv_frame_read(const lpv_frame *f, float *rgba);

#endif
