/*
 * lpv_lookup_volume.h - the accumulated LPV as three RGBA32F 3D textures
 * (r, g, b), the form shaders/lookup.glsl reads with one trilinear texture
 * fetch per channel instead of 8 x 3 buffer loads (on llvmpipe the shading
 * spent most of its time in those loads). Filled from the LPV buffer after
 * every tick that wrote it; the buffer stays what propagation writes and
 * what read-backs (GET_VOLUME) read.
 *
 * Volumes (cascades x normal bins) are stacked along z, and along y when z
 * would pass GL_MAX_3D_TEXTURE_SIZE.
 */
#ifndef LPV_LOOKUP_VOLUME_H
#define LPV_LOOKUP_VOLUME_H

#include <stddef.h>

#include "gl.h"
#include "timer.h"

typedef struct lpv_lookup_volume {
    GLuint tex[3];   /* r, g, b */
    int dims[3];     /* one volume's cells */
    int volumes;
    int slabs_z;     /* volumes stacked along z before the next y-slab */
} lpv_lookup_volume;

/* (Re)allocates for `volumes` volumes of dims cells; keeps what fits. */
int lpv_lookup_volume_alloc(lpv_lookup_volume *l, const int dims[3], int volumes, char *err, size_t err_size);
void lpv_lookup_volume_free(lpv_lookup_volume *l);
/* Copies src (LpvCell per cell, volumes one after another) with prog
 * (lpv_lookup_pack.comp), as the timer stage "lookup_pack". */
void lpv_lookup_volume_fill(const lpv_lookup_volume *l, GLuint prog, GLuint src, lpv_timer *timer);
/* Binds the textures to LPV_TEX_LOOKUP_R/G/B and sets prog's (in use) u_lpv_slabs_z. */
void lpv_lookup_volume_bind(const lpv_lookup_volume *l, GLuint prog);

#endif /* LPV_LOOKUP_VOLUME_H */
