/*
 * settings.h - engine settings, sokol style: zero-initialise, set what you
 * care about, and lpv_settings_resolve() fills every zero with its default.
 * Each knob's default and range is written once, as its row of the knob
 * table (settings_fields.c); the comments below say what a field means.
 */
#ifndef LPV_SETTINGS_H
#define LPV_SETTINGS_H

#include <stddef.h>

/* The GI techniques' names and ids, and the one lpvd uses when none is
 * named: the registry's header (techniques/technique_ids.h). */
#include "technique_ids.h"

#include "settings_switch.h"

/* Named quality presets: points on the accuracy sweep's Pareto front
 * (docs/accuracy.md). A preset supplies grid_dims, iterations, rsm_size,
 * occlusion, central_transport, normal_bins, far_field and scene_surfels; any
 * of those set explicitly wins over it. 0 means "the default", which is
 * BALANCED. */
typedef enum lpv_preset {
    LPV_PRESET_DEFAULT = 0,
    LPV_PRESET_FAST = 1,
    LPV_PRESET_BALANCED = 2,
    LPV_PRESET_ACCURATE = 3,
    LPV_PRESET_COUNT_ /* one past the last; not a preset */
} lpv_preset;

/* The cascaded LPV's own knobs (LPV_TECHNIQUE_LPV, techniques/lpv/gpu/; the first
 * seed): how its volume propagates, occludes, cascades and is read. Every
 * technique gets a struct like this one inside lpv_settings, zero meaning
 * "the default" as everywhere. */
typedef struct lpv_lpv_settings {
    int iterations;         /* propagation steps; default: the preset's scaled to the grid
                               (lpv_settings_scaled_iterations) */
    lpv_switch occlusion;   /* fuzzy occlusion from the geometry volume; default: the preset's (on) */

    /* Cascades (cascaded-LPV paper, section 4; docs/cascades.md). Every cascade
     * has grid_dims cells; cascade k's cells are cascade_ratio^k times the
     * finest cascade's. */
    int cascades;           /* 0 = auto (core/plan.c): with an explicit cascade_size, one grid when
                               the scene fits in it, else LPV_AUTO_CASCADES; with cascade_size
                               auto, LPV_AUTO_CASCADES only when the camera stands inside a wide
                               scene (LPV_CASCADE_WIDE_RATIO) or in a space narrower than a quarter
                               of the scene's cascades (lpv_plan_facts.view_chord), else one grid;
                               N = exactly N */
    float cascade_size;     /* m, the finest cascade's extent along its longest axis; 0 (default)
                               = auto: LPV_CASCADE_AUTO_FRACTION of the scene's longest side, or
                               cells as wide as the space around the camera where that is
                               narrower (lpv_cascade_finest_size) */
    float cascade_ratio;    /* cell size ratio of consecutive cascades */
    float cascade_offset;   /* how far each cascade's centre sits ahead of the camera along
                               the view direction, as a fraction of its extent; default 0.25,
                               negative = 0 (centred on the camera) */

    /* Section 7's multiple bounces and section 3.4's damping; docs/effects.md. */
    lpv_switch bounces;     /* multiple bounces off the geometry volume's blockers */
    float bounce_intensity; /* factor on the blockers' albedo (1 = physical) */
    float damping;          /* directional-derivative damping strength; 0 = off (default) */

    /* Transport and lookup (docs/propagation.md sections 4b, 5b and 6b):
     * measured departures from the paper. The preset supplies the three
     * switches' defaults. */
    lpv_switch central_transport; /* re-emit each face's flux along the face's central direction
                                     instead of its normal */
    lpv_switch normal_bins;       /* one volume per dominant normal axis of the emitters, so a
                                     surface never reads back its own light (6x the volumes) */
    lpv_switch far_field;         /* coarser levels carry on the light of the finest grid (one grid
                                     over the scene gets far_field_levels of them; camera-following
                                     cascades hand light from each to the next) */
    int far_field_levels;         /* coarser levels for one grid over the scene, each doubling the cell
                                     size */
    int far_field_steps;          /* steps each level but the coarsest takes before handing its light
                                     on; the coarsest takes the rest of the iterations, so more
                                     iterations only add steps there */
    lpv_switch smooth_injection;  /* each VPL's light spread bilinearly over the 2 x 2 cells around it
                                     along its surface instead of the one cell holding it, so the volume
                                     changes smoothly as a moving light's RSM texels slide over the
                                     surfaces (grid.glsl vpl_stencil_at); default off */
} lpv_lpv_settings;

/* Everything the engine is told: the volume's resolution and bounds, the
 * shared producers (RSMs, shadow maps, samples of the scene), the shading's
 * effects, the planner, and one nested struct per GI technique. */
/* Imperfect volumes' knobs (lpv_iv_settings): the technique's own header. */
#include "iv_settings.h"
/* Probes' knobs (lpv_probes_settings): the technique's own header. */
#include "probes_settings.h"

typedef struct lpv_settings {
    int grid_dims[3];       /* cells per axis; default: the preset's */
    float bounds_min[3];    /* grid bounds, m; all-zero min and max = the scene's */
    float bounds_max[3];    /*   bounds grown by half a cell on every side */
    int rsm_size;           /* reflective shadow map side, texels; default: the preset's */
    int shadow_size;        /* side of each light face's shadow map for direct light, texels
                               (docs/shadows.md) */
    float indirect_gain;    /* artistic factor on the indirect term */
    int emissive_vpls;      /* VPLs sampled on emissive surfaces */
    lpv_preset preset;      /* supplies the defaults marked "the preset's"; default balanced */
    lpv_technique_id technique; /* the GI technique; default LPV_TECHNIQUE_ID_DEFAULT_IS */

    /* Effects read at render time (docs/effects.md). */
    lpv_switch glossy;      /* glossy reflections by marching the volume; default on (run
                               only when the scene has a glossy material) */
    float glossy_roughness; /* materials with roughness below this are glossy */
    lpv_switch media;       /* participating media single scattering; default on (run only
                               when the scene or the fog settings give a medium) */
    float fog_sigma_s;      /* 1/m, homogeneous fog scattering coefficient; 0 = none (the
                               scene's own medium, if any) */
    float fog_sigma_a;      /* 1/m, homogeneous fog absorption coefficient; 0 = none */
    float media_step;       /* ray-march step as a fraction of the volume's cell */

    lpv_switch planner;     /* on (default): run only the passes the scene needs and reuse an
                               unchanged volume; off: run every pass every tick */

    /* Samples of the scene for occlusion (docs/propagation.md section 3b). */
    lpv_switch scene_surfels;     /* surfels sampled over every triangle join the geometry volume, so
                                     walls no view sees still block; default: the preset's */
    int scene_surfel_count;       /* how many */
    int camera_surfel_step;       /* G-buffer pixels per camera surfel along each axis (a block of
                                     step x step pixels becomes one surfel); 0 (default) = auto,
                                     lpv_settings_camera_surfel_step() */
    int rsm_vpl_step;             /* RSM texels per VPL and surfel block along each axis (each block
                                     gives one VPL per cell it reaches, block_groups.glsl); 0
                                     (default) = auto, lpv_settings_rsm_vpl_step() */
    /* Emissive surfaces as direct area lights (docs/area-lights.md). */
    lpv_switch reach;       /* on (default): no technique's light reaches air a closed surface
                               keeps every light from (core/reach.h, docs/propagation.md
                               "Enclosed lights"); off: the volume as propagated */
    lpv_switch area_lights; /* on (default): emitters light the scene directly through
                               area_light_samples shadow-mapped samples and stop injecting
                               their own VPLs; off: emitters reach the scene only as
                               emissive_vpls VPLs in the volume */
    int area_light_samples; /* samples the emitters are reduced to */
    /* The frame's irradiance lookup (docs/accuracy.md, "The lookup step"). */
    int lookup_step;        /* pixels per lookup of the technique's irradiance along each axis: 1
                               (default) every pixel; N > 1 once per N x N block, spread to the
                               block's pixels by a plane- and normal-aware upsampling */
    /* The area lights' shadows in the frame (docs/area-lights.md, "The area shadow step"). */
    int area_shadow_step;   /* pixels per evaluation of the area light samples' shadow maps along
                               each axis: 1 every pixel; N > 1 (default 2) once per N x N block,
                               as the ratio of shadowed to unshadowed irradiance, spread like the
                               lookup step's blocks; each pixel keeps its own unshadowed light */

    lpv_lpv_settings lpv;   /* the cascaded LPV's knobs (LPV_TECHNIQUE_LPV) */
    lpv_iv_settings iv;     /* the imperfect volume's knobs (LPV_TECHNIQUE_IV) */
    lpv_probes_settings probes; /* the probes' knobs (LPV_TECHNIQUE_PROBES) */
} lpv_settings;

/* The knobs' defaults and ranges are rows of the knob table
 * (settings_fields.c, and each technique's NAME_fields.c); the preset's knobs, rows of the preset table
 * (settings.c). What follows are the rules' constants the tables and the
 * planner share. */
#define LPV_AUTO_CASCADES 3            /* auto cascades, when the camera stands inside a wide scene */
#define LPV_CASCADE_WIDE_RATIO 4.0f    /* auto cascades: only for a scene whose longest side is at least
                                            this x its shortest (a level, not a room), seen from inside */
#define LPV_CASCADE_AUTO_FRACTION 0.25f  /* auto cascade_size: this x the scene's longest side, so
                                            3 cascades of ratio 2 span the whole scene */
#define LPV_CASCADE_LONG_RATIO 4.0f    /* auto cascade_size of a long scene (longest side at least this x
                                            the second longest): cells LPV_CASCADE_LONG_CELL x the
                                            second longest (lpv_cascade_finest_size) */
#define LPV_CASCADE_LONG_CELL 0.75f    /* measured on scenes/tunnel.glb (docs/cascades.md, "Long scenes and
                                            narrow spaces"); used where the camera's space is not measured */
#define LPV_VIEW_ACROSS 0.75f          /* the width of the space the camera stands in, as a share of its
                                            median chord (core/reach.h, lpv_reach_view_chord: 3.4 m in a 3 m
                                            x 2.6 m tunnel): the auto cascades' cells (lpv_cascade_finest_size).
                                            The long scene's LPV_CASCADE_LONG_CELL of its cross-section,
                                            measured instead */
/* Auto camera surfel step: this many surfels per finest cell along the
 * image's height when the grid spans it (seed 000: the camera's buffers are
 * down-sampled before surfel injection). */
#define LPV_CAMERA_SURFELS_PER_CELL 4
#define LPV_MAX_CAMERA_SURFEL_STEP 64
/* Auto RSM VPL step: LPV_RSM_AUTO_STEP. A block of 2 x 2 texels never has
 * more groups than its slots (LPV_BLOCK_SLOTS), so the auto step changes no
 * cell's light or blocking at any grid (each block already gives one VPL per
 * cell it reaches: the VPL count follows what the grid resolves); a larger
 * step can merge groups past the slots (an RSM texel of a light near a
 * corner sees several cells and both walls).
 * LPV_RSM_AUTO_VPL_STEP: the auto step of the layers whose surfels the
 * geometry volume leaves out (the area light samples after the first, whose
 * RSMs see the same surfaces: rsm.frag), which give VPLs only. Blocks of 4 x 4
 * texels into 8 slots: on the built-in Cornell box and the blinds room the
 * injected volumes equal those of one VPL per texel within float rounding
 * (tests/test_downsample.c), and the accuracy sweep's errors are the same to
 * four digits at grids 4 to 64 (docs/accuracy.md, "The down-sampling knobs and the lookup step on the front"), for half
 * the area lights' VPLs. The surfels stay at LPV_RSM_AUTO_STEP: at 4 the
 * Cornell box's geometry volume moved by 5 % of its peak. */
#define LPV_RSM_AUTO_STEP 2
#define LPV_RSM_AUTO_VPL_STEP 4
#define LPV_MAX_RSM_VPL_STEP 64
#define LPV_MAX_LOOKUP_STEP 4
#define LPV_MAX_AREA_SHADOW_STEP 4

/* Fills defaults into zero fields: preset 0 becomes BALANCED, then zero
 * grid_dims / rsm_size / occlusion take the preset's values, zero iterations
 * the preset's scaled to the grid (lpv_settings_scaled_iterations), the
 * other zero fields the engine's defaults. An out-of-range preset is left as
 * is (and its fields untouched) for lpv_settings_validate() to report. */
void lpv_settings_resolve(lpv_settings *s);

/* The iteration count an unset iterations resolves to: the preset's count
 * times the longest axis of s->grid_dims over the preset's grid, rounded up
 * (light moves about a cell a step, so it crosses the same share of the grid,
 * the same metres over the same bounds, at any resolution), clamped to
 * 1..LPV_MAX_ITERATIONS. *wanted (if not NULL): the count before the clamp.
 * A grid_dims of zeros counts as the preset's grid. */
int lpv_settings_scaled_iterations(const lpv_settings *s, int *wanted);

/* One sentence on why s->lpv.iterations (resolved) is what it is, for the
 * plan and the warnings. Returns 1 when it is a warning: an explicit count
 * under half the grid's longest axis (light stops short of the grid), or a
 * scaled count the LPV_MAX_ITERATIONS clamp cut; else 0. */
int lpv_settings_iterations_note(const lpv_settings *s, char *buf, unsigned long n);

/* Writes a preset's values into *out: a zeroed lpv_settings with preset,
 * grid_dims, iterations, rsm_size and occlusion set (DEFAULT gives balanced).
 * Returns 0, or -1 for an unknown preset (out untouched). */
int lpv_preset_settings(lpv_preset p, lpv_settings *out);

/* "fast", "balanced" or "accurate" -> *out. Returns 0, or -1 for any other
 * name (out untouched). */
int lpv_preset_from_name(const char *name, lpv_preset *out);

/* "lpv" (LPV_TECHNIQUE_LPV, ...) -> *out. Returns 0, or -1 for any other
 * name (out untouched). */
int lpv_technique_from_name(const char *name, lpv_technique_id *out);
/* The technique's name (LPV_TECHNIQUE_ID_DEFAULT_IS's for DEFAULT), or NULL for an unknown value. */
const char *lpv_technique_name(lpv_technique_id t);
/* The technique names, comma separated, for help and errors. */
const char *lpv_technique_names(void);

/* What a technique can give beyond irradiance (core/settings.c's table). */
typedef enum lpv_technique_cap {
    LPV_CAP_AO = 1u << 0, /* an ambient occlusion term (frame terms "ao", its iv_ao knob) */
} lpv_technique_cap;
/* Whether technique t (DEFAULT: LPV_TECHNIQUE_ID_DEFAULT_IS; auto: none
 * until resolved) has cap. */
int lpv_technique_has(lpv_technique_id t, lpv_technique_cap cap);
/* 0 when settings s running technique `running` give an ambient occlusion
 * term (a technique with LPV_CAP_AO, its ao knob on); else -1 with why in
 * err, naming the technique and the knob. The one place of that rule. */
int lpv_ao_check(const lpv_settings *s, lpv_technique_id running, char *err, size_t n);
/* The technique's own rules on s beyond each knob's range (its row of
 * techniques/registry.c; the octree: a cubic power-of-two grid): 0, or -1
 * with why in err. lpv_settings_validate calls it. */
int lpv_technique_validate(const lpv_settings *s, char *err, size_t n);

/* The preset's name ("balanced" for DEFAULT), or NULL for an unknown value. */
const char *lpv_preset_name(lpv_preset p);

/* The preset names, comma separated ("fast, balanced, accurate"), for help
 * and error messages. */
const char *lpv_preset_names(void);

/* The preset whose grid_dims / iterations / rsm_size / occlusion equal those
 * of the resolved settings s, or LPV_PRESET_DEFAULT when none does (the
 * accuracy sweep labels its points with it). */
lpv_preset lpv_preset_match(const lpv_settings *s);

/* The four departures from the paper (docs/propagation.md) as the letters
 * "cbfs" (central transport, normal bins, far field, scene surfels), '-' for
 * each that is not on; the sweep's, the bench's and --help's name for them.
 * Writes 5 bytes to buf and returns it. */
const char *lpv_settings_departures(const lpv_settings *s, char buf[5]);

/* 1 when the settings fix the grid bounds (any of bounds_min/max non-zero);
 * all six zero means "the scene's bounds". */
int lpv_settings_bounds_given(const lpv_settings *s);

/* Cells of the settings' grid (grid_dims multiplied). */
double lpv_settings_grid_cells(const lpv_settings *s);

/* Checks ranges after resolve; on failure writes a message naming the setting
 * into err and returns -1. */
int lpv_settings_validate(const lpv_settings *s, char *err, unsigned long err_size);

/* The camera surfel step in effect for an image image_h pixels high:
 * camera_surfel_step when set, else image_h / (LPV_CAMERA_SURFELS_PER_CELL x
 * the grid's largest dimension), at least 1. */
int lpv_settings_camera_surfel_step(const lpv_settings *s, int image_h);
/* The RSM VPL step in effect for RSM faces of `tile` texels a side whose
 * surfels feed the geometry volume (surfels 1) or not (0): rsm_vpl_step when
 * set, else LPV_RSM_AUTO_STEP or LPV_RSM_AUTO_VPL_STEP; then the largest
 * power of two not above it that divides tile, at least 1, so blocks never
 * straddle two faces. */
int lpv_settings_rsm_vpl_step(const lpv_settings *s, int tile, int surfels);

#endif /* LPV_SETTINGS_H */
