/*
 * lpv_internal.h - the cascaded LPV technique's state, shared by its files
 * (technique_lpv.c: the lpv_technique_class; lpv_storage.c: placement and
 * buffers; lpv_inject.c; lpv_gv.c; lpv_propagate.c;
 * lpv_read.c). Not seen outside techniques/lpv/gpu/. Each pass takes the state it works
 * on and the tick's inputs, never the engine.
 */
#ifndef LPV_LPV_INTERNAL_H
#define LPV_LPV_INTERNAL_H

#include "atlas.h"
#include "cascades.h"
#include "gl_util.h"
#include "lpv_lookup_volume.h"
#include "technique.h"


typedef struct lpv_cascaded {
    lpv_technique base;
    lpv_settings settings;
    lpv_grid grid;            /* the finest cascade (cascades.grid[0]) */
    lpv_cascade_set cascades; /* placement of the last commit */
    lpv_cascade_set pending;  /* placement of the last place */
    int bins;                 /* LPV volumes per cascade: 1, or LPV_NORMAL_BINS (normal_bins on) */

    /* prog_propagate without the bounce and medium terms, prog_propagate_effects
     * with them (propagate.comp, LPV_PROPAGATE_EFFECTS) */
    GLuint prog_inject_vpl, prog_inject_gv, prog_pack, prog_gv_merge, prog_transmit, prog_propagate,
        prog_propagate_effects, prog_handoff, prog_lookup_pack,
        prog_normals_pack;
    int borrowed_programs;    /* 1: the programs are another state's (the octree's levels share them) */
    GLuint empty_vao;

    GLuint grid_ubo;
    lpv_atlas lpv_atlas, gv_atlas; /* injection's and the geometry volume's */
    GLuint lpv_injected, lpv_ping, lpv_pong, lpv_acc, gv_total, transmit, reflect;
    GLuint lpv_last; /* the buffer the last propagation step (or hand-off) wrote */
    lpv_lookup_volume lookup; /* lpv_acc as the lookup's 3D textures, when lookup_wanted */
    int lookup_wanted;        /* 1: the shading reads this state (the octree's levels are read merged) */
    GLuint sent[2]; /* what the cells a step reads / writes send: LpvCell x flux limits (flux_limit.glsl) */
    GLuint tbo_injected, tbo_ping, tbo_pong, tbo_sent[2], tbo_acc, tbo_transmit, tbo_reflect; /* buffer-texture views */
    size_t grid_alloc_cells; /* cells of all cascades */
    int grid_alloc_dims[3], grid_alloc_cascades, grid_alloc_bins;
} lpv_cascaded;

/* The cascaded LPV's class (technique_lpv.c), listed in techniques/classes.c. */
extern const lpv_technique_class lpv_technique_cascaded_lpv;

/* Cells of one cascade, and of all cascades in use. */
static inline size_t lpv_cascade_cells(const lpv_cascaded *c) { return lpv_grid_cell_count(&c->grid); }
static inline size_t lpv_all_cells(const lpv_cascaded *c)
{
    return lpv_grid_cell_count(&c->grid) * (size_t)c->cascades.count;
}
/* LPV volumes (cascades x normal bins) and their cells: the size of the LPV
 * buffers; the geometry volume and transmittances stay per cascade. */
static inline int lpv_cascade_volumes(const lpv_cascaded *c) { return c->bins > 1 ? c->bins : 1; }
static inline int lpv_volumes(const lpv_cascaded *c) { return c->cascades.count * lpv_cascade_volumes(c); }
static inline size_t lpv_volume_cells(const lpv_cascaded *c)
{
    return lpv_grid_cell_count(&c->grid) * (size_t)lpv_volumes(c);
}

/* The programs that fill a lookup volume from this state's kind of buffer. */
static inline lpv_lookup_programs lpv_cascaded_lookup_programs(const lpv_cascaded *c)
{
    return (lpv_lookup_programs){c->prog_lookup_pack, c->prog_normals_pack};
}

/* A state with its own programs, or sharing owner's (which must outlive it);
 * delete frees storage, the programs it owns and the state (technique_lpv.c). */
lpv_cascaded *lpv_cascaded_new(char *err, size_t err_size);
lpv_cascaded *lpv_cascaded_new_sharing(const lpv_cascaded *owner, char *err, size_t err_size);
void lpv_cascaded_delete(lpv_cascaded *c);

/* Placement and storage (lpv_storage.c). */
int lpv_cascaded_place(lpv_cascaded *c, const lpv_technique_where *w, int *moved, char *err, size_t err_size);
int lpv_cascaded_commit(lpv_cascaded *c, const lpv_technique_where *w, int *reset, char *err, size_t err_size);
/* One grid exactly where g says (the octree's coarser levels: level 0's box
 * in cells 2^i times its size), instead of placing it from the settings. */
void lpv_cascaded_place_grid(lpv_cascaded *c, const lpv_grid *g, int *moved);
void lpv_cascaded_free_storage(lpv_cascaded *c);
void lpv_cascaded_memory_need(const lpv_cascaded *c, lpv_memory_need *n);


/* The passes; each records its own timer stage. */
void lpv_pass_inject_run(lpv_cascaded *c, const lpv_technique_inputs *in, int rsm_vpls, int emissive_vpls);
void lpv_pass_clear_run(lpv_cascaded *c); /* nothing injected: zero the injected grid and the accumulation */
void lpv_pass_gv_run(lpv_cascaded *c, const lpv_technique_inputs *in, int bounce);
void lpv_pass_propagate_run(lpv_cascaded *c, const lpv_technique_inputs *in, int occlusion, int bounce);

/* Read-backs (lpv_read.c). */
size_t lpv_cascaded_read(lpv_cascaded *c, const lpv_plan *last, lpv_volume_part part, lpv_grid_which which,
                         void *out, size_t max);

#endif /* LPV_LPV_INTERNAL_H */
