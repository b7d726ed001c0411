/*
 * lpv_lookup_volume.h - the accumulated LPV as three RGBA32F 3D textures
 * (r, g, b), the form techniques/lpv/shaders/lookup.glsl reads with one trilinear texture
 * fetch per channel instead of 8 x 3 buffer loads (on llvmpipe the shading
 * spent most of its time in those loads). Filled from the LPV buffer after
 * every tick that wrote it; the buffer stays what propagation writes and
 * what read-backs (GET_VOLUME) read.
 *
 * Volumes (cascades x normal bins) are stacked along z, and along y when z
 * would pass GL_MAX_3D_TEXTURE_SIZE. A fourth texture holds each cascade's
 * irradiance on the six axis normals and on the scene's plane normals
 * (core/scene_planes.h), summed over its bins (lpv_normals_pack.comp), for
 * the surfaces that face them.
 */
#ifndef LPV_LOOKUP_VOLUME_H
#define LPV_LOOKUP_VOLUME_H

#include <stddef.h>

#include "gl.h"
#include "lpv_shared.h"
#include "timer.h"

typedef struct lpv_lookup_volume {
    GLuint tex[3];     /* r, g, b */
    GLuint normals_tex; /* rgb irradiance per cascade and lookup normal */
    int dims[3];       /* one volume's cells */
    int cascades, bins; /* volumes = cascades x bins */
    int slabs_z;       /* volumes stacked along z before the next y-slab */
    int normals_slabs_z;  /* the same for the normals' volumes (cascades x normals) */
    int normals;       /* the lookup's own normals: LPV_LOOKUP_AXES and room for planes, or 0 (no fourth texture) */
    int plane_count;   /* planes filled by the last fill */
    float planes[LPV_MAX_LOOKUP_PLANES][3];
} lpv_lookup_volume;

/* The programs that fill it. */
typedef struct lpv_lookup_programs {
    GLuint pack; /* lpv_lookup_pack.comp */
    GLuint normals; /* lpv_normals_pack.comp */
} lpv_lookup_programs;

/* (Re)allocates for cascades x bins volumes of dims cells; keeps what fits. */
int lpv_lookup_volume_alloc(lpv_lookup_volume *l, const int dims[3], int cascades, int bins, char *err,
                            size_t err_size);
void lpv_lookup_volume_free(lpv_lookup_volume *l);
/* Copies src (LpvCell per cell, volumes one after another) and sums it on
 * the axis normals and the first plane_count of planes (as many as there is
 * room for), as the timer stage "lookup_pack". */
void lpv_lookup_volume_fill(lpv_lookup_volume *l, lpv_lookup_programs progs, GLuint src, const float (*planes)[3],
                            int plane_count, lpv_timer *timer);
/* Binds the textures to LPV_TEX_LOOKUP_R/G/B/AXES and sets prog's (in use)
 * u_lpv_slabs_z and u_lpv_normals_slabs_z. */
void lpv_lookup_volume_bind(const lpv_lookup_volume *l, GLuint prog);

#endif /* LPV_LOOKUP_VOLUME_H */
