/*
 * lpvc_knobs.c - the daemon's knob description (SPEC R4.12) on the client
 * side: reading it from HELLO, checking and parsing values against it, and
 * typing them in a CONFIG body. See lpvc_knobs.h and lpvc.h.
 */
#include "lpvc_knobs.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *str_or_empty(const json_t *o, const char *key)
{
    const char *s = json_string_value(json_object_get(o, key));
    return s ? s : "";
}

/* A JSON number or boolean as a double; -1 when it is neither. */
static int number_of(const json_t *v, double *out)
{
    if (json_is_number(v))
        *out = json_number_value(v);
    else if (json_is_boolean(v))
        *out = json_is_true(v) ? 1.0 : 0.0;
    else
        return -1;
    return 0;
}

/* The strings of hello's array `key` (absent: none) into *out, pointing into
 * hello; -1 out of memory. */
static int names_of(const json_t *hello, const char *key, const char ***out, size_t *count)
{
    const json_t *a = json_object_get(hello, key);
    size_t n = json_is_array(a) ? json_array_size(a) : 0;
    *out = calloc(n ? n : 1, sizeof **out);
    *count = 0;
    if (!*out)
        return -1;
    for (size_t i = 0; i < n; ++i) {
        const char *name = json_string_value(json_array_get(a, i));
        if (name)
            (*out)[(*count)++] = name;
    }
    return 0;
}

int lpvc_knobset_read(lpvc_knobset *ks, json_t *hello, char *err, size_t n)
{
    memset(ks, 0, sizeof *ks);
    ks->hello = json_incref(hello);
    const json_t *arr = json_object_get(hello, "knobs");
    size_t count = json_is_array(arr) ? json_array_size(arr) : 0;
    ks->knobs = calloc(count ? count : 1, sizeof *ks->knobs);
    if (!ks->knobs || names_of(hello, "presets", &ks->presets, &ks->preset_count) != 0 ||
        names_of(hello, "techniques", &ks->techniques, &ks->technique_count) != 0) {
        snprintf(err, n, "out of memory");
        return -1;
    }
    for (size_t i = 0; i < count; ++i) {
        const json_t *o = json_array_get(arr, i);
        lpvc_knob *k = &ks->knobs[i];
        const char *type = json_string_value(json_object_get(o, "type"));
        k->name = json_string_value(json_object_get(o, "name"));
        if (!k->name || !type) {
            snprintf(err, n, "HELLO knobs[%zu]: expected \"name\" and \"type\" strings", i);
            return -1;
        }
        if (strcmp(type, "int") == 0) {
            k->type = LPVC_KNOB_INT;
        } else if (strcmp(type, "number") == 0) {
            k->type = LPVC_KNOB_NUMBER;
        } else if (strcmp(type, "bool") == 0) {
            k->type = LPVC_KNOB_BOOL;
        } else {
            snprintf(err, n, "HELLO knobs[%zu] (%s): unknown type \"%s\"", i, k->name, type);
            return -1;
        }
        k->min = 0.0;
        k->max = 1.0;
        if (k->type != LPVC_KNOB_BOOL && (number_of(json_object_get(o, "min"), &k->min) != 0 ||
                                          number_of(json_object_get(o, "max"), &k->max) != 0)) {
            snprintf(err, n, "HELLO knobs[%zu] (%s): \"min\" and \"max\" must be numbers", i, k->name);
            return -1;
        }
        k->min_exclusive = json_is_true(json_object_get(o, "min_exclusive"));
        if (number_of(json_object_get(o, "default"), &k->def) != 0)
            k->def = NAN;
        k->default_text = str_or_empty(o, "default_text");
        k->unit = str_or_empty(o, "unit");
        k->note = str_or_empty(o, "note");
        k->help = str_or_empty(o, "help");
    }
    ks->count = count;
    return 0;
}

void lpvc_knobset_free(lpvc_knobset *ks)
{
    free(ks->knobs);
    free(ks->presets);
    free(ks->techniques);
    json_decref(ks->hello);
    memset(ks, 0, sizeof *ks);
}

const lpvc_knob *lpvc_knobset_find(const lpvc_knobset *ks, const char *name)
{
    for (size_t i = 0; name && i < ks->count; ++i)
        if (strcmp(ks->knobs[i].name, name) == 0)
            return &ks->knobs[i];
    return NULL;
}

const char *lpvc_knob_expect(const lpvc_knob *k, char *buf, size_t n)
{
    if (k->type == LPVC_KNOB_BOOL)
        snprintf(buf, n, "on or off");
    else if (k->type == LPVC_KNOB_INT)
        snprintf(buf, n, "an integer in %.0f..%.0f", k->min, k->max);
    else if (k->min_exclusive)
        snprintf(buf, n, "a number > %g and <= %g", k->min, k->max);
    else
        snprintf(buf, n, "a number in %g..%g", k->min, k->max);
    return buf;
}

int lpvc_knob_check(const lpvc_knob *k, double v, char *err, size_t n)
{
    char want[96];
    if (k->type == LPVC_KNOB_BOOL)
        return 0; /* any value: zero is off, the rest on */
    int ok = isfinite(v) && v <= k->max && (k->min_exclusive ? v > k->min : v >= k->min);
    if (k->type == LPVC_KNOB_INT && isfinite(v) && v != floor(v))
        ok = 0;
    if (ok)
        return 0;
    snprintf(err, n, "%s: %g is not allowed (expected %s%s%s)", k->name, v, lpvc_knob_expect(k, want, sizeof want),
             k->note[0] ? "; " : "", k->note);
    return -1;
}

int lpvc_knob_parse(const lpvc_knob *k, const char *text, double *v, char *err, size_t n)
{
    char want[96];
    if (!text)
        text = "";
    if (k->type == LPVC_KNOB_BOOL) {
        if (strcmp(text, "on") == 0 || strcmp(text, "true") == 0) {
            *v = 1.0;
            return 0;
        }
        if (strcmp(text, "off") == 0 || strcmp(text, "false") == 0) {
            *v = 0.0;
            return 0;
        }
    } else {
        char *end;
        errno = 0;
        double x = strtod(text, &end);
        if (end != text && !*end && errno == 0) {
            if (lpvc_knob_check(k, x, err, n) != 0)
                return -1;
            *v = x;
            return 0;
        }
    }
    snprintf(err, n, "%s: '%s' is not %s", k->name, text, lpvc_knob_expect(k, want, sizeof want));
    return -1;
}

int lpvc_knobset_add(const lpvc_knobset *ks, json_t *o, const lpvc_setting *set, size_t count, char *err, size_t n)
{
    for (size_t i = 0; i < count; ++i) {
        const lpvc_knob *k = lpvc_knobset_find(ks, set[i].name);
        if (!k) {
            snprintf(err, n, "%s: not a knob this server describes (%zu knobs in its HELLO)",
                     set[i].name ? set[i].name : "(null)", ks->count);
            return -1;
        }
        if (lpvc_knob_check(k, set[i].value, err, n) != 0)
            return -1;
        json_t *v = k->type == LPVC_KNOB_BOOL  ? json_boolean(set[i].value != 0.0)
                    : k->type == LPVC_KNOB_INT ? json_integer((json_int_t)set[i].value)
                                               : json_real(set[i].value);
        if (json_object_set_new(o, k->name, v) != 0) {
            snprintf(err, n, "out of memory");
            return -1;
        }
    }
    return 0;
}
