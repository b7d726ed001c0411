/* stats_json.h - the engine's stats (stages, counts, settings) as JSON. */
#ifndef LPVD_STATS_JSON_H
#define LPVD_STATS_JSON_H

#include <jansson.h>

#include "context.h"
#include "engine.h"

/* A tick's plan: {"cascades": n, "cascades_reason", "recompute": bool,
 * "recompute_reason", "passes": [{"name", "run": bool, "reason"} for every
 * pass of core/plan.h in lpv_pass_id order]} (a new reference; NULL if
 * memory runs out). */
json_t *lpvd_plan_json(const lpv_plan *p);

/* The placements of n cascades, finest first: [{"dims": [3], "cell_size_m",
 * "origin_m": [3]}] (the keys of the stats' "grid"). */
json_t *lpvd_cascades_json(const lpv_grid *cascades, int n);

/* The stats of one tick, the one shape both `lpvd render --stats` and the
 * daemon (TICK's "stats", STATS's "plan") send (docs/protocol.md, "Stats"):
 *   {"stages": [{"name", "gpu_ms", "cpu_ms", "calls"}], "total_gpu_ms",
 *    "tick_ms" (only when tick_ms >= 0: the daemon's wall time of the tick),
 *    "counts": {"lights", "area_lights", "rsm_faces", "vpls_rsm",
 *               "vpls_emissive", "surfels_rsm", "surfels_camera", "cells",
 *               "iterations", "cell_steps", "occlusion"},
 *    "grid": cascade 0, "cascades": n placements, "plan": lpvd_plan_json,
 *    "iv" (technique iv only): {"points", "points_per_piece", "voxels",
 *          "occupied" (when counted), "bounces", "bounces_requested", "rays",
 *          "reprojected": bool, "ao": bool}}
 * cascades: n >= 1 grids, finest first. A new reference (NULL if memory runs out). */
json_t *lpvd_tick_stats_json(const lpv_engine_stats *st, const lpv_plan *plan, const lpv_grid *cascades, int n,
                             double tick_ms);

/* lpvd_tick_stats_json of the last tick/render of e on context ctx, plus
 * "backend", "gl_renderer", "gl_version", "scene" and the engine's "settings". */
json_t *lpvd_stats_json(const lpv_engine *e, const lpv_gl_context *ctx, const char *scene_source);

#endif
