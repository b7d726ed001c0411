/*
 * plan.h - the tick planner: "simulate only the effects a scene calls for".
 *
 * Before every tick the engine gathers facts about the scene, the settings
 * and what changed since the last computed tick, and lpv_plan_make decides
 * how many cascades to use, whether anything must be recomputed at all, and
 * which passes run. Every pass that does not run carries the reason, so
 * --stats, the daemon's STATS reply and each stream header can say what ran
 * and why. Pure logic, no GL: tests/test_plan.c checks every rule, the GPU
 * tests check that a skipped pass really costs nothing.
 */
#ifndef LPV_PLAN_H
#define LPV_PLAN_H

#include <stddef.h>

#include "settings.h"

typedef enum lpv_pass_id {
    LPV_PASS_RSM = 0,   /* reflective shadow maps of the punctual lights and area light samples */
    LPV_PASS_EMISSIVE,  /* injection of the emissive surfaces' VPLs (only with area lights off) */
    LPV_PASS_INJECT,    /* VPL injection into the cascades */
    LPV_PASS_GBUFFER,   /* the camera's G-buffer (surfels for the GV) */
    LPV_PASS_GV,        /* geometry volume and transmittances (fuzzy occlusion) */
    LPV_PASS_PROPAGATE, /* propagation steps */
    LPV_PASS_BOUNCE,    /* multiple bounces off GV blockers (inside propagation) */
    LPV_PASS_GLOSSY,    /* glossy march at render time */
    LPV_PASS_MEDIA,     /* participating media single scattering at render time */
    LPV_PASS_IV_POINTS,    /* imperfect volume: the point cloud lit and splatted into the voxels */
    LPV_PASS_IV_REPROJECT, /* imperfect volume: the camera's visible points refine the voxels */
    LPV_PASS_IV_GATHER,    /* imperfect volume: radiance gathered per voxel by ray marching, per bounce */
    LPV_PASS_IV_AO,        /* imperfect volume: ambient occlusion by ray marching */
    LPV_PASS_TRANSLUCENT,  /* the BLEND surfaces' layer shaded and laid over the frame at render time */
    LPV_PASS_PROBES,       /* probes: a budget of probes traced through the scene's BVH and blended in */
    LPV_PASS_COUNT
} lpv_pass_id;

#define LPV_PLAN_REASON_MAX 128

typedef struct lpv_plan_facts {
    unsigned lights;           /* punctual lights */
    size_t emissive_vpls;      /* VPLs sampled on emissive surfaces */
    unsigned emissive_surfaces; /* emissive draws (surfaces) */
    size_t area_light_samples; /* samples the emitters light the scene through directly; 0 = area lights
                                  off or nothing emits */
    size_t occluder_triangles; /* triangles of non-emissive materials */
    size_t glossy_draws;       /* draws whose material is glossy under the settings */
    size_t blend_draws;        /* draws whose material is alphaMode BLEND */
    int has_medium;            /* the scene or the fog settings give a medium */
    int has_view;              /* a camera is set */
    int camera_inside;         /* the camera stands inside the scene's bounds */
    float scene_extent;        /* m, the scene bounds' longest axis */
    float scene_shortest;      /* m, the scene bounds' shortest axis */
    float scene_middle;        /* m, the scene bounds' middle axis (the second longest: a tunnel's
                                  width, a room's depth) */
    float view_chord;          /* m, how wide the space is around a camera inside the scene
                                  (lpv_reach_view_chord; 0 = not measured, INFINITY = open) */
    float cascade_finest;      /* m, the finest cascade's extent (lpv_cascade_finest_size) */
    float scene_cross;         /* m, a long scene's cross-section (lpv_cascade_cross_section), else 0 */
    int bounds_given;          /* the settings fix the grid bounds */
    int cascades_unfit;        /* snapped cascades cannot be placed over the scene (lpv_cascades_fit) */
    float scene_reach;         /* m, the scene bounds' largest |coordinate| */
    float free_path;           /* m, the scene's mean free path (core/reach.h), 0 = unknown */
    float lit_min[3], lit_max[3]; /* m, where light can go when that is much less than the scene: the lit
                                  air's box (core/reach.h lit_min, within the bounds, at most
                                  LPV_REACH_LIT_BOX_SHARE of their volume), what the imperfect volume then
                                  covers; all 0: the scene's bounds */
    float lit_free_path;       /* m, the free path of the lit air (with lit_min) */
    /* what changed since the last computed tick */
    int first_tick;            /* nothing computed yet */
    int scene_changed;         /* geometry or materials */
    int lights_changed;
    int settings_changed;      /* a knob that shapes the volume changed (core/settings_fields.h) */
    char settings_knob[32];    /* its key, for the reason ("" unknown) */
    int forced;                /* the caller asked for a recompute (lpv_engine_invalidate) */
    int placement_changed;     /* a cascade's snapped placement differs */
    float camera_move_cells;   /* camera travel since the last computed tick, in finest cells */
} lpv_plan_facts;

/* Technique auto (LPV_TECHNIQUE_ID_AUTO): what the planner runs instead. */
#define LPV_AUTO_IV_MAX_TRIANGLES 1000000 /* above: the imperfect volume's point cloud costs seconds per change */
/* The imperfect volume's cubic voxels (the longest axis over iv_resolution)
 * must fit this many times across the scene's middle axis, else auto runs
 * the probes, whose cascades follow a long scene's cross-section: the
 * 240 m tunnel's 15 m voxels over its 3.4 m width left iv the worst of the
 * three there (docs/accuracy.md, "Which technique by default (issue 30)"),
 * and the probes beat the cascaded LPV on the tunnels ("auto and the
 * probes (issue 34)"). */
#define LPV_AUTO_IV_MIN_VOXELS_ACROSS 2.0f

typedef struct lpv_plan {
    char technique[16];                     /* the technique that computed the volume (its class's name) */
    char technique_reason[LPV_PLAN_REASON_MAX]; /* why: the request, or auto's choice and its reason */
    int cascades;                           /* grids in use: lpv_plan_cascades' count, with the far
                                               field's levels added to one grid (lpv_cascades_count) */
    char cascades_reason[LPV_PLAN_REASON_MAX];
    char iterations_reason[4 * LPV_PLAN_REASON_MAX]; /* why the propagation takes the steps it does
                                               (lpv_settings_iterations_note); "" for technique iv */
    int iterations_warning;                 /* 1: the steps leave light short of the grid (an explicit
                                               count under half its longest axis, or the clamp cut),
                                               or the LPV's grid is too fine to carry it
                                               (lpv_plan_grid_reach_note) */
    int recompute;                          /* 0: the cached volume is served, no tick pass runs */
    char recompute_reason[LPV_PLAN_REASON_MAX];
    int light_stale;                        /* set by a technique that carries light from tick to tick
                                               (the probes): the scene, its lights or a knob that shapes
                                               the volume changed, so what it carries is stale; not a
                                               forced recompute, not a camera move */
    struct {
        int run;
        char reason[LPV_PLAN_REASON_MAX];   /* why it runs or why it is skipped */
    } pass[LPV_PASS_COUNT];
    /* Which of the engine's shared producers' outputs the technique's
     * passes read this tick (the engine gates their read-backs and stats on
     * these, not on the technique's pass ids). */
    struct {
        int emissive_vpls;  /* the emissive surfaces' VPLs */
        int surfels;        /* the RSMs' and the scene's surfels (occlusion) */
        int camera_surfels; /* the camera's surfels */
    } consumes;
} lpv_plan;

/* "rsm", "emissive", "inject", "gbuffer", "gv", "propagate", "bounce",
 * "glossy", "media", "iv_points", "iv_reproject", "iv_gather", "iv_ao",
 * "translucent"; NULL
 * for an unknown id. */
const char *lpv_pass_name(lpv_pass_id id);

/* Cascades the settings and facts call for (1..LPV_MAX_CASCADES) with the
 * reason, the count to hand to lpv_cascades_place (1: one grid over the
 * scene, far field levels not counted); independent of what changed. s must
 * be resolved. */
int lpv_plan_cascades(const lpv_settings *s, const lpv_plan_facts *f, char *reason, size_t reason_size);

/* The rules every technique's plan shares (techniques/NAME/core/NAME_plan.c
 * call them; a technique's plan function is in its rules header). */
/* Sets pass id to run (1) or skip (0) with a reason. */
void lpv_plan_decide(lpv_plan *p, lpv_pass_id id, int run, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* Whether the tick must recompute the volume, with the reason. camera_use:
 * what the camera's view feeds (a recompute when it moves a cell), NULL when
 * nothing computed depends on it. */
int lpv_plan_needs_recompute(const lpv_settings *s, const lpv_plan_facts *f, const char *camera_use, char *why,
                             size_t n);
/* Render-time passes: decided first, they do not depend on a recompute. */
void lpv_plan_render_passes(const lpv_settings *s, const lpv_plan_facts *f, lpv_plan *p, int all);
/* The lights' RSMs (the LPV's VPLs and surfels, the imperfect volume's
 * shadows); area: the area lights' summary, for other reasons. */
void lpv_plan_rsm_pass(const lpv_plan_facts *f, lpv_plan *p, int all, char *area, size_t area_size);
/* The technique for technique auto, from the preset and the scene's facts
 * (never LPV_TECHNIQUE_ID_AUTO), with the reason in why. Any other request
 * is returned as it is ("requested"). */
lpv_technique_id lpv_technique_choose(const lpv_settings *s, const lpv_plan_facts *f, char *why, size_t why_size);

#endif /* LPV_PLAN_H */
