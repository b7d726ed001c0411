/*
 * engine_tick.c - one tick: the planner's facts, where the technique's
 * volume goes, the plan, the shared producers (RSMs and their VPLs and
 * surfels, the camera's G-buffer and surfels), the technique's passes on
 * what they made, and the stats.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "engine_internal.h"
#include "error.h"

/* Draws using a material rougher than nothing but below the glossy threshold. */
static size_t glossy_draws(const lpv_engine *e)
{
    size_t n = 0;
    for (uint32_t i = 0; i < e->draw_count; ++i) {
        int m = e->draws[i].material;
        if (m >= 0 && (uint32_t)m < e->material_count && e->materials[m].roughness < e->settings.glossy_roughness)
            ++n;
    }
    return n;
}

/* The planner's facts about the scene, the settings and what changed. */
void lpv_engine_gather_facts(const lpv_engine *e, lpv_plan_facts *f)
{
    memset(f, 0, sizeof *f);
    f->lights = e->light_count;
    f->emissive_vpls = e->emissive_vpl_count;
    f->emissive_surfaces = e->emitters.surfaces;
    f->area_light_samples = e->area_sample_count;
    f->occluder_triangles = e->occluder_triangles;
    f->glossy_draws = glossy_draws(e);
    f->blend_draws = e->blend_draws;
    f->has_medium = e->medium.medium.present || e->settings.fog_sigma_s > 0.0f || e->settings.fog_sigma_a > 0.0f;
    f->has_view = e->has_view;
    f->camera_inside = e->has_view && lpv_point_in_bounds(e->view.eye, e->scene_min, e->scene_max);
    float sides[3];
    lpv_box_sides(e->scene_min, e->scene_max, sides);
    f->scene_shortest = sides[0];
    f->scene_middle = sides[1];
    f->scene_extent = sides[2];
    f->view_chord = f->camera_inside ? e->view_chord : 0.0f;
    f->cascade_finest = lpv_cascade_finest_size(&e->settings, e->scene_min, e->scene_max, f->view_chord);
    f->scene_cross = lpv_cascade_cross_section(e->scene_min, e->scene_max);
    f->free_path = e->reach.free_path;
    if (!lpv_engine_lit_region(e, f->lit_min, f->lit_max, &f->lit_free_path)) { /* the scene's: as unknown */
        memset(f->lit_min, 0, sizeof f->lit_min);
        memset(f->lit_max, 0, sizeof f->lit_max);
        f->lit_free_path = 0.0f;
    }
    f->bounds_given = lpv_settings_bounds_given(&e->settings);
    f->cascades_unfit = !lpv_cascades_fit(&e->settings, e->scene_min, e->scene_max, f->view_chord, NULL, 0);
    for (int i = 0; i < 3; ++i)
        f->scene_reach = fmaxf(f->scene_reach, fmaxf(fabsf(e->scene_min[i]), fabsf(e->scene_max[i])));
    f->first_tick = !e->computed;
    f->scene_changed = e->scene_dirty;
    f->lights_changed = e->lights_dirty;
    f->settings_changed = e->settings_dirty;
    memcpy(f->settings_knob, e->settings_knob, sizeof f->settings_knob);
    f->forced = e->forced;
    if (e->has_view != e->computed_has_view) {
        f->camera_move_cells = INFINITY;
    } else if (e->has_view) {
        float d2 = 0.0f;
        for (int i = 0; i < 3; ++i)
            d2 += (e->view.eye[i] - e->computed_eye[i]) * (e->view.eye[i] - e->computed_eye[i]);
        f->camera_move_cells = sqrtf(d2) / e->desc.level[0].cell_size;
    }
}

void lpv_engine_where(const lpv_engine *e, const lpv_plan_facts *f, lpv_technique_where *w)
{
    memset(w, 0, sizeof *w);
    w->settings = &e->settings;
    w->facts = f;
    memcpy(w->bounds_min, e->scene_min, sizeof w->bounds_min);
    memcpy(w->bounds_max, e->scene_max, sizeof w->bounds_max);
    w->eye = e->has_view ? e->view.eye : NULL;
    w->forward = e->has_view ? e->view.forward : NULL;
    lpv_engine_memory_need(e, &w->others);
    w->limits = &e->mem_limits;
}

/* This tick's inputs for the technique. Surfel sets in the order the
 * geometry volume merges them: each punctual light's RSM, the area light
 * samples' (one set), the camera's (when its G-buffer ran), the scene
 * surfels. */
static void technique_inputs(lpv_engine *e, lpv_technique_inputs *in)
{
    memset(in, 0, sizeof *in);
    in->settings = &e->settings;
    in->plan = &e->plan;
    in->timer = &e->timer;
    in->rsm_vpls = e->vpls_live;
    in->rsm_vpl_draw = e->vpls_draw;
    in->rsm_vpl_count = e->rsm_vpl_count;
    in->emissive_vpls = e->emissive_vpls;
    in->emissive_vpl_count = e->emissive_vpl_count;
    in->medium = &e->medium;
    size_t n = 0;
    for (size_t b = 0, first, count;
         n < LPV_MAX_SURFEL_SETS && (lpv_engine_gv_buffer_range(e, b, &first, &count), count > 0); ++b)
        in->surfel_sets[n++] = (lpv_surfel_set){e->surfels, first, count};
    if (e->plan.pass[LPV_PASS_GBUFFER].run && n < LPV_MAX_SURFEL_SETS)
        in->surfel_sets[n++] =
            (lpv_surfel_set){e->camera_surfels, 0, lpv_engine_camera_surfel_count(e)};
    if (e->scene_surfel_count && n < LPV_MAX_SURFEL_SETS)
        in->surfel_sets[n++] = (lpv_surfel_set){e->scene_surfels, 0, e->scene_surfel_count};
    in->surfel_set_count = n;
    in->light_ubo = e->light_ubo;
    in->rsm_position = e->rsm_position;
    in->rsm_albedo = e->rsm_albedo;
    if (e->plan.pass[LPV_PASS_GBUFFER].run) {
        memcpy(in->gbuffer, e->gbuf_tex, sizeof in->gbuffer);
        in->gbuffer_w = e->gbuf_w;
        in->gbuffer_h = e->gbuf_h;
    }
    in->lookup_planes = (const float (*)[3])e->lookup_planes;
    in->lookup_plane_count = e->lookup_plane_count;
}

static void record_stats(lpv_engine *e)
{
    lpv_engine_stats *s = &e->stats;
    memset(s, 0, sizeof *s);
    lpv_timer_collect(&e->timer);
    int n = e->timer.stage_count;
    for (int i = 0; i < n && i < LPV_STAGE_MAX; ++i) {
        const lpv_timer_stage *st = &e->timer.stages[i];
        snprintf(s->stages[i].name, sizeof s->stages[i].name, "%s", st->name);
        s->stages[i].gpu_ms = st->gpu_ms;
        s->stages[i].cpu_ms = st->cpu_ms;
        s->stages[i].calls = st->count;
        s->stage_count = i + 1;
    }
    s->lights = (unsigned)e->light_block.counts[2];
    s->area_lights = (unsigned)(e->light_block.counts[0] - e->light_block.counts[2]);
    s->rsm_faces = (unsigned)e->face_count;
    s->rsm_size = (unsigned)e->settings.rsm_size;
    s->reach.on = lpv_engine_reach_in_use(e);
    s->reach.per_pixel = lpv_engine_reach_per_pixel(e);
    s->reach.unsure = e->reach.unsure;
    s->reach.voxel_m = e->reach.voxel;
    memcpy(s->reach.dims, e->reach.dims, sizeof s->reach.dims);
    s->reach.components = e->reach.components;
    s->reach.lit_components = e->reach.lit_components;
    s->reach.dark_voxels = e->reach.dark_voxels;
    s->reach.lit_voxels = e->reach.lit_voxels;
    s->vpls_rsm = e->rsm_vpl_count;
    s->vpls_emissive = e->plan.consumes.emissive_vpls ? e->emissive_vpl_count : 0;
    const int gv = e->plan.consumes.surfels;
    s->surfels_rsm = 0;
    for (size_t b = 0, first, count; gv && (lpv_engine_gv_buffer_range(e, b, &first, &count), count > 0); ++b)
        s->surfels_rsm += count;
    s->surfels_camera = e->plan.consumes.camera_surfels ? lpv_engine_camera_surfel_count(e) : 0;
    s->scene_uploads = e->counters.scene_uploads;
    s->scene_samplings = e->counters.scene_samplings;
    e->tech->cls->stats(e->tech, &e->plan, s);
    s->volume = e->desc;
}

void lpv_engine_set_yield(lpv_engine *e, int (*fn)(void *arg), void *arg, double every_ms)
{
    lpv_timer_set_yield(&e->timer, fn, arg, every_ms);
}

/* The tick's caller asked it to stop at a yield point: what it computed so
 * far is partial, so the next tick starts over. */
static int abandoned(lpv_engine *e, char *err, size_t err_size)
{
    e->forced = 1;
    lpv_timer_collect(&e->timer); /* the next pass begins a new frame */
    return lpv_error(err, err_size, "%snobody wants this tick any more", LPV_TICK_ABANDONED);
}

int lpv_engine_tick(lpv_engine *e, char *err, size_t err_size)
{
    if (!e->has_scene)
        return lpv_error(err, err_size, "no scene loaded");
    const lpv_technique_class *t = e->tech->cls;
    lpv_plan_facts facts;
    lpv_engine_gather_facts(e, &facts);
    lpv_technique_where where;
    lpv_engine_where(e, &facts, &where);
    int moved = 0;
    if (t->place(e->tech, &where, &moved, err, err_size) != 0)
        return -1;
    facts.placement_changed = e->computed && moved;
    t->plan(e->tech, &e->settings, &facts, &e->plan);
    snprintf(e->plan.technique, sizeof e->plan.technique, "%s", t->name);
    snprintf(e->plan.technique_reason, sizeof e->plan.technique_reason, "%s", e->tech_reason);
    const lpv_plan *p = &e->plan;
    if (!p->recompute) {
        /* The cached volume stands: no pass runs, no stage is recorded. */
        lpv_timer_collect(&e->timer);
        e->stats.stage_count = 0;
        e->stats.scene_uploads = e->counters.scene_uploads;
        e->stats.scene_samplings = e->counters.scene_samplings;
        /* the same volume, but a knob of its lookup (iv_neighbours) may have changed */
        e->tech->cls->describe(e->tech, &e->desc);
        e->stats.volume = e->desc;
        e->ticked = 1;
        return 0;
    }
    int reset = 0;
    int rc = t->commit(e->tech, &where, &reset, err, err_size);
    lpv_engine_committed(e, reset);
    if (rc != 0)
        return -1;
    lpv_engine_group_scene_surfels(e);
    if (lpv_pass_rsm_prepare(e, err, err_size) != 0)
        return -1;
    if (p->pass[LPV_PASS_RSM].run)
        lpv_pass_rsm_run(e);
    if (lpv_timer_abandoned(&e->timer))
        return abandoned(e, err, err_size);
    /* the shared producers, once per tick; then the technique on what they made */
    if (p->pass[LPV_PASS_GBUFFER].run) {
        if (lpv_pass_gbuffer_run(e, err, err_size) != 0)
            return -1;
        e->gbuf_stale = 0;
    }
    if (lpv_timer_abandoned(&e->timer))
        return abandoned(e, err, err_size);
    lpv_technique_inputs in;
    technique_inputs(e, &in);
    if (t->tick(e->tech, &in, err, err_size) != 0)
        return -1;
    if (lpv_timer_abandoned(&e->timer))
        return abandoned(e, err, err_size);
    GLenum gl_err = glGetError();
    if (gl_err != GL_NO_ERROR)
        return lpv_error(err, err_size, "GL error 0x%04x during the tick", gl_err);
    e->ticked = 1;
    e->computed = 1;
    e->scene_dirty = e->lights_dirty = e->settings_dirty = e->forced = 0;
    e->settings_knob[0] = '\0';
    e->computed_has_view = e->has_view;
    if (e->has_view)
        memcpy(e->computed_eye, e->view.eye, sizeof e->computed_eye);
    record_stats(e);
    return 0;
}

