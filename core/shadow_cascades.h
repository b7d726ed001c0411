/*
 * shadow_cascades.h - cascaded shadow maps for directional lights
 * (docs/shadows.md): the camera's view depth range over the scene is split
 * into slices (a mix of logarithmic and uniform splits), and each slice gets
 * an orthographic shadow-map face that covers its bounding sphere, snapped to
 * whole texels in the light's frame so the map does not shimmer when the
 * camera moves or turns. Pure math, no GL.
 */
#ifndef LPV_SHADOW_CASCADES_H
#define LPV_SHADOW_CASCADES_H

#include <cglm/types.h>

#include "view.h"

/* Weight of the logarithmic split against the uniform one (practical split
 * scheme of parallel-split shadow maps, Zhang et al. 2006). */
#define LPV_SHADOW_SPLIT_LAMBDA 0.75f

typedef struct lpv_shadow_cascade {
    mat4 view_proj;   /* world -> clip (orthographic) */
    float texel;      /* m per shadow-map texel */
    float split_near; /* m along the view direction: the slice it was fitted to */
    float split_far;
    float centre[3];  /* m, the snapped centre of the covered sphere */
    float radius;     /* m, half the side of the covered square (border included) */
} lpv_shadow_cascade;

/* Fits `count` cascades (1..LPV_SHADOW_CASCADES) of `size` texels per side
 * for a directional light travelling along light_dir (need not be unit)
 * to the part of the view's frustum that holds the scene's bounds
 * [scene_min, scene_max]. border_texels are left free at each side of a
 * face (the shader's filter and bias need them). The depth range of every
 * face covers the whole scene towards the light, so every caster is drawn.
 * Returns 0, or -1 for a degenerate input (zero direction, non-finite view). */
int lpv_shadow_cascades_fit(const lpv_view *view, const float light_dir[3], const float scene_min[3],
                            const float scene_max[3], int size, float border_texels, int count,
                            lpv_shadow_cascade *out);

#endif /* LPV_SHADOW_CASCADES_H */
