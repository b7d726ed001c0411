/*
 * settings_fields.c - the lpv_settings field table (see settings_fields.h):
 * each knob's range and default written once, and what reads them (resolve's
 * defaults, validate's ranges, help's words).
 */
#include "settings_fields.h"

#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "area_lights.h"
#include "lpv_shared.h"

#include "settings_rows.h"

/* core's rows: the shared producers', the shading's and the cascaded LPV's
 * (the presets set them); each technique's own follow
 * (techniques/technique_fields.c). */
static const lpv_field CORE_FIELDS[] = {
    /* The older knobs (the preset supplies the defaults of three of them). */
    {"iterations", "iterations", LPV_FIELD_INT, F(lpv.iterations), 1, LPV_MAX_ITERATIONS, 0, "steps",
     D_PRESET("the preset's x grid / its grid"), "", "propagation steps (light moves about a cell a step)", T_VOL,
     LPV_TECHNIQUE_LPV},
    {"rsm_size", "rsm-size", LPV_FIELD_INT, F(rsm_size), 16, LPV_MAX_RSM_SIZE, 0, "texels",
     D_PRESET("the preset's"), "", "reflective shadow map side", T_VOL, ""},
    {"shadow_size", "shadow-size", LPV_FIELD_INT, F(shadow_size), 16, LPV_MAX_SHADOW_SIZE, 0, "texels", D(1024), "",
     "shadow map side per light face, for direct light (docs/shadows.md)", T_SHADOWS, ""},
    {"occlusion", "occlusion", LPV_FIELD_SWITCH, F(lpv.occlusion), 0, 1, 0, "", D_PRESET("the preset's (on)"), "",
     "fuzzy occlusion from the geometry volume", T_VOL, LPV_TECHNIQUE_LPV},
    {"indirect_gain", "indirect-gain", LPV_FIELD_FLOAT, F(indirect_gain), 0, 1e30, 1, "", D(1), "",
     "artistic factor on the LPV term", T_SHADE, ""},
    {"emissive_vpls", "emissive-vpls", LPV_FIELD_INT, F(emissive_vpls), 1, 1 << 20, 0, "", D(4096), "",
     "VPLs sampled on emissive surfaces", T_VOL | T_SAMPLES, ""},

    /* Cascades (docs/cascades.md). */
    {"cascades", "cascades", LPV_FIELD_INT, F(lpv.cascades), 0, LPV_MAX_CASCADES, 0, "", D_ZERO("auto"), "0 = auto",
     "cascade count (auto: one grid unless the camera is inside the scene, else 3)", T_VOL, LPV_TECHNIQUE_LPV},
    {"cascade_size", "cascade-size", LPV_FIELD_FLOAT, F(lpv.cascade_size), 0, 1e6, 0, "m", D_ZERO("auto"),
     "0 = auto: a quarter of the scene's longest side, or cells about as wide as the camera's space",
     "the finest cascade's extent along its longest axis", T_VOL, LPV_TECHNIQUE_LPV},
    {"cascade_ratio", "cascade-ratio", LPV_FIELD_FLOAT, F(lpv.cascade_ratio), 1.25, 8, 0, "", D(2), "",
     "cell size ratio of consecutive cascades", T_VOL, LPV_TECHNIQUE_LPV},
    {"cascade_offset", "cascade-offset", LPV_FIELD_FLOAT, F(lpv.cascade_offset), -1, 0.5, 0, "", D(0.25),
     "negative = centred on the camera",
     "cascade centre ahead of the camera, as a fraction of its extent", T_VOL, LPV_TECHNIQUE_LPV},

    /* Effects and damping (docs/effects.md). */
    {"bounces", "bounces", LPV_FIELD_SWITCH, F(lpv.bounces), 0, 1, 0, "", D(0), "",
     "multiple bounces off the geometry volume's blockers", T_VOL, LPV_TECHNIQUE_LPV},
    {"bounce_intensity", "bounce-intensity", LPV_FIELD_FLOAT, F(lpv.bounce_intensity), 0, 1, 1, "", D(1), "",
     "factor on the blockers' albedo for bounces", T_VOL, LPV_TECHNIQUE_LPV},
    {"damping", "damping", LPV_FIELD_FLOAT, F(lpv.damping), 0, 1, 0, "", D_ZERO("0"), "0 = off",
     "directional-derivative damping strength", T_SHADE, LPV_TECHNIQUE_LPV},
    {"glossy", "glossy", LPV_FIELD_SWITCH, F(glossy), 0, 1, 0, "", D(1), "",
     "glossy reflections by marching the LPV (if a material is glossy)", T_SHADE, ""},
    {"glossy_roughness", "glossy-roughness", LPV_FIELD_FLOAT, F(glossy_roughness), 0, 1, 1, "", D(0.3), "",
     "materials with roughness below this are glossy", T_SHADE, ""},
    {"media", "media", LPV_FIELD_SWITCH, F(media), 0, 1, 0, "", D(1), "",
     "participating media single scattering (if there is a medium)", T_VOL | T_SHADE, ""},
    {"fog_sigma_s", "fog-sigma-s", LPV_FIELD_FLOAT, F(fog_sigma_s), 0, 1000, 0, "1/m", D_ZERO("0"), "0 = none",
     "homogeneous fog scattering coefficient", T_VOL | T_SHADE, ""},
    {"fog_sigma_a", "fog-sigma-a", LPV_FIELD_FLOAT, F(fog_sigma_a), 0, 1000, 0, "1/m", D_ZERO("0"), "0 = none",
     "homogeneous fog absorption coefficient", T_VOL | T_SHADE, ""},
    {"media_step", "media-step", LPV_FIELD_FLOAT, F(media_step), 0.05, 4, 0, "cells", D(0.5), "",
     "media ray-march step", T_SHADE, ""},
    {"planner", "planner", LPV_FIELD_SWITCH, F(planner), 0, 1, 0, "", D(1), "",
     "run only the passes the scene needs (off: every pass every tick)", T_VOL, ""},

    /* Transport, occlusion and lookup (docs/propagation.md). */
    {"central_transport", "central-transport", LPV_FIELD_SWITCH, F(lpv.central_transport), 0, 1, 0, "",
     D_PRESET("the preset's"), "", "re-emit each face's flux along its central direction (less diffusive than the paper)", T_VOL, LPV_TECHNIQUE_LPV},
    {"normal_bins", "normal-bins", LPV_FIELD_SWITCH, F(lpv.normal_bins), 0, 1, 0, "", D_PRESET("the preset's"), "",
     "one volume per emitter normal axis: surfaces never read back their own light", T_VOL, LPV_TECHNIQUE_LPV},
    {"far_field", "far-field", LPV_FIELD_SWITCH, F(lpv.far_field), 0, 1, 0, "", D_PRESET("the preset's"), "",
     "coarser levels carry the light on (reach grows with 2^levels)", T_VOL, LPV_TECHNIQUE_LPV},
    {"far_field_levels", "far-field-levels", LPV_FIELD_INT, F(lpv.far_field_levels), 1, LPV_MAX_CASCADES - 1, 0,
     "levels", D(1), "", "coarser levels (2x the cells each) over one grid", T_VOL, LPV_TECHNIQUE_LPV},
    {"far_field_steps", "far-field-steps", LPV_FIELD_INT, F(lpv.far_field_steps), 1, LPV_MAX_ITERATIONS, 0, "steps",
     D(1), "", "steps each far-field level but the coarsest takes before handing its light on", T_VOL, LPV_TECHNIQUE_LPV},
    {"smooth_injection", "smooth-injection", LPV_FIELD_SWITCH, F(lpv.smooth_injection), 0, 1, 0, "", D(0), "",
     "spread each VPL over the 2 x 2 cells around it along its surface: light that moves smoothly with a moving "
     "lamp (steadier streams, less flicker; off: the cell holding it)", T_VOL, LPV_TECHNIQUE_LPV},
    {"scene_surfels", "scene-surfels", LPV_FIELD_SWITCH, F(scene_surfels), 0, 1, 0, "", D_PRESET("the preset's"), "",
     "surfels over every triangle join the geometry volume (walls no view sees block)", T_VOL | T_SAMPLES, ""},
    {"scene_surfel_count", "scene-surfel-count", LPV_FIELD_INT, F(scene_surfel_count), 1, 1 << 22, 0, "",
     D(65536), "", "surfels sampled over the scene's triangles", T_VOL | T_SAMPLES, ""},
    {"camera_surfel_step", "camera-surfel-step", LPV_FIELD_INT, F(camera_surfel_step), 0,
     LPV_MAX_CAMERA_SURFEL_STEP, 0, "pixels", D_ZERO("auto"), "0 = auto: 4 surfels per finest cell along the image's height",
     "G-buffer pixels per camera surfel along each axis (geometry volume)", T_VOL, ""},
    {"rsm_vpl_step", "rsm-vpl-step", LPV_FIELD_INT, F(rsm_vpl_step), 0, LPV_MAX_RSM_VPL_STEP, 0, "texels", D_ZERO("auto"),
     "0 = auto: 2 (exact: a block never has more cells than slots), 4 in the layers that give VPLs only (the "
     "area light samples after the first); a power of two dividing the face",
     "RSM texels per VPL and surfel along each axis (injection, geometry volume)", T_VOL, ""},
    /* Enclosed lights (docs/propagation.md, "Enclosed lights"). */
    {"reach", "reach", LPV_FIELD_SWITCH, F(reach), 0, 1, 0, "", D(1), "",
     "indirect light only in the air spaces a light reaches (closed walls keep it in)", T_SHADE, ""},
    /* Emissive surfaces as direct area lights (docs/area-lights.md). */
    {"area_lights", "area-lights", LPV_FIELD_SWITCH, F(area_lights), 0, 1, 0, "", D(1), "",
     "emitters light the scene directly as shadow-mapped samples (off: only as LPV VPLs)", T_VOL | T_SHADOWS, ""},
    {"area_light_samples", "area-light-samples", LPV_FIELD_INT, F(area_light_samples), 1, LPV_MAX_AREA_SAMPLES, 0,
     "", D(8), "", "shadow-mapped samples the emitters are reduced to (accuracy vs time)", T_VOL | T_SHADOWS, ""},
    {"lookup_step", "lookup-step", LPV_FIELD_INT, F(lookup_step), 1, LPV_MAX_LOOKUP_STEP, 0, "pixels", D(1), "",
     "pixels per irradiance lookup along each axis in the frame (N > 1: once per N x N block, upsampled "
     "along planes; accuracy vs time)", T_SHADE, ""},
    {"area_shadow_step", "area-shadow-step", LPV_FIELD_INT, F(area_shadow_step), 1, LPV_MAX_AREA_SHADOW_STEP, 0,
     "pixels", D(2), "",
     "pixels per evaluation of the area lights' shadow maps along each axis in the frame (N > 1: once per "
     "N x N block as a visibility ratio, upsampled along planes; accuracy vs time)", T_SHADE, ""},

};

#include "settings_rows_end.h"

/* The knob table: core's rows, then each technique's, put together once
 * (the daemon's threads all read it). */
#define LPV_FIELDS_MAX 128
static lpv_field FIELDS[LPV_FIELDS_MAX];
static size_t FIELD_COUNT;
static pthread_once_t FIELDS_ONCE = PTHREAD_ONCE_INIT;

static void fields_join(void)
{
    size_t n = sizeof CORE_FIELDS / sizeof CORE_FIELDS[0];
    memcpy(FIELDS, CORE_FIELDS, sizeof CORE_FIELDS);
    size_t k = 0;
    for (size_t t = 0; lpv_technique_fields(t, &k); ++t) {
        if (n + k > LPV_FIELDS_MAX) { /* a build with more rows than this: raise LPV_FIELDS_MAX */
            fprintf(stderr, "lpvd: %zu knob rows, the table holds %d\n", n + k, LPV_FIELDS_MAX);
            abort();
        }
        memcpy(FIELDS + n, lpv_technique_fields(t, &k), k * sizeof *FIELDS);
        n += k;
    }
    FIELD_COUNT = n;
}

static void fields_ready(void)
{
    pthread_once(&FIELDS_ONCE, fields_join);
}

const lpv_field *lpv_fields(size_t *count)
{
    fields_ready();
    if (count)
        *count = FIELD_COUNT;
    return FIELDS;
}

const lpv_field *lpv_field_by_key(const char *key)
{
    fields_ready();
    for (size_t i = 0; key && i < FIELD_COUNT; ++i)
        if (strcmp(FIELDS[i].key, key) == 0)
            return &FIELDS[i];
    return NULL;
}

const lpv_field *lpv_field_by_flag(const char *flag)
{
    fields_ready();
    for (size_t i = 0; flag && i < FIELD_COUNT; ++i)
        if (strcmp(FIELDS[i].flag, flag) == 0)
            return &FIELDS[i];
    return NULL;
}

const char *lpv_field_expect(const lpv_field *f, char *buf, size_t n)
{
    if (f->kind == LPV_FIELD_SWITCH)
        snprintf(buf, n, "on or off");
    else if (f->kind == LPV_FIELD_INT)
        snprintf(buf, n, "an integer in %.0f..%.0f", f->min, f->max);
    else if (f->min_exclusive)
        snprintf(buf, n, "a number > %g and <= %g", f->min, f->max);
    else
        snprintf(buf, n, "a number in %g..%g", f->min, f->max);
    return buf;
}

const char *lpv_field_metavar(const lpv_field *f)
{
    switch (f->kind) {
    case LPV_FIELD_SWITCH: return "on|off";
    case LPV_FIELD_INT: return "N";
    default: return "X";
    }
}

static int in_range(const lpv_field *f, double v)
{
    if (!isfinite(v) || v > f->max)
        return 0;
    return f->min_exclusive ? v > f->min : v >= f->min;
}

int lpv_field_set_bool(lpv_settings *s, const lpv_field *f, int on)
{
    if (f->kind != LPV_FIELD_SWITCH)
        return -1;
    *(lpv_switch *)((char *)s + f->offset) = on ? LPV_SWITCH_ON : LPV_SWITCH_OFF;
    return 0;
}

int lpv_field_set_number(lpv_settings *s, const lpv_field *f, double v, char *err, size_t n)
{
    char want[96];
    if (f->kind == LPV_FIELD_SWITCH)
        return lpv_field_set_bool(s, f, v != 0.0);
    if (f->kind == LPV_FIELD_INT && isfinite(v) && v != floor(v)) {
        if (err && n)
            snprintf(err, n, "expected an integer, got %g", v);
        return -1;
    }
    if (!in_range(f, v)) {
        if (err && n)
            snprintf(err, n, "%g is out of range (allowed: %s%s%s)", v, lpv_field_expect(f, want, sizeof want),
                     f->note[0] ? "; " : "", f->note);
        return -1;
    }
    if (f->kind == LPV_FIELD_FLOAT && v != 0.0 && fabs(v) < FLT_MIN) {
        /* it would round to 0 (or lose its digits) in the setting's float,
         * and 0 often means "the default" or "none" (issue 31, item 12) */
        if (err && n)
            snprintf(err, n, "%g is too small: it would round to 0 in a 32-bit float (the smallest nonzero value "
                     "is %.9g)", v, (double)FLT_MIN);
        return -1;
    }
    char *p = (char *)s + f->offset;
    if (f->kind == LPV_FIELD_INT)
        *(int *)p = (int)v;
    else
        *(float *)p = (float)v;
    return 0;
}

int lpv_field_set_string(lpv_settings *s, const lpv_field *f, const char *v, char *err, size_t n)
{
    char want[96];
    lpv_field_expect(f, want, sizeof want);
    if (!v)
        v = "";
    if (f->kind == LPV_FIELD_SWITCH) {
        if (strcmp(v, "on") == 0)
            return lpv_field_set_bool(s, f, 1);
        if (strcmp(v, "off") == 0)
            return lpv_field_set_bool(s, f, 0);
    } else if (f->kind == LPV_FIELD_INT) {
        char *end;
        errno = 0;
        long x = strtol(v, &end, 10);
        if (end != v && !*end && errno == 0 && in_range(f, (double)x))
            return lpv_field_set_number(s, f, (double)x, NULL, 0);
    } else {
        char *end;
        double x = strtod(v, &end);
        if (end != v && !*end && in_range(f, x))
            return lpv_field_set_number(s, f, x, err, n);
    }
    if (err && n)
        snprintf(err, n, "expected %s%s%s", want, f->note[0] ? "; " : "", f->note);
    return -1;
}

double lpv_field_get(const lpv_settings *s, const lpv_field *f)
{
    const char *p = (const char *)s + f->offset;
    if (f->kind == LPV_FIELD_INT)
        return (double)*(const int *)p;
    if (f->kind == LPV_FIELD_SWITCH) {
        lpv_switch w = *(const lpv_switch *)p;
        return w == LPV_SWITCH_ON ? 1.0 : w == LPV_SWITCH_OFF ? 0.0 : -1.0;
    }
    float x = *(const float *)p;
    char buf[48];
    for (int prec = 6; prec <= 9; ++prec) { /* the shortest decimal that is the same float */
        snprintf(buf, sizeof buf, "%.*g", prec, (double)x);
        double d = strtod(buf, NULL);
        if ((float)d == x)
            return d;
    }
    return (double)x;
}

int lpv_field_is_default(const lpv_settings *s, const lpv_field *f)
{
    const char *p = (const char *)s + f->offset;
    switch (f->kind) {
    case LPV_FIELD_INT: return *(const int *)p == 0;
    case LPV_FIELD_SWITCH: return *(const lpv_switch *)p == LPV_SWITCH_DEFAULT;
    default: return *(const float *)p == 0.0f;
    }
}

const char *lpv_field_default_words(const lpv_field *f, char *buf, size_t n)
{
    if (f->dflt_rule != LPV_DEFAULT_VALUE)
        snprintf(buf, n, "%s", f->dflt_words);
    else if (f->kind == LPV_FIELD_SWITCH)
        snprintf(buf, n, "%s", f->dflt != 0.0 ? "on" : "off");
    else if (f->kind == LPV_FIELD_INT)
        snprintf(buf, n, "%.0f", f->dflt);
    else
        snprintf(buf, n, "%g", f->dflt);
    return buf;
}

void lpv_fields_resolve(lpv_settings *s)
{
    fields_ready();
    for (size_t i = 0; i < FIELD_COUNT; ++i) {
        const lpv_field *f = &FIELDS[i];
        if (f->dflt_rule != LPV_DEFAULT_VALUE || !lpv_field_is_default(s, f))
            continue;
        char *p = (char *)s + f->offset;
        if (f->kind == LPV_FIELD_SWITCH)
            *(lpv_switch *)p = f->dflt != 0.0 ? LPV_SWITCH_ON : LPV_SWITCH_OFF;
        else if (f->kind == LPV_FIELD_INT)
            *(int *)p = (int)f->dflt;
        else
            *(float *)p = (float)f->dflt;
    }
}

int lpv_field_check(const lpv_settings *s, const lpv_field *f, char *err, size_t n)
{
    char want[96];
    const char *p = (const char *)s + f->offset;
    if (f->kind == LPV_FIELD_SWITCH) {
        const lpv_switch w = *(const lpv_switch *)p;
        if (w == LPV_SWITCH_DEFAULT || w == LPV_SWITCH_ON || w == LPV_SWITCH_OFF)
            return 0;
        if (err && n)
            snprintf(err, n, "%s = %d is out of range (allowed 0 = default, 1 = on, 2 = off)", f->key, (int)w);
        return -1;
    }
    if (lpv_field_is_default(s, f))
        return 0; /* zero: the default (resolved away unless the row's rule keeps it) */
    const double v = f->kind == LPV_FIELD_INT ? (double)*(const int *)p : (double)*(const float *)p;
    /* a float holds the range's ends as floats: 1e30 is stored as 1.0000000150e30 */
    const lpv_field stored = {.kind = f->kind, .min_exclusive = f->min_exclusive,
                              .min = f->kind == LPV_FIELD_FLOAT ? (double)(float)f->min : f->min,
                              .max = f->kind == LPV_FIELD_FLOAT ? (double)(float)f->max : f->max};
    if (in_range(&stored, v))
        return 0;
    if (err && n)
        snprintf(err, n, "%s = %g%s%s is out of range (allowed: %s%s%s)", f->key, v, f->unit[0] ? " " : "", f->unit,
                 lpv_field_expect(f, want, sizeof want), f->note[0] ? "; " : "", f->note);
    return -1;
}

/* A field's value as stored: ints, floats and switches are each 4 bytes, so
 * a byte comparison tells a change (and -0 from 0, which no knob accepts). */
static int field_differs(const lpv_settings *a, const lpv_settings *b, const lpv_field *f)
{
    const size_t size = f->kind == LPV_FIELD_FLOAT ? sizeof(float)
                        : f->kind == LPV_FIELD_INT ? sizeof(int)
                                                   : sizeof(lpv_switch);
    return memcmp((const char *)a + f->offset, (const char *)b + f->offset, size) != 0;
}

static void note_first(char *first, size_t n, const char *key)
{
    if (first && n && !first[0])
        snprintf(first, n, "%s", key);
}

unsigned lpv_settings_touches(const lpv_settings *a, const lpv_settings *b, char *first, size_t first_size)
{
    unsigned touches = 0;
    if (first && first_size)
        first[0] = '\0';
    /* the knobs with their own syntax (not in the table) all shape the volume */
    if (memcmp(a->grid_dims, b->grid_dims, sizeof a->grid_dims) != 0) {
        touches |= LPV_TOUCH_VOLUME;
        note_first(first, first_size, "grid");
    }
    if (memcmp(a->bounds_min, b->bounds_min, sizeof a->bounds_min) != 0 ||
        memcmp(a->bounds_max, b->bounds_max, sizeof a->bounds_max) != 0) {
        touches |= LPV_TOUCH_VOLUME;
        note_first(first, first_size, "bounds");
    }
    if (a->preset != b->preset) {
        touches |= LPV_TOUCH_VOLUME;
        note_first(first, first_size, "preset");
    }
    if (a->technique != b->technique) { /* another technique: everything anew */
        touches |= LPV_TOUCH_VOLUME | LPV_TOUCH_SAMPLES | LPV_TOUCH_SHADOWS | LPV_TOUCH_SHADING;
        note_first(first, first_size, "technique");
    }
    fields_ready();
    for (size_t i = 0; i < FIELD_COUNT; ++i) {
        if (!field_differs(a, b, &FIELDS[i]))
            continue;
        touches |= FIELDS[i].touches;
        if (FIELDS[i].touches & LPV_TOUCH_VOLUME)
            note_first(first, first_size, FIELDS[i].key);
    }
    /* a field the table does not know (added to lpv_settings without a row)
     * recomputes everything rather than nothing */
    if (!touches && memcmp(a, b, sizeof *a) != 0) {
        touches = LPV_TOUCH_VOLUME | LPV_TOUCH_SAMPLES | LPV_TOUCH_SHADOWS | LPV_TOUCH_SHADING;
        note_first(first, first_size, "settings");
    }
    return touches;
}
