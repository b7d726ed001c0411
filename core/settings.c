/*
 * settings.c - defaults and range checks for lpv_settings (see settings.h).
 *
 * Zero means "default" for every field, so a zero-initialised struct is a
 * valid configuration after lpv_settings_resolve(). The one consequence to
 * know: iterations = 0 resolves to LPV_DEFAULT_ITERATIONS (8). Injection-only
 * runs (0 steps) are valid for lpv_settings_validate(), but only when the
 * caller skips resolve or sets iterations after it.
 */
#include "settings.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>

#include "lpv_shared.h"

#define LPV_MIN_RSM_SIZE 16
#define LPV_MAX_EMISSIVE_VPLS (1 << 20)

void lpv_settings_resolve(lpv_settings *s)
{
    for (int i = 0; i < 3; i++) {
        if (s->grid_dims[i] == 0)
            s->grid_dims[i] = LPV_DEFAULT_GRID_DIM;
    }
    if (s->iterations == 0)
        s->iterations = LPV_DEFAULT_ITERATIONS;
    if (s->rsm_size == 0)
        s->rsm_size = LPV_DEFAULT_RSM_SIZE;
    if (s->occlusion == LPV_SWITCH_DEFAULT)
        s->occlusion = LPV_SWITCH_ON;
    if (s->indirect_gain == 0.0f)
        s->indirect_gain = 1.0f;
    if (s->emissive_vpls == 0)
        s->emissive_vpls = LPV_DEFAULT_EMISSIVE_VPLS;
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

static int bounds_given(const lpv_settings *s)
{
    for (int i = 0; i < 3; i++) {
        if (s->bounds_min[i] != 0.0f || s->bounds_max[i] != 0.0f)
            return 1;
    }
    return 0;
}

static int validate_bounds(const lpv_settings *s, char *err, unsigned long err_size)
{
    if (!bounds_given(s))
        return 0; /* all zero: the scene's bounds */
    for (int i = 0; i < 3; i++) {
        float lo = s->bounds_min[i], hi = s->bounds_max[i];
        if (!isfinite(lo) || !isfinite(hi) || !(hi >= lo))
            return fail(err, err_size,
                        "bounds_min[%d] = %g, bounds_max[%d] = %g are out of range "
                        "(allowed finite with bounds_max >= bounds_min, or all six zero)",
                        i, (double)lo, i, (double)hi);
    }
    return 0;
}

int lpv_settings_validate(const lpv_settings *s, char *err, unsigned long err_size)
{
    for (int i = 0; i < 3; i++) {
        if (s->grid_dims[i] < 1 || s->grid_dims[i] > LPV_MAX_GRID_DIM)
            return fail(err, err_size, "grid_dims[%d] = %d is out of range (allowed 1..%d)", i, s->grid_dims[i],
                        LPV_MAX_GRID_DIM);
    }
    if (s->iterations < 0 || s->iterations > LPV_MAX_ITERATIONS)
        return fail(err, err_size, "iterations = %d is out of range (allowed 0..%d; 0 = injection only)",
                    s->iterations, LPV_MAX_ITERATIONS);
    if (s->rsm_size < LPV_MIN_RSM_SIZE || s->rsm_size > LPV_MAX_RSM_SIZE)
        return fail(err, err_size, "rsm_size = %d is out of range (allowed %d..%d)", s->rsm_size, LPV_MIN_RSM_SIZE,
                    LPV_MAX_RSM_SIZE);
    if (s->occlusion != LPV_SWITCH_DEFAULT && s->occlusion != LPV_SWITCH_ON && s->occlusion != LPV_SWITCH_OFF)
        return fail(err, err_size, "occlusion = %d is out of range (allowed 0 = default, 1 = on, 2 = off)",
                    (int)s->occlusion);
    if (!isfinite(s->indirect_gain) || s->indirect_gain < 0.0f)
        return fail(err, err_size, "indirect_gain = %g is out of range (allowed finite and >= 0)",
                    (double)s->indirect_gain);
    if (s->emissive_vpls < 0 || s->emissive_vpls > LPV_MAX_EMISSIVE_VPLS)
        return fail(err, err_size, "emissive_vpls = %d is out of range (allowed 0..%d)", s->emissive_vpls,
                    LPV_MAX_EMISSIVE_VPLS);
    return validate_bounds(s, err, err_size);
}
