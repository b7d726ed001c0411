/*
 * settings_validate.c - whether settings are allowed: the preset and the
 * technique by their tables, every knob by its row (settings_fields.c), the
 * technique's own rules (its row of techniques/registry.c) and the bounds;
 * and the one check of "ambient occlusion needs a technique that has it".
 * Apart from settings.c so the techniques' cost rules, which read settings
 * (settings.c), sit below the registry that this file asks.
 */
#include "settings.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>

#include "error.h"
#include "grid.h"
#include "scene.h"
#include "settings_fields.h"
#include "lpv_shared.h"

int lpv_ao_check(const lpv_settings *s, lpv_technique_id running, char *err, size_t n)
{
    if (lpv_technique_has(running, LPV_CAP_AO) && s->iv.ao == LPV_SWITCH_ON)
        return 0;
    const char *t = lpv_technique_name(running);
    return lpv_error(err, n, "ambient occlusion needs technique %s with iv_ao on; this has technique %s and iv_ao %s",
                     LPV_TECHNIQUE_IV, t ? t : "?", s->iv.ao == LPV_SWITCH_ON ? "on" : "off");
}

/* Writes a formatted message into err (when there is room) and returns -1. */
static int fail(char *err, unsigned long err_size, const char *fmt, ...)
{
    if (err && err_size > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, (size_t)err_size, fmt, ap);
        va_end(ap);
    }
    return -1;
}

static int validate_bounds(const lpv_settings *s, char *err, unsigned long err_size)
{
    if (!lpv_settings_bounds_given(s))
        return 0; /* all zero: the scene's bounds */
    for (int i = 0; i < 3; i++) {
        float lo = s->bounds_min[i], hi = s->bounds_max[i];
        if (!(fabsf(lo) <= LPV_MAX_COORD) || !(fabsf(hi) <= LPV_MAX_COORD) || !(hi >= lo))
            return fail(err, err_size,
                        "bounds_min[%d] = %g, bounds_max[%d] = %g are out of range "
                        "(allowed within +-%g m with bounds_max >= bounds_min, or all six zero)",
                        i, (double)lo, i, (double)hi, LPV_MAX_COORD);
    }
    /* the grid would otherwise replace them (lpv_grid_place's fallback) */
    double cell = lpv_grid_cell_size_over(s->grid_dims, s->bounds_min, s->bounds_max);
    if (!(cell >= LPV_MIN_CELL_SIZE))
        return fail(err, err_size, "bounds: over %dx%dx%d cells this box gives cells of %g m, under the smallest "
                    "cell size %g m", s->grid_dims[0], s->grid_dims[1], s->grid_dims[2], cell, LPV_MIN_CELL_SIZE);
    return 0;
}

int lpv_settings_validate(const lpv_settings *s, char *err, unsigned long err_size)
{
    if (s->preset != LPV_PRESET_DEFAULT && !lpv_preset_name(s->preset))
        return fail(err, err_size, "preset = %d is out of range (allowed 0 = default, 1 = fast, 2 = balanced, "
                    "3 = accurate)", (int)s->preset);
    if (s->technique != LPV_TECHNIQUE_ID_DEFAULT && !lpv_technique_name(s->technique))
        return fail(err, err_size, "technique = %d is out of range (allowed: %s)", (int)s->technique,
                    lpv_technique_names());
    if (lpv_technique_validate(s, err, err_size) != 0) /* its own rules (techniques/registry.c) */
        return -1;
    for (int i = 0; i < 3; i++) {
        if (s->grid_dims[i] < 1 || s->grid_dims[i] > LPV_MAX_GRID_DIM)
            return fail(err, err_size, "grid_dims[%d] = %d is out of range (allowed 1..%d)", i, s->grid_dims[i],
                        LPV_MAX_GRID_DIM);
    }
    size_t n;
    const lpv_field *fields = lpv_fields(&n);
    for (size_t i = 0; i < n; ++i) /* every knob's range: its row in settings_fields.c */
        if (lpv_field_check(s, &fields[i], err, (size_t)err_size) != 0)
            return -1;
    return validate_bounds(s, err, err_size);
}

