/*
 * settings_fields.h - one table describing the tunable scalar fields of
 * lpv_settings, so the CLI (server/options.c), the daemon's CONFIG
 * (server/serve/serve_controls.c) and the clients expose every knob without each
 * writing the same code again.
 *
 * Not in the table (they have their own syntax): grid_dims (N | NxMxK, or a
 * JSON [3]), bounds (six numbers) and preset (a name).
 *
 * Values set through the table are the user-facing ones: a field whose zero
 * means "resolve to a non-zero default" (e.g. bounce_intensity, iterations)
 * has a range that leaves zero out, so a value that is set reads back as set.
 * Every range lies inside what lpv_settings_validate() accepts (a test checks
 * it), so a value the table accepts never fails validation on its own (the
 * fog pair and bounds are checked there as well).
 */
#ifndef LPV_SETTINGS_FIELDS_H
#define LPV_SETTINGS_FIELDS_H

#include <stddef.h>

#include "settings.h"

typedef enum lpv_field_kind {
    LPV_FIELD_INT = 0,    /* int field; CLI: a decimal integer; CONFIG: a JSON integer */
    LPV_FIELD_FLOAT = 1,  /* float field; CLI: a number; CONFIG: a JSON number */
    LPV_FIELD_SWITCH = 2, /* lpv_switch field; CLI: on|off; CONFIG: a JSON boolean */
} lpv_field_kind;

/* What a knob's value reaches, so a change recomputes only that
 * (lpv_settings_touches; the engine acts on it in lpv_engine_set_settings). */
typedef enum lpv_touch {
    LPV_TOUCH_VOLUME = 1u << 0,  /* the tick's volume: injection, occlusion, propagation (recompute) */
    LPV_TOUCH_SAMPLES = 1u << 1, /* the engine's samples of the scene (emissive VPLs, scene surfels) */
    LPV_TOUCH_SHADOWS = 1u << 2, /* direct light's shadow maps */
    LPV_TOUCH_SHADING = 1u << 3, /* render-time only: the lookup, glossy and media marches, the gain */
} lpv_touch;

typedef struct lpv_field {
    const char *key;      /* CONFIG key and effective-config key (snake_case) */
    const char *flag;     /* CLI flag without the leading "--" (kebab-case) */
    lpv_field_kind kind;
    size_t offset;        /* offsetof(lpv_settings, field) */
    double min, max;      /* allowed values (ints and floats; switches ignore them) */
    int min_exclusive;    /* 1: the value must be > min (min itself is refused) */
    const char *unit;     /* "m", "1/m", "cells", ... or "" */
    const char *deflt;    /* the default, in words ("8", "auto", "on", "the preset's") */
    const char *note;     /* what special values mean ("0 = auto"), or "" */
    const char *help;     /* one line */
    unsigned touches;     /* lpv_touch bits: what a change of this knob must recompute */
    const char *technique; /* the GI technique the knob tunes (its class name, LPV_TECHNIQUE_LPV), or
                              "" for the engine's shared producers and shading */
} lpv_field;

/* The table, and its length in *count (may be NULL). */
const lpv_field *lpv_fields(size_t *count);

/* The entry for a CONFIG key / a CLI flag (without "--"), or NULL. */
const lpv_field *lpv_field_by_key(const char *key);
const lpv_field *lpv_field_by_flag(const char *flag);

/* The allowed values in words for help and errors: "an integer in 0..4",
 * "a number in 0..1", "a number > 0 and <= 1e+06", "on or off". Returns buf. */
const char *lpv_field_expect(const lpv_field *f, char *buf, size_t n);

/* Short metavariable for help: "N", "X" or "on|off". */
const char *lpv_field_metavar(const lpv_field *f);

/* Sets f in *s from a CLI string: "on"/"off" for switches, a decimal integer
 * for ints, a finite number for floats, each within the range. Returns 0, or
 * -1 with "expected ..." (no flag name; callers prefix it) in err. */
int lpv_field_set_string(lpv_settings *s, const lpv_field *f, const char *value, char *err, size_t err_size);

/* Sets f from a number (ints: must be integral; switches: nonzero = on,
 * zero = off). Returns 0, or -1 with "<value> is out of range (allowed ...)"
 * or "expected an integer" in err. */
int lpv_field_set_number(lpv_settings *s, const lpv_field *f, double value, char *err, size_t err_size);

/* Sets a switch (on != 0: ON, else OFF); -1 if f is not a switch. */
int lpv_field_set_bool(lpv_settings *s, const lpv_field *f, int on);

/* Reads f back: ints as is; floats as the shortest decimal that converts
 * back to the same float (0.3f reads 0.3, not 0.30000001192...); switches as
 * 1 (ON), 0 (OFF) or -1 (DEFAULT, i.e. not resolved). */
double lpv_field_get(const lpv_settings *s, const lpv_field *f);

/* What changing the settings from a to b must recompute: the OR of the
 * lpv_touch bits of every knob whose value differs (grid_dims, bounds and
 * the preset touch the volume). Compare resolved settings, so a preset's
 * values count as the knobs they set. When `first` is not NULL it receives
 * the key of the first differing knob that touches the volume ("" if none),
 * for the planner's reason. */
unsigned lpv_settings_touches(const lpv_settings *a, const lpv_settings *b, char *first, size_t first_size);

/* Whether f holds its zero ("the default") value. */
int lpv_field_is_default(const lpv_settings *s, const lpv_field *f);

#endif /* LPV_SETTINGS_FIELDS_H */
