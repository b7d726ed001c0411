/*
 * medium.h - a participating medium's GPU state: its coefficients and box
 * (from the scene) and its density as a 3D texture, uploaded with the scene,
 * and the uniforms of medium.glsl. The media pass reads it to scatter, a
 * technique's propagation to attenuate; neither needs the engine for it.
 */
#ifndef LPV_MEDIUM_H
#define LPV_MEDIUM_H

#include <stddef.h>

#include "gl.h"
#include "scene.h"
#include "settings.h"

typedef struct lpv_medium_gpu {
    lpv_medium medium; /* coefficients and box; density NULL (the texture holds it) */
    GLuint density;    /* 3D R32F texture, 0 = none */
} lpv_medium_gpu;

/* Replaces m with the scene's medium (none when the scene has none).
 * Returns 0, or -1 with err when the texture cannot be made. */
int lpv_medium_upload(lpv_medium_gpu *m, const lpv_scene *scene, char *err, size_t err_size);
void lpv_medium_free(lpv_medium_gpu *m);
/* Sets medium.glsl's uniforms of prog (in use): the fog settings win over the
 * scene's medium; on = 0 binds "no medium". */
void lpv_medium_bind(const lpv_medium_gpu *m, const lpv_settings *s, GLuint prog, int on);
/* Whether lpv_medium_bind(m, s, prog, on) binds a medium (u_medium != 0). */
int lpv_medium_active(const lpv_medium_gpu *m, const lpv_settings *s, int on);

#endif /* LPV_MEDIUM_H */
