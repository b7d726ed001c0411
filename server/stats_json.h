/* stats_json.h - the engine's stats (stages, counts, settings) as JSON. */
#ifndef LPVD_STATS_JSON_H
#define LPVD_STATS_JSON_H

#include <jansson.h>

#include "context.h"
#include "engine.h"

/* A new JSON object describing the last tick/render of e on context ctx. */
json_t *lpvd_stats_json(const lpv_engine *e, const lpv_gl_context *ctx, const char *scene_source);

#endif
