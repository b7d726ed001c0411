/*
 * scene_defaults.h - what a scene lacks to be seen (docs/scenes.md,
 * "Defaults"): a camera when the file has none, a light when it has neither a
 * punctual light nor an emissive surface. Both are placed by casting rays
 * against the scene (raycast.h), at distances relative to the scene's size,
 * so a millimetre CAD model gets the same view as the same model in metres.
 */
#ifndef LPV_SCENE_DEFAULTS_H
#define LPV_SCENE_DEFAULTS_H

#include <stddef.h>

#include "scene.h"

/* Adds a perspective camera named "default" when the scene has no camera
 * (sets default_camera_added), then a point light named "default" when it
 * has no punctual light and no emissive material that a draw uses (sets
 * default_light_added). Returns 0, or -1 with a message in err (out of
 * memory, Embree failure). */
int lpv_scene_add_defaults(lpv_scene *scene, char *err, size_t err_size);

/* The tests' view of the choice (also used by lpv_scene_add_defaults). */

/* 1 when p lies inside closed geometry: more than half of the rays of a
 * 64-direction probe that hit something leave p through the back of a surface. */
int lpv_defaults_inside_solid(const lpv_scene *scene, const float p[3]);

#endif
