/*
 * technique_iv.c - imperfect volumes (Mavridis & Papaioannou, the third
 * seed; docs/imperfect-volumes.md) as an lpv_technique.
 *
 * A grid of cubic voxels over the whole scene (core/grid.h,
 * lpv_grid_place_cubic), rebuilt every computed tick:
 *
 *   iv_points     the scene's point cloud (techniques/iv/core/iv_points.h, N points per
 *                 triangle by Turk's formula, made when the geometry or its
 *                 knobs change, sorted by voxel) lit by the lights through
 *                 their RSMs, each voxel summing its own (paper 3.1)
 *   iv_reproject  the camera's visible pixels, lit the same way, splatted
 *                 into the same voxels (3.2)
 *   iv_resolve    the sums into per-voxel means and occupancy bits
 *   iv_gather     per bounce: every occupied voxel's emission (direct light,
 *                 plus its albedo times the previous gather's irradiance),
 *                 then every voxel a lookup reads marches its rays and
 *                 stores the arriving radiance as SH (3.3), ping-ponging
 *                 two volumes; then the bounces after the last as the
 *                 series the last ones set (iv_tail.comp); then each
 *                 surface voxel's the mean of those beside it on its
 *                 plane (iv_filter.comp, LPV_IV_FILTER)
 *   iv_ao         the same march for visibility within a reach (3.5)
 *
 * The lookup (iv_volume.glsl, iv_lookup.glsl) reconstructs irradiance at a
 * surface from the voxels around it (3.4). techniques/iv/core/oracle_iv.c is the
 * reference the tests hold this to.
 */
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "iv_internal.h"
#include "iv_points.h"
#include "iv_rules.h"
#include "shader.h"


static const char *const INC_SPLAT[] = {"grid.glsl", "lights.glsl", "iv_direct.glsl", "iv_volume.glsl", "iv_sums.glsl",
                                        NULL};
static const char *const INC_GRID[] = {"grid.glsl", NULL};
static const char *const INC_SURFACE[] = {"grid.glsl", "iv_surface.glsl", NULL};
static const char *const LOOKUP[] = {"grid.glsl", "iv_volume.glsl", "iv_lookup.glsl", NULL};

static void free_storage(lpv_iv_gpu *v)
{
    lpv_atlas_destroy(&v->atlas);
    lpv_gl_delete_buffer(&v->voxels);
    lpv_gl_delete_buffer(&v->occupancy);
    lpv_gl_delete_buffer(&v->emit);
    lpv_gl_delete_buffer(&v->radiance[0]);
    lpv_gl_delete_buffer(&v->radiance[1]);
    lpv_gl_delete_buffer(&v->tail_base);
    lpv_gl_delete_buffer(&v->ao);
    v->cells = 0;
    memset(v->alloc_dims, 0, sizeof v->alloc_dims);
}

static void destroy(lpv_technique *t)
{
    lpv_iv_gpu *v = (lpv_iv_gpu *)t;
    if (!v)
        return;
    free_storage(v);
    lpv_iv_free_cloud(v);
    lpv_gl_delete_buffer(&v->splats);
    GLuint progs[] = {v->prog_points, v->prog_reproject, v->prog_splat, v->prog_resolve,
                      v->prog_emit,   v->prog_gather,    v->prog_tail,  v->prog_filter};
    for (size_t i = 0; i < sizeof progs / sizeof progs[0]; ++i)
        if (progs[i])
            glDeleteProgram(progs[i]);
    lpv_gl_delete_buffer(&v->grid_ubo);
    lpv_gl_delete_buffer(&v->tail);
    if (v->empty_vao)
        glDeleteVertexArrays(1, &v->empty_vao);
    free(v);
}

static lpv_technique *create(char *err, size_t err_size)
{
    lpv_iv_gpu *v = calloc(1, sizeof *v);
    if (!v) {
        lpv_error(err, err_size, "out of memory");
        return NULL;
    }
    v->base.cls = &lpv_technique_iv;
    v->prog_points = lpv_program_build("iv_points.comp", NULL, NULL, INC_SPLAT, err, err_size);
    v->prog_reproject =
        v->prog_points ? lpv_program_build("iv_reproject.comp", NULL, NULL, INC_SPLAT, err, err_size) : 0;
    v->prog_splat =
        v->prog_reproject ? lpv_program_build("iv_splat.vert", NULL, "iv_splat.frag", INC_GRID, err, err_size) : 0;
    v->prog_resolve = v->prog_splat ? lpv_program_build("iv_resolve.comp", NULL, NULL, INC_GRID, err, err_size) : 0;
    v->prog_emit = v->prog_resolve ? lpv_program_build("iv_emit.comp", NULL, NULL, LOOKUP, err, err_size) : 0;
    v->prog_gather = v->prog_emit ? lpv_program_build("iv_gather.comp", NULL, NULL, INC_SURFACE, err, err_size) : 0;
    v->prog_tail = v->prog_gather ? lpv_program_build("iv_tail.comp", NULL, NULL, INC_GRID, err, err_size) : 0;
    v->prog_filter = v->prog_tail ? lpv_program_build("iv_filter.comp", NULL, NULL, INC_SURFACE, err, err_size) : 0;
    if (!v->prog_filter) {
        destroy(&v->base);
        return NULL;
    }
    glGenVertexArrays(1, &v->empty_vao);
    glGenBuffers(1, &v->grid_ubo);
    glBindBuffer(GL_UNIFORM_BUFFER, v->grid_ubo);
    glBufferData(GL_UNIFORM_BUFFER, sizeof(struct LpvGridParams), NULL, GL_DYNAMIC_DRAW);
    glBindBuffer(GL_UNIFORM_BUFFER, 0);
    v->tail = lpv_gl_new_ssbo(3 * LPV_IV_TAIL_SLOTS * sizeof(float));
    lpv_settings_resolve(&v->settings);
    return &v->base;
}

static void configure(lpv_technique *t, const lpv_settings *s) { ((lpv_iv_gpu *)t)->settings = *s; }

static int place(lpv_technique *t, const lpv_technique_where *w, int *moved, char *err, size_t err_size)
{
    lpv_iv_gpu *v = (lpv_iv_gpu *)t;
    const lpv_settings *s = w->settings;
    lpv_grid g;
    /* over where light can go (the lit air's box, lpv_plan_facts.lit_min) */
    const lpv_plan_facts *f = w->facts;
    const int lit = f && f->lit_max[0] > f->lit_min[0];
    if (lpv_iv_place(s, lit ? f->lit_min : w->bounds_min, lit ? f->lit_max : w->bounds_max,
                     f ? (lit ? f->lit_free_path : f->free_path) : 0.0f, &g) != 0)
        return lpv_error(err, err_size, "cannot place %d voxels over the %s bounds (not finite)", s->iv.resolution,
                         lpv_settings_bounds_given(s) ? "settings'" : "scene's");
    v->pending = g;
    if (moved)
        *moved = memcmp(&g, &v->grid, sizeof g) != 0;
    return 0;
}

static void memory_need(const lpv_technique *t, lpv_memory_need *n)
{
    const lpv_iv_gpu *v = (const lpv_iv_gpu *)t;
    const lpv_grid *g = v->cells ? &v->grid : &v->pending;
    /* per voxel: the atlas (8 x 16), IvVoxel (128), emission, two radiance
     * volumes and the tail's base (4 x 48), AO (16): 464 bytes, within one
     * LPV cell's (LPV_MEM_CELL) */
    n->cells += lpv_grid_cell_count(g);
    n->cascades = 1;
    memcpy(n->grid_dims, g->dims, sizeof n->grid_dims);
}

static void upload_grid(lpv_iv_gpu *v)
{
    const lpv_grid *g = &v->grid;
    struct LpvGridParams params = {
        .dims = {(float)g->dims[0], (float)g->dims[1], (float)g->dims[2], (float)lpv_grid_cell_count(g)},
        .info = {1.0f, 0.0f, 1.0f, 0.0f},
    };
    for (int i = 0; i < 3; ++i)
        params.cascade[0][i] = g->origin[i] / g->cell_size;
    params.cascade[0][3] = g->cell_size;
    glBindBuffer(GL_UNIFORM_BUFFER, v->grid_ubo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof params, &params);
    glBindBuffer(GL_UNIFORM_BUFFER, 0);
}

static int commit(lpv_technique *t, const lpv_technique_where *w, int *reset, char *err, size_t err_size)
{
    lpv_iv_gpu *v = (lpv_iv_gpu *)t;
    *reset = 0;
    v->grid = v->pending;
    upload_grid(v);
    if (v->cells && memcmp(v->alloc_dims, v->grid.dims, sizeof v->alloc_dims) == 0)
        return 0;
    lpv_memory_need need = w->others;
    need.cells += lpv_grid_cell_count(&v->grid);
    need.cascades = 1;
    memcpy(need.grid_dims, v->grid.dims, sizeof need.grid_dims);
    if (lpv_memory_check(&need, w->limits, err, err_size) != 0)
        return -1;
    free_storage(v);
    *reset = 1;
    const size_t cells = lpv_grid_cell_count(&v->grid);
    if (lpv_atlas_create(&v->atlas, v->grid.dims, IV_ATTACHMENTS, err, err_size) != 0)
        return -1;
    v->voxels = lpv_gl_new_ssbo(cells * sizeof(struct IvVoxel));
    v->occupancy = lpv_gl_new_ssbo((cells + 31) / 32 * sizeof(uint32_t));
    v->emit = lpv_gl_new_ssbo(cells * sizeof(struct LpvCell));
    v->radiance[0] = lpv_gl_new_ssbo(cells * sizeof(struct LpvCell));
    v->radiance[1] = lpv_gl_new_ssbo(cells * sizeof(struct LpvCell));
    v->tail_base = lpv_gl_new_ssbo(cells * sizeof(struct LpvCell));
    v->ao = lpv_gl_new_ssbo(cells * 4 * sizeof(float));
    v->cells = cells;
    memcpy(v->alloc_dims, v->grid.dims, sizeof v->alloc_dims);
    v->result = 0;
    if (glGetError() != GL_NO_ERROR) {
        free_storage(v);
        return lpv_error(err, err_size, "could not allocate the imperfect volume's %dx%dx%d voxels",
                         v->grid.dims[0], v->grid.dims[1], v->grid.dims[2]);
    }
    return 0;
}

static void plan(const lpv_technique *t, const lpv_settings *s, const lpv_plan_facts *f, lpv_plan *p)
{
    const lpv_iv_gpu *v = (const lpv_iv_gpu *)t;
    lpv_plan_make_iv(s, f, &v->cloud, p);
    /* The cloud is sorted by the voxels of the placement it was sampled for;
     * the engine samples again when the placement moves (samples_stale), so
     * this only says so if a path ever forgets to. */
    if (p->pass[LPV_PASS_IV_POINTS].run && v->points && memcmp(&v->pending, &v->cloud_grid, sizeof v->pending) != 0)
        lpv_plan_decide(p, LPV_PASS_IV_POINTS, 0,
                        "the point cloud was sampled for another placement (%dx%dx%d voxels, now %dx%dx%d): only the "
                        "camera's pixels fill the volume until the scene is sampled again",
                        v->cloud_grid.dims[0], v->cloud_grid.dims[1], v->cloud_grid.dims[2], v->pending.dims[0],
                        v->pending.dims[1], v->pending.dims[2]);
}

static int tick(lpv_technique *t, const lpv_technique_inputs *in, char *err, size_t err_size)
{
    (void)err;
    (void)err_size;
    lpv_iv_gpu *v = (lpv_iv_gpu *)t;
    const lpv_plan *p = in->plan;
    lpv_iv_create_volume(v, in);
    if (p->pass[LPV_PASS_IV_GATHER].run) {
        lpv_iv_gather_bounces(v, in);
    } else {
        v->result = 0;
        v->bounces_run = 0;
        v->tail_run = 0;
        v->filter_run = 0;
        lpv_iv_clear_buffer(v->radiance[0]);
    }
    if (p->pass[LPV_PASS_IV_AO].run) {
        lpv_timer_begin(in->timer, "iv_ao");
        lpv_iv_march_volume(v, in->settings, v->radiance[1 - v->result], 1, in->timer);
        lpv_timer_end(in->timer);
    }
    glUseProgram(0);
    return 0;
}

static void bind_lookup(const lpv_technique *t, GLuint prog, float damping)
{
    const lpv_iv_gpu *v = (const lpv_iv_gpu *)t;
    glUniform1f(glGetUniformLocation(prog, "u_damping"), damping);
    glUniform1i(glGetUniformLocation(prog, "u_iv_neighbours"), v->settings.iv.neighbours);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, v->grid_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_ACC, v->radiance[v->result]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_AO, v->ao);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_OCCUPANCY, v->occupancy);
}

static void describe(const lpv_technique *t, lpv_volume_desc *d)
{
    const lpv_iv_gpu *v = (const lpv_iv_gpu *)t;
    memset(d, 0, sizeof *d);
    d->technique = lpv_technique_iv.name;
    d->levels = 1;
    d->level[0] = v->grid;
    d->volumes_per_level = 1;
    d->values_per_cell = 12;
    d->kind = LPV_LEVELS_IV_VOXELS; /* radiance at the voxel centres, looked up by iv_blend (SPEC R5.14) */
    d->units = "W/(m^2 sr)";
    d->iv_neighbours = v->settings.iv.neighbours;
}

/* The voxels' direct light (IvVoxel.r, g, b) as LpvCells. */
static size_t read_direct(const lpv_iv_gpu *v, lpv_cell *out, size_t max)
{
    size_t n = v->cells < max ? v->cells : max;
    struct IvVoxel *vox = n ? malloc(n * sizeof *vox) : NULL;
    if (!vox)
        return 0;
    n = lpv_gl_read_buffer(v->voxels, sizeof *vox, v->cells, vox, n);
    for (size_t i = 0; i < n; ++i) {
        memcpy(out[i].r, vox[i].r, sizeof out[i].r);
        memcpy(out[i].g, vox[i].g, sizeof out[i].g);
        memcpy(out[i].b, vox[i].b, sizeof out[i].b);
    }
    free(vox);
    return n;
}

static size_t read(lpv_technique *t, const lpv_plan *last, lpv_volume_part part, lpv_grid_which which, void *out,
                   size_t max)
{
    (void)last;
    lpv_iv_gpu *v = (lpv_iv_gpu *)t;
    switch (part) {
    case LPV_VOLUME_SUMMED:
    case LPV_VOLUME_STORED:
        if (which == LPV_GRID_INJECTED)
            return read_direct(v, out, max);
        return lpv_gl_read_buffer(v->radiance[v->result], sizeof(lpv_cell), v->cells, out, max);
    case LPV_VOLUME_IV_VOXELS:
        return lpv_gl_read_buffer(v->voxels, sizeof(struct IvVoxel), v->cells, out, max);
    case LPV_VOLUME_AO:
        return lpv_gl_read_buffer(v->ao, 4 * sizeof(float), v->cells, out, max);
    case LPV_VOLUME_GEOMETRY:
    case LPV_VOLUME_TRANSMIT:
    case LPV_VOLUME_INDEX:
    case LPV_VOLUME_VISIBILITY:
        return 0;
    }
    return 0;
}

static void stats(const lpv_technique *t, const lpv_plan *last, lpv_engine_stats *s)
{
    const lpv_iv_gpu *v = (const lpv_iv_gpu *)t;
    s->cascades = 1;
    s->cells = v->cells;
    s->iterations = last->pass[LPV_PASS_IV_GATHER].run ? v->bounces_run : 0;
    s->cell_steps = 0.0;
    s->occlusion = 1; /* the march stops at occupied voxels */
    /* what the tick's volume was made of (the stats JSON's "iv"; the daemon
     * adds "occupied", counted from the index it sends, SPEC R5.14) */
    const int tail = last->pass[LPV_PASS_IV_GATHER].run && v->tail_run;
    float ratio[3] = {0.0f, 0.0f, 0.0f}; /* the tail's per-bounce ratio per channel (iv_tail.comp); 0 without */
    if (tail)
        lpv_iv_gpu_tail_ratio(v, ratio);
    lpv_stats_put(s, "points", LPV_STAT_INT, (double)v->cloud.points, 0, 0); /* the scene's point cloud */
    lpv_stats_put(s, "points_per_piece", LPV_STAT_INT, v->cloud.points_per_piece, 0, 0); /* after the budget */
    lpv_stats_put(s, "voxels", LPV_STAT_INT, (double)s->cells, 0, 0);
    lpv_stats_put(s, "bounces", LPV_STAT_INT, s->iterations, 0, 0); /* gathered: 0 when iv_gather did not run */
    lpv_stats_put(s, "bounces_requested", LPV_STAT_INT, v->settings.iv.bounces, 0, 0);
    lpv_stats_put(s, "rays", LPV_STAT_INT, v->settings.iv.rays, 0, 0); /* per voxel and bounce */
    lpv_stats_put(s, "reprojected", LPV_STAT_BOOL, last->pass[LPV_PASS_IV_REPROJECT].run, 0, 0);
    lpv_stats_put(s, "ao", LPV_STAT_BOOL, last->pass[LPV_PASS_IV_AO].run, 0, 0); /* the ao term has a volume */
    lpv_stats_put(s, "tail", LPV_STAT_BOOL, tail, 0, 0); /* the bounces after these added as a series */
    lpv_stats_put(s, "tail_ratio", LPV_STAT_REAL3, ratio[0], ratio[1], ratio[2]);
    /* the surface voxels took their plane's mean (LPV_IV_FILTER) */
    lpv_stats_put(s, "filtered", LPV_STAT_BOOL, last->pass[LPV_PASS_IV_GATHER].run && v->filter_run, 0, 0);
}

const lpv_technique_class lpv_technique_iv = {
    .name = LPV_TECHNIQUE_IV,
    .lookup_includes = LOOKUP,
    .create = create,
    .destroy = destroy,
    .configure = configure,
    .sample_scene = lpv_iv_sample_scene,
    .samples_stale = lpv_iv_samples_stale,
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
