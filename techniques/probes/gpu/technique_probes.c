/*
 * technique_probes.c - ray-traced irradiance probes (issue 34; Majercik et
 * al., "Dynamic Diffuse Global Illumination with Ray-Traced Irradiance
 * Fields", JCGT 2019) on the technique seam (gpu/technique.h). Every pass is
 * a compute shader:
 *
 *   sample_scene   the scene's triangles into a BVH (Embree's builder,
 *                  core/probes_bvh.c) and each triangle's albedo and
 *                  emission, uploaded as storage buffers
 *   place/commit   a probe at the centre of every cell of the cascades the
 *                  LPV would place (core/cascades.c, without the far
 *                  field's hand-off: every cascade holds all its light)
 *   tick           probes_update.comp traces a batch of probes' rays and
 *                  shades the hits (direct light by shadow rays, the
 *                  probes' own light for the next bounce), probes_blend.comp
 *                  folds them into each probe's SH, distance moments and
 *                  back-face share with the hysteresis. A volume without
 *                  history runs probes_warmup passes over every probe (the
 *                  bounces a single tick, e.g. lpvd render, sees); after
 *                  that a tick updates probes_budget probes, round robin.
 *                  A camera-following cascade that moved by whole cells
 *                  keeps its probes' light (probes_scroll.comp moves it
 *                  along) and warms up only the probes it brought in.
 *   lookup         probes_lookup.glsl: 8 probes, visibility-weighted
 *
 * The volume is an LpvCell per probe in the cascades' layout, so the wire's
 * volume and the clients' lookup are the LPV's (without the visibility).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cascades.h"
#include "error.h"
#include "gl_util.h"
#include "hash.h"
#include "material_sample.h"
#include "probes_bvh.h"
#include "probes_lookup.h"
#include "probes_math.h"
#include "probes_rules.h"
#include "probes_table.h"
#include "shader.h"
#include "technique.h"

extern const lpv_technique_class lpv_technique_probes;

typedef struct lpv_probes_gpu {
    lpv_technique base;
    lpv_settings settings;
    lpv_cascade_set cascades, pending;
    GLuint prog_update, prog_blend, prog_scroll;
    GLuint grid_ubo;
    /* the scene (sample_scene) */
    GLuint nodes, leaf_tris, verts, materials;
    size_t triangles;
    uint64_t scene_bytes; /* the four buffers' */
    uint64_t topology;    /* the scene's source and its triangles' corners' indices, hashed: the same in a
                             re-posed scene */
    float scene_size;     /* m, the bounds' diagonal: the rays' reach */
    /* the probes (commit) */
    GLuint sh, moments, state, ray_out, irradiance;
    GLuint ray_dirs, taps; /* the batch's ray table */
    GLuint list;           /* uint per probe: the probes a scroll brought in, the first `fresh` */
    lpv_probes_table table;
    size_t probes, ray_out_rays;
    int oct;
    /* progress */
    uint32_t tick_no;
    size_t cursor;
    size_t fresh;    /* probes a scroll brought in that await their warmup */
    int shift[LPV_MAX_CASCADES][3]; /* place's scroll (progress.scroll), which commit carries out */
    size_t scrolled; /* the last tick's warmed-up fresh probes */
    size_t refine_probes, refine_cursor; /* the list's probes averaging more passes (progress.refine),
                                            and the next to trace */
    lpv_probes_progress progress;
    size_t updated, rays_traced; /* the last tick's */
    size_t off, moved;           /* probes off (inside geometry) and relocated after the last warmup or
                                    relocating sweep */
    size_t relocate_left;        /* after the scene was posed anew: probes the round robin still relocates,
                                    then still traces from where they moved before off and moved are
                                    counted again (2 sweeps) */
} lpv_probes_gpu;

static const char *const LOOKUP[] = {"probes_lookup.glsl", NULL};
static const char *const INC_UPDATE[] = {"grid.glsl",          "lights.glsl",        "probes_trace.glsl",
                                         "probes_lookup.glsl", "probes_batch.glsl", NULL};
static const char *const INC_BLEND[] = {"grid.glsl", "probes_batch.glsl", NULL};

static void free_scene(lpv_probes_gpu *g)
{
    GLuint *b[] = {&g->nodes, &g->leaf_tris, &g->verts, &g->materials};
    for (size_t i = 0; i < sizeof b / sizeof b[0]; ++i)
        lpv_gl_delete_buffer(b[i]);
    g->triangles = 0;
    g->scene_bytes = 0;
}

static void free_probes(lpv_probes_gpu *g)
{
    GLuint *b[] = {&g->sh, &g->moments, &g->state, &g->ray_out, &g->ray_dirs, &g->taps, &g->irradiance, &g->list};
    for (size_t i = 0; i < sizeof b / sizeof b[0]; ++i)
        lpv_gl_delete_buffer(b[i]);
    g->probes = g->ray_out_rays = g->fresh = 0;
    g->progress = (lpv_probes_progress){0};
}

static void destroy(lpv_technique *t)
{
    lpv_probes_gpu *g = (lpv_probes_gpu *)t;
    if (!g)
        return;
    free_scene(g);
    free_probes(g);
    if (g->prog_update)
        glDeleteProgram(g->prog_update);
    if (g->prog_blend)
        glDeleteProgram(g->prog_blend);
    if (g->prog_scroll)
        glDeleteProgram(g->prog_scroll);
    lpv_gl_delete_buffer(&g->grid_ubo);
    lpv_probes_table_free(&g->table);
    free(g);
}

static lpv_technique *create(char *err, size_t err_size)
{
    lpv_probes_gpu *g = calloc(1, sizeof *g);
    if (!g)
        return lpv_error(err, err_size, "out of memory"), NULL;
    g->base.cls = &lpv_technique_probes;
    g->prog_update = lpv_program_build("probes_update.comp", NULL, NULL, INC_UPDATE, err, err_size);
    g->prog_blend = g->prog_update ? lpv_program_build("probes_blend.comp", NULL, NULL, INC_BLEND, err, err_size) : 0;
    g->prog_scroll = g->prog_blend ? lpv_program_build("probes_scroll.comp", NULL, NULL, NULL, err, err_size) : 0;
    if (!g->prog_scroll) {
        destroy(&g->base);
        return NULL;
    }
    glGenBuffers(1, &g->grid_ubo);
    glBindBuffer(GL_UNIFORM_BUFFER, g->grid_ubo);
    glBufferData(GL_UNIFORM_BUFFER, sizeof(struct LpvGridParams), NULL, GL_DYNAMIC_DRAW);
    glBindBuffer(GL_UNIFORM_BUFFER, 0);
    lpv_settings_resolve(&g->settings);
    return &g->base;
}

static void configure(lpv_technique *t, const lpv_settings *s)
{
    lpv_probes_gpu *g = (lpv_probes_gpu *)t;
    g->settings = *s;
}

static void clear_zero(GLuint b)
{
    static const float zero = 0.0f;
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, b);
    glClearBufferData(GL_SHADER_STORAGE_BUFFER, GL_R32F, GL_RED, GL_FLOAT, &zero);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
}

/* A storage buffer of n elements of `size` bytes from data (NULL: zeros);
 * one element of padding when n is 0 (a bound buffer must not be empty). */
static GLuint upload(const void *data, size_t n, size_t size)
{
    GLuint b = lpv_gl_new_ssbo((n ? n : 1) * size);
    if (data && n) {
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, b);
        glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(n * size), data);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
    }
    return b;
}

/* Each triangle's albedo (w: 1 = double-sided) and emission (W/(m^2 sr)) at
 * its centroid's texture coordinates, in the order of the BVH's ids. */
static void triangle_material(const lpv_scene *sc, const lpv_draw *d, const uint32_t *idx, float out[8])
{
    const lpv_material *m = &sc->materials[d->material];
    float uv0[2] = {0, 0}, uv1[2] = {0, 0}, color[4] = {0, 0, 0, 0};
    for (int v = 0; v < 3; ++v) {
        const lpv_vertex *x = &sc->vertices[idx[v]];
        for (int i = 0; i < 2; ++i) {
            uv0[i] += x->uv[i] / 3.0f;
            uv1[i] += x->uv1[i] / 3.0f;
        }
        for (int i = 0; i < 4; ++i)
            color[i] += x->color[i] / 3.0f;
    }
    memset(out, 0, 8 * sizeof *out);
    if (m->unlit) /* neither reflects nor emits (core/material_sample.h) */
        return;
    lpv_material_albedo_at(sc, m, uv0, uv1, d->vertex_color ? color : NULL, out);
    out[3] = m->double_sided ? 1.0f : 0.0f;
    lpv_material_emission_at(sc, m, uv0, uv1, out + 4);
}

static int sample_scene(lpv_technique *t, const lpv_technique_scene *in, char *err, size_t err_size)
{
    lpv_probes_gpu *g = (lpv_probes_gpu *)t;
    const lpv_scene *sc = in->geometry;
    size_t tris = 0;
    for (uint32_t k = 0; k < sc->draw_count; ++k)
        if (sc->draws[k].mode == LPV_DRAW_TRIANGLES)
            tris += sc->draws[k].index_count / 3;
    float *pos = malloc((sc->vertex_count ? sc->vertex_count : 1) * 3 * sizeof *pos);
    uint32_t *idx = malloc((tris ? tris : 1) * 3 * sizeof *idx);
    float *mat = malloc((tris ? tris : 1) * 8 * sizeof *mat);
    if (!pos || !idx || !mat) {
        free(pos), free(idx), free(mat);
        return lpv_error(err, err_size, "%s: out of memory for %zu triangles", LPV_TECHNIQUE_PROBES, tris);
    }
    for (uint32_t v = 0; v < sc->vertex_count; ++v)
        memcpy(pos + 3 * v, sc->vertices[v].position, 3 * sizeof *pos);
    size_t n = 0;
    for (uint32_t k = 0; k < sc->draw_count; ++k) {
        const lpv_draw *d = &sc->draws[k];
        if (d->mode != LPV_DRAW_TRIANGLES)
            continue;
        for (uint32_t i = 0; i + 2 < d->index_count; i += 3, ++n) {
            memcpy(idx + 3 * n, sc->indices + d->first_index + i, 3 * sizeof *idx);
            triangle_material(sc, d, idx + 3 * n, mat + 8 * n);
        }
    }
    uint64_t topology = lpv_hash_bytes(LPV_HASH_INIT, sc->source, strlen(sc->source));
    topology = lpv_hash_bytes(topology, &sc->vertex_count, sizeof sc->vertex_count);
    topology = lpv_hash_bytes(topology, idx, n * 3 * sizeof *idx);
    lpv_probes_bvh bvh;
    const int rc = lpv_probes_bvh_build(&bvh, pos, sc->vertex_count, idx, n, err, err_size);
    free(pos);
    free(idx);
    if (rc != 0) {
        free(mat);
        return -1;
    }
    free_scene(g);
    g->nodes = upload(bvh.nodes, bvh.node_count, sizeof *bvh.nodes);
    g->leaf_tris = upload(bvh.leaf_tris, bvh.leaf_tri_count, sizeof *bvh.leaf_tris);
    g->verts = upload(bvh.vertices, bvh.triangle_count * 3, 4 * sizeof(float));
    g->materials = upload(mat, n, 8 * sizeof(float));
    g->triangles = n;
    g->scene_bytes = (uint64_t)bvh.node_count * sizeof *bvh.nodes + (uint64_t)bvh.leaf_tri_count * sizeof *bvh.leaf_tris +
                     (uint64_t)bvh.triangle_count * 3 * 4 * sizeof(float) + (uint64_t)n * 8 * sizeof(float);
    free(mat);
    lpv_probes_bvh_free(&bvh);
    float d2 = 0.0f;
    for (int i = 0; i < 3; ++i) {
        const float e = sc->bounds_max[i] - sc->bounds_min[i];
        d2 += e > 0.0f ? e * e : 0.0f;
    }
    g->scene_size = sqrtf(d2) > 1e-3f ? sqrtf(d2) : 1e-3f;
    /* A new scene: no light is right any more. The same file's triangles
     * posed anew (nodes that moved, materials that changed): the probes keep
     * their light and follow the change as they follow a moved light (the
     * plan's light_stale: the hysteresis ramps, the probes settle again). */
    if (topology != g->topology)
        g->progress.history = 0;
    else if (g->progress.history) /* moved geometry may hold probes now: the next sweep relocates them */
        g->relocate_left = 2 * g->probes;
    g->topology = topology;
    return 0;
}

/* The settings the cascades are placed with: the far field's hand-off
 * splits one light between cascades, and every probe holds all of its. */
static lpv_settings cascade_settings(const lpv_settings *s)
{
    lpv_settings c = *s;
    c.lpv.far_field = LPV_SWITCH_OFF;
    return c;
}

/* One grid over the bounds puts its first and last cell centres on the
 * bounds (the LPV's cells straddle the walls): a probe there sits in the
 * wall's plane and sees half of nothing. Shrinking the cells by (n - 1) / n
 * about the grid's centre puts the outer probes half a cell inside. A
 * camera-following cascade lands anywhere; relocating the probes it puts in
 * walls is the README's "what is not here yet". */
static void inset_grid(lpv_cascade_set *c)
{
    lpv_grid *g = &c->grid[0];
    int n = g->dims[0] > g->dims[1] ? g->dims[0] : g->dims[1];
    n = n > g->dims[2] ? n : g->dims[2];
    if (n < 2)
        return;
    const float cell = g->cell_size * (float)(n - 1) / (float)n;
    for (int i = 0; i < 3; ++i) {
        const float centre = g->origin[i] + 0.5f * (float)g->dims[i] * g->cell_size;
        g->origin[i] = centre - 0.5f * (float)g->dims[i] * cell;
        c->origin_cells[0][i] = g->origin[i] / cell;
    }
    g->cell_size = cell;
}

static size_t probe_count(const lpv_cascade_set *c)
{
    return lpv_grid_cell_count(&c->grid[0]) * (size_t)(c->count > 0 ? c->count : 1);
}

/* The rays a batch holds: the budget's probes (at most every probe) x rays. */
static size_t batch_rays(const lpv_settings *s, size_t probes)
{
    const size_t budget = (size_t)s->probes.budget;
    return (budget < probes ? budget : probes) * (size_t)s->probes.rays;
}

/* Whether cascades `set` keep the probes' buffers (the same probes, distance
 * maps and batch), so their light can stay. */
static int keeps_buffers(const lpv_probes_gpu *g, const lpv_cascade_set *set)
{
    const size_t n = probe_count(set);
    return n == g->probes && g->settings.probes.oct == g->oct && batch_rays(&g->settings, n) == g->ray_out_rays;
}

static int place(lpv_technique *t, const lpv_technique_where *w, int *moved, char *err, size_t err_size)
{
    lpv_probes_gpu *g = (lpv_probes_gpu *)t;
    const lpv_settings s = cascade_settings(w->settings);
    char why[LPV_PLAN_REASON_MAX];
    const int count = lpv_plan_cascades(&s, w->facts, why, sizeof why);
    float f[3];
    const float *fwd = w->forward;
    if (fwd) {
        const float len = sqrtf(fwd[0] * fwd[0] + fwd[1] * fwd[1] + fwd[2] * fwd[2]);
        for (int i = 0; i < 3; ++i)
            f[i] = len > 0.0f ? fwd[i] / len : 0.0f;
        fwd = f;
    }
    if (lpv_cascades_place(&s, count, w->bounds_min, w->bounds_max, w->eye, fwd, w->facts->view_chord,
                           &g->pending) != 0)
        return lpv_error(err, err_size, "%s: %d cascades of %dx%dx%d probes cannot be placed", LPV_TECHNIQUE_PROBES,
                         count, s.grid_dims[0], s.grid_dims[1], s.grid_dims[2]);
    if (!g->pending.snapped && g->pending.count == 1)
        inset_grid(&g->pending);
    const int differ = !lpv_cascades_equal(&g->pending, &g->cascades);
    /* the plan's and commit's: the probes that stay keep their light */
    g->progress.scroll = differ && g->progress.history && !g->fresh && keeps_buffers(g, &g->pending) &&
                         lpv_probes_scroll_kept(&g->cascades, &g->pending, g->shift, NULL, NULL) > 0;
    if (moved)
        *moved = differ;
    return 0;
}

/* Copies buffer *b (stride floats a probe) into the scrolled layout. */
static void scroll_buffer(const lpv_probes_gpu *g, GLuint *b, size_t stride)
{
    const GLuint dst = lpv_gl_new_ssbo(g->probes * stride * sizeof(float));
    glUniform1ui(glGetUniformLocation(g->prog_scroll, "u_stride"), (GLuint)stride);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_SCROLL_SRC, *b);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_SCROLL_DST, dst);
    glDispatchCompute(lpv_div_up(g->probes, LPV_PROBES_WG), 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    lpv_gl_delete_buffer(b); /* GL keeps it until the dispatch has read it */
    *b = dst;
}

/* Moves the probes' light, distances and state from the cascades to
 * `to` (place's g->shift) and lists the probes the move brought in,
 * which the next tick warms up alone: a camera crossing a cell pays for a
 * slab of probes, not a warmup of every probe, and the others keep every
 * bounce they gathered. Returns the probes kept (0: out of memory for the
 * list, nothing moved). */
static size_t scroll(lpv_probes_gpu *g, const lpv_cascade_set *to)
{
    const lpv_grid *grid = &to->grid[0];
    uint32_t *fresh = malloc(g->probes * sizeof *fresh);
    if (!fresh)
        return 0;
    size_t n = 0;
    lpv_probes_scroll_kept(&g->cascades, to, g->shift, fresh, &n);
    if (n < g->probes) {
        glUseProgram(g->prog_scroll);
        glUniform1ui(glGetUniformLocation(g->prog_scroll, "u_total"), (GLuint)g->probes);
        glUniform3iv(glGetUniformLocation(g->prog_scroll, "u_dims"), 1, grid->dims);
        glUniform3iv(glGetUniformLocation(g->prog_scroll, "u_shift"), LPV_MAX_CASCADES, &g->shift[0][0]);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        const size_t oct2 = (size_t)g->oct * (size_t)g->oct;
        scroll_buffer(g, &g->sh, sizeof(struct LpvCell) / sizeof(float));
        scroll_buffer(g, &g->moments, 2 * oct2);
        scroll_buffer(g, &g->state, 8);
        scroll_buffer(g, &g->irradiance, 3 * (size_t)LPV_PROBES_IRR_OCT * LPV_PROBES_IRR_OCT);
        glUseProgram(0);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, g->list);
        glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(n * sizeof *fresh), fresh);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
        g->fresh = n;
        g->progress.refine = 0; /* the list is this move's: an earlier slab stops refining */
    }
    free(fresh);
    return g->probes - n;
}

static int commit(lpv_technique *t, const lpv_technique_where *w, int *reset, char *err, size_t err_size)
{
    lpv_probes_gpu *g = (lpv_probes_gpu *)t;
    const lpv_cascade_set *set = &g->pending;
    const int moved = !lpv_cascades_equal(set, &g->cascades);
    const int scrolls = moved && g->progress.scroll;
    g->progress.scroll = 0;
    /* the scroll reads the old cascades: it runs before they change */
    const size_t kept = scrolls && keeps_buffers(g, set) ? scroll(g, set) : 0;
    g->cascades = *set;
    struct LpvGridParams params;
    lpv_cascades_grid_params(set, &params);
    params.info[2] = 1.0f; /* one volume a cascade (grid.glsl's bin_count) */
    glBindBuffer(GL_UNIFORM_BUFFER, g->grid_ubo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof params, &params);
    glBindBuffer(GL_UNIFORM_BUFFER, 0);
    const size_t n = probe_count(set);
    const int oct = g->settings.probes.oct;
    const size_t rays = batch_rays(&g->settings, n);
    *reset = 0;
    if (keeps_buffers(g, set)) {
        /* probes that moved with the camera hold another place's light:
         * a whole-cell move keeps the light of the cells that stay, any
         * other move starts afresh */
        if (moved && kept == 0)
            g->progress.history = 0;
        return 0;
    }
    lpv_memory_need need = w->others;
    lpv_probes_memory_need(&g->settings, n, g->scene_bytes, &need);
    if (lpv_memory_check(&need, w->limits, err, err_size) != 0)
        return -1;
    free_probes(g);
    *reset = 1;
    g->sh = lpv_gl_new_ssbo(n * sizeof(struct LpvCell));
    g->moments = lpv_gl_new_ssbo(n * (size_t)oct * (size_t)oct * 2 * sizeof(float));
    g->state = lpv_gl_new_ssbo(n * 8 * sizeof(float));
    g->irradiance = lpv_gl_new_ssbo(n * LPV_PROBES_IRR_OCT * LPV_PROBES_IRR_OCT * 3 * sizeof(float));
    g->ray_out = lpv_gl_new_ssbo((rays ? rays : 1) * 4 * sizeof(float));
    g->list = lpv_gl_new_ssbo(n * sizeof(uint32_t));
    clear_zero(g->sh);
    clear_zero(g->moments);
    clear_zero(g->state);
    clear_zero(g->irradiance);
    g->probes = n;
    g->oct = oct;
    g->ray_out_rays = rays;
    g->cursor = 0;
    g->progress = (lpv_probes_progress){.probes = n};
    return 0;
}

static void plan(const lpv_technique *t, const lpv_settings *s, const lpv_plan_facts *f, lpv_plan *p)
{
    const lpv_probes_gpu *g = (const lpv_probes_gpu *)t;
    const lpv_settings c = cascade_settings(s);
    lpv_plan_make_probes(&c, f, &g->progress, p);
}

static void bind_scene(const lpv_probes_gpu *g)
{
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_NODES, g->nodes);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_LEAF_TRIS, g->leaf_tris);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_VERTS, g->verts);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_MATERIALS, g->materials);
}

static void bind_probes(const lpv_probes_gpu *g)
{
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, g->grid_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_SH, g->sh);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_MOMENTS, g->moments);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_STATE, g->state);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_IRRADIANCE, g->irradiance);
}

/* The batch's ray table (probes_table.h) into its two buffers. */
static int upload_table(lpv_probes_gpu *g, uint32_t tick)
{
    const lpv_probes_settings *ps = &g->settings.probes;
    if (lpv_probes_table_make(&g->table, tick, LPV_PROBES_SEED, (uint32_t)ps->rays, g->oct, LPV_PROBES_SHARPNESS,
                              LPV_PROBES_IRR_OCT) != 0)
        return -1;
    lpv_gl_delete_buffer(&g->ray_dirs);
    lpv_gl_delete_buffer(&g->taps);
    g->ray_dirs = upload(g->table.dirs, (size_t)ps->rays, 4 * sizeof(float));
    g->taps = upload(g->table.taps, g->table.tap_words, sizeof(uint32_t));
    return 0;
}

static void set_batch(GLuint prog, size_t first, size_t batch, size_t total, int rays, int listed)
{
    glUniform1i(glGetUniformLocation(prog, "u_listed"), listed);
    glUniform1ui(glGetUniformLocation(prog, "u_first"), (GLuint)first);
    glUniform1ui(glGetUniformLocation(prog, "u_batch"), (GLuint)batch);
    glUniform1ui(glGetUniformLocation(prog, "u_total"), (GLuint)total);
    glUniform1ui(glGetUniformLocation(prog, "u_rays"), (GLuint)rays);
}

/* One batch: probes [first, first + batch) (mod the count), or entries
 * [first, first + batch) of the list of fresh probes (listed 1), trace and
 * blend. */
static int run_batch(lpv_probes_gpu *g, const lpv_technique_inputs *in, size_t first, size_t batch, int listed,
                     int feedback, float hysteresis, float moment_hysteresis, int relocate)
{
    const lpv_probes_settings *ps = &g->settings.probes;
    const size_t rays = batch * (size_t)ps->rays;
    const uint32_t tick = g->tick_no++;
    if (upload_table(g, tick) != 0)
        return -1;
    lpv_timer_begin(in->timer, "probes_trace");
    glUseProgram(g->prog_update);
    bind_scene(g);
    bind_probes(g);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_LIGHT, in->light_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_RAY_OUT, g->ray_out);
    set_batch(g->prog_update, first, batch, g->probes, ps->rays, listed);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_LIST, g->list);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_RAY_DIRS, g->ray_dirs);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_TAPS, g->taps);
    glUniform1ui(glGetUniformLocation(g->prog_update, "u_tick"), tick);
    glUniform1f(glGetUniformLocation(g->prog_update, "u_max_distance"), 2.0f * g->scene_size);
    glUniform1f(glGetUniformLocation(g->prog_update, "u_eps"), 1e-4f * g->scene_size);
    glUniform1f(glGetUniformLocation(g->prog_update, "u_emission"),
                in->settings->area_lights == LPV_SWITCH_OFF ? 1.0f : 0.0f);
    glUniform1f(glGetUniformLocation(g->prog_update, "u_feedback"), feedback ? 1.0f : 0.0f);
    static const float sky[3] = {0.0f, 0.0f, 0.0f}; /* no environment light yet */
    glUniform3fv(glGetUniformLocation(g->prog_update, "u_sky"), 1, sky);
    glUniform1i(glGetUniformLocation(g->prog_update, "u_probes_oct"), g->oct);
    glUniform1f(glGetUniformLocation(g->prog_update, "u_probes_bias"), LPV_PROBES_BIAS_CELLS);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    glDispatchCompute(lpv_div_up(rays, LPV_PROBES_WG), 1, 1);
    lpv_timer_count(in->timer, 1);
    lpv_timer_end(in->timer);

    lpv_timer_begin(in->timer, "probes_blend");
    glUseProgram(g->prog_blend);
    set_batch(g->prog_blend, first, batch, g->probes, ps->rays, listed);
    glUniform1i(glGetUniformLocation(g->prog_blend, "u_oct"), g->oct);
    glUniform1f(glGetUniformLocation(g->prog_blend, "u_hysteresis"), hysteresis);
    /* a listed warmup averages its passes: no change of the light to follow */
    glUniform1i(glGetUniformLocation(g->prog_blend, "u_change_test"), !listed && lpv_probes_change_test_on(&g->progress));
    glUniform1f(glGetUniformLocation(g->prog_blend, "u_moment_hysteresis"), moment_hysteresis);
    glUniform1f(glGetUniformLocation(g->prog_blend, "u_moment_cells"), LPV_PROBES_MOMENT_CELLS);
    glUniform1f(glGetUniformLocation(g->prog_blend, "u_backface_off"), LPV_PROBES_BACKFACE_OFF);
    glUniform1i(glGetUniformLocation(g->prog_blend, "u_relocate"), relocate);
    glUniform1f(glGetUniformLocation(g->prog_blend, "u_min_front"), LPV_PROBES_MIN_FRONT_CELLS);
    glUniform1f(glGetUniformLocation(g->prog_blend, "u_max_offset"), LPV_PROBES_MAX_OFFSET_CELLS);
    glUniform1f(glGetUniformLocation(g->prog_blend, "u_max_distance"), 2.0f * g->scene_size);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    glDispatchCompute(lpv_div_up(batch, LPV_PROBES_WG), 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    lpv_timer_count(in->timer, 1);
    lpv_timer_end(in->timer);
    g->updated += batch;
    g->rays_traced += rays;
    return 0;
}

/* Probes the last blend turned off (state.y 0) and moved (state.z 1):
 * read back once a warmup. */
static void count_state(lpv_probes_gpu *g)
{
    float *st = malloc(g->probes * 8 * sizeof *st);
    g->off = g->moved = 0;
    if (!st)
        return;
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    const size_t n = lpv_gl_read_buffer(g->state, 8 * sizeof(float), g->probes, st, g->probes);
    for (size_t i = 0; i < n; ++i) {
        g->off += st[8 * i + 1] == 0.0f;
        g->moved += st[8 * i + 4] != 0.0f || st[8 * i + 5] != 0.0f || st[8 * i + 6] != 0.0f;
    }
    free(st);
}

/* Warmup passes over `count` probes: every probe (listed 0), whose pass b
 * reads pass b - 1's probes for its hits' light and replaces it (each pass
 * a bounce more), or the list's, the probes a scroll brought in, whose hits
 * read the probes that stayed from the first pass on, so their passes
 * after the first average (a third of the noise at 4 passes). Pass 0
 * relocates; the distances average from pass 1 on, where the probes stay. */
static int warm_up(lpv_probes_gpu *g, const lpv_technique_inputs *in, size_t count, int listed)
{
    const lpv_probes_settings *ps = &g->settings.probes;
    const size_t batch = g->ray_out_rays / (size_t)ps->rays;
    for (int pass = 0; pass < ps->warmup; ++pass) {
        const float mean = pass < 2 ? 0.0f : (float)(pass - 1) / (float)pass; /* a running mean from pass 1 */
        for (size_t first = 0; first < count; first += batch)
            if (run_batch(g, in, first, count - first < batch ? count - first : batch, listed, pass > 0 || listed,
                          listed ? mean : 0.0f, mean, pass == 0 && ps->warmup > 1) != 0)
                return -1;
    }
    count_state(g);
    return 0;
}

static int tick(lpv_technique *t, const lpv_technique_inputs *in, char *err, size_t err_size)
{
    lpv_probes_gpu *g = (lpv_probes_gpu *)t;
    const lpv_plan *p = in->plan;
    g->updated = g->rays_traced = g->scrolled = 0;
    if (!p->pass[LPV_PASS_PROBES].run || !g->probes)
        return 0;
    const lpv_probes_settings *ps = &g->settings.probes;
    const size_t batch = g->ray_out_rays / (size_t)ps->rays;
    if (!g->progress.history) {
        /* every probe: the rotations start over, so a fresh volume's light
         * does not depend on what the technique did before */
        g->tick_no = 0;
        g->fresh = 0;
        g->progress.refine = 0;
        g->relocate_left = 0; /* the warmup's pass 0 relocates every probe */
        clear_zero(g->state); /* no offsets: pass 0 places the probes again */
        if (warm_up(g, in, g->probes, 0) != 0)
            return lpv_error(err, err_size, "%s: out of memory for the ray table", LPV_TECHNIQUE_PROBES);
        g->cursor = 0;
        g->progress.history = 1;
        g->progress.sweeps = 0;
        g->progress.changed = 0;
    } else {
        if (p->light_stale) {
            g->progress.sweeps = 0; /* a change: settle again, forgetting the old light faster */
            g->progress.changed = 1;
            g->progress.refine = 0; /* the round robin follows it; a running mean would lag */
        }
        const size_t fresh = g->fresh;
        g->fresh = 0;
        if (fresh && warm_up(g, in, fresh, 1) != 0)
            return lpv_error(err, err_size, "%s: out of memory for the ray table", LPV_TECHNIQUE_PROBES);
        g->scrolled = fresh;
        /* the probes a scroll brought in then average more passes, a
         * budget of them a tick, until they weigh as many as the settled
         * probes' blend (lpv_probes_refine_passes): alone, as a settled
         * volume runs nothing else */
        const int passes = lpv_probes_refine_passes(ps->hysteresis, ps->warmup);
        int refined = 0;
        if (fresh && !p->light_stale) {
            g->refine_probes = fresh;
            g->refine_cursor = 0;
            g->progress.refine = ps->warmup > 1 ? ps->warmup - 1 : 1; /* the warmup's averaged passes */
            if (g->progress.refine >= passes)
                g->progress.refine = 0;
        } else if (!fresh && g->progress.refine > 0) {
            const size_t left = g->refine_probes - g->refine_cursor, n = left < batch ? left : batch;
            const float mean = (float)g->progress.refine / (float)(g->progress.refine + 1);
            if (run_batch(g, in, g->refine_cursor, n, 1, 1, mean, mean, 0) != 0)
                return lpv_error(err, err_size, "%s: out of memory for the ray table", LPV_TECHNIQUE_PROBES);
            g->refine_cursor += n;
            if (g->refine_cursor >= g->refine_probes) {
                g->refine_cursor = 0;
                if (++g->progress.refine >= passes)
                    g->progress.refine = 0;
            }
            refined = 1;
        }
        /* after a scroll the kept probes wait for the next tick, unless
         * the light changed too; the sweep after geometry moved relocates
         * (as pass 0 of a warmup: out of what now holds them) */
        const int round = (!fresh && !refined) || p->light_stale, relocate = round && g->relocate_left > g->probes;
        if (round && run_batch(g, in, g->cursor, batch, 0, 1, lpv_probes_hysteresis_now(ps->hysteresis, &g->progress),
                               ps->hysteresis, relocate) != 0)
            return lpv_error(err, err_size, "%s: out of memory for the ray table", LPV_TECHNIQUE_PROBES);
        if (round && g->relocate_left) {
            g->relocate_left -= g->relocate_left < batch ? g->relocate_left : batch;
            if (!g->relocate_left)
                count_state(g);
        }
        if (round)
            g->cursor += batch;
        if (g->cursor >= g->probes) {
            g->cursor %= g->probes;
            ++g->progress.sweeps;
        }
    }
    glUseProgram(0);
    return 0;
}

/* lpv_engine_forget: the next tick warms up from nothing, its rotations
 * from the first, as a fresh engine's. */
static void forget(lpv_technique *t) { ((lpv_probes_gpu *)t)->progress.history = 0; }

static void bind_lookup(const lpv_technique *t, GLuint prog, float damping)
{
    const lpv_probes_gpu *g = (const lpv_probes_gpu *)t;
    glUniform1f(glGetUniformLocation(prog, "u_damping"), damping);
    glUniform1i(glGetUniformLocation(prog, "u_probes_oct"), g->oct > 0 ? g->oct : 1);
    glUniform1f(glGetUniformLocation(prog, "u_probes_bias"), LPV_PROBES_BIAS_CELLS);
    bind_probes(g);
}

static void describe(const lpv_technique *t, lpv_volume_desc *d)
{
    const lpv_probes_gpu *g = (const lpv_probes_gpu *)t;
    memset(d, 0, sizeof *d);
    d->technique = lpv_technique_probes.name;
    d->levels = g->cascades.count > 0 ? g->cascades.count : 1;
    for (int k = 0; k < d->levels && k < g->cascades.count; ++k) {
        d->level[k] = g->cascades.grid[k];
        memcpy(d->origin_cells[k], g->cascades.origin_cells[k], sizeof d->origin_cells[k]);
    }
    d->volumes_per_level = 1;
    d->values_per_cell = 12;
    d->kind = LPV_LEVELS_CASCADES;
    d->units = "W/sr";
    d->visibility_side = g->oct;
    d->irradiance_side = LPV_PROBES_IRR_OCT;
    d->visibility_bias_cells = LPV_PROBES_BIAS_CELLS;
}

/* The probes' visibility as lpv_engine_read_visibility reads it: each
 * probe's record (probes_lookup.h) gathered from the state, irradiance and
 * distance buffers. Whole probes only; returns the floats written. */
static size_t read_visibility(const lpv_probes_gpu *g, float *out, size_t max)
{
    const size_t per = lpv_probes_record_values(LPV_PROBES_IRR_OCT, g->oct),
                 at = lpv_probes_record_distance_at(LPV_PROBES_IRR_OCT);
    const size_t irr = 3 * (size_t)LPV_PROBES_IRR_OCT * LPV_PROBES_IRR_OCT, dist = 2 * (size_t)g->oct * g->oct;
    const size_t n = per ? (max / per < g->probes ? max / per : g->probes) : 0;
    float *state = malloc((n ? n : 1) * 8 * sizeof *state), *e = malloc((n ? n : 1) * irr * sizeof *e),
          *m = malloc((n ? n : 1) * dist * sizeof *m);
    size_t done = 0;
    if (state && e && m && lpv_gl_read_buffer(g->state, 8 * sizeof(float), g->probes, state, n) == n &&
        lpv_gl_read_buffer(g->irradiance, irr * sizeof(float), g->probes, e, n) == n &&
        lpv_gl_read_buffer(g->moments, dist * sizeof(float), g->probes, m, n) == n) {
        for (size_t p = 0; p < n; ++p) {
            float *r = out + p * per;
            memcpy(r + LPV_PROBES_RECORD_OFFSET, state + 8 * p + 4, 3 * sizeof(float)); /* vec4 (offset, 0) */
            r[LPV_PROBES_RECORD_ACTIVE] = state[8 * p + 1] != 0.0f ? 1.0f : 0.0f;  /* vec4 (share, active, moved, 0) */
            memcpy(r + LPV_PROBES_RECORD_IRRADIANCE, e + p * irr, irr * sizeof(float));
            memcpy(r + at, m + p * dist, dist * sizeof(float));
        }
        done = n * per;
    }
    free(state);
    free(e);
    free(m);
    return done;
}

static size_t read(lpv_technique *t, const lpv_plan *last, lpv_volume_part part, lpv_grid_which which, void *out,
                   size_t max)
{
    (void)last;
    (void)which;
    lpv_probes_gpu *g = (lpv_probes_gpu *)t;
    if (!g->sh)
        return 0;
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    if (part == LPV_VOLUME_VISIBILITY)
        return read_visibility(g, out, max);
    if (part != LPV_VOLUME_SUMMED && part != LPV_VOLUME_STORED)
        return 0;
    return lpv_gl_read_buffer(g->sh, sizeof(struct LpvCell), g->probes, out, max);
}

static void memory_need(const lpv_technique *t, lpv_memory_need *n)
{
    const lpv_probes_gpu *g = (const lpv_probes_gpu *)t;
    lpv_probes_memory_need(&g->settings, g->probes, g->scene_bytes, n);
    n->cascades = g->cascades.count;
    memcpy(n->grid_dims, g->cascades.grid[0].dims, sizeof n->grid_dims);
}

static void stats(const lpv_technique *t, const lpv_plan *last, lpv_engine_stats *s)
{
    const lpv_probes_gpu *g = (const lpv_probes_gpu *)t;
    /* a tick the plan served from the cache does not reach tick() */
    const int ran = last->pass[LPV_PASS_PROBES].run;
    s->cascades = g->cascades.count;
    s->cells = g->probes;
    s->cell_steps = ran ? (double)g->rays_traced / LPV_TICK_COST_PROBES_RAYS_PER_STEP : 0.0;
    lpv_stats_put(s, "probes_updated", LPV_STAT_INT, ran ? (double)g->updated : 0.0, 0, 0);
    lpv_stats_put(s, "probes_rays", LPV_STAT_INT, ran ? (double)g->rays_traced : 0.0, 0, 0);
    lpv_stats_put(s, "probes_off", LPV_STAT_INT, (double)g->off, 0, 0);
    lpv_stats_put(s, "probes_moved", LPV_STAT_INT, (double)g->moved, 0, 0);
    lpv_stats_put(s, "probes_scrolled_in", LPV_STAT_INT, ran ? (double)g->scrolled : 0.0, 0, 0);
    lpv_stats_put(s, "probes_sweeps", LPV_STAT_INT, (double)g->progress.sweeps, 0, 0);
    lpv_stats_put(s, "probes_triangles", LPV_STAT_INT, (double)g->triangles, 0, 0);
}

const lpv_technique_class lpv_technique_probes = {
    .name = LPV_TECHNIQUE_PROBES,
    .lookup_includes = LOOKUP,
    .create = create,
    .destroy = destroy,
    .configure = configure,
    .sample_scene = sample_scene,
    .place = place,
    .commit = commit,
    .plan = plan,
    .tick = tick,
    .forget = forget,
    .bind_lookup = bind_lookup,
    .describe = describe,
    .read = read,
    .memory_need = memory_need,
    .stats = stats,
};
