/*
 * technique_ids.h - the techniques lpvd knows, by name and id: the one
 * list a new technique adds itself to (with its rows in registry.c and
 * classes.c, docs/architecture.md "Adding a technique"). core/settings.h
 * includes it, so every layer names techniques by these.
 */
#ifndef LPV_TECHNIQUE_IDS_H
#define LPV_TECHNIQUE_IDS_H

/* The GI techniques' names (gpu/technique.h's class names; the wire's and the
 * knob description's "technique"; --technique and CONFIG's "technique"). */
#define LPV_TECHNIQUE_LPV "lpv"       /* cascaded light propagation volumes (techniques/lpv/gpu/) */
#define LPV_TECHNIQUE_OCTREE "octree" /* octree light propagation volumes (techniques/octree/gpu/technique_octree.c) */
#define LPV_TECHNIQUE_IV "iv"         /* imperfect volumes (techniques/iv/gpu/) */
#define LPV_TECHNIQUE_AUTO "auto"     /* the planner chooses from the scene and the preset (core/plan.c) */
#define LPV_TECHNIQUE_PROBES "probes" /* ray-traced irradiance probes with visibility (techniques/probes/) */

/* Which technique computes the volume; 0 means "the default"
 * (LPV_TECHNIQUE_ID_DEFAULT_IS, below). The names, capabilities and tick
 * costs are techniques/registry.c's table, the classes techniques/classes.c's. */
typedef enum lpv_technique_id {
    LPV_TECHNIQUE_ID_DEFAULT = 0,
    LPV_TECHNIQUE_ID_LPV = 1,
    LPV_TECHNIQUE_ID_OCTREE = 2,
    LPV_TECHNIQUE_ID_IV = 3,
    LPV_TECHNIQUE_ID_AUTO = 4, /* not a class: the engine resolves it (lpv_technique_choose) */
    LPV_TECHNIQUE_ID_PROBES = 5,
    LPV_TECHNIQUE_ID_COUNT_ /* one past the last; not a technique */
} lpv_technique_id;

/* The technique when none is named (lpvd render, serve, batch and the
 * library): written here once; lpv_settings_resolve, lpv_technique_name,
 * lpv_technique_choose and techniques/classes.c read it; lpv, octree, iv or
 * auto (then lpv_technique_choose's rules decide). Why it is auto (the
 * best light for the time on the accuracy set against converged light):
 * docs/accuracy.md, "Which technique by default (issue 30)". */
#define LPV_TECHNIQUE_ID_DEFAULT_IS LPV_TECHNIQUE_ID_AUTO

#endif
