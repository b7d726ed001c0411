/*
 * atlas.h - a 2D atlas of a grid's z slices that points are blended into
 * (fp32 render targets, one attachment per part of a point's data): the
 * paper's point splatting, portable because it needs no float atomics and
 * deterministic because blending follows primitive order. The LPV's
 * injection and geometry volume and the imperfect volume's creation use it;
 * grid.glsl's atlas_texel() finds a cell's texel.
 */
#ifndef LPV_ATLAS_H
#define LPV_ATLAS_H

#include <stddef.h>

#include "gl.h"
#include "timer.h"

#define LPV_ATLAS_MAX_ATTACHMENTS 8

typedef struct lpv_atlas {
    int tiles_x, width, height;
    int attachments;
    GLuint tex[LPV_ATLAS_MAX_ATTACHMENTS];
    GLuint fbo;
} lpv_atlas;

/* Created per placement, owned by its technique's state. */
int lpv_atlas_create(lpv_atlas *a, const int dims[3], int attachments, char *err, size_t err_size);
void lpv_atlas_destroy(lpv_atlas *a);
/* Sets the state for additive point splatting with prog into a, cleared
 * first (begin) or as it is (begin_keep); the grid block and an empty VAO
 * bound. */
void lpv_atlas_begin(const lpv_atlas *a, GLuint prog, GLuint grid_ubo, GLuint empty_vao);
void lpv_atlas_begin_keep(const lpv_atlas *a, GLuint prog, GLuint grid_ubo, GLuint empty_vao);
/* Draws count points of elements [first, first + count) of buffer at binding,
 * `instances` times (gl_InstanceID: the cascade, for splats into every one),
 * in draws of LPV_ATLAS_SPLAT_CHUNK points with a yield point between them
 * (timer.h): blending follows primitive order, so the sum is the same. */
#define LPV_ATLAS_SPLAT_CHUNK ((size_t)1 << 19)
void lpv_atlas_splat(GLuint prog, GLuint binding, GLuint buffer, size_t first, size_t count, int instances,
                     lpv_timer *timer);
/* The same for the samples compacted into buffer with their count in the
 * draw command at the start of draw (compact.h): only the live ones are
 * drawn. */
void lpv_atlas_splat_indirect(GLuint prog, GLuint binding, GLuint buffer, GLuint draw, int instances, lpv_timer *timer);
void lpv_atlas_end(void);

#endif /* LPV_ATLAS_H */
