/*
 * probes_settings.h - the probes' knobs as lpv_settings holds them
 * (settings.probes); their rows (range, default, help, what a change
 * recomputes) are probes_fields.c's.
 */
#ifndef LPV_PROBES_SETTINGS_H
#define LPV_PROBES_SETTINGS_H

/* The rows' ranges. */
#define LPV_PROBES_MAX_RAYS 1024
#define LPV_PROBES_MAX_BUDGET (1 << 20)
#define LPV_PROBES_MAX_WARMUP 16
#define LPV_PROBES_MAX_OCT 16 /* <= probes_update.h's LPV_PROBES_OCT_MAX */

/* Ray-traced irradiance probes (issue 34; techniques/probes/README.md): a
 * probe at the centre of every cell of the cascades, updated a budget of
 * probes a tick by rays through the scene's BVH. A zero field takes its
 * default (probes_fields.c). The probe spacing is the grid's cell. */
typedef struct lpv_probes_settings {
    int rays;         /* rays a probe shoots per update */
    int budget;       /* probes updated per tick once the volume has history */
    float hysteresis; /* weight of a probe's old value in an update, before it adapts to change (0..0.99) */
    int warmup;       /* passes over every probe on a volume without history: the bounces a single tick sees */
    int oct;          /* texels per side of each probe's distance map */
} lpv_probes_settings;

#endif
