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

/* A new JSON object describing the last tick/render of e on context ctx
 * (with "grid" = cascade 0, "cascades" and the last tick's "plan"). */
json_t *lpvd_stats_json(const lpv_engine *e, const lpv_gl_context *ctx, const char *scene_source);

#endif
