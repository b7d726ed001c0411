/*
 * memory_budget.h - what the engine's GPU storage costs, checked before it
 * is allocated (docs/shadows.md, "Memory"). Every knob that sizes storage
 * (rsm_size and shadow_size per light face, the grid and its cascades, the
 * image) is estimated here, and a configuration that does not fit is refused
 * with a message naming the setting and the estimate, instead of failing
 * inside the driver (llvmpipe segfaults on shader storage past 2 GiB).
 * Pure arithmetic, no GL: the limits come from gpu/memory_limits.c.
 */
#ifndef LPV_MEMORY_BUDGET_H
#define LPV_MEMORY_BUDGET_H

#include <stddef.h>
#include <stdint.h>

/* Bytes per element of each kind of storage (the GL formats in gpu/). */
#define LPV_MEM_RSM_TEXEL 56u     /* 3 x RGBA32F + RGBA8 + DEPTH32F per RSM texel */
#define LPV_MEM_VPL 48u           /* one LpvVpl per RSM texel */
#define LPV_MEM_VPL_LIVE 49u      /* per RSM texel: the dense copy of the VPLs that carry light (48), and two
                                     uints per 32 for their live bits and places (gpu/compact.h; rounded up) */
#define LPV_MEM_SURFEL 48u        /* one LpvSurfel per RSM texel or pixel */
#define LPV_MEM_SHADOW_TEXEL 4u   /* DEPTH32F per shadow-map texel */
#define LPV_MEM_SHADOW_TRANSMIT_TEXEL 8u /* RGBA16F per shadow-map texel: what BLEND surfaces let through
                                            (scenes with one, lpv_memory_need.translucent) */
#define LPV_MEM_CELL 504u         /* per cell: 4 LPV buffers (4 x 48), the lookup's 3D textures (48), transmittances (24), reflectances
                                     (96), what the cells send (2 x 48), the injection atlas (3 x RGBA32F) */
#define LPV_MEM_LOOKUP_NORMAL_TEXEL 16u /* RGBA32F per texel of the lookup's normals (LPV_LOOKUP_NORMAL_TEXELS
                                          at most) */
#define LPV_MEM_GV_POINT 80u      /* per geometry-volume point: the total (48, an LpvGvPoint) and atlas
                                     (2 x RGBA32F) */
#define LPV_MEM_CELL_BUFFER 48u   /* the largest single grid buffer (one LpvCell per cell) */
#define LPV_MEM_PIXEL 109u        /* G-buffer (RGBA32F x3, RGBA16F, R8), depth, frame (RGBA32F) per pixel, the
                                     lookup step's and the area shadow step's blocks (2 x RGBA32F each per
                                     block of >= 2 x 2 pixels) and the frame's two lists for second passes
                                     (an ivec2 per pixel each) */
#define LPV_MEM_LAYER_PIXEL 74u   /* the translucent layer per pixel (scenes with a BLEND material): its
                                     G-buffer (RGBA32F x3, RGBA16F, R8), coverage (R8) and frame (RGBA32F) */

/* What the device allows. */
typedef struct lpv_memory_limits {
    uint64_t budget;        /* bytes the engine may hold in all */
    char budget_source[160]; /* where the budget comes from, in words */
    uint64_t max_buffer;    /* bytes one shader storage buffer may hold */
    int max_texture_size;   /* texels per side */
    int max_layers;         /* layers of an array texture */
} lpv_memory_limits;

/* What a configuration asks for. */
typedef struct lpv_memory_need {
    /* faces: layers of side rsm_size / shadow_size; a punctual light's face
     * fills one, an area light sample's five faces are tiles, four to a layer */
    int rsm_size, rsm_faces;       /* texels per side, light faces with an RSM */
    int shadow_size, shadow_faces; /* texels per side, shadow-map faces */
    size_t cells;                  /* grid cells of every cascade */
    size_t gv_points;              /* geometry-volume points of every cascade */
    int cascades;                  /* for the message */
    int grid_dims[3];
    int image_w, image_h;          /* 0 x 0 = no camera */
    int translucent;               /* 1: the scene has BLEND surfaces (the shadow maps' transmission, the
                                      frame's translucent layer) */
    /* A technique's own storage beyond LPV_MEM_CELL a cell (the probes' maps,
     * ray results and BVH), counted with the grid, and its largest single
     * buffer, checked against max_buffer and named in a refusal. */
    uint64_t technique_bytes;
    uint64_t technique_buffer;
    const char *technique_buffer_what;  /* e.g. "the probes' ray results (probes_budget x probes_rays x 16 B)" */
    const char *technique_buffer_lower; /* the knobs that shrink it, e.g. "probes_budget or probes_rays" */
} lpv_memory_need;

/* Bytes of each part, and of all. */
/* The most samples a w x h buffer down-sampled in blocks makes at any step
 * (block_groups.glsl: camera surfels, RSM VPLs and surfels per layer): the
 * size of their buffers. */
uint64_t lpv_memory_block_samples(int w, int h);
uint64_t lpv_memory_rsm_bytes(const lpv_memory_need *n);    /* RSM textures + VPL + surfel buffers */
uint64_t lpv_memory_shadow_bytes(const lpv_memory_need *n); /* shadow maps */
uint64_t lpv_memory_grid_bytes(const lpv_memory_need *n);
uint64_t lpv_memory_image_bytes(const lpv_memory_need *n);
uint64_t lpv_memory_total_bytes(const lpv_memory_need *n);

/* 0 when n fits the limits; else -1 with a message that starts with
 * LPV_MEMORY_REFUSED and names the setting that asks for the most, its
 * estimate and the limit, e.g. "does not fit: rsm_size 2048 x 48 light faces
 * needs 9.66 GB for one VPL buffer; a shader storage buffer may hold at most
 * 2.15 GB". The prefix tells a caller (the daemon: ERROR LIMIT, not INTERNAL)
 * that the settings ask for more than this device or server allows. */
#define LPV_MEMORY_REFUSED "does not fit: "
int lpv_memory_check(const lpv_memory_need *n, const lpv_memory_limits *lim, char *err, size_t err_size);

/* The least any scene needs under settings s (resolved, core/settings.h):
 * one light face of RSM and of shadow map at their sizes times light_faces
 * (at least 1), and the technique's own floor (lpv_technique_memory_floor:
 * for the LPV and the octree their grid at the cascades asked for, for the
 * probes theirs with the probes' maps and a batch's rays; nothing for the
 * imperfect volume or auto, whose grids the scene places). What
 * fails lpv_memory_check here can never run, so the daemon refuses it at
 * CONFIG (issue 31, item 11). */
struct lpv_settings;
void lpv_memory_need_floor(const struct lpv_settings *s, int light_faces, lpv_memory_need *n);
/* Sets n's grid to `levels` grids of s's grid_dims cells (and their
 * geometry-volume points): the LPVs' floor. */
void lpv_memory_need_grid(const struct lpv_settings *s, int levels, lpv_memory_need *n);
/* Adds the technique's own least storage under s to n (its row of
 * techniques/registry.c; none for a technique without one). */
void lpv_technique_memory_floor(const struct lpv_settings *s, lpv_memory_need *n);

#endif /* LPV_MEMORY_BUDGET_H */
