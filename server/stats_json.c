/* stats_json.c - see stats_json.h. Field names are documented in README.md. */
#include "stats_json.h"

json_t *lpvd_stats_json(const lpv_engine *e, const lpv_gl_context *ctx, const char *scene_source)
{
    const lpv_engine_stats *s = lpv_engine_last_stats(e);
    const lpv_settings *set = lpv_engine_settings(e);
    const lpv_grid *g = lpv_engine_grid(e);

    json_t *stages = json_array();
    double total = 0.0;
    for (int i = 0; i < s->stage_count; ++i) {
        json_array_append_new(stages, json_pack("{s:s, s:f, s:f, s:i}", "name", s->stages[i].name, "gpu_ms",
                                                s->stages[i].gpu_ms, "cpu_ms", s->stages[i].cpu_ms, "calls",
                                                (int)s->stages[i].calls));
        total += s->stages[i].gpu_ms;
    }
    json_t *grid = json_pack("{s:[i,i,i], s:f, s:[f,f,f]}", "dims", g->dims[0], g->dims[1], g->dims[2], "cell_size_m",
                             (double)g->cell_size, "origin_m", (double)g->origin[0], (double)g->origin[1],
                             (double)g->origin[2]);
    /* preset: the one the settings started from; explicit flags may have overridden its values */
    const char *preset = lpv_preset_name(set->preset);
    json_t *settings = json_pack("{s:s, s:i, s:i, s:b, s:f, s:i}", "preset", preset ? preset : "", "iterations",
                                 set->iterations, "rsm_size", set->rsm_size, "occlusion",
                                 set->occlusion == LPV_SWITCH_ON, "indirect_gain", (double)set->indirect_gain,
                                 "emissive_vpls", set->emissive_vpls);
    json_t *counts = json_pack("{s:i, s:i, s:I, s:I, s:I, s:I, s:I, s:f}", "lights", (int)s->lights, "rsm_faces",
                               (int)s->rsm_faces, "vpls_rsm", (json_int_t)s->vpls_rsm, "vpls_emissive",
                               (json_int_t)s->vpls_emissive, "surfels_rsm", (json_int_t)s->surfels_rsm,
                               "surfels_camera", (json_int_t)s->surfels_camera, "cells", (json_int_t)s->cells,
                               "cell_steps", s->cell_steps);
    return json_pack("{s:s, s:s, s:s, s:s, s:o, s:o, s:o, s:o, s:f}", "backend",
                     lpv_backend_name(lpv_gl_context_backend(ctx)), "gl_renderer", lpv_gl_context_renderer(ctx),
                     "gl_version", lpv_gl_context_version(ctx), "scene", scene_source, "grid", grid, "settings",
                     settings, "counts", counts, "stages", stages, "total_gpu_ms", total);
}
