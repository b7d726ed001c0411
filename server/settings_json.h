/* settings_json.h - the daemon's description of its settings knobs (SPEC
 * R4.12), built from core's field table so clients need no copy of it. */
#ifndef LPVD_SETTINGS_JSON_H
#define LPVD_SETTINGS_JSON_H

#include <jansson.h>

#include "settings.h"

/* One object per entry of core/settings_fields.c's table, in its order:
 *   {"name", "type": "int" | "number" | "bool",
 *    "min", "max", "min_exclusive" (int and number only),
 *    "default": the value a session starts with (defaults, resolved; typed
 *               like the knob), "default_text": the default in words,
 *    "unit", "note", "help"}
 * defaults: the daemon's default CONFIG (zero fields = the engine's
 * defaults). max_texture: the daemon's --max-texture, which also bounds the
 * knobs measured in texels (rsm_size, shadow_size), so the range described
 * is the range CONFIG accepts. A new reference (NULL if memory runs out). */
json_t *lpvd_knobs_json(const lpv_settings *defaults, int max_texture);

/* The preset names of core's preset table, in its order: ["fast", ...]. */
json_t *lpvd_presets_json(void);
/* The technique names CONFIG "technique" accepts (R4.14), core's table in its order. */
json_t *lpvd_techniques_json(void);

/* What a settings object may ask for (the daemon's --max-grid and
 * --max-texture; a batch job has none: INT_MAX). */
typedef struct lpvd_settings_limits {
    int max_grid;
    int max_texture;
} lpvd_settings_limits;

enum { LPVD_SETTINGS_OK = 0, LPVD_SETTINGS_BAD = -1, LPVD_SETTINGS_LIMIT = -2 };

/* CONFIG's settings keys (SPEC R4.4: "preset", "technique", "grid" as N or
 * [x, y, z], "bounds", and every knob of core's field table) from the JSON
 * object j into *st, in that order, each checked and named when refused;
 * keys not named here are ignored (the caller checks its own). Returns
 * LPVD_SETTINGS_OK, _BAD or _LIMIT (over lim), with the message in err; *st
 * may be partly changed on failure. The daemon's CONFIG and lpvd batch's
 * job files both read settings here. */
int lpvd_settings_apply_json(const json_t *j, lpv_settings *st, const lpvd_settings_limits *lim, char *err, size_t n);

#endif
