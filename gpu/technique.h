/*
 * technique.h - the seam between the engine and a GI technique.
 *
 * The engine owns what every technique consumes and runs it once per tick:
 * the scene on the GPU, the lights' reflective shadow maps (VPLs and
 * surfels), the camera's G-buffer and surfels, the scene surfels, the
 * emissive surfaces' VPLs, the medium, the shadow maps and the shading,
 * glossy, media and query passes. A technique turns those inputs into a
 * volume of light and provides the lookup those passes read it with:
 *
 *   C side    an lpv_technique_class (below): a struct of functions;
 *   GLSL side the includes named in lookup_includes, which must define
 *               vec3  lpv_irradiance(vec3 p, vec3 n)  irradiance (W/m^2) of a
 *                                                     surface at p facing n
 *               vec3  lpv_irradiance_listed(vec3 p, vec3 n, out bool done)
 *                                                     the same where it is
 *                                                     cheap (done), else done
 *                                                     = false: the frame then
 *                                                     calls lpv_irradiance in
 *                                                     a second pass
 *                                                     (shade_rest.comp) when
 *                                                     lookup_split says so
 *               vec3  lpv_project(vec3 x, vec4 v)     the SH at x dotted with v
 *                                                     per channel, / cell^2
 *               float lpv_cell_at(vec3 x)             the volume's scale at x (m)
 *               uniform float u_damping;              0 = off
 *             and whatever they bind (bind_lookup binds it). The engine
 *             pastes them into shade.comp, glossy.frag, media.frag and
 *             query.comp when it builds those programs, after grid.glsl
 *             (the SH basis and grid block, which those shaders use too:
 *             a technique may name it, it is pasted once).
 *
 * A technique sees none of the engine: what it needs comes in the structs
 * below. docs/architecture.md, "Adding a technique", walks through writing
 * one; techniques/lpv/gpu/ is the cascaded LPV on this seam.
 */
#ifndef LPV_TECHNIQUE_H
#define LPV_TECHNIQUE_H

#include <stddef.h>

#include "engine.h"
#include "gl.h"
#include "grid.h"
#include "lpv_shared.h"
#include "medium.h"
#include "memory_budget.h"
#include "plan.h"
#include "scene.h"
#include "settings.h"
#include "timer.h"

/* A range of surfels in a storage buffer (LpvSurfel elements). */
typedef struct lpv_surfel_set {
    GLuint buffer;
    size_t first, count;
} lpv_surfel_set;

/* Each punctual light's RSM, the area light samples', the camera's and the
 * scene surfels. */
#define LPV_MAX_SURFEL_SETS (LPV_MAX_LIGHTS + 3)

/* Where the volume must go: the settings, the scene's bounds and the camera.
 * facts are the planner's (for the level count); `others` is the storage the
 * engine's own producers need, so the technique checks the whole budget. */
typedef struct lpv_technique_where {
    const lpv_settings *settings; /* resolved and valid */
    const lpv_plan_facts *facts;
    float bounds_min[3], bounds_max[3];
    const float *eye, *forward;   /* NULL without a camera */
    lpv_memory_need others;
    const lpv_memory_limits *limits;
} lpv_technique_where;

/* What the shared producers made this tick, for the technique's passes. */
typedef struct lpv_technique_inputs {
    const lpv_settings *settings;
    const lpv_plan *plan;         /* this tick's, with the technique's passes decided */
    lpv_timer *timer;             /* each pass records its own stage */
    GLuint rsm_vpls;              /* the RSMs' LpvVpls that carry light, in order (compact.h) */
    GLuint rsm_vpl_draw;          /* their draw command: the count (lpv_atlas_splat_indirect) */
    size_t rsm_vpl_count;         /* at most this many (the RSMs' blocks x slots) */
    GLuint emissive_vpls;         /* the emissive surfaces' VPLs */
    size_t emissive_vpl_count;
    size_t surfel_set_count;      /* the surfaces seen this tick, for occlusion */
    lpv_surfel_set surfel_sets[LPV_MAX_SURFEL_SETS];
    const lpv_medium_gpu *medium; /* attenuation during transport */
    /* For a technique that lights surfaces itself (the imperfect volume):
     * the lights' block and their RSMs' position and albedo layers as
     * shadow maps, and the camera's G-buffer (0 when it did not run this
     * tick). */
    GLuint light_ubo;
    GLuint rsm_position, rsm_albedo;        /* 2D array textures (rsm.frag's targets) */
    GLuint gbuffer[4];                      /* position, normal, albedo, emission (gbuffer.frag) */
    int gbuffer_w, gbuffer_h;
    /* The normals of the scene's largest flat surfaces (core/scene_planes.h),
     * for a lookup that keeps their irradiance per cell. */
    const float (*lookup_planes)[3];
    int lookup_plane_count;
} lpv_technique_inputs;

/* The scene, for a technique that samples it itself (sample_scene). */
typedef struct lpv_technique_scene {
    const lpv_scene *geometry;    /* the engine's copy: triangles, draws, materials, textures */
    const lpv_settings *settings; /* resolved and valid */
    float lit_min[3], lit_max[3]; /* where light can go (the engine's reach), else the scene's box */
    float free_path;              /* of that space (m) */
} lpv_technique_scene;

/* What the volume is: lpv_volume_desc (engine.h, where the tick's stats
 * carry it to readers on other threads). */

/* What read returns. */
typedef enum lpv_volume_part {
    LPV_VOLUME_SUMMED = 0, /* lpv_cell per cell of every level (volumes of a level summed) */
    LPV_VOLUME_STORED,     /* lpv_cell per cell of every volume, as stored */
    LPV_VOLUME_GEOMETRY,   /* lpv_gv_point per geometry-volume point (0 if none) */
    LPV_VOLUME_TRANSMIT,   /* float per cell and direction (0 if none) */
    LPV_VOLUME_INDEX,      /* int32 per level-0 cell: the octree level its light comes from (0 if none) */
    LPV_VOLUME_IV_VOXELS,  /* lpv_iv_voxel per voxel: the imperfect volume's voxels (0 if none) */
    LPV_VOLUME_AO,         /* 4 floats per voxel: SH of the visible directions (0 if none) */
    LPV_VOLUME_VISIBILITY, /* floats: lpv_visibility_values per probe (engine.h; 0 if none) */
} lpv_volume_part;

typedef struct lpv_technique_class lpv_technique_class;

/* An instance: a technique's own struct starts with this. */
typedef struct lpv_technique {
    const lpv_technique_class *cls;
} lpv_technique;

struct lpv_technique_class {
    const char *name;
    /* the GLSL lookup (see the top of this file), NULL-terminated */
    const char *const *lookup_includes;

    /* Builds the programs; the GL context is current. NULL with err. */
    lpv_technique *(*create)(char *err, size_t err_size);
    void (*destroy)(lpv_technique *t);
    /* Takes new (resolved, valid) settings. */
    void (*configure)(lpv_technique *t, const lpv_settings *s);
    /* Optional: a technique that samples the scene itself (iv's point
     * cloud) does it here, on a new scene, a new technique or a change of a
     * knob that touches the samples (LPV_TOUCH_SAMPLES); the engine then
     * makes none of its own samples (emissive VPLs, scene surfels). */
    int (*sample_scene)(lpv_technique *t, const lpv_technique_scene *sc, char *err, size_t err_size);
    /* Optional: 1 when the samples no longer fit sc (the lit space moved
     * the volume they were made for); the engine samples again. */
    int (*samples_stale)(const lpv_technique *t, const lpv_technique_scene *sc);
    /* Where the volume goes now (no GL); *moved: it differs from where the
     * last commit put it. */
    int (*place)(lpv_technique *t, const lpv_technique_where *w, int *moved, char *err, size_t err_size);
    /* Makes the last placement current: uploads it and (re)sizes storage
     * within the budget; *reset: storage was made anew (nothing computed). */
    int (*commit)(lpv_technique *t, const lpv_technique_where *w, int *reset, char *err, size_t err_size);
    /* Decides the tick's passes into the plan, the shared producers' too
     * (core/plan.h's rules for what each technique consumes). */
    void (*plan)(const lpv_technique *t, const lpv_settings *s, const lpv_plan_facts *f, lpv_plan *p);
    /* Runs the plan's technique passes on this tick's inputs. */
    int (*tick)(lpv_technique *t, const lpv_technique_inputs *in, char *err, size_t err_size);
    /* Optional: a technique whose volume carries light from tick to tick
     * (the probes' hysteresis) drops it, so the next tick computes what a
     * fresh engine would (lpv_engine_forget); NULL: nothing is carried. */
    void (*forget)(lpv_technique *t);
    /* Binds what lookup_includes read for prog (in use). */
    void (*bind_lookup)(const lpv_technique *t, GLuint prog, float damping);
    /* Optional: 1 when lpv_irradiance_listed serves most pixels cheaply, so
     * the frame looks up in two passes (shading.glsl, LPV_LOOKUP_SPLIT);
     * NULL or 0: one pass of lpv_irradiance. */
    int (*lookup_split)(const lpv_technique *t);
    void (*describe)(const lpv_technique *t, lpv_volume_desc *d);
    /* Copies a part of the volume computed under plan `last` (which: an
     * lpv_grid_which for the light's parts); returns elements written. */
    size_t (*read)(lpv_technique *t, const lpv_plan *last, lpv_volume_part part, lpv_grid_which which, void *out,
                   size_t max);
    /* Adds the technique's storage at its current placement to n. */
    void (*memory_need)(const lpv_technique *t, lpv_memory_need *n);
    /* Fills the technique's counts of the stats for the plan `last`. */
    void (*stats)(const lpv_technique *t, const lpv_plan *last, lpv_engine_stats *s);
};

/* The class of a technique (core/settings.h's ids; the table of
 * techniques/classes.c, which names each module's class), or NULL for an id
 * without one. */
const lpv_technique_class *lpv_technique_class_of(lpv_technique_id id);

#endif /* LPV_TECHNIQUE_H */
