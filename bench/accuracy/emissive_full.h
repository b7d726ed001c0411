/*
 * emissive_full.h - `lpvd-accuracy --emissive` (issue 10, docs/area-lights.md):
 * lpvd's FULL frame (emission + direct + LPV) against the path tracer's full
 * frame (lpv_ref_render_full, one bounce) on scenes lit only by emissive
 * surfaces, for area lights off (the emitters reach the scene only as VPLs in
 * the LPV: the state before issue 10) and on with several sample counts, at
 * 4, 8 and 16 samples also at the area shadow steps 1 and 4 besides the
 * settings' (docs/area-lights.md, "The area shadow step").
 *
 * Scenes: cornell-emissive (the built-in Cornell box without its spot light:
 * only the ceiling quad lights it) and, when present, scenes/emissive-room.glb.
 * The emitters' own pixels are left out of the metrics (both renderers show
 * L_e there exactly, and they are hundreds of times brighter than the lit
 * surfaces, so they would hide every error).
 *
 * Writes OUT/emissive.csv and OUT/emissive.md, and per scene and point the
 * tone-mapped frames and error images under OUT/emissive/. Times are GPU ms
 * per frame (tick + render stages, median), never asserted.
 */
#ifndef LPV_ACCURACY_EMISSIVE_FULL_H
#define LPV_ACCURACY_EMISSIVE_FULL_H

#include "engine.h"
#include "options.h"

typedef struct lpv_acc_emissive_desc {
    const char *out_dir;
    const char *scenes_dir;        /* where emissive-room.glb lives */
    const lpvd_options *opt;       /* base settings and camera flags (size) */
    int spp;                       /* reference samples per pixel */
    int ticks, warmup;
} lpv_acc_emissive_desc;

/* Runs the comparison; returns 0, or non-zero after printing why. */
int lpv_acc_emissive_run(lpv_engine *engine, const lpv_acc_emissive_desc *d);

#endif
