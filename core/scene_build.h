/*
 * scene_build.h - building lpv_scene models in code: the hard cases of the
 * stability tests and the accuracy report, the calibration scenes, anything
 * that needs a scene without a glTF file. Every call appends; allocation
 * failures return -1 and leave the scene valid (free it as usual).
 *
 *   lpv_scene s = {0};
 *   int grey = lpv_scene_add_material(&s, "grey", (float[3]){0.5f, 0.5f, 0.5f}, NULL);
 *   lpv_scene_add_quad(&s, grey, corners, NULL);      // winding gives the front
 *   lpv_scene_add_point_light(&s, (float[3]){0, 2, 0}, 10.0f);
 *   lpv_scene_compute_bounds(&s);
 */
#ifndef LPV_SCENE_BUILD_H
#define LPV_SCENE_BUILD_H

#include "scene.h"

/* A diffuse material (metallic 0, roughness 1, single-sided) with linear
 * albedo rgb and emitted radiance emission (W/(m^2 sr), NULL = none).
 * Returns its index, or -1. */
int lpv_scene_add_material(lpv_scene *s, const char *name, const float albedo[3], const float emission[3]);

/* A planar quad c0 c1 c2 c3 (counter-clockwise seen from its front) as two
 * triangles of a new draw with material m. The vertex normal is the
 * winding's normal unless normal is given (it is stored as given, even when
 * degenerate: tests use that). Returns the draw index, or -1. */
int lpv_scene_add_quad(lpv_scene *s, int material, const float c[4][3], const float normal[3]);

/* The axis-aligned box [lo, hi] with outward faces, one draw. Returns the
 * draw index, or -1. */
int lpv_scene_add_box(lpv_scene *s, int material, const float lo[3], const float hi[3]);

/* Appends a white light; returns a pointer to it for further fields (valid
 * until the next add), or NULL. Point: intensity W/sr. Directional: dir is
 * the direction the light travels, irradiance W/m^2 on a surface facing it. */
lpv_light *lpv_scene_add_point_light(lpv_scene *s, const float pos[3], float intensity);
lpv_light *lpv_scene_add_directional_light(lpv_scene *s, const float dir[3], float irradiance);

#endif /* LPV_SCENE_BUILD_H */
