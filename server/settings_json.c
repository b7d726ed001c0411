/* settings_json.c - see settings_json.h. */
#include "settings_json.h"

#include <string.h>

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
        double max = f->max;
        if (strcmp(f->unit, "texels") == 0 && max > (double)max_texture) /* CONFIG refuses more with LIMIT */
            max = (double)max_texture;
        json_t *o = json_pack("{s:s, s:s, s:o, s:s, s:s, s:s, s:s, s:s, s:o}", "name", f->key, "type",
                              type_name(f->kind), "default", typed(f, lpv_field_get(&d, f)), "default_text", f->deflt,
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
