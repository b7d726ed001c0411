/*
 * scene_planes.h - the normals of the scene's largest flat surfaces, for the
 * lookup's per-normal irradiance (techniques/lpv/shaders/lookup.glsl, "planes"): a pixel
 * of a flat triangle has its vertices' normal up to rounding, so the lookup
 * can read that normal's irradiance, summed over the normal bins once per
 * cell, with one fetch per cascade instead of three per volume.
 */
#ifndef LPV_SCENE_PLANES_H
#define LPV_SCENE_PLANES_H

#include "lpv_shared.h" /* LPV_MAX_LOOKUP_PLANES */
#include "scene.h"

/* Up to `max` unit normals (xyz, world) of flat triangles (three equal
 * vertex normals), the largest total area first, each with its negation
 * (the G-buffer turns a normal to the camera's side), none listed twice
 * (within LPV_LOOKUP_PLANE_TOLERANCE per component). Normals along an axis,
 * or within the tolerance of one, are left out (the lookup has the axes
 * already, and a pixel must not match both). Returns the count, or -1 when
 * out of memory. */
int lpv_scene_plane_normals(const lpv_scene *scene, float (*out)[3], int max);

#endif /* LPV_SCENE_PLANES_H */
