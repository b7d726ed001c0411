/*
 * engine_internal.h - the engine's state: the shared producers' GL objects
 * (scene, RSMs, camera, shadow maps, medium) and the technique it drives
 * (technique.h). Shared by engine*.c and the shared producers' pass files
 * (pass_*.c, light_faces.c); a technique never sees it. Not public API.
 */
#ifndef LPV_ENGINE_INTERNAL_H
#define LPV_ENGINE_INTERNAL_H

#include "area_lights.h"
#include "cascades.h"
#include "engine.h"
#include "error.h"
#include "gl.h"
#include "gl_util.h"
#include "lpv_shared.h"
#include "medium.h"
#include "reach.h"
#include "scene_gpu.h"
#include "block_groups.h"
#include "frame.h"
#include "gbuffer.h"
#include "rsm_maps.h"
#include "shadow_maps.h"
#include "memory_budget.h"
#include "surfel_groups.h"
#include "technique.h"
#include "timer.h"


/* The frame's variants (shade.comp's defines, shading.glsl), a bit each. */
enum {
    LPV_FRAME_DIRECTIONAL = 1, /* the directional lights' loop (scenes that have one) */
    LPV_FRAME_DAMPED = 2,      /* the lookup's damping (settings.lpv.damping > 0) */
    LPV_FRAME_SPLIT = 4,       /* the first of two passes (the technique's lookup_split) */
    LPV_FRAME_BLOCKS = 8,      /* the irradiance from the lookup step's blocks */
    LPV_FRAME_AREA_BLOCKS = 16, /* the area light samples' visibility from the area shadow step's blocks */
    LPV_FRAME_OCCLUSION = 32,   /* the G-buffer's occlusion target (scenes with an occlusionTexture) */
    LPV_FRAME_UNLIT = 64,       /* unlit pixels (scenes with a KHR_materials_unlit material) */
    LPV_FRAME_VARIANTS = 128
};




/* The engine's programs: the shared producers' (built at create, engine.c)
 * and those that read the technique's volume through its lookup (rebuilt
 * with each technique, engine_technique.c). GLuints only: destroy deletes
 * them as one array, so a program added here is freed without another list. */
typedef struct lpv_engine_programs {
    GLuint rsm, vpl_extract, vpl_blocks, vpl_blocks8, gbuffer, camera_surfels, query, glossy, media, shadow;
    /* the frame programs (shade.comp), one per variant (LPV_FRAME_*), built
     * when first used (lpv_engine_frame_program) */
    GLuint frame[LPV_FRAME_VARIANTS];
    GLuint vpl_blocks8_vpls; /* vpl_blocks.comp without the surfels (LPV_BLOCKS_VPLS_ONLY) */
    /* the second pass of a frame in two passes (LPV_FRAME_SPLIT):
     * shade_rest.comp adds the indirect light of the pixels the first listed */
    GLuint shade_rest, shade_rest_damped;
    /* the scene passes' programs without textures, normal maps and alpha cuts
     * (LPV_MATERIAL_PLAIN), for scenes with none (lpv_scene_gpu_program) */
    GLuint rsm_plain, gbuffer_plain, shadow_plain;
    /* the lookup step (settings.lookup_step > 1): the blocks' lookup without
     * and with damping (lookup_blocks.comp); the area shadow step
     * (settings.area_shadow_step > 1): the blocks' area light visibility
     * (area_shadow_blocks.comp) */
    GLuint lookup_blocks, lookup_blocks_damped, area_shadow_blocks;
    GLuint area_shadow_rest; /* the area light of the pixels no block is alike to (area_shadow_rest.comp) */
    GLuint compact[2];       /* compact.comp's scan and copy */
    GLuint translucent;      /* translucent.comp: the translucent layer laid over the frame */
} lpv_engine_programs;
_Static_assert(sizeof(lpv_engine_programs) % sizeof(GLuint) == 0, "lpv_engine_programs holds GLuints only");

struct lpv_engine {
    lpv_settings settings;
    lpv_technique *tech;      /* the GI technique (gpu/technique.h) */
    lpv_technique_id tech_id; /* which (settings.technique, resolved; auto: lpv_technique_choose's) */
    char tech_reason[LPV_PLAN_REASON_MAX]; /* why */
    lpv_volume_desc desc;     /* its volume after the last commit */
    int has_scene;

    /* What changed since the last computed tick (the planner's facts). */
    int computed;             /* a tick computed the volume at least once since set_scene/settings */
    int scene_dirty, lights_dirty, settings_dirty, forced;
    char settings_knob[32];   /* the first knob that touched the volume since the last computed tick */
    uint64_t geometry_sig;    /* hash of vertices, indices, materials */
    float computed_eye[3];
    int computed_has_view;
    size_t occluder_triangles;
    lpv_medium_gpu medium;    /* the scene's participating medium (medium.present), if any */

    lpv_engine_programs progs; /* the shared producers' and the lookup's programs */

    /* scene */
    lpv_scene_gpu geo;        /* its draws, materials and textures on the GPU (scene_gpu.h) */
    GLuint empty_vao;
    lpv_light lights[LPV_MAX_LIGHTS];
    uint32_t light_count;
    float scene_min[3], scene_max[3];
    lpv_scene geometry;       /* the CPU copy the samples below are drawn from (lpv_scene_copy_geometry) */
    GLuint emissive_vpls;
    size_t emissive_vpl_count;
    GLuint scene_surfels;     /* settings.scene_surfel_count over every triangle (GV), 0 = none, grouped by
                                 the GV points of the volume's cascades (core/surfel_groups.h) */
    size_t scene_surfel_count; /* in the buffer: the groups */
    lpv_surfel *scene_surfel_samples; /* the samples themselves, regrouped when the cascades move */
    size_t scene_surfel_sample_count;
    uint64_t scene_surfel_grid_sig; /* the cascades the buffer's groups are for; 0 = none yet */
    /* the scene's flat surfaces' normals for the lookup (core/scene_planes.h) */
    float lookup_planes[LPV_MAX_LOOKUP_PLANES][3];
    int lookup_plane_count;
    lpv_emitter_list emitters;                          /* emissive triangles (area lights) */
    lpv_area_sample area_samples[LPV_MAX_AREA_LIGHTS];  /* the emitters as area light samples */
    size_t area_sample_count;                           /* 0: area lights off or no emitter */
    lpv_reach reach;          /* where light can reach (core/reach.h), for the scene's geometry */
    GLuint reach_tex;         /* its mask for reach.glsl (R8UI 3D), 0 = none */
    float view_chord;          /* m, lpv_reach_view_chord at view_chord_eye (0 = not measured) */
    float view_chord_eye[3];

    /* lights and RSMs */
    struct LpvLightBlock light_block;
    GLuint light_ubo;
    /* each light's clearance (light_faces.c: the distance from its eye to
     * the nearest surface that can shadow what it lights, for its faces'
     * near planes), per light of light_block, and what it was found for:
     * position, normal (an area light sample's; 0 for a punctual light),
     * search radius, geometry_sig */
    struct {
        float distance[LPV_MAX_LIGHTS + LPV_MAX_AREA_LIGHTS];
        float key[LPV_MAX_LIGHTS + LPV_MAX_AREA_LIGHTS][8];
        int pending[LPV_MAX_LIGHTS + LPV_MAX_AREA_LIGHTS]; /* lights whose triangles are to scan */
        int pending_count;
    } clearance;
    lpv_rsms rsm; /* the lights' RSMs and the VPLs and surfels made from them (pass_rsm.c) */

    lpv_shadow_maps shadows; /* direct light's shadow maps (shadow_maps.h) */

    lpv_memory_limits mem_limits; /* of the context, read at create; the budget lowered by caps */
    uint64_t mem_device_budget;    /* the budget as read at create */
    char mem_device_source[160];

    int ticked;               /* a tick ran since the last change that discards the volume */

    /* camera */
    int has_view;
    lpv_view view;
    GLuint view_ubo;
    struct LpvViewBlock view_block;
    lpv_gbuffer gbuf;      /* the camera's G-buffer and surfels (pass_camera.c) */
    lpv_frame frame;       /* the shaded frame and its passes' buffers (frame.c) */

    GLuint query_in, query_out; /* irradiance queries */
    size_t query_capacity;

    lpv_engine_counters counters;
    lpv_timer timer;
    lpv_engine_stats stats;
    lpv_plan plan;
};

/* The scene's GPU objects (engine_scene.c): freed, and the emitters as area
 * light samples under the current settings (none when area lights are off). */
void lpv_engine_free_scene(lpv_engine *e);

/* gpu/reach_volume.c: where light can reach (core/reach.h). build: for the
 * scene's geometry (lpv_engine_set_scene); light: for the engine's lights
 * and emitters, uploading the mask; bind: the technique's lookup and the
 * mask for a program in use that reads the volume (reach.glsl). */
int lpv_engine_reach_build(lpv_engine *e, const lpv_scene *scene, char *err, size_t err_size);
void lpv_engine_reach_light(lpv_engine *e);
void lpv_engine_reach_free(lpv_engine *e);
/* Where light can go and its free path: the lit air's box (core/reach.h)
 * within the scene's bounds while the reach mask is in use and the box holds
 * at most LPV_REACH_LIT_BOX_SHARE of the bounds' volume, else the scene's
 * bounds and free path (returns 0). The imperfect volume covers this box. */
int lpv_engine_lit_region(const lpv_engine *e, float min[3], float max[3], float *free_path);
/* Measures how wide the space around the camera's eye is (view_chord) again when
 * the eye has moved a reach voxel or more since it was measured. */
void lpv_engine_reach_view(lpv_engine *e);
void lpv_engine_bind_lookup(const lpv_engine *e, GLuint prog, float damping);
/* The mask is built and switched on (setting reach, a sure mask); and the
 * frame reads it per pixel (the camera does not stand in lit air). */
int lpv_engine_reach_in_use(const lpv_engine *e);
int lpv_engine_reach_per_pixel(const lpv_engine *e);
void lpv_engine_update_area_samples(lpv_engine *e);
/* The emissive VPLs and scene surfels under the current settings, from
 * e->geometry (engine_scene.c). */
int lpv_engine_sample_scene(lpv_engine *e, char *err, size_t err_size);
/* 1 when the technique's own samples of the scene (iv's point cloud) were
 * made for another volume than the current settings and lit space place:
 * they must be made again (lpv_technique_class.samples_stale). */
int lpv_engine_samples_stale(const lpv_engine *e);

/* The frame program of a variant (LPV_FRAME_* bits), built on first use and
 * kept until the technique changes; 0 with err set if it does not build
 * (engine_technique.c). */
GLuint lpv_engine_frame_program(lpv_engine *e, unsigned variant, char *err, size_t err_size);
/* Deletes the frame programs built so far. */
void lpv_engine_free_frame_programs(lpv_engine *e);
/* Makes technique id the engine's: creates its instance and builds the
 * passes that read its volume with its lookup includes. On failure the
 * current technique stays. */
int lpv_engine_use_technique(lpv_engine *e, lpv_technique_id id, char *err, size_t err_size);

/* Per-pass set-up and work; each _run records its own timer stage. */
int lpv_pass_rsm_prepare(lpv_engine *e, char *err, size_t err_size); /* light faces, RSM storage */
void lpv_pass_rsm_run(lpv_engine *e);
int lpv_pass_gbuffer_run(lpv_engine *e, char *err, size_t err_size); /* -1: the targets could not be allocated */
int lpv_pass_shade_run(lpv_engine *e, lpv_frame_terms terms, char *err, size_t err_size);
void lpv_pass_glossy_run(lpv_engine *e);
/* The translucent layer's frame laid over the frame (LPV_PASS_TRANSLUCENT;
 * after the glossy pass, before media): adds its lists' pixels to *full_lookups
 * and *area_rest_pixels. */
int lpv_pass_translucent_run(lpv_engine *e, lpv_frame_terms terms, size_t *full_lookups, size_t *area_rest_pixels,
                             char *err, size_t err_size);
void lpv_pass_media_run(lpv_engine *e);

/* Surfels [first, first + count) of the RSM surfel buffer that GV buffer
 * `buffer` splats (0, 0 for the camera's or one past the end). */
void lpv_engine_gv_buffer_range(const lpv_engine *e, size_t buffer, size_t *first, size_t *count);

/* Light faces (RSM views) for the scene's lights and area light samples:
 * fills e->light_block and e->rsm's face_count, punctual_faces, layers. */
void lpv_light_faces_build(lpv_engine *e);

/* RSM layers and shadow-map layers the scene's lights and area light samples
 * will need (the rules of lpv_light_faces_build and lpv_shadow_faces_build,
 * without building them): a punctual light's face fills a layer, area light
 * faces are tiles, four to a layer. */
void lpv_light_face_counts(const lpv_engine *e, int *rsm_layers, int *shadow_layers);


/* The shadow-map faces for e->light_block's lights (punctual lights and area
 * light samples) at shadow_size, the directional cascades fitted to e->view.
 * Returns 0 or -1 with err. */
int lpv_shadow_faces_build(const lpv_engine *e, struct LpvShadowBlock *b, char *err, size_t err_size);

/* The engine's shadow maps brought to its lights, scene and view
 * (engine_render.c): builds the faces, checks the memory budget before the
 * maps (re)allocate, and has them redraw what changed (shadow_maps.h).
 * Returns 0 or -1. */
int lpv_engine_shadows_update(lpv_engine *e, char *err, size_t err_size);
/* Each producer deletes what it made (also what a failed allocation left):
 * the passes call these before remaking their storage, and
 * lpv_engine_destroy calls them, so each list of objects is written once. */
void lpv_pass_camera_free(lpv_engine *e);

/* The storage the engine's own producers call for (RSMs, shadow maps, the
 * image; memory_limits.c); the technique adds its own. */
void lpv_engine_memory_need(const lpv_engine *e, lpv_memory_need *n);
/* The engine's and the technique's storage at the current inputs against
 * the context's limits (core/memory_budget.h). Returns 0, or -1 with a
 * message naming the setting. */
int lpv_engine_memory_check(const lpv_engine *e, char *err, size_t err_size);

/* The planner's facts about the scene, the settings and what changed
 * (engine_facts.c). */
void lpv_engine_gather_facts(const lpv_engine *e, lpv_plan_facts *f);
/* Where the technique's volume must go now, under facts f. */
void lpv_engine_where(const lpv_engine *e, const lpv_plan_facts *f, lpv_technique_where *w);
/* engine_technique.c: switches to the technique settings s call for (technique auto: chosen from
 * the scene's facts, lpv_technique_choose) and configures it with s. */
int lpv_engine_resolve_technique(lpv_engine *e, const lpv_settings *s, char *err, size_t err_size);
/* Places and commits the technique's volume for the current inputs without a
 * tick, so lpv_engine_grid() answers right after set_scene/set_settings. */
int lpv_engine_place_volume(lpv_engine *e, char *err, size_t err_size);
/* After a commit: the volume's description, and what a storage reset drops. */
void lpv_engine_committed(lpv_engine *e, int reset);

/* Groups the scene surfels by the GV points of the cascades committed last,
 * unless they already are (engine_scene.c). */
void lpv_engine_group_scene_surfels(lpv_engine *e);

/* The volume's cascades after the last commit as the groups' keys see them
 * (block_groups.glsl, core/surfel_groups.h): fills g and returns how many
 * (0 for a technique without cascades: one group per block). block_groups.c. */
int lpv_engine_group_grids(const lpv_engine *e, lpv_group_grid g[LPV_MAX_CASCADES]);
/* The area lights' RSM layers (after the punctual lights') that hold the
 * first sample's faces: the only ones whose surfels the geometry volume
 * takes (rsm.frag); pass_rsm.c. */
int lpv_engine_area_gv_layers(const lpv_engine *e);

/* The camera's surfels the last G-buffer pass made (pass_camera.c). */
static inline size_t lpv_engine_camera_surfel_count(const lpv_engine *e)
{
    return (size_t)e->gbuf.surfel_w * (size_t)e->gbuf.surfel_h * (size_t)e->gbuf.surfel_slots;
}

#endif /* LPV_ENGINE_INTERNAL_H */
