/*
 * technique_lpv.c - the cascaded light propagation volume (Kaplanyan &
 * Dachsbacher) as an lpv_technique: its programs, its plan (lpv_plan.c's
 * rules, techniques/lpv/core), its tick (inject -> geometry volume -> propagation with the
 * far-field hand-off), its lookup (techniques/lpv/shaders/lookup.glsl over grid.glsl) and
 * what it says about its volume. The passes are in lpv_*.c beside it.
 */
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "lpv_internal.h"
#include "lpv_rules.h"
#include "shader.h"

static const char *const INC_GRID[] = {"grid.glsl", NULL};
static const char *const INC_PROPAGATE[] = {"grid.glsl", "flux_limit.glsl", "medium.glsl", NULL};
static const char *const LOOKUP[] = {"grid.glsl", "lookup.glsl", NULL};

void lpv_cascaded_delete(lpv_cascaded *c)
{
    if (!c)
        return;
    lpv_cascaded_free_storage(c);
    GLuint *progs[] = {&c->prog_inject_vpl, &c->prog_inject_gv, &c->prog_pack,    &c->prog_gv_merge,
                       &c->prog_transmit,   &c->prog_propagate, &c->prog_propagate_effects,
                       &c->prog_handoff,    &c->prog_lookup_pack, &c->prog_normals_pack};
    for (size_t i = 0; !c->borrowed_programs && i < sizeof progs / sizeof progs[0]; ++i)
        if (*progs[i])
            glDeleteProgram(*progs[i]);
    if (c->empty_vao)
        glDeleteVertexArrays(1, &c->empty_vao);
    lpv_gl_delete_buffer(&c->grid_ubo);
    free(c);
}

/* The state with an empty VAO and its grid block; programs are the caller's. */
static lpv_cascaded *cascaded_alloc(char *err, size_t err_size)
{
    lpv_cascaded *c = calloc(1, sizeof *c);
    if (!c) {
        lpv_error(err, err_size, "out of memory");
        return NULL;
    }
    c->base.cls = &lpv_technique_cascaded_lpv;
    glGenVertexArrays(1, &c->empty_vao);
    glGenBuffers(1, &c->grid_ubo);
    glBindBuffer(GL_UNIFORM_BUFFER, c->grid_ubo);
    glBufferData(GL_UNIFORM_BUFFER, sizeof(struct LpvGridParams), NULL, GL_DYNAMIC_DRAW);
    lpv_settings_resolve(&c->settings);
    return c;
}

lpv_cascaded *lpv_cascaded_new(char *err, size_t err_size)
{
    lpv_cascaded *c = cascaded_alloc(err, err_size);
    if (!c)
        return NULL;
    struct {
        GLuint *prog;
        const char *a, *b;
        const char *const *inc;
        const char *defines;
    } progs[] = {
        {&c->prog_inject_vpl, "inject_vpl.vert", "inject_vpl.frag", INC_GRID},
        {&c->prog_inject_gv, "inject_gv.vert", "inject_gv.frag", INC_GRID},
        {&c->prog_pack, "lpv_pack.comp", NULL, INC_PROPAGATE},
        {&c->prog_gv_merge, "gv_merge.comp", NULL, INC_GRID},
        {&c->prog_transmit, "transmit.comp", NULL, INC_GRID},
        {&c->prog_propagate, "propagate.comp", NULL, INC_PROPAGATE, "#define LPV_PROPAGATE_EFFECTS 0"},
        {&c->prog_propagate_effects, "propagate.comp", NULL, INC_PROPAGATE, "#define LPV_PROPAGATE_EFFECTS 1"},
        {&c->prog_handoff, "lpv_handoff.comp", NULL, INC_PROPAGATE},
        {&c->prog_lookup_pack, "lpv_lookup_pack.comp", NULL, NULL},
        {&c->prog_normals_pack, "lpv_normals_pack.comp", NULL, LOOKUP},
    };
    for (size_t i = 0; i < sizeof progs / sizeof progs[0]; ++i) {
        *progs[i].prog =
            lpv_program_build_defines(progs[i].a, NULL, progs[i].b, progs[i].defines, progs[i].inc, err, err_size);
        if (!*progs[i].prog) {
            lpv_cascaded_delete(c);
            return NULL;
        }
    }
    return c;
}

lpv_cascaded *lpv_cascaded_new_sharing(const lpv_cascaded *owner, char *err, size_t err_size)
{
    lpv_cascaded *c = cascaded_alloc(err, err_size);
    if (!c)
        return NULL;
    c->borrowed_programs = 1;
    c->prog_inject_vpl = owner->prog_inject_vpl;
    c->prog_inject_gv = owner->prog_inject_gv;
    c->prog_pack = owner->prog_pack;
    c->prog_gv_merge = owner->prog_gv_merge;
    c->prog_transmit = owner->prog_transmit;
    c->prog_propagate = owner->prog_propagate;
    c->prog_propagate_effects = owner->prog_propagate_effects;
    c->prog_handoff = owner->prog_handoff;
    c->prog_lookup_pack = owner->prog_lookup_pack;
    c->prog_normals_pack = owner->prog_normals_pack;
    return c;
}

static void destroy(lpv_technique *t) { lpv_cascaded_delete((lpv_cascaded *)t); }

static lpv_technique *create(char *err, size_t err_size)
{
    lpv_cascaded *c = lpv_cascaded_new(err, err_size);
    if (c)
        c->lookup_wanted = 1;
    return c ? &c->base : NULL;
}

static void configure(lpv_technique *t, const lpv_settings *s) { ((lpv_cascaded *)t)->settings = *s; }

static int place(lpv_technique *t, const lpv_technique_where *w, int *moved, char *err, size_t err_size)
{
    return lpv_cascaded_place((lpv_cascaded *)t, w, moved, err, err_size);
}

static int commit(lpv_technique *t, const lpv_technique_where *w, int *reset, char *err, size_t err_size)
{
    return lpv_cascaded_commit((lpv_cascaded *)t, w, reset, err, err_size);
}

/* The LPV's rules (techniques/lpv/core/lpv_plan.c): they also decide which of the shared
 * producers run (the RSMs feed injection, the camera's surfels the GV). */
static void plan(const lpv_technique *t, const lpv_settings *s, const lpv_plan_facts *f, lpv_plan *p)
{
    (void)t;
    lpv_plan_make_lpv(s, f, p);
    lpv_plan_grid_reach_note(s, p);
}

static int tick(lpv_technique *t, const lpv_technique_inputs *in, char *err, size_t err_size)
{
    (void)err;
    (void)err_size;
    lpv_cascaded *c = (lpv_cascaded *)t;
    const lpv_plan *p = in->plan;
    if (p->pass[LPV_PASS_INJECT].run)
        lpv_pass_inject_run(c, in, p->pass[LPV_PASS_RSM].run, p->pass[LPV_PASS_EMISSIVE].run);
    else
        lpv_pass_clear_run(c);
    if (p->pass[LPV_PASS_GV].run)
        lpv_pass_gv_run(c, in, p->pass[LPV_PASS_BOUNCE].run);
    if (p->pass[LPV_PASS_PROPAGATE].run)
        lpv_pass_propagate_run(c, in, p->pass[LPV_PASS_GV].run, p->pass[LPV_PASS_BOUNCE].run);
    lpv_lookup_volume_fill(&c->lookup, lpv_cascaded_lookup_programs(c), c->lpv_acc, in->lookup_planes,
                           in->lookup_plane_count, in->timer);
    return 0;
}

static void bind_lookup(const lpv_technique *t, GLuint prog, float damping)
{
    const lpv_cascaded *c = (const lpv_cascaded *)t;
    glUniform1f(glGetUniformLocation(prog, "u_damping"), damping);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, c->grid_ubo);
    lpv_lookup_volume_bind(&c->lookup, prog);
}

static int lookup_split(const lpv_technique *t) { return ((const lpv_cascaded *)t)->lookup.normals > 0; }

static void describe(const lpv_technique *t, lpv_volume_desc *d)
{
    const lpv_cascaded *c = (const lpv_cascaded *)t;
    memset(d, 0, sizeof *d);
    d->technique = lpv_technique_cascaded_lpv.name;
    d->levels = c->cascades.count > 0 ? c->cascades.count : 1;
    for (int k = 0; k < d->levels; ++k) {
        d->level[k] = (k < c->cascades.count) ? c->cascades.grid[k] : c->grid;
        for (int i = 0; i < 3; ++i)
            d->origin_cells[k][i] = k < c->cascades.count ? c->cascades.origin_cells[k][i]
                                                          : c->grid.origin[i] / c->grid.cell_size;
    }
    d->far_field = c->cascades.handoff;
    d->vpl_spread = c->settings.lpv.smooth_injection == LPV_SWITCH_ON;
    d->volumes_per_level = c->bins > 1 ? c->bins : 1;
    d->values_per_cell = 12;
    d->kind = LPV_LEVELS_CASCADES;
    d->units = "W/sr";
}

static size_t read(lpv_technique *t, const lpv_plan *last, lpv_volume_part part, lpv_grid_which which, void *out,
                   size_t max)
{
    return lpv_cascaded_read((lpv_cascaded *)t, last, part, which, out, max);
}

static void memory_need(const lpv_technique *t, lpv_memory_need *n)
{
    lpv_cascaded_memory_need((const lpv_cascaded *)t, n);
}

static void stats(const lpv_technique *t, const lpv_plan *last, lpv_engine_stats *s)
{
    const lpv_cascaded *c = (const lpv_cascaded *)t;
    s->cascades = c->cascades.count;
    s->cells = lpv_all_cells(c);
    s->iterations = c->settings.lpv.iterations;
    s->cell_steps = last->pass[LPV_PASS_PROPAGATE].run ? (double)lpv_volume_cells(c) * c->settings.lpv.iterations : 0.0;
    s->occlusion = last->pass[LPV_PASS_GV].run;
}

const lpv_technique_class lpv_technique_cascaded_lpv = {
    .name = LPV_TECHNIQUE_LPV,
    .lookup_includes = LOOKUP,
    .create = create,
    .destroy = destroy,
    .configure = configure,
    .place = place,
    .commit = commit,
    .plan = plan,
    .tick = tick,
    .bind_lookup = bind_lookup,
    .lookup_split = lookup_split,
    .describe = describe,
    .read = read,
    .memory_need = memory_need,
    .stats = stats,
};
