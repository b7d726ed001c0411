/*
 * iv_internal.h - the imperfect volume's state, shared by its files
 * (technique_iv.c: the lpv_technique_class, placement and storage;
 * iv_cloud.c: the scene's point cloud; iv_passes.c: the tick's passes). Not seen outside techniques/iv/gpu/; like the LPV's
 * passes, these take the technique's state and the tick's inputs, never the
 * engine.
 */
#ifndef LPV_IV_INTERNAL_H
#define LPV_IV_INTERNAL_H

#include "atlas.h"
#include "gl_util.h"
#include "iv_points.h"
#include "technique.h"

/* The atlas's attachments: r, g, b SH sums, normal + count, albedo + area,
 * folded normal + signed area (added), then the points' greatest place in
 * the voxel and 1 - their least (from IV_ATTACHMENT_MAX on: the greatest
 * kept; LPV_IV_COVER). */
#define IV_ATTACHMENTS 8
#define IV_ATTACHMENT_MAX 6
/* Rays per dispatch of a march (lpv_iv_march_volume): 32768 voxels at the
 * default 128 rays, a few tens of ms on llvmpipe. */
#define LPV_IV_MARCH_CHUNK_RAYS ((size_t)1 << 22)

typedef struct lpv_iv_gpu {
    lpv_technique base;
    lpv_settings settings;
    lpv_grid grid;    /* of the last commit */
    lpv_grid pending; /* of the last place */
    GLuint prog_points, prog_reproject, prog_splat, prog_resolve, prog_emit, prog_gather, prog_tail, prog_filter;
    GLuint empty_vao, grid_ubo, tail; /* tail: iv_tail.comp's totals and ratio */
    lpv_atlas atlas;
    GLuint voxels, occupancy, emit, radiance[2], tail_base, ao; /* tail_base: I_{K-2} for the tail */
    GLuint splats;       /* IvSplat: iv_reproject.comp's sums per block and voxel, for the splat */
    size_t splat_slots;  /* allocated for */
    int result;       /* radiance[result] holds the last gather: what the lookup reads */
    size_t cells;     /* allocated for */
    int alloc_dims[3];
    int bounces_run;  /* by the last computed tick */
    int tail_run;     /* the last computed tick added the tail (iv_tail.comp) */
    int filter_run;   /* the last computed tick filtered the surface voxels (iv_filter.comp) */
    /* the scene's point cloud (iv_cloud.c; techniques/iv/core/iv_points.h) */
    GLuint points;            /* IvPoint sorted by voxel of cloud_grid, 0 = not sampled */
    GLuint point_starts;      /* uint per voxel + 1: where each voxel's points begin (iv_points.comp) */
    size_t *chunk_ends;       /* voxel ends of iv_points' dispatches, about LPV_ATLAS_SPLAT_CHUNK points each */
    size_t chunk_count;
    lpv_iv_point_stats cloud; /* what sampling it gave (cloud.points: its count) */
    lpv_grid cloud_grid;      /* the volume it was made for (its pieces split by its voxel, kept in its box) */
} lpv_iv_gpu;

/* The class (technique_iv.c), listed in techniques/classes.c. */
extern const lpv_technique_class lpv_technique_iv;

/* The class's sample_scene and samples_stale (iv_cloud.c): the point cloud
 * at the voxel size the settings place over the lit space. */
int lpv_iv_sample_scene(lpv_technique *t, const lpv_technique_scene *sc, char *err, size_t err_size);
int lpv_iv_samples_stale(const lpv_technique *t, const lpv_technique_scene *sc);
void lpv_iv_free_cloud(lpv_iv_gpu *v);

/* Zeroes a buffer (floats or bits alike). */
void lpv_iv_clear_buffer(GLuint b);
/* iv_points, iv_reproject and iv_resolve: the points into the atlas, then
 * into voxel means and occupancy bits. */
void lpv_iv_create_volume(lpv_iv_gpu *v, const lpv_technique_inputs *in);
/* One march over the volume: radiance from the emission (ao 0) into out, or
 * visibility into the AO volume (ao 1). */
void lpv_iv_march_volume(lpv_iv_gpu *v, const lpv_settings *s, GLuint out, int ao, lpv_timer *timer);
/* iv_gather: bounces 1..K, each an emission pass and a march, then with
 * iv_tail on (K >= 3) the bounces after K as a series, then with iv_filter
 * on the surface voxels' plane means; the result in v->radiance[v->result]. */
void lpv_iv_gather_bounces(lpv_iv_gpu *v, const lpv_technique_inputs *in);
/* The ratios (r, g, b) the last tail used (0: none), read back from the GPU. */
void lpv_iv_gpu_tail_ratio(const lpv_iv_gpu *v, float rgb[3]);

#endif /* LPV_IV_INTERNAL_H */
