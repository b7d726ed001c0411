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

/* A diffuse material (metallic 0, roughness 1, double-sided, opaque, no
 * normal map) with linear albedo rgb and emitted radiance emission
 * (W/(m^2 sr), NULL = none). An emitter (emission not all 0) is made
 * single-sided instead: it emits from its front only, and the camera culls
 * its back; set double_sided = 1 afterwards for one that emits from both
 * sides (docs/area-lights.md). Returns its index, or -1. */
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

/* Sets material m's roughness (0 mirror-like .. 1 matte; materials start at 1).
 * Returns 0, or -1 for an index out of range or a roughness outside [0, 1]. */
int lpv_scene_set_material_roughness(lpv_scene *s, int material, float roughness);

/* Participating media (docs/scenes.md, "Media"). Both replace the scene's
 * medium; sigma_s and sigma_a (1/m, rgb) must be finite and within
 * 0 .. LPV_MEDIUM_SIGMA_MAX. All six zero removes the medium (present 0).
 * On -1 (bad argument or out of memory) the old medium is left as it was. */

/* Homogeneous fog filling all space (density 1 everywhere). */
int lpv_scene_set_fog(lpv_scene *s, const float sigma_s[3], const float sigma_a[3]);

/* A medium confined to the box [box_min, box_max] (min < max on every axis,
 * finite). With dims all 0 and density NULL it is homogeneous (density 1)
 * inside the box; otherwise dims are 1 .. LPV_MEDIUM_DIMS_MAX cells per axis
 * and density holds dims[0]*dims[1]*dims[2] values (x fastest), each finite
 * and within 0 .. LPV_MEDIUM_DENSITY_MAX; they are copied. */
int lpv_scene_set_medium_box(lpv_scene *s, const float sigma_s[3], const float sigma_a[3], const float box_min[3],
                             const float box_max[3], const int dims[3], const float *density);

#endif /* LPV_SCENE_BUILD_H */
