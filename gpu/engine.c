/*
 * engine.c - the engine object: its producers' programs and shared GL
 * objects, settings, view and what they invalidate. The technique it drives
 * and the programs that read its volume are in engine_technique.c, the
 * planner's facts in engine_facts.c, the scene's upload in engine_scene.c,
 * the tick in engine_tick.c, rendering and queries in engine_render.c,
 * read-backs in engine_read.c; the shared producers' passes in pass_*.c.
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
static const char *const INC_BLOCKS8[] = {"grid.glsl", "block_slots8.glsl", "block_groups.glsl", NULL};
/* the RSMs' VPL producers mark the VPLs that carry light (compact.glsl) */
static const char *const INC_VPL_BLOCKS[] = {"grid.glsl", "block_groups.glsl", "compact.glsl", NULL};
static const char *const INC_VPL_BLOCKS8[] = {"grid.glsl", "block_slots8.glsl", "block_groups.glsl", "compact.glsl",
                                              NULL};
static const char *const INC_COMPACT[] = {"compact.glsl", NULL};

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
        {&e->progs.rsm, "scene.vert", "rsm.frag", INC_RSM},
        {&e->progs.rsm_plain, "scene.vert", "rsm.frag", INC_RSM, PLAIN},
        {&e->progs.vpl_extract, "vpl_extract.comp", NULL, INC_COMPACT},
        {&e->progs.vpl_blocks, "vpl_blocks.comp", NULL, INC_VPL_BLOCKS},
        {&e->progs.vpl_blocks8, "vpl_blocks.comp", NULL, INC_VPL_BLOCKS8},
        {&e->progs.vpl_blocks8_vpls, "vpl_blocks.comp", NULL, INC_VPL_BLOCKS8, "#define LPV_BLOCKS_VPLS_ONLY 1"},
        {&e->progs.gbuffer, "scene.vert", "gbuffer.frag", INC_MATERIAL},
        {&e->progs.gbuffer_plain, "scene.vert", "gbuffer.frag", INC_MATERIAL, PLAIN},
        {&e->progs.camera_surfels, "camera_surfels.comp", NULL, INC_BLOCKS8},
        {&e->progs.shadow, "scene.vert", "shadow_depth.frag", INC_MATERIAL},
        {&e->progs.shadow_plain, "scene.vert", "shadow_depth.frag", INC_MATERIAL, PLAIN},
        {&e->progs.compact[0], "compact.comp", NULL, INC_COMPACT, "#define LPV_COMPACT_PHASE 1"},
        {&e->progs.compact[1], "compact.comp", NULL, INC_COMPACT, "#define LPV_COMPACT_PHASE 2"},
        {&e->progs.translucent, "translucent.comp", NULL, NULL},
    };
    for (size_t i = 0; i < sizeof progs / sizeof progs[0]; ++i) {
        *progs[i].prog =
            lpv_program_build_defines(progs[i].a, NULL, progs[i].b, progs[i].defines, progs[i].inc, err, err_size);
        if (!*progs[i].prog) {
            lpv_engine_destroy(e);
            return NULL;
        }
    }
    if (lpv_engine_use_technique(e, LPV_TECHNIQUE_ID_LPV, err, err_size) != 0) {
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
    lpv_shadow_maps_create(&e->shadows);
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
    lpv_rsms_free(&e->rsm);
    lpv_pass_camera_free(e);
    lpv_shadow_maps_destroy(&e->shadows);
    lpv_medium_free(&e->medium);
    lpv_gl_delete_buffer(&e->query_in);
    lpv_gl_delete_buffer(&e->query_out);
    if (e->tech)
        e->tech->cls->destroy(e->tech);
    lpv_engine_free_frame_programs(e);
    GLuint *progs = (GLuint *)&e->progs;
    for (size_t i = 0; i < sizeof e->progs / sizeof(GLuint); ++i)
        if (progs[i])
            glDeleteProgram(progs[i]);
    if (e->empty_vao)
        glDeleteVertexArrays(1, &e->empty_vao);
    lpv_gl_delete_buffer(&e->light_ubo);
    lpv_gl_delete_buffer(&e->view_ubo);
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
        e->gbuf.stale = 1;
    }
    if (touches & LPV_TOUCH_SHADOWS)
        e->shadows.valid = 0;
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
        e->gbuf.stale = 1;
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
        e->gbuf.stale = 1;
    e->view = *view;
    e->has_view = 1;
    lpv_engine_reach_view(e);
    return 0;
}

void lpv_engine_invalidate(lpv_engine *e)
{
    e->forced = 1;
    e->shadows.valid = 0;
}

void lpv_engine_forget(lpv_engine *e)
{
    if (e->tech && e->tech->cls->forget)
        e->tech->cls->forget(e->tech);
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

