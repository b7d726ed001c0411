/*
 * settings.c - the presets, and resolve: every zero field's default, read
 * from the tables that hold them (the preset table below and the knob
 * table, settings_fields.c). Validate, which reads the same rows, is in
 * settings_validate.c.
 *
 * Zero means "default" for every field, so a zero-initialised struct is a
 * valid configuration after lpv_settings_resolve(). The one consequence to
 * know: lpv.iterations = 0 resolves to the preset's iteration count scaled
 * to the grid (lpv_settings_scaled_iterations).
 * Injection-only runs (0 steps) are valid for lpv_settings_validate(),
 * but only when the caller skips resolve or sets lpv.iterations after it.
 */
#include "settings.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "area_lights.h"
#include "scene.h"
#include "settings_fields.h"
#include "lpv_shared.h"

/* The named presets: ONE table, indexed by lpv_preset. The values are points
 * on the accuracy sweep's Pareto front (bench/accuracy, docs/accuracy.md);
 * re-run the sweep before changing a row. */
typedef struct preset_row {
    const char *name;
    int grid, iterations, rsm_size;
    lpv_switch occlusion, central_transport, normal_bins, far_field, scene_surfels;
} preset_row;

/* The presets' names, once: the table below and lpv_preset_names() use them. */
#define NAME_FAST "fast"
#define NAME_BALANCED "balanced"
#define NAME_ACCURATE "accurate"

static const preset_row PRESETS[LPV_PRESET_COUNT_] = {
    [LPV_PRESET_DEFAULT] = {NULL, 0, 0, 0, LPV_SWITCH_DEFAULT}, /* not a row: resolves to BALANCED */
    /* Each row is a point on the overall front of the full sweep (3 scenes x
     * grid 6..32 x iterations 2..16 x the 16 combinations of the departures
     * from the paper; docs/accuracy.md, "Presets"). Coarse grids win: light
     * in an LPV moves about a cell per step and diffuses, so a grid whose
     * cells span the scene's rooms in a few steps gets the light where the
     * path tracer has it; finer grids sharpen but stay dark far from the
     * lit surfaces (docs/calibration.md, 4). */
    /* fast: the front's knee below a third of balanced's cost (central transport and scene surfels) */
    [LPV_PRESET_FAST] = {NAME_FAST, 8, 4, 128, LPV_SWITCH_ON, LPV_SWITCH_ON, LPV_SWITCH_OFF, LPV_SWITCH_OFF,
                         LPV_SWITCH_ON},
    /* balanced, the default: all four departures on, the front's knee (8 steps cost 2 % more
     * than 4 and buy 0.04 on the Cornell box: the far field's coarse level carries them) */
    [LPV_PRESET_BALANCED] = {NAME_BALANCED, 8, 8, 128,
                             LPV_SWITCH_ON, LPV_SWITCH_ON, LPV_SWITCH_ON, LPV_SWITCH_ON, LPV_SWITCH_ON},
    /* accurate: the front's lowest error */
    [LPV_PRESET_ACCURATE] = {NAME_ACCURATE, 16, 16, 128, LPV_SWITCH_ON, LPV_SWITCH_ON, LPV_SWITCH_ON, LPV_SWITCH_ON,
                             LPV_SWITCH_ON},
};

/* The table row of p (DEFAULT -> BALANCED), or NULL when p is out of range. */
static const preset_row *preset_row_of(lpv_preset p)
{
    if (p == LPV_PRESET_DEFAULT)
        p = LPV_PRESET_BALANCED;
    if ((int)p <= (int)LPV_PRESET_DEFAULT || (int)p >= (int)LPV_PRESET_COUNT_)
        return NULL;
    return &PRESETS[p];
}

int lpv_preset_settings(lpv_preset p, lpv_settings *out)
{
    const preset_row *r = preset_row_of(p);
    if (!r)
        return -1;
    *out = (lpv_settings){.preset = p == LPV_PRESET_DEFAULT ? LPV_PRESET_BALANCED : p,
                          .grid_dims = {r->grid, r->grid, r->grid},
                          .lpv.iterations = r->iterations,
                          .rsm_size = r->rsm_size,
                          .lpv.occlusion = r->occlusion,
                          .lpv.central_transport = r->central_transport,
                          .lpv.normal_bins = r->normal_bins,
                          .lpv.far_field = r->far_field,
                          .scene_surfels = r->scene_surfels};
    return 0;
}

const char *lpv_settings_departures(const lpv_settings *s, char buf[5])
{
    const lpv_switch on[4] = {s->lpv.central_transport, s->lpv.normal_bins, s->lpv.far_field, s->scene_surfels};
    for (int i = 0; i < 4; ++i)
        buf[i] = on[i] == LPV_SWITCH_ON ? "cbfs"[i] : '-';
    buf[4] = '\0';
    return buf;
}

int lpv_preset_from_name(const char *name, lpv_preset *out)
{
    for (int p = LPV_PRESET_DEFAULT + 1; name && p < LPV_PRESET_COUNT_; ++p) {
        if (strcmp(name, PRESETS[p].name) == 0) {
            *out = (lpv_preset)p;
            return 0;
        }
    }
    return -1;
}

const char *lpv_preset_name(lpv_preset p)
{
    const preset_row *r = preset_row_of(p);
    return r ? r->name : NULL;
}

const char *lpv_preset_names(void)
{
    return NAME_FAST ", " NAME_BALANCED ", " NAME_ACCURATE; /* the table's names, in its order */
}

lpv_preset lpv_preset_match(const lpv_settings *s)
{
    for (int p = LPV_PRESET_DEFAULT + 1; p < LPV_PRESET_COUNT_; ++p) {
        const preset_row *r = &PRESETS[p];
        if (s->grid_dims[0] == r->grid && s->grid_dims[1] == r->grid && s->grid_dims[2] == r->grid &&
            s->lpv.iterations == r->iterations && s->rsm_size == r->rsm_size && s->lpv.occlusion == r->occlusion &&
            s->lpv.central_transport == r->central_transport && s->lpv.normal_bins == r->normal_bins &&
            s->lpv.far_field == r->far_field && s->scene_surfels == r->scene_surfels)
            return (lpv_preset)p;
    }
    return LPV_PRESET_DEFAULT;
}

/* The longest of a grid's three axes (0 for an unset grid). */
static int longest_axis(const int dims[3])
{
    int m = dims[0];
    for (int i = 1; i < 3; ++i)
        m = dims[i] > m ? dims[i] : m;
    return m;
}

int lpv_settings_scaled_iterations(const lpv_settings *s, int *wanted)
{
    const preset_row *r = preset_row_of(s->preset);
    if (!r)
        r = preset_row_of(LPV_PRESET_BALANCED);
    const int grid = longest_axis(s->grid_dims) > 0 ? longest_axis(s->grid_dims) : r->grid;
    /* light moves about a cell per step: the preset's steps per cell of its
     * own grid, so the light crosses the same share of the grid (the same
     * metres over the same bounds) at any resolution; rounded up */
    const long long n = ((long long)r->iterations * grid + r->grid - 1) / r->grid;
    if (wanted)
        *wanted = n > INT_MAX ? INT_MAX : (int)n;
    return n < 1 ? 1 : n > LPV_MAX_ITERATIONS ? LPV_MAX_ITERATIONS : (int)n;
}

int lpv_settings_iterations_note(const lpv_settings *s, char *buf, unsigned long n)
{
    const preset_row *r = preset_row_of(s->preset);
    const int grid = longest_axis(s->grid_dims) > 0 ? longest_axis(s->grid_dims) : 1, k = s->lpv.iterations;
    int wanted = 0;
    const int scaled = lpv_settings_scaled_iterations(s, &wanted);
    if (k == 0) {
        snprintf(buf, n, "iterations = 0: injection only, no light moves");
        return 0;
    }
    if (k == scaled && r && wanted > scaled) {
        snprintf(buf, n, "%d steps: the %s preset's %d at grid %d scaled to grid %d would be %d, clamped to the "
                 "most (%d); light covers %.0f %% of the grid's longest axis", k, r->name, r->iterations, r->grid,
                 grid, wanted, LPV_MAX_ITERATIONS, 100.0 * k / grid);
        return 1;
    }
    if (k == scaled && r) {
        snprintf(buf, n, "%d steps: the %s preset's %d at grid %d scaled to grid %d (light crosses %.0f %% of the "
                 "grid's longest axis, as the preset's does)", k, r->name, r->iterations, r->grid, grid,
                 100.0 * k / grid);
        return 0;
    }
    if (2 * k < grid) {
        snprintf(buf, n, "%d steps set explicitly cover only %.0f %% of the grid's %d cells (light moves about a "
                 "cell a step): the volume stays dark far from the lights; leave iterations unset for %d", k,
                 100.0 * k / grid, grid, scaled);
        return 1;
    }
    snprintf(buf, n, "%d steps set explicitly (%.0f %% of the grid's longest axis)", k, 100.0 * k / grid);
    return 0;
}

void lpv_settings_resolve(lpv_settings *s)
{
    if (s->preset == LPV_PRESET_DEFAULT)
        s->preset = LPV_PRESET_BALANCED;
    lpv_settings p;
    if (lpv_preset_settings(s->preset, &p) == 0) { /* an unknown preset is validate's to report */
        for (int i = 0; i < 3; i++) {
            if (s->grid_dims[i] == 0)
                s->grid_dims[i] = p.grid_dims[i];
        }
        /* after grid_dims: the count follows the grid */
        p.lpv.iterations = lpv_settings_scaled_iterations(s, NULL);
        size_t n;
        const lpv_field *fields = lpv_fields(&n);
        for (size_t i = 0; i < n; ++i) /* the preset's knobs: each a 4-byte int or switch */
            if (fields[i].dflt_rule == LPV_DEFAULT_PRESET && lpv_field_is_default(s, &fields[i]))
                memcpy((char *)s + fields[i].offset, (const char *)&p + fields[i].offset, sizeof(int));
    }
    if (s->technique == LPV_TECHNIQUE_ID_DEFAULT)
        s->technique = LPV_TECHNIQUE_ID_DEFAULT_IS;
    lpv_fields_resolve(s); /* every other knob's default: its row in settings_fields.c */
}

int lpv_settings_bounds_given(const lpv_settings *s)
{
    for (int i = 0; i < 3; i++) {
        if (s->bounds_min[i] != 0.0f || s->bounds_max[i] != 0.0f)
            return 1;
    }
    return 0;
}

double lpv_settings_grid_cells(const lpv_settings *s)
{
    return (double)s->grid_dims[0] * (double)s->grid_dims[1] * (double)s->grid_dims[2];
}

int lpv_settings_camera_surfel_step(const lpv_settings *s, int image_h)
{
    if (s->camera_surfel_step > 0)
        return s->camera_surfel_step;
    int g = s->grid_dims[0];
    for (int i = 1; i < 3; ++i)
        if (s->grid_dims[i] > g)
            g = s->grid_dims[i];
    int step = g > 0 ? image_h / (LPV_CAMERA_SURFELS_PER_CELL * g) : 1;
    if (step > LPV_MAX_CAMERA_SURFEL_STEP)
        step = LPV_MAX_CAMERA_SURFEL_STEP;
    return step > 1 ? step : 1;
}

int lpv_settings_rsm_vpl_step(const lpv_settings *s, int tile, int surfels)
{
    int want = s->rsm_vpl_step > 0 ? s->rsm_vpl_step : surfels ? LPV_RSM_AUTO_STEP : LPV_RSM_AUTO_VPL_STEP;
    int step = 1;
    while (step * 2 <= want && tile > 0 && tile % (step * 2) == 0)
        step *= 2;
    return step;
}
