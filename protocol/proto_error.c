/*
 * proto_error.c - the protocol's errors (SPEC section 3): the codes' names,
 * which codes close the connection (R3.4), the ERROR body (its frame:
 * proto_build.c), and
 * lpvp_set_error, the one way every function of this library reports what
 * was wrong (a message naming the field or value, ready to be an ERROR's
 * "message"). See proto.h.
 */
#include "proto.h"

#include <stdio.h>

static const char *const error_names[LPVP_E_COUNT] = {
    NULL,          "BAD_MAGIC",      "BAD_VERSION", "BAD_FRAME",    "TOO_LARGE",
    "BAD_JSON",    "UNKNOWN_TYPE",   "BAD_FIELD",   "UNAUTHORIZED", "HELLO_REQUIRED",
    "NOT_READY",   "SCENE_INVALID",  "PATH_REFUSED", "LIMIT",       "INTERNAL",
    "SHUTTING_DOWN",
};

const char *lpvp_error_name(int code)
{
    if (code >= 1 && code < LPVP_E_COUNT)
        return error_names[code];
    return "UNKNOWN";
}

int lpvp_error_closes(int code)
{
    switch (code) {
    case LPVP_E_BAD_MAGIC:
    case LPVP_E_BAD_VERSION:
    case LPVP_E_BAD_FRAME:
    case LPVP_E_TOO_LARGE:
    case LPVP_E_UNAUTHORIZED:
    case LPVP_E_SHUTTING_DOWN:
        return 1;
    default:
        return 0;
    }
}

void lpvp_set_error(char *err, size_t err_n, const char *fmt, ...)
{
    va_list ap;
    if (!err || err_n == 0)
        return;
    va_start(ap, fmt);
    vsnprintf(err, err_n, fmt, ap);
    va_end(ap);
}

/* ---- ERROR bodies and frames ---------------------------------------------- */

json_t *lpvp_error_vbody(int code, const char *fmt, va_list ap)
{
    char msg[1024];
    json_t *o;
    vsnprintf(msg, sizeof msg, fmt ? fmt : "", ap);
    /* The message may contain caller-provided bytes: json_string refuses
     * invalid UTF-8, so fall back to a plain message rather than fail. */
    o = json_object();
    if (!o)
        return NULL;
    json_t *m = json_string(msg);
    if (!m)
        m = json_string("(message was not valid UTF-8)");
    if (json_object_set_new(o, "code", json_integer(code)) != 0 ||
        json_object_set_new(o, "name", json_string(lpvp_error_name(code))) != 0 ||
        json_object_set_new(o, "message", m) != 0) {
        json_decref(o);
        return NULL;
    }
    if (code == LPVP_E_BAD_VERSION) { /* R2.3, R4.1: list the versions spoken */
        json_t *v = json_array();
        if (!v || json_array_append_new(v, json_integer(LPVP_VERSION)) != 0 ||
            json_object_set_new(o, "versions", v) != 0) {
            json_decref(o);
            return NULL;
        }
    }
    return o;
}

json_t *lpvp_error_body(int code, const char *fmt, ...)
{
    va_list ap;
    json_t *o;
    va_start(ap, fmt);
    o = lpvp_error_vbody(code, fmt, ap);
    va_end(ap);
    return o;
}
