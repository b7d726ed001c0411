/* stats_json.c - see stats_json.h. Field names are documented in docs/render.md ("--stats") and protocol/SPEC.md. */
#include "stats_json.h"

#include <string.h>

/* A reason's length (it may fill its whole buffer without a NUL). */
static int reason_len_n(const char *r, size_t max)
{
    const char *end = memchr(r, '\0', max);
    return end ? (int)(end - r) : (int)max;
}

static int reason_len(const char *r) { return reason_len_n(r, LPV_PLAN_REASON_MAX); }

static json_t *grid_json(const lpv_grid *g)
{
    return json_pack("{s:[i,i,i], s:f, s:[f,f,f]}", "dims", g->dims[0], g->dims[1], g->dims[2], "cell_size_m",
                     (double)g->cell_size, "origin_m", (double)g->origin[0], (double)g->origin[1],
                     (double)g->origin[2]);
}

json_t *lpvd_cascades_json(const lpv_grid *cascades, int n)
{
    json_t *a = json_array();
    for (int k = 0; a && k < n; ++k) {
        if (json_array_append_new(a, grid_json(&cascades[k])) != 0) {
            json_decref(a);
            return NULL;
        }
    }
    return a;
}

json_t *lpvd_plan_json(const lpv_plan *p)
{
    json_t *passes = json_array();
    for (int i = 0; passes && i < LPV_PASS_COUNT; ++i) {
        const char *name = lpv_pass_name((lpv_pass_id)i);
        json_t *o = json_pack("{s:s, s:b, s:s#}", "name", name ? name : "", "run", p->pass[i].run != 0, "reason",
                              p->pass[i].reason, reason_len(p->pass[i].reason));
        if (json_array_append_new(passes, o) != 0) {
            json_decref(passes);
            return NULL;
        }
    }
    if (!passes)
        return NULL;
    return json_pack("{s:s, s:s#, s:i, s:s#, s:s#, s:b, s:b, s:s#, s:o}", "technique", p->technique,
                     "technique_reason", p->technique_reason, reason_len(p->technique_reason), "cascades", p->cascades,
                     "cascades_reason", p->cascades_reason, reason_len(p->cascades_reason), "iterations_reason",
                     p->iterations_reason, reason_len_n(p->iterations_reason, sizeof p->iterations_reason), "iterations_warning",
                     p->iterations_warning != 0, "recompute", p->recompute != 0,
                     "recompute_reason", p->recompute_reason,
                     reason_len(p->recompute_reason), "passes", passes);
}

/* The technique's own counts (lpv_engine_stats.technique_stats), by name. */
static json_t *technique_json(const lpv_engine_stats *st)
{
    json_t *o = json_object();
    for (int i = 0; o && i < st->technique_stat_count; ++i) {
        const lpv_stat *v = &st->technique_stats[i];
        json_t *j = v->kind == LPV_STAT_BOOL    ? json_boolean(v->v[0] != 0.0)
                    : v->kind == LPV_STAT_REAL3 ? json_pack("[f, f, f]", v->v[0], v->v[1], v->v[2])
                                                : json_integer((json_int_t)v->v[0]);
        if (json_object_set_new(o, v->name, j) != 0) {
            json_decref(o);
            return NULL;
        }
    }
    return o;
}

json_t *lpvd_tick_stats_json(const lpv_engine_stats *st, const lpv_plan *plan, const lpv_grid *cascades, int n,
                             double tick_ms)
{
    json_t *stages = json_array();
    double total = 0.0;
    for (int i = 0; stages && i < st->stage_count; ++i) {
        json_array_append_new(stages, json_pack("{s:s, s:f, s:f, s:i}", "name", st->stages[i].name, "gpu_ms",
                                                st->stages[i].gpu_ms, "cpu_ms", st->stages[i].cpu_ms, "calls",
                                                (int)st->stages[i].calls));
        total += st->stages[i].gpu_ms;
    }
    json_t *counts = json_pack(
        "{s:i, s:i, s:i, s:I, s:I, s:I, s:I, s:I, s:i, s:f, s:b, s:I, s:I, s:I, s:I}", "lights", (int)st->lights, "area_lights",
        (int)st->area_lights, "rsm_faces", (int)st->rsm_faces, "vpls_rsm", (json_int_t)st->vpls_rsm, "vpls_emissive",
        (json_int_t)st->vpls_emissive, "surfels_rsm", (json_int_t)st->surfels_rsm, "surfels_camera",
        (json_int_t)st->surfels_camera, "cells", (json_int_t)st->cells, "iterations", st->iterations, "cell_steps",
        st->cell_steps, "occlusion", st->occlusion != 0, "scene_uploads", (json_int_t)st->scene_uploads,
        "scene_samplings", (json_int_t)st->scene_samplings, "frame_full_lookups", (json_int_t)st->frame_full_lookups,
        "frame_area_shadow_pixels", (json_int_t)st->frame_area_shadow_pixels);
    json_t *o = json_pack("{s:o, s:f, s:o, s:o, s:o, s:o}", "stages", stages, "total_gpu_ms", total, "counts", counts,
                          "grid", grid_json(&cascades[0]), "cascades", lpvd_cascades_json(cascades, n), "plan",
                          lpvd_plan_json(plan));
    if (o && tick_ms >= 0.0 && json_object_set_new(o, "tick_ms", json_real(tick_ms)) != 0) {
        json_decref(o);
        return NULL;
    }
    json_t *reach = json_pack("{s:b, s:b, s:b, s:f, s:[i, i, i], s:i, s:i, s:I, s:I}", "on", st->reach.on != 0,
                              "per_pixel", st->reach.per_pixel != 0, "unsure",
                              st->reach.unsure != 0, "voxel_m", (double)st->reach.voxel_m, "dims",
                              st->reach.dims[0], st->reach.dims[1], st->reach.dims[2], "components",
                              (int)st->reach.components, "lit_components", (int)st->reach.lit_components,
                              "dark_voxels", (json_int_t)st->reach.dark_voxels, "lit_voxels",
                              (json_int_t)st->reach.lit_voxels);
    if (o && (!reach || json_object_set_new(o, "reach", reach) != 0)) {
        json_decref(o);
        return NULL;
    }
    if (o && st->technique_stat_count && st->volume.technique &&
        json_object_set_new(o, st->volume.technique, technique_json(st)) != 0) {
        json_decref(o);
        return NULL;
    }
    return o;
}

json_t *lpvd_stats_json(const lpv_engine *e, const lpv_gl_context *ctx, const char *scene_source)
{
    const lpv_settings *set = lpv_engine_settings(e);
    const lpv_grid *g = lpv_engine_grid(e);
    lpv_grid cascades[LPV_MAX_CASCADES];
    int ncascades = lpv_engine_cascade_count(e);
    if (ncascades < 1)
        ncascades = 1;
    if (ncascades > LPV_MAX_CASCADES)
        ncascades = LPV_MAX_CASCADES;
    for (int k = 0; k < ncascades; ++k) {
        const lpv_grid *c = lpv_engine_cascade(e, k);
        cascades[k] = c ? *c : *g;
    }
    json_t *o = lpvd_tick_stats_json(lpv_engine_last_stats(e), lpv_engine_last_plan(e), cascades, ncascades, -1.0);
    /* preset: the one the settings started from; explicit flags may have overridden its values */
    const char *preset = lpv_preset_name(set->preset);
    json_t *settings = json_pack("{s:s, s:i, s:i, s:i, s:b, s:f, s:i}", "preset", preset ? preset : "", "iterations",
                                 set->lpv.iterations, "rsm_size", set->rsm_size, "shadow_size", set->shadow_size,
                                 "occlusion", set->lpv.occlusion == LPV_SWITCH_ON, "indirect_gain",
                                 (double)set->indirect_gain, "emissive_vpls", set->emissive_vpls);
    json_t *extra = json_pack("{s:s, s:s, s:s, s:s, s:o}", "backend", lpv_backend_name(lpv_gl_context_backend(ctx)),
                              "gl_renderer", lpv_gl_context_renderer(ctx), "gl_version",
                              lpv_gl_context_version(ctx), "scene", scene_source, "settings", settings);
    if (!o || !extra || json_object_update(o, extra) != 0) {
        json_decref(o);
        json_decref(extra);
        return NULL;
    }
    json_decref(extra);
    return o;
}
