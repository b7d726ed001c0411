/*
 * scene_surfels.h - surfels spread over every triangle of the scene, for the
 * geometry volume (docs/propagation.md section 3b). The paper's GV sees only
 * what the camera and the lights' RSMs see, so a wall seen edge-on by the
 * camera and never lit (the blinds room's partition) blocks nothing and light
 * leaks through it. These surfels sample the geometry itself, independent of
 * any view, as imperfect volumes do (Mavridis & Papaioannou, section 3.1).
 */
#ifndef LPV_SCENE_SURFELS_H
#define LPV_SCENE_SURFELS_H

#include <stddef.h>

#include "oracle.h"
#include "scene.h"

/* Writes up to max surfels, about `target` in all, spread over the scene's
 * non-degenerate triangles of opaque, non-emissive materials (emitters are
 * light sources only in the geometry volume, as in the RSM and camera
 * surfels, and the planner counts only non-emissive triangles as occluders;
 * alpha cut-outs block where the RSM and camera see them opaque) in
 * proportion to their area on a deterministic low-discrepancy pattern. Each carries its triangle's front normal, its
 * material's base colour (the bounces' albedo) and an area such that the
 * surfels' areas sum to the triangles' total area (a triangle too small for
 * a sample of its own hands its area to the next sample). Returns the count. */
size_t lpv_scene_surfels(const lpv_scene *scene, size_t target, lpv_surfel *out, size_t max);

#endif
