/*
 * hard_cases.h - the engine's hard cases as a table of named scenes
 * (docs/hard-cases.md): extreme dynamic range, lights on cell corners, VPLs
 * on the grid's boundary, a wall much thinner than a cell, 1000 propagation
 * steps, degenerate geometry, degenerate grids. The GL stability tests
 * (tests/test_gpu_stability.c) and `lpvd-hard-cases`, which compares each
 * with the path-traced reference, build their scenes here, so both always
 * look at the same thing. Plain C11 on core/scene_build.h, no GL.
 *
 *   lpv_hard_scene h = {0};
 *   if (lpv_hard_case_build("thin_wall", &h) == 0) {
 *       lpv_view v;
 *       lpv_hard_case_view(&h, 64, 64, &v);
 *       ... h.scene, h.settings, v ...
 *   }
 *   lpv_hard_scene_free(&h);
 */
#ifndef LPV_HARD_CASES_H
#define LPV_HARD_CASES_H

#include <stddef.h>

#include "scene.h"
#include "settings.h"
#include "view.h"

typedef struct lpv_hard_case_info {
    const char *name; /* identifier, [a-z0-9_] */
    const char *what; /* what it tests, one line */
} lpv_hard_case_info;

/* A built case: the scene, the engine settings it is meant for, a camera
 * looking in, and optionally a "dark side": the region (axis-aligned box,
 * world m) the light should hardly reach, whose error is reported apart. */
typedef struct lpv_hard_scene {
    lpv_scene scene;
    lpv_settings settings;
    float eye[3], target[3];
    float yfov; /* rad */
    int has_dark_side;
    float dark_lo[3], dark_hi[3];
} lpv_hard_scene;

/* The table, in report order. */
size_t lpv_hard_case_count(void);
const lpv_hard_case_info *lpv_hard_case_get(size_t i);
/* Index of a case by name, or -1. */
int lpv_hard_case_find(const char *name);

/* Builds case `name` into out (overwritten; free with lpv_hard_scene_free).
 * Returns 0, or -1 for an unknown name or an allocation failure (out is then
 * empty and may still be freed). */
int lpv_hard_case_build(const char *name, lpv_hard_scene *out);

/* The case's camera as a width x height view. Returns 0 or -1. */
int lpv_hard_case_view(const lpv_hard_scene *h, int width, int height, lpv_view *out);

void lpv_hard_scene_free(lpv_hard_scene *h);

#endif /* LPV_HARD_CASES_H */
