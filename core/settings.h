/*
 * settings.h - engine settings, sokol style: zero-initialise, set what you
 * care about, and lpv_settings_resolve() fills every zero with its default.
 */
#ifndef LPV_SETTINGS_H
#define LPV_SETTINGS_H

/* Tri-state switch: 0 means "the default". */
typedef enum lpv_switch {
    LPV_SWITCH_DEFAULT = 0,
    LPV_SWITCH_ON = 1,
    LPV_SWITCH_OFF = 2,
} lpv_switch;

typedef struct lpv_settings {
    int grid_dims[3];       /* cells per axis; default 32 x 32 x 32 */
    float bounds_min[3];    /* grid bounds, m; all-zero min and max = the scene's */
    float bounds_max[3];    /*   bounds grown by half a cell on every side */
    int iterations;         /* propagation steps; default 8 */
    int rsm_size;           /* reflective shadow map side, texels; default 256 */
    lpv_switch occlusion;   /* fuzzy occlusion from the geometry volume; default on */
    float indirect_gain;    /* artistic factor on the LPV term; default 1 (0 = default) */
    int emissive_vpls;      /* VPLs sampled on emissive surfaces; default 4096 */
} lpv_settings;

#define LPV_DEFAULT_GRID_DIM 32
#define LPV_DEFAULT_ITERATIONS 8
#define LPV_DEFAULT_RSM_SIZE 256
#define LPV_DEFAULT_EMISSIVE_VPLS 4096

/* Fills defaults into zero fields. */
void lpv_settings_resolve(lpv_settings *s);

/* Checks ranges after resolve; on failure writes a message naming the setting
 * into err and returns -1. */
int lpv_settings_validate(const lpv_settings *s, char *err, unsigned long err_size);

#endif /* LPV_SETTINGS_H */
