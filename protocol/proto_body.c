/*
 * proto_body.c - a received frame's JSON body: parsing it strictly (R2.7:
 * an object, valid UTF-8, no duplicate keys) and the field getters that
 * check each field's type and range, with a message naming the field and
 * the value (R2.9), which the daemon sends back as BAD_FIELD. See proto.h.
 */
#include "proto.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* ---- Body parsing --------------------------------------------------------- */

json_t *lpvp_body_parse(const char *body, size_t len, char *err, size_t err_n)
{
    json_error_t je;
    json_t *j;
    if (err && err_n)
        err[0] = '\0';
    if (!body && len) {
        lpvp_set_error(err, err_n, "no body");
        return NULL;
    }
    /* R2.7: jansson checks UTF-8, refuses \u0000 (no JSON_ALLOW_NUL), trailing
     * data (no JSON_DISABLE_EOF_CHECK), deep nesting; duplicate keys are
     * refused so that no field has two meanings. */
    j = json_loadb(body ? body : "", len, JSON_REJECT_DUPLICATES, &je);
    if (!j) {
        lpvp_set_error(err, err_n, "invalid JSON body at byte %d: %s", je.position, je.text);
        return NULL;
    }
    if (!json_is_object(j)) {
        static const char *const kinds[] = {"an object", "an array", "a string", "an integer",
                                            "a real", "true", "false", "null"};
        int t = json_typeof(j);
        lpvp_set_error(err, err_n, "the body must be a JSON object, not %s",
                (t >= 0 && t < 8) ? kinds[t] : "this");
        json_decref(j);
        return NULL;
    }
    return j;
}

/* ---- Field getters -------------------------------------------------------- */

static const char *type_word(const json_t *v)
{
    switch (json_typeof(v)) {
    case JSON_OBJECT: return "an object";
    case JSON_ARRAY: return "an array";
    case JSON_STRING: return "a string";
    case JSON_INTEGER: return "an integer";
    case JSON_REAL: return "a number";
    case JSON_TRUE:
    case JSON_FALSE: return "a boolean";
    case JSON_NULL: return "null";
    }
    return "something else";
}

/* Looks up key; returns OK with *v, ABSENT, or BAD (required and missing). */
static int lookup(const json_t *obj, const char *key, int required, json_t **v, char *err,
                  size_t err_n)
{
    *v = json_is_object(obj) ? json_object_get(obj, key) : NULL;
    if (*v)
        return LPVP_FIELD_OK;
    if (required) {
        lpvp_set_error(err, err_n, "%s: missing required field", key);
        return LPVP_FIELD_BAD;
    }
    return LPVP_FIELD_ABSENT;
}

/* Integer value of v: a JSON integer only (R4.11: "Integers MUST be JSON
 * integers"; 4.0 and 4e0 are JSON numbers with a fraction or an exponent,
 * which a reader in another language may not take as integers);
 * 0 ok, -1 not an integer. */
static int int_value(const json_t *v, int64_t *out)
{
    if (json_is_integer(v)) {
        *out = (int64_t)json_integer_value(v);
        return 0;
    }
    return -1;
}

static int check_int(const json_t *v, const char *key, const char *idx, int64_t min, int64_t max,
                     int64_t *out, char *err, size_t err_n)
{
    int64_t x;
    if (int_value(v, &x) != 0) {
        if (json_is_real(v))
            lpvp_set_error(err, err_n, "%s%s: expected an integer, got the number %.17g written with a fraction "
                           "or an exponent (write integers as integers)", key, idx, json_real_value(v));
        else
            lpvp_set_error(err, err_n, "%s%s: expected an integer, got %s", key, idx, type_word(v));
        return LPVP_FIELD_BAD;
    }
    if (x < min || x > max) {
        lpvp_set_error(err, err_n, "%s%s: %lld is out of range [%lld, %lld]", key, idx, (long long)x,
                (long long)min, (long long)max);
        return LPVP_FIELD_BAD;
    }
    *out = x;
    return LPVP_FIELD_OK;
}

static int check_number(const json_t *v, const char *key, const char *idx, double min,
                        double max, double *out, char *err, size_t err_n)
{
    double d;
    if (!json_is_number(v)) {
        lpvp_set_error(err, err_n, "%s%s: expected a number, got %s", key, idx, type_word(v));
        return LPVP_FIELD_BAD;
    }
    d = json_number_value(v);
    if (!isfinite(d)) {
        lpvp_set_error(err, err_n, "%s%s: not a finite number", key, idx);
        return LPVP_FIELD_BAD;
    }
    if (!(d >= min && d <= max)) {
        lpvp_set_error(err, err_n, "%s%s: %.9g is out of range [%.9g, %.9g]", key, idx, d, min, max);
        return LPVP_FIELD_BAD;
    }
    *out = d;
    return LPVP_FIELD_OK;
}

int lpvp_get_int(const json_t *obj, const char *key, int required, int64_t min, int64_t max,
                 int64_t *out, char *err, size_t err_n)
{
    json_t *v;
    int st = lookup(obj, key, required, &v, err, err_n);
    if (st != LPVP_FIELD_OK)
        return st;
    return check_int(v, key, "", min, max, out, err, err_n);
}

int lpvp_get_number(const json_t *obj, const char *key, int required, double min, double max,
                    double *out, char *err, size_t err_n)
{
    json_t *v;
    int st = lookup(obj, key, required, &v, err, err_n);
    if (st != LPVP_FIELD_OK)
        return st;
    return check_number(v, key, "", min, max, out, err, err_n);
}

int lpvp_get_float(const json_t *obj, const char *key, int required, double min, double max,
                   float *out, char *err, size_t err_n)
{
    double d;
    int st = lpvp_get_number(obj, key, required, min, max, &d, err, err_n);
    if (st == LPVP_FIELD_OK) {
        if (fabs(d) > 3.4028234663852886e38) {
            lpvp_set_error(err, err_n, "%s: %.9g does not fit in a float", key, d);
            return LPVP_FIELD_BAD;
        }
        if (d != 0.0 && fabs(d) < 1.17549435082228751e-38) { /* FLT_MIN: it would round to 0, often "none" */
            lpvp_set_error(err, err_n,
                           "%s: %g is too small: it would round to 0 in a 32-bit float (the smallest nonzero value "
                           "is 1.17549435e-38)", key, d);
            return LPVP_FIELD_BAD;
        }
        *out = (float)d;
    }
    return st;
}

int lpvp_get_bool(const json_t *obj, const char *key, int required, int *out, char *err,
                  size_t err_n)
{
    json_t *v;
    int st = lookup(obj, key, required, &v, err, err_n);
    if (st != LPVP_FIELD_OK)
        return st;
    if (!json_is_boolean(v)) {
        lpvp_set_error(err, err_n, "%s: expected true or false, got %s", key, type_word(v));
        return LPVP_FIELD_BAD;
    }
    *out = json_is_true(v) ? 1 : 0;
    return LPVP_FIELD_OK;
}

int lpvp_get_string(const json_t *obj, const char *key, int required, size_t max_len,
                    const char **out, size_t *out_len, char *err, size_t err_n)
{
    json_t *v;
    int st = lookup(obj, key, required, &v, err, err_n);
    size_t n;
    if (st != LPVP_FIELD_OK)
        return st;
    if (!json_is_string(v)) {
        lpvp_set_error(err, err_n, "%s: expected a string, got %s", key, type_word(v));
        return LPVP_FIELD_BAD;
    }
    n = json_string_length(v);
    if (n > max_len) {
        lpvp_set_error(err, err_n, "%s: string of %zu bytes is longer than %zu", key, n, max_len);
        return LPVP_FIELD_BAD;
    }
    *out = json_string_value(v);
    if (out_len)
        *out_len = n;
    return LPVP_FIELD_OK;
}

int lpvp_get_enum(const json_t *obj, const char *key, int required,
                  const char *const *choices, size_t n_choices, int *out, char *err,
                  size_t err_n)
{
    json_t *v;
    int st = lookup(obj, key, required, &v, err, err_n);
    if (st != LPVP_FIELD_OK)
        return st;
    if (json_is_string(v)) {
        const char *s = json_string_value(v);
        size_t n = json_string_length(v);
        for (size_t i = 0; i < n_choices; i++) {
            if (strlen(choices[i]) == n && memcmp(choices[i], s, n) == 0) {
                *out = (int)i;
                return LPVP_FIELD_OK;
            }
        }
    }
    if (err && err_n) {
        size_t at;
        lpvp_set_error(err, err_n, "%s: expected one of ", key);
        at = strlen(err);
        for (size_t i = 0; i < n_choices && at + 1 < err_n; i++) {
            snprintf(err + at, err_n - at, "%s\"%s\"", i ? ", " : "", choices[i]);
            at = strlen(err);
        }
        if (!json_is_string(v) && at + 1 < err_n)
            snprintf(err + at, err_n - at, ", got %s", type_word(v));
    }
    return LPVP_FIELD_BAD;
}

static int get_array_n(const json_t *obj, const char *key, int required, size_t count,
                       json_t **arr, char *err, size_t err_n)
{
    int st = lookup(obj, key, required, arr, err, err_n);
    if (st != LPVP_FIELD_OK)
        return st;
    if (!json_is_array(*arr) || json_array_size(*arr) != count) {
        if (json_is_array(*arr))
            lpvp_set_error(err, err_n, "%s: expected an array of %zu numbers, got %zu elements", key,
                    count, json_array_size(*arr));
        else
            lpvp_set_error(err, err_n, "%s: expected an array of %zu numbers, got %s", key, count,
                    type_word(*arr));
        return LPVP_FIELD_BAD;
    }
    return LPVP_FIELD_OK;
}

int lpvp_get_numbers(const json_t *obj, const char *key, int required, size_t count, double min,
                     double max, double *out, char *err, size_t err_n)
{
    json_t *a;
    char idx[32];
    int st = get_array_n(obj, key, required, count, &a, err, err_n);
    if (st != LPVP_FIELD_OK)
        return st;
    for (size_t i = 0; i < count; i++) {
        snprintf(idx, sizeof idx, "[%zu]", i);
        if (check_number(json_array_get(a, i), key, idx, min, max, &out[i], err, err_n) !=
            LPVP_FIELD_OK)
            return LPVP_FIELD_BAD;
    }
    return LPVP_FIELD_OK;
}

int lpvp_get_floats(const json_t *obj, const char *key, int required, size_t count, double min,
                    double max, float *out, char *err, size_t err_n)
{
    json_t *a;
    char idx[32];
    int st = get_array_n(obj, key, required, count, &a, err, err_n);
    if (st != LPVP_FIELD_OK)
        return st;
    for (size_t i = 0; i < count; i++) {
        double d;
        snprintf(idx, sizeof idx, "[%zu]", i);
        if (check_number(json_array_get(a, i), key, idx, min, max, &d, err, err_n) !=
            LPVP_FIELD_OK)
            return LPVP_FIELD_BAD;
        if (fabs(d) > 3.4028234663852886e38) {
            lpvp_set_error(err, err_n, "%s%s: %.9g does not fit in a float", key, idx, d);
            return LPVP_FIELD_BAD;
        }
        out[i] = (float)d;
    }
    return LPVP_FIELD_OK;
}

int lpvp_get_ints(const json_t *obj, const char *key, int required, size_t count, int64_t min,
                  int64_t max, int64_t *out, char *err, size_t err_n)
{
    json_t *a;
    char idx[32];
    int st = lookup(obj, key, required, &a, err, err_n);
    if (st != LPVP_FIELD_OK)
        return st;
    if (!json_is_array(a) || json_array_size(a) != count) {
        if (json_is_array(a))
            lpvp_set_error(err, err_n, "%s: expected an array of %zu integers, got %zu elements", key,
                    count, json_array_size(a));
        else
            lpvp_set_error(err, err_n, "%s: expected an array of %zu integers, got %s", key, count,
                    type_word(a));
        return LPVP_FIELD_BAD;
    }
    for (size_t i = 0; i < count; i++) {
        snprintf(idx, sizeof idx, "[%zu]", i);
        if (check_int(json_array_get(a, i), key, idx, min, max, &out[i], err, err_n) !=
            LPVP_FIELD_OK)
            return LPVP_FIELD_BAD;
    }
    return LPVP_FIELD_OK;
}

int lpvp_get_object(const json_t *obj, const char *key, int required, const json_t **out,
                    char *err, size_t err_n)
{
    json_t *v;
    int st = lookup(obj, key, required, &v, err, err_n);
    if (st != LPVP_FIELD_OK)
        return st;
    if (!json_is_object(v)) {
        lpvp_set_error(err, err_n, "%s: expected an object, got %s", key, type_word(v));
        return LPVP_FIELD_BAD;
    }
    *out = v;
    return LPVP_FIELD_OK;
}

int lpvp_get_array(const json_t *obj, const char *key, int required, size_t max_len,
                   const json_t **out, char *err, size_t err_n)
{
    json_t *v;
    int st = lookup(obj, key, required, &v, err, err_n);
    if (st != LPVP_FIELD_OK)
        return st;
    if (!json_is_array(v)) {
        lpvp_set_error(err, err_n, "%s: expected an array, got %s", key, type_word(v));
        return LPVP_FIELD_BAD;
    }
    if (json_array_size(v) > max_len) {
        lpvp_set_error(err, err_n, "%s: %zu elements, at most %zu allowed", key, json_array_size(v),
                max_len);
        return LPVP_FIELD_BAD;
    }
    *out = v;
    return LPVP_FIELD_OK;
}

void lpvp_err_prefix(char *err, size_t err_n, const char *fmt, ...)
{
    char prefix[256];
    char *old;
    va_list ap;
    size_t plen, olen;
    if (!err || err_n == 0)
        return;
    va_start(ap, fmt);
    vsnprintf(prefix, sizeof prefix, fmt, ap);
    va_end(ap);
    plen = strlen(prefix);
    olen = strnlen(err, err_n - 1);
    if (plen >= err_n - 1) {
        memcpy(err, prefix, err_n - 1);
        err[err_n - 1] = '\0';
        return;
    }
    old = err;
    if (plen + olen > err_n - 1)
        olen = err_n - 1 - plen;
    memmove(old + plen, old, olen);
    memcpy(old, prefix, plen);
    old[plen + olen] = '\0';
}
