/* settings_json.c - see settings_json.h. */
#include "settings_json.h"

#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "proto.h"
#include "scene.h"
#include "settings_fields.h"

static const char *type_name(lpv_field_kind k)
{
    return k == LPV_FIELD_INT ? "int" : k == LPV_FIELD_SWITCH ? "bool" : "number";
}

/* v typed as the knob's CONFIG value: integer, boolean or number. */
static json_t *typed(const lpv_field *f, double v)
{
    if (f->kind == LPV_FIELD_INT)
        return json_integer((json_int_t)v);
    if (f->kind == LPV_FIELD_SWITCH)
        return json_boolean(v > 0.0);
    return json_real(v);
}

/* A knob's lpv_touch bits as names, in a fixed order. */
static json_t *touches_json(unsigned t)
{
    static const struct {
        unsigned bit;
        const char *name;
    } names[] = {{LPV_TOUCH_VOLUME, "volume"},
                 {LPV_TOUCH_SAMPLES, "samples"},
                 {LPV_TOUCH_SHADOWS, "shadows"},
                 {LPV_TOUCH_SHADING, "shading"}};
    json_t *a = json_array();
    for (size_t i = 0; a && i < sizeof names / sizeof names[0]; ++i)
        if ((t & names[i].bit) && json_array_append_new(a, json_string(names[i].name)) != 0) {
            json_decref(a);
            return NULL;
        }
    return a;
}

json_t *lpvd_knobs_json(const lpv_settings *defaults, int max_texture)
{
    lpv_settings d = *defaults;
    lpv_settings_resolve(&d); /* what a fresh session's effective config reports */
    size_t n;
    const lpv_field *fields = lpv_fields(&n);
    json_t *a = json_array();
    for (size_t i = 0; a && i < n; ++i) {
        const lpv_field *f = &fields[i];
        char dflt[32];
        double max = f->max;
        if (strcmp(f->unit, "texels") == 0 && max > (double)max_texture) /* CONFIG refuses more with LIMIT */
            max = (double)max_texture;
        json_t *o = json_pack("{s:s, s:s, s:o, s:s, s:s, s:s, s:s, s:s, s:o}", "name", f->key, "type",
                              type_name(f->kind), "default", typed(f, lpv_field_get(&d, f)), "default_text",
                              lpv_field_default_words(f, dflt, sizeof dflt),
                              "unit", f->unit, "note", f->note, "help", f->help, "technique", f->technique, "touches",
                              touches_json(f->touches));
        if (o && f->kind != LPV_FIELD_SWITCH &&
            (json_object_set_new(o, "min", typed(f, f->min)) != 0 || json_object_set_new(o, "max", typed(f, max)) != 0 ||
             json_object_set_new(o, "min_exclusive", json_boolean(f->min_exclusive)) != 0)) {
            json_decref(o);
            o = NULL;
        }
        if (json_array_append_new(a, o) != 0) {
            json_decref(a);
            return NULL;
        }
    }
    return a;
}

/* A JSON array of a core table's names, name(first) .. name(end - 1). */
static json_t *names_json(const char *(*name)(int), int first, int end)
{
    json_t *a = json_array();
    for (int i = first; a && i < end; ++i)
        if (json_array_append_new(a, json_string(name(i))) != 0) {
            json_decref(a);
            return NULL;
        }
    return a;
}

static const char *technique_name(int t) { return lpv_technique_name((lpv_technique_id)t); }
static const char *preset_name(int p) { return lpv_preset_name((lpv_preset)p); }

json_t *lpvd_techniques_json(void)
{
    return names_json(technique_name, LPV_TECHNIQUE_ID_DEFAULT + 1, LPV_TECHNIQUE_ID_COUNT_);
}

json_t *lpvd_presets_json(void) { return names_json(preset_name, LPV_PRESET_DEFAULT + 1, LPV_PRESET_COUNT_); }


/* "preset": resets grid / iterations / rsm_size / occlusion to the preset's
 * (by clearing them, so resolve fills them in), before the other keys
 * override them. Returns LPVP_FIELD_OK or _ABSENT, LPVP_FIELD_BAD (message
 * in err), or LPVD_SETTINGS_LIMIT when the preset is over lim (--max-grid
 * and --max-texture bound presets as well). */
static int apply_preset(const json_t *j, lpv_settings *st, const lpvd_settings_limits *lim, char *err, size_t n)
{
    /* the choices are core's preset table (lpv_preset_name), in its order */
    const char *names[LPV_PRESET_COUNT_];
    int count = 0, idx = 0;
    for (int q = LPV_PRESET_DEFAULT + 1; q < LPV_PRESET_COUNT_; ++q)
        names[count++] = lpv_preset_name((lpv_preset)q);
    int rc = lpvp_get_enum(j, "preset", 0, names, (size_t)count, &idx, err, n);
    if (rc != LPVP_FIELD_OK)
        return rc;
    lpv_settings p;
    lpv_preset_settings((lpv_preset)(LPV_PRESET_DEFAULT + 1 + idx), &p);
    if (p.grid_dims[0] > lim->max_grid || p.rsm_size > lim->max_texture) {
        snprintf(err, n, "preset: %s (grid %d, rsm_size %d) is over the server's limits (--max-grid %d, --max-texture %d)",
                 names[idx], p.grid_dims[0], p.rsm_size, lim->max_grid, lim->max_texture);
        return LPVD_SETTINGS_LIMIT;
    }
    st->preset = p.preset;
    memset(st->grid_dims, 0, sizeof st->grid_dims);
    st->lpv.iterations = 0;
    st->rsm_size = 0;
    st->lpv.occlusion = LPV_SWITCH_DEFAULT;
    return LPVP_FIELD_OK;
}

/* "technique": one of core's technique table's names (R4.14). */
static int apply_technique(const json_t *j, lpv_settings *st, char *err, size_t n)
{
    const char *names[LPV_TECHNIQUE_ID_COUNT_];
    int count = 0, idx = 0;
    for (int t = LPV_TECHNIQUE_ID_DEFAULT + 1; t < LPV_TECHNIQUE_ID_COUNT_; ++t)
        names[count++] = lpv_technique_name((lpv_technique_id)t);
    int rc = lpvp_get_enum(j, "technique", 0, names, (size_t)count, &idx, err, n);
    if (rc == LPVP_FIELD_OK)
        st->technique = (lpv_technique_id)(LPV_TECHNIQUE_ID_DEFAULT + 1 + idx);
    return rc;
}

/* The scalar knobs, one per entry of the field table (core/settings_fields.h):
 * ints as JSON integers, floats as JSON numbers, switches as JSON booleans,
 * each within the table's range. Returns 0, or -1 with a message naming the key. */
static int apply_fields(const json_t *j, lpv_settings *st, char *err, size_t n)
{
    size_t nf;
    const lpv_field *fields = lpv_fields(&nf);
    for (size_t i = 0; i < nf; ++i) {
        const lpv_field *f = &fields[i];
        int64_t iv;
        double dv;
        int bv, rc;
        char why[160];
        if (f->kind == LPV_FIELD_SWITCH) {
            if ((rc = lpvp_get_bool(j, f->key, 0, &bv, err, n)) == LPVP_FIELD_OK)
                lpv_field_set_bool(st, f, bv);
        } else if (f->kind == LPV_FIELD_INT) {
            if ((rc = lpvp_get_int(j, f->key, 0, (int64_t)f->min, (int64_t)f->max, &iv, err, n)) == LPVP_FIELD_OK)
                lpv_field_set_number(st, f, (double)iv, NULL, 0);
        } else if ((rc = lpvp_get_number(j, f->key, 0, f->min, f->max, &dv, err, n)) == LPVP_FIELD_OK &&
                   lpv_field_set_number(st, f, dv, why, sizeof why) != 0) { /* an exclusive minimum */
            snprintf(err, n, "%s: %s", f->key, why);
            return -1;
        }
        if (rc == LPVP_FIELD_BAD)
            return -1;
    }
    return 0;
}

int lpvd_settings_apply_json(const json_t *j, lpv_settings *st, const lpvd_settings_limits *lim, char *err, size_t n)
{
    int pst = apply_preset(j, st, lim, err, n);
    if (pst == LPVD_SETTINGS_LIMIT)
        return LPVD_SETTINGS_LIMIT;
    if (pst == LPVP_FIELD_BAD || apply_technique(j, st, err, n) == LPVP_FIELD_BAD)
        return LPVD_SETTINGS_BAD;
    int64_t grid[3];
    int gst;
    const json_t *gj = json_object_get(j, "grid");
    if (gj && json_is_integer(gj)) { /* a single N is accepted as NxNxN */
        gst = lpvp_get_int(j, "grid", 1, 1, INT32_MAX, &grid[0], err, n);
        grid[1] = grid[2] = grid[0];
    } else {
        gst = lpvp_get_ints(j, "grid", 0, 3, 1, INT32_MAX, grid, err, n);
    }
    if (gst == LPVP_FIELD_BAD)
        return LPVD_SETTINGS_BAD;
    if (gst == LPVP_FIELD_OK) {
        for (int i = 0; i < 3; ++i)
            if (grid[i] > lim->max_grid) {
                snprintf(err, n, "grid: %lld cells on an axis is over the server's limit of %d (--max-grid)",
                         (long long)grid[i], lim->max_grid);
                return LPVD_SETTINGS_LIMIT;
            }
        for (int i = 0; i < 3; ++i)
            st->grid_dims[i] = (int)grid[i];
    }
    float bounds[6];
    int bst = lpvp_get_floats(j, "bounds", 0, 6, -LPV_MAX_COORD, LPV_MAX_COORD, bounds, err, n);
    if (bst == LPVP_FIELD_BAD)
        return LPVD_SETTINGS_BAD;
    if (bst == LPVP_FIELD_OK) {
        if (!(bounds[3] > bounds[0] && bounds[4] > bounds[1] && bounds[5] > bounds[2])) {
            snprintf(err, n, "bounds: expected [x0, y0, z0, x1, y1, z1] with max > min");
            return LPVD_SETTINGS_BAD;
        }
        memcpy(st->bounds_min, bounds, sizeof st->bounds_min);
        memcpy(st->bounds_max, bounds + 3, sizeof st->bounds_max);
    }
    if (apply_fields(j, st, err, n) != 0) /* iterations, rsm_size, occlusion, ..., planner */
        return LPVD_SETTINGS_BAD;
    if (json_object_get(j, "rsm_size") && st->rsm_size > lim->max_texture) {
        snprintf(err, n, "rsm_size: %d is over the server's texture limit of %d (--max-texture)", st->rsm_size,
                 lim->max_texture);
        return LPVD_SETTINGS_LIMIT;
    }
    if (json_object_get(j, "shadow_size") && st->shadow_size > lim->max_texture) {
        snprintf(err, n, "shadow_size: %d is over the server's texture limit of %d (--max-texture)",
                 st->shadow_size, lim->max_texture);
        return LPVD_SETTINGS_LIMIT;
    }
    return LPVD_SETTINGS_OK;
}
