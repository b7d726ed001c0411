/*
 * engine.c - the engine object: its programs and shared GL objects, the
 * technique it drives (technique.h), settings, view and what they
 * invalidate. The scene's upload is in engine_scene.c, the tick in
 * engine_tick.c, rendering and queries in engine_render.c, read-backs in
 * engine_read.c; the shared producers' passes in pass_*.c.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "engine_internal.h"
#include "error.h"
#include "memory_limits.h"
#include "settings_fields.h"
#include "shader.h"

static const char *const INC_MATERIAL[] = {"material.glsl", NULL};
static const char *const INC_RSM[] = {"material.glsl", "lights.glsl", NULL};
static const char *const INC_SHADE[] = {"lights.glsl", "shadow.glsl", "shading.glsl", NULL};
static const char *const INC_MEDIA[] = {"lights.glsl", "shadow.glsl", "medium.glsl", NULL};
static const char *const INC_BLOCKS8[] = {"grid.glsl", "block_slots8.glsl", "block_groups.glsl", NULL};
/* the RSMs' VPL producers mark the VPLs that carry light (compact.glsl) */
static const char *const INC_VPL_BLOCKS[] = {"grid.glsl", "block_groups.glsl", "compact.glsl", NULL};
static const char *const INC_VPL_BLOCKS8[] = {"grid.glsl", "block_slots8.glsl", "block_groups.glsl", "compact.glsl",
                                              NULL};
static const char *const INC_COMPACT[] = {"compact.glsl", NULL};

/* out = grid.glsl (the SH basis and grid block every reader of a volume
 * uses, whatever the technique), the technique's lookup includes (a name
 * already in the list is not pasted twice), reach.glsl (the enclosed-light
 * mask every reader of the volume multiplies by), then the pass's own (both
 * NULL-terminated; own may be NULL). Returns -1 when they do not fit. */
static int includes(const char **out, size_t cap, const char *const *own, const char *const *lookup)
{
    size_t n = 0;
    out[n++] = "grid.glsl";
    for (const char *const *i = lookup; i && *i; ++i) {
        int dup = 0;
        for (size_t k = 0; k < n; ++k)
            dup |= strcmp(out[k], *i) == 0;
        if (dup)
            continue;
        if (n + 1 < cap)
            out[n++] = *i;
        else
            return -1;
    }
    if (n + 1 < cap)
        out[n++] = "reach.glsl";
    else
        return -1;
    for (const char *const *i = own; i && *i; ++i)
        if (n + 1 < cap)
            out[n++] = *i;
        else
            return -1;
    out[n] = NULL;
    return 0;
}

/* The frame programs built so far (lpv_engine_frame_program). */
static void delete_frame_programs(lpv_engine *e)
{
    for (int v = 0; v < LPV_FRAME_VARIANTS; ++v)
        if (e->prog_frame[v]) {
            glDeleteProgram(e->prog_frame[v]);
            e->prog_frame[v] = 0;
        }
}

/* Makes technique id the engine's: creates its instance and builds the
 * passes that read its volume (shading, query, glossy, media) with its
 * lookup includes (technique.h). On failure the current technique stays. */
static int use_technique(lpv_engine *e, lpv_technique_id id, char *err, size_t err_size)
{
    const lpv_technique_class *cls = lpv_technique_class_of(id);
    if (!cls)
        return lpv_error(err, err_size, "technique %d has no implementation", (int)id);
    const char *const *lookup = cls->lookup_includes;
    const char *inc_shade[16], *inc_media[16], *inc_lookup[16];
    if (includes(inc_shade, 16, INC_SHADE, lookup) || includes(inc_media, 16, INC_MEDIA, lookup) ||
        includes(inc_lookup, 16, NULL, lookup))
        return lpv_error(err, err_size, "technique %s names too many lookup includes", cls->name);
    struct {
        GLuint *prog;
        const char *a, *b;
        const char *const *inc;
        const char *defines;
    } progs[] = {
        /* the frame's programs are built when first used (lpv_engine_frame_program) */
        {&e->prog_shade_rest, "shade_rest.comp", NULL, inc_shade,
         "#define LPV_LOOKUP_DAMPING 0\n#define LPV_LOOKUP_SPLIT 1"},
        {&e->prog_shade_rest_damped, "shade_rest.comp", NULL, inc_shade, "#define LPV_LOOKUP_SPLIT 1"},
        {&e->prog_area_shadow_blocks, "area_shadow_blocks.comp", NULL, inc_shade, "#define LPV_LOOKUP_DAMPING 0"},
        {&e->prog_area_shadow_rest, "area_shadow_rest.comp", NULL, inc_shade,
         "#define LPV_LOOKUP_DAMPING 0\n#define LPV_AREA_SHADOW_BLOCKS 1"},
        {&e->prog_lookup_blocks, "lookup_blocks.comp", NULL, inc_shade, "#define LPV_LOOKUP_DAMPING 0"},
        {&e->prog_lookup_blocks_damped, "lookup_blocks.comp", NULL, inc_shade, NULL},
        {&e->prog_query, "query.comp", NULL, inc_lookup},
        {&e->prog_glossy, "fullscreen.vert", "glossy.frag", inc_lookup},
        {&e->prog_media, "fullscreen.vert", "media.frag", inc_media},
    };
    enum { N = sizeof progs / sizeof progs[0] };
    GLuint built[N] = {0};
    for (size_t i = 0; i < N; ++i) {
        built[i] = lpv_program_build_defines(progs[i].a, NULL, progs[i].b, progs[i].defines, progs[i].inc, err,
                                             err_size);
        if (!built[i]) {
            for (size_t k = 0; k < i; ++k)
                glDeleteProgram(built[k]);
            return -1;
        }
    }
    lpv_technique *t = cls->create(err, err_size);
    if (!t) {
        for (size_t k = 0; k < N; ++k)
            glDeleteProgram(built[k]);
        return -1;
    }
    for (size_t i = 0; i < N; ++i) {
        if (*progs[i].prog)
            glDeleteProgram(*progs[i].prog);
        *progs[i].prog = built[i];
    }
    if (e->tech)
        e->tech->cls->destroy(e->tech);
    e->tech = t;
    e->tech_id = id;
    delete_frame_programs(e); /* they hold the previous technique's lookup */
    return 0;
}

GLuint lpv_engine_frame_program(lpv_engine *e, unsigned variant, char *err, size_t err_size)
{
    if (variant & LPV_FRAME_BLOCKS) /* the frame reads the blocks' irradiance: it looks nothing up */
        variant &= ~(unsigned)(LPV_FRAME_DAMPED | LPV_FRAME_SPLIT);
    if (e->prog_frame[variant])
        return e->prog_frame[variant];
    const char *inc_shade[16];
    if (includes(inc_shade, 16, INC_SHADE, e->tech->cls->lookup_includes)) {
        lpv_error(err, err_size, "technique %s names too many lookup includes", e->tech->cls->name);
        return 0;
    }
    char defines[384];
    snprintf(defines, sizeof defines, "%s%s%s%s%s%s%s",
             variant & LPV_FRAME_OCCLUSION ? "" : "#define LPV_FRAME_OCCLUSION 0\n",
             variant & LPV_FRAME_UNLIT ? "" : "#define LPV_FRAME_UNLIT 0\n",
             variant & LPV_FRAME_DIRECTIONAL ? "" : "#define LPV_SHADE_DIRECTIONAL 0\n",
             variant & LPV_FRAME_DAMPED ? "" : "#define LPV_LOOKUP_DAMPING 0\n",
             variant & LPV_FRAME_SPLIT ? "#define LPV_LOOKUP_SPLIT 1\n" : "",
             variant & LPV_FRAME_BLOCKS ? "#define LPV_LOOKUP_BLOCKS 1\n" : "",
             variant & LPV_FRAME_AREA_BLOCKS ? "#define LPV_AREA_SHADOW_BLOCKS 1\n" : "");
    e->prog_frame[variant] = lpv_program_build_defines("shade.comp", NULL, NULL, defines, inc_shade, err, err_size);
    return e->prog_frame[variant];
}

int lpv_engine_resolve_technique(lpv_engine *e, const lpv_settings *s, char *err, size_t err_size)
{
    lpv_plan_facts facts;
    lpv_engine_gather_facts(e, &facts);
    char why[sizeof e->tech_reason];
    const lpv_technique_id id = lpv_technique_choose(s, e->has_scene ? &facts : NULL, why, sizeof why);
    if (id != e->tech_id && use_technique(e, id, err, err_size) != 0)
        return -1;
    e->tech->cls->configure(e->tech, s);
    memcpy(e->tech_reason, why, sizeof why);
    return 0;
}

/* The scene passes' programs for scenes of plain materials (material.glsl). */
#define PLAIN "#define LPV_MATERIAL_PLAIN 1"

lpv_engine *lpv_engine_create(char *err, size_t err_size)
{
    lpv_engine *e = calloc(1, sizeof *e);
    if (!e) {
        lpv_error(err, err_size, "out of memory");
        return NULL;
    }
    struct {
        GLuint *prog;
        const char *a, *b;
        const char *const *inc;
        const char *defines;
    } progs[] = {
        {&e->prog_rsm, "scene.vert", "rsm.frag", INC_RSM},
        {&e->prog_rsm_plain, "scene.vert", "rsm.frag", INC_RSM, PLAIN},
        {&e->prog_vpl_extract, "vpl_extract.comp", NULL, INC_COMPACT},
        {&e->prog_vpl_blocks, "vpl_blocks.comp", NULL, INC_VPL_BLOCKS},
        {&e->prog_vpl_blocks8, "vpl_blocks.comp", NULL, INC_VPL_BLOCKS8},
        {&e->prog_vpl_blocks8_vpls, "vpl_blocks.comp", NULL, INC_VPL_BLOCKS8, "#define LPV_BLOCKS_VPLS_ONLY 1"},
        {&e->prog_gbuffer, "scene.vert", "gbuffer.frag", INC_MATERIAL},
        {&e->prog_gbuffer_plain, "scene.vert", "gbuffer.frag", INC_MATERIAL, PLAIN},
        {&e->prog_camera_surfels, "camera_surfels.comp", NULL, INC_BLOCKS8},
        {&e->prog_shadow, "scene.vert", "shadow_depth.frag", INC_MATERIAL},
        {&e->prog_shadow_plain, "scene.vert", "shadow_depth.frag", INC_MATERIAL, PLAIN},
        {&e->prog_compact[0], "compact.comp", NULL, INC_COMPACT, "#define LPV_COMPACT_PHASE 1"},
        {&e->prog_compact[1], "compact.comp", NULL, INC_COMPACT, "#define LPV_COMPACT_PHASE 2"},
        {&e->prog_translucent, "translucent.comp", NULL, NULL},
    };
    for (size_t i = 0; i < sizeof progs / sizeof progs[0]; ++i) {
        *progs[i].prog =
            lpv_program_build_defines(progs[i].a, NULL, progs[i].b, progs[i].defines, progs[i].inc, err, err_size);
        if (!*progs[i].prog) {
            lpv_engine_destroy(e);
            return NULL;
        }
    }
    if (use_technique(e, LPV_TECHNIQUE_ID_LPV, err, err_size) != 0) {
        lpv_engine_destroy(e);
        return NULL;
    }
    snprintf(e->tech_reason, sizeof e->tech_reason, "requested");
    GLint max_block = 0;
    glGetIntegerv(GL_MAX_UNIFORM_BLOCK_SIZE, &max_block);
    if ((size_t)max_block < sizeof(struct LpvLightBlock) || (size_t)max_block < sizeof(struct LpvShadowBlock)) {
        lpv_error(err, err_size, "the light and shadow blocks need %zu and %zu bytes of uniform block, GL allows %d",
                  sizeof(struct LpvLightBlock), sizeof(struct LpvShadowBlock), max_block);
        lpv_engine_destroy(e);
        return NULL;
    }
    glGenVertexArrays(1, &e->empty_vao);
    glGenBuffers(1, &e->light_ubo);
    glGenBuffers(1, &e->view_ubo);
    glGenBuffers(1, &e->shadow_ubo);
    glBindBuffer(GL_UNIFORM_BUFFER, e->shadow_ubo);
    glBufferData(GL_UNIFORM_BUFFER, sizeof(struct LpvShadowBlock), NULL, GL_DYNAMIC_DRAW);
    glBindBuffer(GL_UNIFORM_BUFFER, e->light_ubo);
    glBufferData(GL_UNIFORM_BUFFER, sizeof(struct LpvLightBlock), NULL, GL_DYNAMIC_DRAW);
    glBindBuffer(GL_UNIFORM_BUFFER, e->view_ubo);
    glBufferData(GL_UNIFORM_BUFFER, sizeof(struct LpvViewBlock), NULL, GL_DYNAMIC_DRAW);
    lpv_timer_init(&e->timer);
    lpv_settings_resolve(&e->settings);
    lpv_memory_limits_query(&e->mem_limits);
    e->mem_device_budget = e->mem_limits.budget;
    snprintf(e->mem_device_source, sizeof e->mem_device_source, "%s", e->mem_limits.budget_source);
    e->tech->cls->describe(e->tech, &e->desc);
    return e;
}

void lpv_engine_destroy(lpv_engine *e)
{
    if (!e)
        return;
    lpv_engine_free_scene(e);
    lpv_pass_rsm_free(e);
    lpv_pass_camera_free(e);
    lpv_frame_blocks_free(e);
    lpv_pass_shadow_free(e);
    lpv_medium_free(&e->medium);
    lpv_gl_delete_buffer(&e->query_in);
    lpv_gl_delete_buffer(&e->query_out);
    if (e->tech)
        e->tech->cls->destroy(e->tech);
    delete_frame_programs(e);
    GLuint *progs[] = {&e->prog_rsm,
                       &e->prog_rsm_plain,
                       &e->prog_vpl_extract,
                       &e->prog_vpl_blocks,
                       &e->prog_vpl_blocks8,
                       &e->prog_vpl_blocks8_vpls,
                       &e->prog_gbuffer,
                       &e->prog_gbuffer_plain,
                       &e->prog_camera_surfels,
                       &e->prog_query,
                       &e->prog_glossy,
                       &e->prog_media,
                       &e->prog_shadow,
                       &e->prog_shadow_plain,
                       &e->prog_lookup_blocks,
                       &e->prog_lookup_blocks_damped,
                       &e->prog_shade_rest,
                       &e->prog_shade_rest_damped,
                       &e->prog_area_shadow_blocks,
                       &e->prog_area_shadow_rest,
                       &e->prog_compact[0],
                       &e->prog_compact[1],
                       &e->prog_translucent};
    for (size_t i = 0; i < sizeof progs / sizeof progs[0]; ++i)
        if (*progs[i])
            glDeleteProgram(*progs[i]);
    if (e->empty_vao)
        glDeleteVertexArrays(1, &e->empty_vao);
    lpv_gl_delete_buffer(&e->light_ubo);
    lpv_gl_delete_buffer(&e->view_ubo);
    lpv_gl_delete_buffer(&e->shadow_ubo);
    lpv_timer_destroy(&e->timer);
    free(e);
}

int lpv_engine_set_settings(lpv_engine *e, const lpv_settings *settings, char *err, size_t err_size)
{
    lpv_settings s = *settings;
    lpv_settings_resolve(&s);
    if (lpv_settings_validate(&s, err, err_size) != 0)
        return -1;
    char knob[sizeof e->settings_knob];
    unsigned touches = lpv_settings_touches(&e->settings, &s, knob, sizeof knob);
    if (!touches)
        return 0;
    const lpv_technique_id was = e->tech_id;
    if (lpv_engine_resolve_technique(e, &s, err, err_size) != 0)
        return -1; /* the technique touches the volume: the next tick computes it anew */
    if (e->tech_id != was) { /* auto chose another technique (a preset, say): everything anew, as when one is named
                              * (lpv_settings_touches), the scene's samples being the technique's own */
        touches |= LPV_TOUCH_VOLUME | LPV_TOUCH_SAMPLES | LPV_TOUCH_SHADOWS | LPV_TOUCH_SHADING;
        if (!knob[0]) /* no knob of the volume's changed: the plan's reason names the technique */
            snprintf(knob, sizeof knob, "technique");
    }
    e->settings = s;
    e->tech->cls->configure(e->tech, &e->settings);
    e->ticked = 0; /* a render or read-back follows a tick under the new settings */
    if (touches & LPV_TOUCH_VOLUME) {
        if (!e->settings_dirty)
            memcpy(e->settings_knob, knob, sizeof knob);
        e->settings_dirty = 1;
        e->gbuf_stale = 1;
    }
    if (touches & LPV_TOUCH_SHADOWS)
        e->shadow_valid = 0;
    lpv_engine_update_area_samples(e);
    if (!e->has_scene)
        return 0;
    if (((touches & LPV_TOUCH_SAMPLES) || lpv_engine_samples_stale(e)) && lpv_engine_sample_scene(e, err, err_size) != 0)
        return -1;
    return lpv_engine_place_volume(e, err, err_size);
}

lpv_engine_counters lpv_engine_get_counters(const lpv_engine *e) { return e->counters; }

int lpv_engine_set_view(lpv_engine *e, const lpv_view *view, char *err, size_t err_size)
{
    if (!view) {
        e->has_view = 0;
        e->gbuf_stale = 1;
        return 0;
    }
    if (view->width < 1 || view->height < 1 || view->width > 16384 || view->height > 16384)
        return lpv_error(err, err_size, "image size %dx%d outside 1..16384", view->width, view->height);
    if (e->has_scene) { /* the image's storage must fit next to the rest */
        lpv_memory_need need;
        lpv_engine_memory_need(e, &need);
        e->tech->cls->memory_need(e->tech, &need);
        need.image_w = view->width;
        need.image_h = view->height;
        if (lpv_memory_check(&need, &e->mem_limits, err, err_size) != 0)
            return -1;
    }
    if (!e->has_view || memcmp(&e->view, view, sizeof *view) != 0)
        e->gbuf_stale = 1;
    e->view = *view;
    e->has_view = 1;
    lpv_engine_reach_view(e);
    return 0;
}

void lpv_engine_invalidate(lpv_engine *e)
{
    e->forced = 1;
    e->shadow_valid = 0;
}

int lpv_engine_place_volume(lpv_engine *e, char *err, size_t err_size)
{
    lpv_plan_facts f;
    lpv_engine_gather_facts(e, &f);
    lpv_technique_where w;
    lpv_engine_where(e, &f, &w);
    int reset = 0;
    if (e->tech->cls->place(e->tech, &w, NULL, err, err_size) != 0)
        return -1;
    int rc = e->tech->cls->commit(e->tech, &w, &reset, err, err_size);
    lpv_engine_committed(e, reset);
    return rc;
}

void lpv_engine_committed(lpv_engine *e, int reset)
{
    e->tech->cls->describe(e->tech, &e->desc);
    if (reset) { /* new storage holds nothing computed */
        e->ticked = 0;
        e->computed = 0;
    }
}

const lpv_grid *lpv_engine_grid(const lpv_engine *e) { return &e->desc.level[0]; }
const lpv_settings *lpv_engine_settings(const lpv_engine *e) { return &e->settings; }
const lpv_engine_stats *lpv_engine_last_stats(const lpv_engine *e) { return &e->stats; }
const lpv_plan *lpv_engine_last_plan(const lpv_engine *e) { return &e->plan; }
int lpv_engine_cascade_count(const lpv_engine *e) { return e->desc.levels; }

const lpv_grid *lpv_engine_cascade(const lpv_engine *e, int k)
{
    return &e->desc.level[(k >= 0 && k < e->desc.levels) ? k : 0];
}

