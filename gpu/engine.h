/*
 * engine.h - the GPU light propagation volume engine.
 *
 * One engine per GL context. Give it a scene and settings, optionally a view
 * (camera), then each tick runs, in order:
 *   RSMs (one per light face; emissive surfaces as area light samples) -> VPL
 *   and surfel extraction -> VPL injection (+ emissive-surface VPLs when area
 *   lights are off) -> geometry volume (one per RSM light and the camera,
 *   max-merged) -> transmittances -> propagation -> accumulation,
 * and lpv_engine_render shades the camera's view with direct light (shadow
 * maps, punctual and area lights) and the LPV's irradiance. Every stage is timed with GL timer queries.
 *
 * All functions need the engine's GL context current on the calling thread.
 */
#ifndef LPV_ENGINE_H
#define LPV_ENGINE_H

#include <stddef.h>
#include <stdint.h>

#include "grid.h"
#include "lpv_shared.h"
#include "oracle.h"
#include "plan.h"
#include "scene.h"
#include "settings.h"
#include "view.h"

typedef struct lpv_engine lpv_engine;

typedef enum lpv_frame_terms {
    LPV_TERMS_FULL = 0,          /* direct + gain * LPV + emission */
    LPV_TERMS_INDIRECT_ONLY = 1, /* gain * LPV only (albedo / pi * E_lpv) */
    LPV_TERMS_DIRECT_ONLY = 2,   /* direct + emission */
    LPV_TERMS_AO = 3,            /* ambient occlusion, grey, 1 = open (technique iv with iv_ao on) */
} lpv_frame_terms;

#define LPV_STAGE_MAX 16

/* What the last tick and render did: GPU milliseconds per stage (timer
 * queries), dispatches and draws per stage, and counts. */
/* What a volume's levels are, for a reader that has only the volume (the
 * daemon's description, SPEC R5.10 - R5.14). */
typedef enum lpv_levels_kind {
    LPV_LEVELS_CASCADES = 0,  /* an LPV's cascades (or far-field levels): radiant intensity per cell, W/sr,
                                 read by the trilinear lookup / cell_size^2 (R5.7) */
    LPV_LEVELS_IV_VOXELS = 1, /* technique iv's one level of voxels: the radiance arriving at each voxel centre,
                                 W/(m^2 sr), read by the imperfect volume's reconstruction (techniques/iv/core/oracle_iv.h
                                 lpv_iv_irradiance, R5.14), which also needs which voxels hold a surface
                                 (lpv_engine_read_iv_voxels) and iv_neighbours below */
} lpv_levels_kind;

/* What the volume is: its levels (cascades) and what a cell holds, as the
 * technique describes it (lpv_technique_class.describe, technique.h). */
typedef struct lpv_volume_desc {
    const char *technique;        /* the class's name (static) */
    int levels;                   /* 1..LPV_MAX_CASCADES */
    lpv_grid level[LPV_MAX_CASCADES];
    float origin_cells[LPV_MAX_CASCADES][3]; /* each level's lower corner in its cells, exactly as the shaders
                                                place it (grid.glsl cascade_coords) */
    int far_field;                /* level k + 1 carries on the light of level k */
    int vpl_spread;               /* VPLs are spread over the 2 x 2 cells around them along their surface
                                     (settings lpv.smooth_injection): the RSMs' VPLs group by that
                                     stencil (block_groups.glsl) */
    int volumes_per_level;        /* 1, or the normal bins */
    int values_per_cell;          /* floats: 12 = SH bands 0-1 of r, g, b */
    lpv_levels_kind kind;         /* what the levels are and how they are looked up */
    const char *units;            /* of the values (static): "W/sr" (cascades), "W/(m^2 sr)" (iv voxels) */
    int iv_neighbours;            /* LPV_LEVELS_IV_VOXELS: the lookup's voxels (settings iv.neighbours); else 0 */
    /* Technique probes: each cell's probe also has visibility
     * (lpv_engine_read_visibility, SPEC R5.15); 0 for the others. */
    int visibility_side;          /* > 0: texels a side of each probe's distance map */
    int irradiance_side;          /* texels a side of each probe's irradiance map */
    float visibility_bias_cells;  /* the lookup's point moves this far along the normal (cells) */
    int index_levels;             /* the merged grid comes from levels the technique can also give whole, with
                                     an index volume over level 0 (the octree: lpv_engine_read_volumes,
                                     lpv_engine_read_index; SPEC R5.13's content "levels"); else 0 */
} lpv_volume_desc;

/* One of a technique's own counts in the stats. */
typedef enum lpv_stat_kind {
    LPV_STAT_INT = 0,  /* v[0], a whole number */
    LPV_STAT_BOOL,     /* v[0], 0 or 1 */
    LPV_STAT_REAL3,    /* v[0..2], e.g. per channel */
} lpv_stat_kind;
typedef struct lpv_stat {
    const char *name;  /* static; a JSON key */
    lpv_stat_kind kind;
    double v[3];
} lpv_stat;
#define LPV_TECHNIQUE_STATS_MAX 16

typedef struct lpv_engine_stats {
    int stage_count;
    struct {
        char name[32];
        double gpu_ms;
        double cpu_ms;
        unsigned calls; /* dispatches + draws */
    } stages[LPV_STAGE_MAX];
    unsigned lights, rsm_faces, rsm_size; /* lights: punctual ones */
    unsigned area_lights;                  /* area light samples (emissive surfaces) */
    size_t vpls_rsm, vpls_emissive, vpls_injected_capacity;
    size_t surfels_rsm, surfels_camera;
    int cascades;
    size_t cells; /* of all cascades */
    int iterations;
    double cell_steps;
    int occlusion;
    unsigned long scene_uploads, scene_samplings; /* lpv_engine_counters, as of this tick */
    /* pixels of the last frame whose indirect light took the technique's full
     * lookup (shade_rest.comp) instead of their normal's own volume
     * (lookup.glsl; 0 with the lookup step, or before a frame) */
    size_t frame_full_lookups;
    /* pixels of the last frame whose area light took every sample's shadow
     * map (area_shadow_rest.comp) because no block of the area shadow step
     * around them lies on their surface (0 at step 1, or before a frame) */
    size_t frame_area_shadow_pixels;
    /* The technique's own counts, by name (its class's stats fills them;
     * the stats JSON puts them in an object named after the technique):
     * technique iv's are what the tick's imperfect volume was made of
     * (docs/imperfect-volumes.md). lpv_stats_put, lpv_stats_get. */
    int technique_stat_count;
    lpv_stat technique_stats[LPV_TECHNIQUE_STATS_MAX];
    /* where light can reach (core/reach.h, docs/propagation.md 6d): the
     * scene's voxels of air and which a light reaches; the frame multiplies
     * the technique's light by it */
    struct {
        int on;               /* the mask is in use (setting reach on, a scene, not unsure) */
        int per_pixel;        /* the frame reads it per pixel: the camera does not stand in lit air (in
                                 lit air every surface it sees faces that air, so it reads 1) */
        int unsure;           /* a light had no air around it: nothing is taken away */
        float voxel_m;        /* voxel side, m */
        int dims[3];
        unsigned components;  /* air spaces (6-connected) */
        unsigned lit_components;
        size_t dark_voxels;   /* air no light reaches */
        size_t lit_voxels;
    } reach;
    /* the volume these stats' tick computed: a copy, so a reader on another
     * thread (the daemon's encoder) gets it with the tick's cells */
    lpv_volume_desc volume;
} lpv_engine_stats;

/* The engine's costly scene work since it was created, for tests and the
 * daemon's stats: a CONFIG or a light move must not redo what it does not
 * touch (core/settings_fields.h, lpv_touch). */
typedef struct lpv_engine_counters {
    unsigned long scene_uploads;   /* geometry, materials and textures sent to the GPU */
    unsigned long scene_samplings; /* emissive VPLs and scene surfels drawn from the scene */
} lpv_engine_counters;

lpv_engine_counters lpv_engine_get_counters(const lpv_engine *e);

lpv_engine *lpv_engine_create(char *err, size_t err_size);
void lpv_engine_destroy(lpv_engine *e);

/* Sets the memory the engine may allocate to bytes, or to the device's
 * budget (half of the video memory or RAM, gpu/memory_limits.c) when that
 * is lower, whatever earlier calls said; source says where the cap comes
 * from in refusals (e.g. "--max-world-memory"). The daemon sets it before
 * every tick: its share of all worlds' memory moves. */
void lpv_engine_set_memory_cap(lpv_engine *e, uint64_t bytes, const char *source);

/* Bytes of storage the engine's current settings, lights, view and
 * technique call for (core/memory_budget.h's estimate): what it holds after
 * a tick. */
uint64_t lpv_engine_memory_bytes(const lpv_engine *e);

/* Uploads the scene (geometry, materials, textures, lights) and samples its
 * emissive surfaces into VPLs and keeps them for the area light samples. The
 * scene may be freed afterwards (the engine keeps a copy of its geometry to
 * re-sample it when a knob changes). A scene whose geometry, materials,
 * textures and medium equal the current one's only updates the lights:
 * nothing is uploaded again. The grid is re-placed from the settings and the
 * scene's bounds. */
int lpv_engine_set_scene(lpv_engine *e, const lpv_scene *scene, char *err, size_t err_size);

/* Copies, resolves and validates settings (zero fields get defaults). A
 * change recomputes only what the changed knobs touch (lpv_touch): the
 * scene's samples, the volume (the next tick recomputes, the planner naming
 * the knob), the shadow maps, or nothing but the next render's shading. */
int lpv_engine_set_settings(lpv_engine *e, const lpv_settings *settings, char *err, size_t err_size);

/* Sets the camera (NULL: none; the GV then uses only the RSMs). */
int lpv_engine_set_view(lpv_engine *e, const lpv_view *view, char *err, size_t err_size);

/* Makes the next tick recompute everything even if nothing changed (the
 * plan says "recompute requested"): for benchmarks that time full ticks. */
void lpv_engine_invalidate(lpv_engine *e);

/* Drops what the technique carries from tick to tick (the probes'
 * history; the others carry nothing), so the next tick computes what a
 * fresh engine makes of the same inputs: for an item whose output must not
 * depend on the items before it (a batch's). The benchmarks' full ticks
 * (lpv_engine_invalidate) keep it. */
void lpv_engine_forget(lpv_engine *e);

/* One item of work, as `lpvd render`, a batch item and a daemon world's tick
 * all run it: what changed since the engine's last item (NULL: unchanged),
 * applied in the one order every program uses, settings, then scene, then
 * view (a scene set after the settings is sampled once, with the knobs it
 * will be ticked with), then, when tick is set, one tick. recompute: the tick
 * recomputes even when the planner would serve the cached volume
 * (lpv_engine_invalidate); forget: the technique's history is dropped
 * first, so the tick is a fresh engine's (lpv_engine_forget). What an
 * item outputs (a frame, a volume, points' irradiance) is the caller's:
 * each program wants different ones. */
typedef struct lpv_engine_item {
    const lpv_settings *settings;
    const lpv_scene *scene;
    const lpv_view *view;
    int recompute;
    int forget;
    int tick;
} lpv_engine_item;

/* Applies the item and ticks when it asks; 0, or -1 with err from the step
 * that failed (lpv_engine_set_settings, _set_scene, _set_view, _tick). */
int lpv_engine_run_item(lpv_engine *e, const lpv_engine_item *item, char *err, size_t err_size);

/* Runs one tick: RSMs through propagation. A tick whose yield hook asked it
 * to stop (lpv_engine_set_yield) returns -1 with err starting with
 * LPV_TICK_ABANDONED; the next tick recomputes everything. */
int lpv_engine_tick(lpv_engine *e, char *err, size_t err_size);
#define LPV_TICK_ABANDONED "abandoned: "

/* Lets the caller run other work while a tick or a render of this engine is
 * under way: between the passes, and between the steps of a long pass, once
 * every_ms of wall time has passed since the last time, the engine finishes
 * what it submitted and calls fn(arg) (gpu/timer.h, "Yield points"). fn may
 * make another GL context current and run other engines there, and must make
 * this engine's context current again before it returns; a nonzero return
 * abandons the tick. fn NULL (the default) never yields. */
void lpv_engine_set_yield(lpv_engine *e, int (*fn)(void *arg), void *arg, double every_ms);

/* Shades the view after a tick into rgba (width*height*4 floats, linear
 * radiance W/(m^2 sr), top row first, alpha 1 where geometry was hit). */
int lpv_engine_render(lpv_engine *e, lpv_frame_terms terms, float *rgba, char *err, size_t err_size);

/* Irradiance (W/m^2, rgb) from the last tick's accumulated LPV at n points
 * (xyz triples) for surfaces with the given normals (xyz triples), the lookup
 * the shading uses. rgb receives 3n floats. Any n: the GPU work goes in
 * chunks of 2^20 points (one dispatch reaches 4,194,240). */
int lpv_engine_irradiance(lpv_engine *e, const float *points, const float *normals, size_t n, float *rgb, char *err,
                          size_t err_size);

/* The finest cascade (cascade 0). */
const lpv_grid *lpv_engine_grid(const lpv_engine *e);
/* Cascades in use after the last tick (1..LPV_MAX_CASCADES) and the placement
 * of cascade k (0 = finest; every cascade has the same dims). */
int lpv_engine_cascade_count(const lpv_engine *e);
const lpv_grid *lpv_engine_cascade(const lpv_engine *e, int k);
/* The plan of the last tick (passes run and skipped, with reasons). */
const lpv_plan *lpv_engine_last_plan(const lpv_engine *e);
const lpv_settings *lpv_engine_settings(const lpv_engine *e);
const lpv_engine_stats *lpv_engine_last_stats(const lpv_engine *e);
/* Sets the technique's count `name` (static) in s, replacing one of that
 * name, else appending it (dropped past LPV_TECHNIQUE_STATS_MAX). */
void lpv_stats_put(lpv_engine_stats *s, const char *name, lpv_stat_kind kind, double a, double b, double c);
/* The technique's count `name` in s, or NULL. */
const lpv_stat *lpv_stats_get(const lpv_engine_stats *s, const char *name);

/* Read-backs for tests and the daemon. Each returns the element count written
 * (at most max), or 0 if nothing exists yet. */
typedef enum lpv_grid_which {
    LPV_GRID_INJECTED = 0,
    LPV_GRID_ACCUMULATED = 1,
    LPV_GRID_LAST_STEP = 2, /* the output of the last propagation step */
} lpv_grid_which;
/* Every cascade's cells, cascade 0 first (cascade k starts at k * cells of one
 * cascade); with one cascade simply the grid. */
size_t lpv_engine_read_grid(lpv_engine *e, lpv_grid_which which, lpv_cell *out, size_t max);
/* With normal bins on (settings.lpv.normal_bins) each cascade holds
 * lpv_engine_bins() volumes, bin b of cascade k at (k * bins + b) * cells of
 * one cascade; read_grid returns their sum per cascade (the physical field),
 * read_volumes every volume as stored. With bins off the two agree. */
size_t lpv_engine_read_volumes(lpv_engine *e, lpv_grid_which which, lpv_cell *out, size_t max);
int lpv_engine_bins(const lpv_engine *e);
/* The geometry volume's total (LpvGvPoint: per travel direction the largest
 * blocking any buffer holds, and the albedo), every cascade's points,
 * cascade 0 first. */
size_t lpv_engine_read_gv(lpv_engine *e, lpv_gv_point *out, size_t max);
size_t lpv_engine_read_transmittance(lpv_engine *e, float *out, size_t max_floats);
/* The octree technique's index volume: per level-0 cell, the level its
 * merged light comes from (0 for techniques without one). With the octree,
 * read_grid(ACCUMULATED) is the merged volume and read_volumes every level's
 * accumulation, level 0 first. */
size_t lpv_engine_read_index(lpv_engine *e, int32_t *out, size_t max);
/* The imperfect volume's voxels after creation (struct IvVoxel per voxel,
 * lpv_shared.h) and its ambient occlusion (4 floats of SH per voxel); 0 for
 * the other techniques. read_grid(ACCUMULATED) is its gathered radiance
 * (W/(m^2 sr)), read_grid(INJECTED) its voxels' direct light. */
size_t lpv_engine_read_iv_voxels(lpv_engine *e, struct IvVoxel *out, size_t max);
size_t lpv_engine_read_ao(lpv_engine *e, float *out, size_t max_floats);
/* The probes' visibility (technique probes; SPEC R5.15 sends it as is):
 * per probe, in read_grid's order, its record
 * (techniques/probes/core/probes_lookup.h: offset, active, irradiance map,
 * distance map), lpv_probes_record_values(volume.irradiance_side,
 * volume.visibility_side) floats. Returns the floats written (whole probes
 * only), 0 for the other techniques. */
size_t lpv_engine_read_visibility(lpv_engine *e, float *out, size_t max_floats);
/* RSM VPLs (punctual lights' and area light samples'), then the emissive VPLs
 * when the last tick injected them (area lights off). */
size_t lpv_engine_read_vpls(lpv_engine *e, lpv_vpl *out, size_t max);
/* The RSMs' VPLs the injection drew at the last tick: those of
 * lpv_engine_read_vpls's RSM part that carry light (position[3] != 0), in
 * their order (gpu/compact.h). Returns how many (at most max copied). */
size_t lpv_engine_read_injected_vpls(lpv_engine *e, lpv_vpl *out, size_t max);
/* Surfels of one GV buffer: 0..P-1 = each punctual light's RSM; P = the area
 * light samples' (when there are any); then the camera (with a view); then
 * the scene surfels (settings.scene_surfels on). */
size_t lpv_engine_gv_buffer_count(const lpv_engine *e);
size_t lpv_engine_read_surfels(lpv_engine *e, size_t buffer, lpv_surfel *out, size_t max);

#endif /* LPV_ENGINE_H */
