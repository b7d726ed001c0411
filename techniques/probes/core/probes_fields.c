/*
 * probes_fields.c - the probes' knob rows (core/settings_fields.h): each
 * knob's range, default, help and what a change recomputes, written once.
 * technique_fields.c hands them to the knob table after core's and iv's.
 */
#include "probes_rules.h"

#include "lpv_shared.h"

#include "settings_rows.h"

static const lpv_field PROBES_FIELDS[] = {
    /* Ray-traced irradiance probes (techniques/probes/README.md). */
    {"probes_rays", "probes-rays", LPV_FIELD_INT, F(probes.rays), 1, LPV_PROBES_MAX_RAYS, 0, "", D(64), "",
     "rays a probe traces per update (stratified, turned every tick)", T_VOL, LPV_TECHNIQUE_PROBES},
    {"probes_budget", "probes-budget", LPV_FIELD_INT, F(probes.budget), 1, LPV_PROBES_MAX_BUDGET, 0, "probes",
     D(1024), "", "probes updated per tick once the volume has history (a cheaper tick, slower to follow a change)",
     T_VOL, LPV_TECHNIQUE_PROBES},
    {"probes_hysteresis", "probes-hysteresis", LPV_FIELD_FLOAT, F(probes.hysteresis), 0, 0.99, 1, "", D(0.9), "",
     "weight of a probe's old light in an update (lowered where the light changed)", T_VOL, LPV_TECHNIQUE_PROBES},
    {"probes_warmup", "probes-warmup", LPV_FIELD_INT, F(probes.warmup), 1, LPV_PROBES_MAX_WARMUP, 0, "", D(4), "",
     "passes over every probe when the volume has no history: the bounces one tick sees", T_VOL,
     LPV_TECHNIQUE_PROBES},
    {"probes_oct", "probes-oct", LPV_FIELD_INT, F(probes.oct), 1, LPV_PROBES_MAX_OCT, 0, "texels", D(8), "",
     "texels per side of each probe's distance map (the visibility test's resolution)", T_VOL,
     LPV_TECHNIQUE_PROBES},
};

#include "settings_rows_end.h"

const lpv_field *lpv_probes_fields(size_t *count)
{
    *count = sizeof PROBES_FIELDS / sizeof PROBES_FIELDS[0];
    return PROBES_FIELDS;
}
