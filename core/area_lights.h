/*
 * area_lights.h - emissive surfaces as direct area lights (issue 10,
 * docs/area-lights.md).
 *
 * The scene's emissive triangles (radiance L_e in W/(m^2 sr) from the front
 * side, and the same from the back when the material is double-sided, as
 * glTF's doubleSided means: each side is an emitter of its own here) are
 * reduced to a bounded number K of "area light samples": points on the
 * emitters with a Lambertian (cosine) emission profile over the hemisphere
 * of the side they stand for,
 *
 *     I_k(w) = I_k max(0, <n_k, w>)   W/sr per channel,   I_k = sum of L_e A over the part it stands for,
 *
 * so each sample emits pi I_k W and all K together emit exactly the
 * emitters' flux pi sum(L_e A) per channel (the sum over emitting sides: a
 * double-sided emitter has twice the flux of a single-sided one). The engine
 * renders every sample through the punctual-light machinery (shadow maps,
 * RSM faces).
 *
 * Placement: the triangles are laid end to end along their emitted power
 * (weight (L_r + L_g + L_b) A) in scene order, and the line is cut into K
 * equal parts. Sample k stands for part k: its intensity and area are the
 * exact sums over the (fractions of) triangles inside the part. A fraction of
 * a triangle is a compact patch of it (a midpoint-subdivision curve maps the
 * line onto the triangle), so K samples on one big triangle split it into K
 * patches of equal area. The sample sits at the power-weighted centroid of
 * its patches when they are coplanar (a rectangular lamp of two triangles
 * with K = 1: its centre), else at the centroid of the patch holding the
 * part's midpoint, and faces that patch's emitting side (so a part that
 * straddles the front and back of a double-sided emitter, as with K = 1 or
 * an odd K on one such emitter, sends both sides' power the midpoint's
 * way). Neighbouring triangles of a mesh are usually neighbours in space,
 * so a part is a patch of an emitter.
 * Deterministic: the same scene and K give the same samples.
 */
#ifndef LPV_AREA_LIGHTS_H
#define LPV_AREA_LIGHTS_H

#include <stddef.h>

#include "lpv_shared.h"
#include "scene.h"

/* Most samples a scene gets (the settings' area_light_samples range). */
#define LPV_MAX_AREA_SAMPLES LPV_MAX_AREA_LIGHTS

/* One emitting side of a usable emissive triangle: its front, and for a
 * double-sided material also its back (the same corners, the normal turned). */
typedef struct lpv_emitter_tri {
    float p[3][3];     /* corners, m */
    float normal[3];   /* unit normal of the emitting side */
    float emission[3]; /* radiance, W/(m^2 sr) */
    double area;       /* m^2 */
} lpv_emitter_tri;

typedef struct lpv_emitter_list {
    lpv_emitter_tri *tris;
    size_t count;
    unsigned surfaces; /* emissive draws that kept at least one triangle */
} lpv_emitter_list;

/* Collects the scene's emissive triangles (draws whose material has finite,
 * positive emission; degenerate triangles skipped), per draw its triangles'
 * fronts, then for a double-sided material their backs. Returns 0, or -1 on
 * allocation failure (list left empty). */
int lpv_emitters_collect(const lpv_scene *scene, lpv_emitter_list *list);
void lpv_emitters_free(lpv_emitter_list *list);

typedef struct lpv_area_sample {
    float position[3];  /* m, on the emitter */
    float normal[3];    /* unit, the emitting side */
    float intensity[3]; /* W/sr along the normal, rgb (= L_e x area for one emitter) */
    float area;         /* m^2 of emitter the sample stands for */
} lpv_area_sample;

/* Writes min(k, what the emitters allow) samples into out (room for k) as
 * described above; 0 when there are no emitters or k == 0. */
size_t lpv_area_lights_sample(const lpv_emitter_list *list, size_t k, lpv_area_sample *out);

#endif
