/*
 * raycast.h - first-hit ray casting against a scene's triangles (Embree 3),
 * for choosing default cameras and lights (scene_defaults.c). Each hit
 * reports the front normal of its triangle (lpv_scene_triangle's rule), so a
 * caller can tell whether a ray left from behind a surface.
 */
#ifndef LPV_RAYCAST_H
#define LPV_RAYCAST_H

#include <stddef.h>

#include "scene.h"

typedef struct lpv_raycast lpv_raycast;

/* Builds the acceleration structure over the scene's valid triangles (the
 * scene may be freed after). Returns 0, or -1 with a message in err. */
int lpv_raycast_create(const lpv_scene *scene, lpv_raycast **out, char *err, size_t err_size);
void lpv_raycast_destroy(lpv_raycast *rc);

/* Triangles in the structure. */
unsigned lpv_raycast_triangles(const lpv_raycast *rc);

/* The first triangle along org + t * dir (dir unit) with t in (tmin, tmax):
 * returns 1 with its t and the triangle's unit front normal (either may be
 * NULL), else 0. */
int lpv_raycast_hit(const lpv_raycast *rc, const float org[3], const float dir[3], float tmin, float tmax, float *t,
                    float front[3]);

#endif
