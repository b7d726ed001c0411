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

/* Named quality presets: points on the accuracy sweep's Pareto front
 * (docs/accuracy.md). A preset supplies grid_dims, iterations, rsm_size and
 * occlusion; any of those set explicitly wins over it. 0 means "the default",
 * which is BALANCED. */
typedef enum lpv_preset {
    LPV_PRESET_DEFAULT = 0,
    LPV_PRESET_FAST = 1,
    LPV_PRESET_BALANCED = 2,
    LPV_PRESET_ACCURATE = 3,
    LPV_PRESET_COUNT_ /* one past the last; not a preset */
} lpv_preset;

typedef struct lpv_settings {
    int grid_dims[3];       /* cells per axis; default: the preset's (balanced: 32 x 32 x 32) */
    float bounds_min[3];    /* grid bounds, m; all-zero min and max = the scene's */
    float bounds_max[3];    /*   bounds grown by half a cell on every side */
    int iterations;         /* propagation steps; default: the preset's (balanced: 4) */
    int rsm_size;           /* reflective shadow map side, texels; default: the preset's (balanced: 128) */
    int shadow_size;        /* side of each light face's shadow map for direct light, texels;
                               default LPV_DEFAULT_SHADOW_SIZE (docs/shadows.md) */
    lpv_switch occlusion;   /* fuzzy occlusion from the geometry volume; default: the preset's (on) */
    float indirect_gain;    /* artistic factor on the LPV term; default 1 (0 = default) */
    int emissive_vpls;      /* VPLs sampled on emissive surfaces; default 4096 */
    lpv_preset preset;      /* supplies the four defaults marked "the preset's"; default balanced */

    /* Cascades (cascaded-LPV paper, section 4; docs/cascades.md). Every cascade
     * has grid_dims cells; cascade k's cells are cascade_ratio^k times the
     * finest cascade's. */
    int cascades;           /* 0 = auto: one grid over the scene when the scene fits in
                               the finest cascade, else LPV_DEFAULT_CASCADES; N = exactly N */
    float cascade_size;     /* m, the finest cascade's extent along its longest axis; default 8 */
    float cascade_ratio;    /* cell size ratio of consecutive cascades; default 2 */
    float cascade_offset;   /* how far each cascade's centre sits ahead of the camera along
                               the view direction, as a fraction of its extent; default 0.25,
                               negative = 0 (centred on the camera) */

    /* Section 7 effects and damping (section 3.4); docs/effects.md. */
    lpv_switch bounces;     /* multiple bounces off the geometry volume's blockers; default off */
    float bounce_intensity; /* factor on the blockers' albedo (1 = physical); default 1 */
    float damping;          /* directional-derivative damping strength; 0 = off (default) */
    lpv_switch glossy;      /* glossy reflections by marching the LPV; default on (run
                               only when the scene has a glossy material) */
    float glossy_roughness; /* materials with roughness below this are glossy; default 0.3 */
    lpv_switch media;       /* participating media single scattering; default on (run only
                               when the scene or the fog settings give a medium) */
    float fog_sigma_s;      /* 1/m, homogeneous fog scattering coefficient; 0 = none (the
                               scene's own medium, if any) */
    float fog_sigma_a;      /* 1/m, homogeneous fog absorption coefficient; 0 = none */
    float media_step;       /* ray-march step as a fraction of the cascade's cell; default 0.5 */

    lpv_switch planner;     /* on (default): run only the passes the scene needs and reuse an
                               unchanged volume; off: run every pass every tick */
} lpv_settings;

/* The balanced preset's values, i.e. the engine's defaults. They mirror the
 * preset table in settings.c (a test checks that they agree). */
#define LPV_DEFAULT_GRID_DIM 32
#define LPV_DEFAULT_ITERATIONS 4
#define LPV_DEFAULT_RSM_SIZE 128
#define LPV_DEFAULT_SHADOW_SIZE 1024
#define LPV_DEFAULT_EMISSIVE_VPLS 4096
#define LPV_DEFAULT_CASCADES 3
#define LPV_DEFAULT_CASCADE_SIZE 8.0f
#define LPV_DEFAULT_CASCADE_RATIO 2.0f
#define LPV_DEFAULT_CASCADE_OFFSET 0.25f
#define LPV_DEFAULT_GLOSSY_ROUGHNESS 0.3f
#define LPV_DEFAULT_MEDIA_STEP 0.5f

/* Fills defaults into zero fields: preset 0 becomes BALANCED, then zero
 * grid_dims / iterations / rsm_size / occlusion take the preset's values, the
 * other zero fields the engine's defaults. An out-of-range preset is left as
 * is (and its fields untouched) for lpv_settings_validate() to report. */
void lpv_settings_resolve(lpv_settings *s);

/* Writes a preset's values into *out: a zeroed lpv_settings with preset,
 * grid_dims, iterations, rsm_size and occlusion set (DEFAULT gives balanced).
 * Returns 0, or -1 for an unknown preset (out untouched). */
int lpv_preset_settings(lpv_preset p, lpv_settings *out);

/* "fast", "balanced" or "accurate" -> *out. Returns 0, or -1 for any other
 * name (out untouched). */
int lpv_preset_from_name(const char *name, lpv_preset *out);

/* The preset's name ("balanced" for DEFAULT), or NULL for an unknown value. */
const char *lpv_preset_name(lpv_preset p);

/* The preset names, comma separated ("fast, balanced, accurate"), for help
 * and error messages. */
const char *lpv_preset_names(void);

/* The preset whose grid_dims / iterations / rsm_size / occlusion equal those
 * of the resolved settings s, or LPV_PRESET_DEFAULT when none does (the
 * accuracy sweep labels its points with it). */
lpv_preset lpv_preset_match(const lpv_settings *s);

/* 1 when the settings fix the grid bounds (any of bounds_min/max non-zero);
 * all six zero means "the scene's bounds". */
int lpv_settings_bounds_given(const lpv_settings *s);

/* Checks ranges after resolve; on failure writes a message naming the setting
 * into err and returns -1. */
int lpv_settings_validate(const lpv_settings *s, char *err, unsigned long err_size);

#endif /* LPV_SETTINGS_H */
