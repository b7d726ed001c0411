/*
 * engine_tick.c - one tick: the plan (from engine_facts.c's facts), the
 * technique's placement, the shared producers (RSMs and their VPLs and
 * surfels, the camera's G-buffer and surfels), the technique's passes on
 * what they made, and the stats.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "engine_internal.h"
#include "error.h"

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
    in->rsm_vpls = e->rsm.vpls_live;
    in->rsm_vpl_draw = e->rsm.vpls_draw;
    in->rsm_vpl_count = e->rsm.vpl_count;
    in->emissive_vpls = e->emissive_vpls;
    in->emissive_vpl_count = e->emissive_vpl_count;
    in->medium = &e->medium;
    size_t n = 0;
    for (size_t b = 0, first, count;
         n < LPV_MAX_SURFEL_SETS && (lpv_engine_gv_buffer_range(e, b, &first, &count), count > 0); ++b)
        in->surfel_sets[n++] = (lpv_surfel_set){e->rsm.surfels, first, count};
    if (e->plan.pass[LPV_PASS_GBUFFER].run && n < LPV_MAX_SURFEL_SETS)
        in->surfel_sets[n++] =
            (lpv_surfel_set){e->gbuf.surfels, 0, lpv_engine_camera_surfel_count(e)};
    if (e->scene_surfel_count && n < LPV_MAX_SURFEL_SETS)
        in->surfel_sets[n++] = (lpv_surfel_set){e->scene_surfels, 0, e->scene_surfel_count};
    in->surfel_set_count = n;
    in->light_ubo = e->light_ubo;
    in->rsm_position = e->rsm.position;
    in->rsm_albedo = e->rsm.albedo;
    if (e->plan.pass[LPV_PASS_GBUFFER].run) {
        memcpy(in->gbuffer, e->gbuf.tex, sizeof in->gbuffer);
        in->gbuffer_w = e->gbuf.w;
        in->gbuffer_h = e->gbuf.h;
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
    s->rsm_faces = (unsigned)e->rsm.face_count;
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
    s->vpls_rsm = e->rsm.vpl_count;
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
        /* what the technique ran is this tick's, nothing (its counts of
         * the probes traced or the cells stepped go to 0; what the volume
         * holds stays) */
        t->stats(e->tech, p, &e->stats);
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
        e->gbuf.stale = 0;
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

