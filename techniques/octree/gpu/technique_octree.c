/*
 * technique_octree.c - octree light propagation volumes (Olovsson's thesis,
 * the second seed, sections 4.2 and 5.2) as an lpv_technique.
 *
 * A full octree over the n^3 grid: l = log2(n) + 1 levels, level i a uniform
 * grid of (n / 2^i)^3 cells of 2^i times level 0's size over the same box.
 * Each level is a single-cascade LPV state of the cascaded technique
 * (lpv_internal.h; they share one set of programs), so injection, the
 * geometry volume, the transmittances and the propagation scheme are exactly
 * the cascaded LPV's:
 *
 *   inject       the VPLs into level 0 (the cascaded injection)
 *   downsample   level i = the mean of level i - 1's eight children (eq. 11),
 *                i = 1 .. l - 1 (octree_downsample.comp)
 *   gv           every level's geometry volume from the surfels at its own
 *                resolution, as techniques/octree/core/oracle_octree.c does
 *   propagate    every level on its own, k iterations each (p = 1)
 *   merge        M(x) = O_I(x)(x / 2^I(x)), I(x) the finest level holding light
 *                over x (eq. 10; octree_merge.comp)
 *
 * The shading reads M with the cascaded LPV's lookup (one grid, level 0's),
 * as the thesis renders with the ordinary lookup. The knobs are the LPV's
 * (iterations, occlusion, central transport, bounces, damping); cascades,
 * the far field and normal bins do not apply. techniques/octree/core/oracle_octree.c is the
 * reference the tests hold this to (techniques/octree/tests/test_octree_gpu.c).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "lpv_internal.h"
#include "lpv_rules.h"
#include "oracle_octree.h"
#include "shader.h"

/* The class (below), listed in techniques/classes.c. */
extern const lpv_technique_class lpv_technique_octree;

typedef struct lpv_octree_gpu {
    lpv_technique base;
    lpv_settings settings;
    int levels;                              /* l, at the last place */
    lpv_cascaded *level[LPV_OCTREE_MAX_LEVELS];  /* level[0] owns the programs */
    lpv_settings level_settings[LPV_OCTREE_MAX_LEVELS];
    GLuint prog_downsample, prog_merge;
    GLuint merged;                           /* LpvCell per level-0 cell: what the lookup reads */
    GLuint index;                            /* int per level-0 cell: I(x) */
    lpv_lookup_volume lookup;                /* merged as the lookup's 3D textures */
    size_t merged_cells;
} lpv_octree_gpu;

static const char *const INC_DOWNSAMPLE[] = {"grid.glsl", "flux_limit.glsl", NULL};
static const char *const INC_GRID[] = {"grid.glsl", NULL};
static const char *const LOOKUP[] = {"grid.glsl", "lookup.glsl", NULL};

static int log2_exact(int n)
{
    int l = 0;
    while ((1 << l) < n)
        ++l;
    return l;
}

static void free_merged(lpv_octree_gpu *o)
{
    lpv_gl_delete_buffer(&o->merged);
    lpv_gl_delete_buffer(&o->index);
    lpv_lookup_volume_free(&o->lookup);
    o->merged_cells = 0;
}

static void destroy(lpv_technique *t)
{
    lpv_octree_gpu *o = (lpv_octree_gpu *)t;
    if (!o)
        return;
    free_merged(o);
    for (int i = LPV_OCTREE_MAX_LEVELS - 1; i >= 0; --i) /* level 0 last: the others borrow its programs */
        lpv_cascaded_delete(o->level[i]);
    if (o->prog_downsample)
        glDeleteProgram(o->prog_downsample);
    if (o->prog_merge)
        glDeleteProgram(o->prog_merge);
    free(o);
}

static lpv_technique *create(char *err, size_t err_size)
{
    lpv_octree_gpu *o = calloc(1, sizeof *o);
    if (!o) {
        lpv_error(err, err_size, "out of memory");
        return NULL;
    }
    o->base.cls = &lpv_technique_octree;
    o->level[0] = lpv_cascaded_new(err, err_size);
    o->prog_downsample = o->level[0] ? lpv_program_build("octree_downsample.comp", NULL, NULL, INC_DOWNSAMPLE, err,
                                                         err_size)
                                     : 0;
    o->prog_merge = o->prog_downsample ? lpv_program_build("octree_merge.comp", NULL, NULL, INC_GRID, err, err_size)
                                       : 0;
    if (!o->prog_merge) {
        destroy(&o->base);
        return NULL;
    }
    lpv_settings_resolve(&o->settings);
    return &o->base;
}

static void configure(lpv_technique *t, const lpv_settings *s) { ((lpv_octree_gpu *)t)->settings = *s; }

/* Level i's settings: one grid of n / 2^i cells with the LPV's knobs (no
 * cascades, far field or normal bins: a level is one uniform grid). */
static void level_settings(const lpv_settings *s, int i, lpv_settings *out)
{
    *out = *s;
    out->lpv.cascades = 1;
    out->lpv.far_field = LPV_SWITCH_OFF;
    out->lpv.normal_bins = LPV_SWITCH_OFF;
    for (int k = 0; k < 3; ++k)
        out->grid_dims[k] = s->grid_dims[k] >> i;
}

static int place(lpv_technique *t, const lpv_technique_where *w, int *moved, char *err, size_t err_size)
{
    lpv_octree_gpu *o = (lpv_octree_gpu *)t;
    const int n = w->settings->grid_dims[0];
    if (n < 1 || (n & (n - 1)) != 0 || n != w->settings->grid_dims[1] || n != w->settings->grid_dims[2])
        return lpv_error(err, err_size, "technique octree needs a cubic grid of a power of two cells per axis (%dx%dx%d)",
                         w->settings->grid_dims[0], w->settings->grid_dims[1], w->settings->grid_dims[2]);
    const int levels = log2_exact(n) + 1;
    if (levels > LPV_OCTREE_MAX_LEVELS)
        return lpv_error(err, err_size, "an octree over %d^3 cells needs %d levels, at most %d", n, levels,
                         LPV_OCTREE_MAX_LEVELS);
    for (int i = 1; i < levels; ++i)
        if (!o->level[i] && !(o->level[i] = lpv_cascaded_new_sharing(o->level[0], err, err_size)))
            return -1;
    for (int i = levels; i < LPV_OCTREE_MAX_LEVELS; ++i) {
        lpv_cascaded_delete(o->level[i]);
        o->level[i] = NULL;
    }
    int any_moved = o->levels != levels;
    for (int i = 0; i < levels; ++i) {
        level_settings(w->settings, i, &o->level_settings[i]);
        o->level[i]->settings = o->level_settings[i];
        int m = 0;
        if (i == 0) {
            lpv_technique_where w0 = *w;
            w0.settings = &o->level_settings[0];
            if (lpv_cascaded_place(o->level[0], &w0, &m, err, err_size) != 0)
                return -1;
        } else { /* level 0's box, in cells 2^i times level 0's */
            lpv_grid g = o->level[0]->pending.grid[0];
            for (int k = 0; k < 3; ++k)
                g.dims[k] >>= i;
            g.cell_size = ldexpf(g.cell_size, i);
            lpv_cascaded_place_grid(o->level[i], &g, &m);
        }
        any_moved |= m;
    }
    o->levels = levels;
    if (moved)
        *moved = any_moved;
    return 0;
}

static void memory_need(const lpv_technique *t, lpv_memory_need *n)
{
    const lpv_octree_gpu *o = (const lpv_octree_gpu *)t;
    lpv_memory_need sum = {0};
    for (int i = 0; i < o->levels; ++i) {
        lpv_memory_need li = {0};
        lpv_cascaded_memory_need(o->level[i], &li);
        sum.cells += li.cells;
        sum.gv_points += li.gv_points;
    }
    n->cells += sum.cells + (o->levels ? lpv_grid_cell_count(&o->level[0]->grid) : 0); /* + the merged volume */
    n->gv_points += sum.gv_points;
    n->cascades = o->levels;
    if (o->levels)
        memcpy(n->grid_dims, o->level[0]->grid.dims, sizeof n->grid_dims);
}

static int commit(lpv_technique *t, const lpv_technique_where *w, int *reset, char *err, size_t err_size)
{
    lpv_octree_gpu *o = (lpv_octree_gpu *)t;
    *reset = 0;
    /* each level checks the budget with the levels before it (and the merged
     * volume) counted as the engine's own */
    lpv_memory_need others = w->others;
    others.cells += lpv_grid_cell_count(&o->level[0]->pending.grid[0]);
    for (int i = 0; i < o->levels; ++i) {
        lpv_technique_where wi = *w;
        wi.settings = &o->level_settings[i];
        wi.others = others;
        int r = 0;
        if (lpv_cascaded_commit(o->level[i], &wi, &r, err, err_size) != 0)
            return -1;
        *reset |= r;
        lpv_memory_need li = {0};
        lpv_cascaded_memory_need(o->level[i], &li);
        others.cells += li.cells;
        others.gv_points += li.gv_points;
    }
    const size_t cells = lpv_grid_cell_count(&o->level[0]->grid);
    if (o->merged_cells != cells) {
        free_merged(o);
        o->merged = lpv_gl_new_ssbo(cells * sizeof(lpv_cell));
        o->index = lpv_gl_new_ssbo(cells * sizeof(int32_t));
        o->merged_cells = cells;
        *reset = 1;
        if (glGetError() != GL_NO_ERROR)
            return lpv_error(err, err_size, "could not allocate the octree's merged %zu-cell volume", cells);
        if (lpv_lookup_volume_alloc(&o->lookup, o->level[0]->grid.dims, 1, 1, err, err_size) != 0)
            return -1;
    }
    return 0;
}

/* The LPV's rules (techniques/lpv/core/lpv_plan.c), and the octree's levels with the reason the
 * thesis gives: after k steps, levels l-1-floor(log2 k) .. l-1 are covered
 * completely (section 4.2). */
static void plan(const lpv_technique *t, const lpv_settings *s, const lpv_plan_facts *f, lpv_plan *p)
{
    const lpv_octree_gpu *o = (const lpv_octree_gpu *)t;
    lpv_plan_make_lpv(s, f, p);
    const int l = o->levels > 0 ? o->levels : 1, k = s->lpv.iterations;
    int floor_log2_k = 0;
    while (k > 0 && (2 << floor_log2_k) <= k)
        ++floor_log2_k;
    int complete = k > 0 ? l - 1 - floor_log2_k : l - 1;
    if (complete < 0)
        complete = 0;
    p->cascades = l;
    snprintf(p->cascades_reason, sizeof p->cascades_reason,
             "octree: %d levels (%d^3 .. 1^3); %d iterations cover levels %d..%d completely", l, 1 << (l - 1), k,
             complete, l - 1);
}

/* Level i (i >= 1) from level i - 1: eq. 11, with the flux limits of the
 * first propagation step. */
static void downsample(lpv_octree_gpu *o, int i, lpv_timer *timer)
{
    const lpv_cascaded *fine = o->level[i - 1];
    lpv_cascaded *c = o->level[i];
    glUseProgram(o->prog_downsample);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, c->grid_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_VPLS, fine->lpv_injected);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_OUT, c->lpv_injected);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_ACC, c->lpv_acc);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_SENT_OUT, c->sent[0]);
    glUniform3i(glGetUniformLocation(o->prog_downsample, "u_fine_dims"), fine->grid.dims[0], fine->grid.dims[1],
                fine->grid.dims[2]);
    glDispatchCompute(lpv_div_up((size_t)c->grid.dims[0], LPV_WG_2D), lpv_div_up((size_t)c->grid.dims[1], LPV_WG_2D),
                      (GLuint)c->grid.dims[2]);
    lpv_timer_count(timer, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
}

/* eq. 10 into o->merged and the index volume, coarsest level first. */
static void merge(lpv_octree_gpu *o, lpv_timer *timer)
{
    const lpv_cascaded *c0 = o->level[0];
    glUseProgram(o->prog_merge);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, c0->grid_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_OUT, o->merged);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_SURFELS, o->index);
    for (int i = o->levels - 1; i >= 0; --i) {
        const lpv_cascaded *c = o->level[i];
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_VPLS, c->lpv_acc);
        glUniform1i(glGetUniformLocation(o->prog_merge, "u_level"), i);
        glUniform1i(glGetUniformLocation(o->prog_merge, "u_coarsest"), i == o->levels - 1);
        glUniform3i(glGetUniformLocation(o->prog_merge, "u_level_dims"), c->grid.dims[0], c->grid.dims[1],
                    c->grid.dims[2]);
        glDispatchCompute(lpv_div_up((size_t)c0->grid.dims[0], LPV_WG_2D),
                          lpv_div_up((size_t)c0->grid.dims[1], LPV_WG_2D), (GLuint)c0->grid.dims[2]);
        lpv_timer_count(timer, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
}

static int tick(lpv_technique *t, const lpv_technique_inputs *in, char *err, size_t err_size)
{
    (void)err;
    (void)err_size;
    lpv_octree_gpu *o = (lpv_octree_gpu *)t;
    const lpv_plan *p = in->plan;
    if (p->pass[LPV_PASS_INJECT].run)
        lpv_pass_inject_run(o->level[0], in, p->pass[LPV_PASS_RSM].run, p->pass[LPV_PASS_EMISSIVE].run);
    else
        lpv_pass_clear_run(o->level[0]);
    lpv_timer_begin(in->timer, "downsample");
    for (int i = 1; i < o->levels; ++i)
        downsample(o, i, in->timer);
    lpv_timer_end(in->timer);
    for (int i = 0; i < o->levels; ++i) {
        if (p->pass[LPV_PASS_GV].run)
            lpv_pass_gv_run(o->level[i], in, p->pass[LPV_PASS_BOUNCE].run);
        if (p->pass[LPV_PASS_PROPAGATE].run)
            lpv_pass_propagate_run(o->level[i], in, p->pass[LPV_PASS_GV].run, p->pass[LPV_PASS_BOUNCE].run);
    }
    lpv_timer_begin(in->timer, "merge");
    merge(o, in->timer);
    lpv_timer_end(in->timer);
    lpv_lookup_volume_fill(&o->lookup, lpv_cascaded_lookup_programs(o->level[0]), o->merged, in->lookup_planes,
                           in->lookup_plane_count, in->timer);
    return 0;
}

static void bind_lookup(const lpv_technique *t, GLuint prog, float damping)
{
    const lpv_octree_gpu *o = (const lpv_octree_gpu *)t;
    glUniform1f(glGetUniformLocation(prog, "u_damping"), damping);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, o->level[0]->grid_ubo);
    lpv_lookup_volume_bind(&o->lookup, prog);
}

static void describe(const lpv_technique *t, lpv_volume_desc *d)
{
    const lpv_octree_gpu *o = (const lpv_octree_gpu *)t;
    memset(d, 0, sizeof *d);
    d->technique = lpv_technique_octree.name;
    d->levels = 1; /* the merged volume: one grid, level 0's */
    d->level[0] = o->level[0]->grid;
    for (int i = 0; i < 3; ++i)
        d->origin_cells[0][i] = o->level[0]->cascades.origin_cells[0][i];
    d->far_field = 0;
    d->vpl_spread = o->level[0]->settings.lpv.smooth_injection == LPV_SWITCH_ON; /* level 0 injects */
    d->volumes_per_level = 1;
    d->values_per_cell = 12;
    d->kind = LPV_LEVELS_CASCADES; /* the merged grid reads as one cascade */
    d->units = "W/sr";
    d->index_levels = 1; /* read back only when a request asks for them (read below) */
}

static size_t read(lpv_technique *t, const lpv_plan *last, lpv_volume_part part, lpv_grid_which which, void *out,
                   size_t max)
{
    lpv_octree_gpu *o = (lpv_octree_gpu *)t;
    switch (part) {
    case LPV_VOLUME_SUMMED:
        if (which == LPV_GRID_ACCUMULATED)
            return lpv_gl_read_buffer(o->merged, sizeof(lpv_cell), o->merged_cells, out, max);
        return lpv_cascaded_read(o->level[0], last, part, which, out, max);
    case LPV_VOLUME_STORED: { /* every level's, level 0 first */
        size_t n = 0;
        for (int i = 0; i < o->levels && n < max; ++i)
            n += lpv_cascaded_read(o->level[i], last, LPV_VOLUME_SUMMED, which, (lpv_cell *)out + n, max - n);
        return n;
    }
    case LPV_VOLUME_IV_VOXELS:
    case LPV_VOLUME_AO:
    case LPV_VOLUME_VISIBILITY:
        return 0;
    case LPV_VOLUME_INDEX:
        return lpv_gl_read_buffer(o->index, sizeof(int32_t), o->merged_cells, out, max);
    case LPV_VOLUME_GEOMETRY:
    case LPV_VOLUME_TRANSMIT: { /* every level's, level 0 first */
        const size_t size = part == LPV_VOLUME_GEOMETRY ? sizeof(lpv_gv_point) : sizeof(float);
        size_t n = 0;
        for (int i = 0; i < o->levels && n < max; ++i)
            n += lpv_cascaded_read(o->level[i], last, part, which, (char *)out + n * size, max - n);
        return n;
    }
    }
    return 0;
}

static void stats(const lpv_technique *t, const lpv_plan *last, lpv_engine_stats *s)
{
    const lpv_octree_gpu *o = (const lpv_octree_gpu *)t;
    size_t cells = 0;
    for (int i = 0; i < o->levels; ++i)
        cells += lpv_grid_cell_count(&o->level[i]->grid);
    s->cascades = o->levels;
    s->cells = cells;
    s->iterations = o->settings.lpv.iterations;
    s->cell_steps = last->pass[LPV_PASS_PROPAGATE].run ? (double)cells * o->settings.lpv.iterations : 0.0;
    s->occlusion = last->pass[LPV_PASS_GV].run;
}

const lpv_technique_class lpv_technique_octree = {
    .name = LPV_TECHNIQUE_OCTREE,
    .lookup_includes = LOOKUP,
    .create = create,
    .destroy = destroy,
    .configure = configure,
    .place = place,
    .commit = commit,
    .plan = plan,
    .tick = tick,
    .bind_lookup = bind_lookup,
    .describe = describe,
    .read = read,
    .memory_need = memory_need,
    .stats = stats,
};
