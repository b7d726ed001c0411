/*
 * emissive.h - emissive surfaces as VPLs (cascaded-LPV paper 3.1: area lights
 * as "low-frequency direct light"). A Lambertian emitter of radiance L and
 * area A emits flux pi * L * A from its front side, and as much again from
 * its back when its material is double-sided (glTF doubleSided: each side a
 * set of VPLs facing its own way); each triangle side gets a share
 * of the samples proportional to its flux, placed on a deterministic
 * low-discrepancy pattern, so the same scene always gives the same VPLs.
 */
#ifndef LPV_EMISSIVE_H
#define LPV_EMISSIVE_H

#include <stddef.h>
#include "oracle.h"
#include "scene.h"

/* Writes up to max VPLs for the scene's emissive triangles (target: about
 * `target` in total, at least one per emitting triangle side while room lasts).
 * The flux of all VPLs sums to the surfaces' emitted flux. Returns the count. */
size_t lpv_emissive_sample(const lpv_scene *scene, size_t target, lpv_vpl *out, size_t max);

/* Total flux (W, rgb) emitted by the scene's emissive surfaces. */
void lpv_emissive_total_flux(const lpv_scene *scene, double flux[3]);

#endif
