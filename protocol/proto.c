/*
 * proto.c - the lpvd wire protocol v1: names, header codec, incremental
 * parser, frame building, body parsing and field getters. See proto.h and
 * SPEC.md (requirement numbers in comments).
 */
#include "proto.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- Names ---------------------------------------------------------------- */

static const char *const request_names[] = {
    NULL,           "HELLO",     "SCENE_LOAD",   "SCENE_UPDATE", "LIGHT_SET",
    "LIGHT_REMOVE", "CAMERA_SET", "CONFIG",      "TICK",         "SUBSCRIBE",
    "UNSUBSCRIBE",  "GET_VOLUME", "GET_FRAME",   "QUERY_IRRADIANCE", "STATS",
    "BYE",          "ACK",
};

static const char *const reply_names[] = {
    NULL,                 "HELLO_REPLY",       "SCENE_LOAD_REPLY",  "SCENE_UPDATE_REPLY",
    "LIGHT_SET_REPLY",    "LIGHT_REMOVE_REPLY", "CAMERA_SET_REPLY", "CONFIG_REPLY",
    "TICK_REPLY",         "SUBSCRIBE_REPLY",   "UNSUBSCRIBE_REPLY", "GET_VOLUME_REPLY",
    "GET_FRAME_REPLY",    "QUERY_IRRADIANCE_REPLY", "STATS_REPLY", "BYE_REPLY",
    "ACK_REPLY",
};

const char *lpvp_type_name(uint16_t type)
{
    if (type >= LPVP_HELLO && type <= LPVP_ACK)
        return request_names[type];
    if (type == LPVP_VOLUME)
        return "VOLUME";
    if (type == LPVP_FRAME)
        return "FRAME";
    if (type == LPVP_ERROR)
        return "ERROR";
    /* ACK has no reply (R3.1), so 0x8010 is not a type. */
    if ((type & LPVP_REPLY_BIT) && (type & 0x7FFF) >= LPVP_HELLO && (type & 0x7FFF) < LPVP_ACK)
        return reply_names[type & 0x7FFF];
    return "UNKNOWN";
}

int lpvp_type_is_request(uint16_t type)
{
    return type >= LPVP_HELLO && type <= LPVP_ACK;
}

int lpvp_type_has_reply(uint16_t type)
{
    return lpvp_type_is_request(type) && type != LPVP_ACK;
}

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

/* ---- Limits and header ---------------------------------------------------- */

void lpvp_limits_default(lpvp_limits *lim)
{
    lim->max_body = LPVP_DEFAULT_MAX_BODY;
    lim->max_message = LPVP_DEFAULT_MAX_MESSAGE;
    lim->no_attachment = 0;
}

static lpvp_limits limits_or_default(const lpvp_limits *lim)
{
    lpvp_limits l;
    if (lim)
        return *lim;
    lpvp_limits_default(&l);
    return l;
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

void lpvp_header_encode(const lpvp_header *h, uint8_t out[LPVP_HEADER_SIZE])
{
    memcpy(out, LPVP_MAGIC, LPVP_MAGIC_LEN);
    lpvp_put_u16(out + 4, h->version);
    lpvp_put_u16(out + 6, h->type);
    lpvp_put_u32(out + 8, h->request_id);
    lpvp_put_u32(out + 12, h->flags);
    lpvp_put_u32(out + 16, h->json_length);
    lpvp_put_u32(out + 20, h->attachment_length);
}

int lpvp_header_check(const uint8_t in[LPVP_HEADER_SIZE], const lpvp_limits *lim,
                      lpvp_header *h, char *err, size_t err_n)
{
    lpvp_limits l = limits_or_default(lim);
    h->version = lpvp_get_u16(in + 4);
    h->type = lpvp_get_u16(in + 6);
    h->request_id = lpvp_get_u32(in + 8);
    h->flags = lpvp_get_u32(in + 12);
    h->json_length = lpvp_get_u32(in + 16);
    h->attachment_length = lpvp_get_u32(in + 20);
    if (err && err_n)
        err[0] = '\0';

    if (memcmp(in, LPVP_MAGIC, LPVP_MAGIC_LEN) != 0) { /* R2.2 */
        h->request_id = 0;
        lpvp_set_error(err, err_n, "bad magic %02x %02x %02x %02x (expected \"LPVD\")", in[0], in[1],
                in[2], in[3]);
        return LPVP_E_BAD_MAGIC;
    }
    if (h->version != LPVP_VERSION) { /* R2.3 */
        lpvp_set_error(err, err_n, "frame version %u not spoken (versions: [%d])", (unsigned)h->version,
                LPVP_VERSION);
        return LPVP_E_BAD_VERSION;
    }
    if (h->flags != 0) { /* R2.4 */
        lpvp_set_error(err, err_n, "flags 0x%08x must be 0", (unsigned)h->flags);
        return LPVP_E_BAD_FRAME;
    }
    if (h->json_length < LPVP_MIN_JSON_LENGTH) { /* R2.1 */
        lpvp_set_error(err, err_n, "json_length %u is less than 2 (the body is at least {})",
                (unsigned)h->json_length);
        return LPVP_E_BAD_FRAME;
    }
    if (h->json_length > l.max_body) { /* R2.5 */
        lpvp_set_error(err, err_n, "json_length %u exceeds the body limit %u", (unsigned)h->json_length,
                (unsigned)l.max_body);
        return LPVP_E_TOO_LARGE;
    }
    if ((uint64_t)h->json_length + h->attachment_length > l.max_message) { /* R2.5 */
        lpvp_set_error(err, err_n,
                "json_length %u + attachment_length %u exceeds the message limit %llu",
                (unsigned)h->json_length, (unsigned)h->attachment_length,
                (unsigned long long)l.max_message);
        return LPVP_E_TOO_LARGE;
    }
    if (l.no_attachment && h->attachment_length) { /* R2.5a */
        lpvp_set_error(err, err_n, "attachment_length %u: this frame may carry no attachment",
                (unsigned)h->attachment_length);
        return LPVP_E_TOO_LARGE;
    }
    return LPVP_E_NONE;
}

int lpvp_header_decode(const uint8_t in[LPVP_HEADER_SIZE], const lpvp_limits *lim,
                       lpvp_header *h, int *error_code)
{
    int code = lpvp_header_check(in, lim, h, NULL, 0);
    if (error_code)
        *error_code = code;
    return code == LPVP_E_NONE ? 0 : -1;
}

/* ---- Parser --------------------------------------------------------------- */

void lpvp_parser_init(lpvp_parser *p, const lpvp_limits *lim)
{
    memset(p, 0, sizeof *p);
    p->limits = limits_or_default(lim);
}

void lpvp_parser_free(lpvp_parser *p)
{
    free(p->buf);
    p->buf = NULL;
    p->buf_cap = 0;
    p->buf_have = 0;
}

int lpvp_parser_mid_frame(const lpvp_parser *p)
{
    return !p->failed && (p->hdr_have > 0);
}

static int parser_fail(lpvp_parser *p, int code, uint32_t request_id)
{
    p->failed = 1;
    p->error_code = code;
    p->error_request_id = request_id;
    return LPVP_PARSE_ERROR;
}

static size_t payload_len(const lpvp_header *h)
{
    return (size_t)h->json_length + (size_t)h->attachment_length;
}

uint64_t lpvp_parser_payload_have(const lpvp_parser *p)
{
    return !p->failed && p->hdr_have == LPVP_HEADER_SIZE ? (uint64_t)p->buf_have : 0;
}

uint64_t lpvp_parser_frame_payload(const lpvp_parser *p)
{
    return !p->failed && p->hdr_have == LPVP_HEADER_SIZE ? payload_len(&p->header) : 0;
}

static void fill_frame(lpvp_frame *f, const lpvp_header *h, const uint8_t *payload)
{
    f->header = *h;
    f->body = (const char *)payload;
    f->body_len = h->json_length;
    f->attachment_len = h->attachment_length;
    f->attachment = h->attachment_length ? payload + h->json_length : NULL;
}

/* Grows p->buf to hold at least `want` bytes (want <= the frame's payload,
 * itself within the limits), doubling so that the total allocated stays
 * within twice what was received. */
static int parser_reserve(lpvp_parser *p, size_t want, size_t total)
{
    size_t cap;
    uint8_t *nb;
    if (want <= p->buf_cap)
        return 0;
    cap = p->buf_cap ? p->buf_cap : 4096;
    while (cap < want)
        cap = cap > ((size_t)-1) / 2 ? want : cap * 2;
    if (cap > total)
        cap = total;
    nb = realloc(p->buf, cap);
    if (!nb)
        return -1;
    p->buf = nb;
    p->buf_cap = cap;
    return 0;
}

int lpvp_parser_feed(lpvp_parser *p, const void *data, size_t len, size_t *consumed,
                     lpvp_frame *frame)
{
    const uint8_t *in = data;
    size_t used = 0;
    *consumed = 0;
    if (p->failed)
        return LPVP_PARSE_ERROR;
    /* Between frames a connection holds no more than 1 MiB: a buffer that
     * assembled a 256 MiB upload is not kept (the frame it backed was valid
     * only until this call). */
    if (p->hdr_have == 0 && p->buf_cap > ((size_t)1 << 20)) {
        free(p->buf);
        p->buf = NULL;
        p->buf_cap = 0;
    }

    while (used < len) { /* a payload is never empty (json_length >= 2) */
        if (p->hdr_have < LPVP_HEADER_SIZE) {
            /* Header bytes; the magic is checked byte by byte (R2.2). */
            size_t take = LPVP_HEADER_SIZE - p->hdr_have;
            if (take > len - used)
                take = len - used;
            for (size_t i = 0; i < take; i++) {
                size_t at = p->hdr_have + i;
                if (at < LPVP_MAGIC_LEN && in[used + i] != (uint8_t)LPVP_MAGIC[at]) {
                    memcpy(p->hdr + p->hdr_have, in + used, i + 1);
                    *consumed = used + i + 1;
                    p->bytes += *consumed;
                    snprintf(p->error_message, sizeof p->error_message,
                             "bad magic: byte %zu is 0x%02x (expected \"LPVD\")", at,
                             in[used + i]);
                    return parser_fail(p, LPVP_E_BAD_MAGIC, 0);
                }
            }
            memcpy(p->hdr + p->hdr_have, in + used, take);
            p->hdr_have += take;
            used += take;
            if (p->hdr_have < LPVP_HEADER_SIZE)
                break;
            {
                int code = lpvp_header_check(p->hdr, &p->limits, &p->header, p->error_message,
                                             sizeof p->error_message);
                if (code != LPVP_E_NONE) { /* R2.1-R2.5: before reading the body */
                    *consumed = used;
                    p->bytes += used;
                    return parser_fail(p, code, p->header.request_id);
                }
            }
            p->buf_have = 0;
            /* Zero copy: the whole payload is in this chunk. */
            if (len - used >= payload_len(&p->header)) {
                size_t n = payload_len(&p->header);
                if (frame)
                    fill_frame(frame, &p->header, in + used);
                used += n;
                p->hdr_have = 0;
                p->frames++;
                *consumed = used;
                p->bytes += used;
                return LPVP_PARSE_FRAME;
            }
            /* Do not keep a big buffer from an earlier frame around. */
            if (p->buf_cap > ((size_t)1 << 20) && payload_len(&p->header) < p->buf_cap / 4) {
                free(p->buf);
                p->buf = NULL;
                p->buf_cap = 0;
            }
            continue;
        }
        /* Payload bytes. */
        {
            size_t total = payload_len(&p->header);
            size_t take = total - p->buf_have;
            if (take > len - used)
                take = len - used;
            if (p->buf_have == 0 && take == total) {
                /* Zero copy: the header came earlier, the whole payload now. */
                if (frame)
                    fill_frame(frame, &p->header, in + used);
                used += total;
                p->hdr_have = 0;
                p->frames++;
                *consumed = used;
                p->bytes += used;
                return LPVP_PARSE_FRAME;
            }
            if (take) {
                if (parser_reserve(p, p->buf_have + take, total) != 0) {
                    *consumed = used;
                    p->bytes += used;
                    snprintf(p->error_message, sizeof p->error_message,
                             "out of memory buffering a %zu-byte frame", total);
                    return parser_fail(p, LPVP_E_INTERNAL, p->header.request_id);
                }
                memcpy(p->buf + p->buf_have, in + used, take);
                p->buf_have += take;
                used += take;
            }
            if (p->buf_have == total) {
                if (frame)
                    fill_frame(frame, &p->header, p->buf);
                p->hdr_have = 0;
                p->buf_have = 0;
                p->frames++;
                *consumed = used;
                p->bytes += used;
                return LPVP_PARSE_FRAME;
            }
        }
    }
    *consumed = used;
    p->bytes += used;
    return LPVP_PARSE_NEED_MORE;
}

/* ---- Building ------------------------------------------------------------- */

static uint8_t *build(uint16_t type, uint32_t request_id, const char *json, size_t json_len,
                      const void *attachment, size_t att_len, int copy_att, size_t *out_len)
{
    lpvp_header h;
    size_t total;
    uint8_t *out;
    if (!json) {
        json = "{}";
        json_len = 2;
    }
    if (json_len > UINT32_MAX || att_len > UINT32_MAX)
        return NULL;
    total = LPVP_HEADER_SIZE + json_len + (copy_att ? att_len : 0);
    out = malloc(total ? total : 1);
    if (!out)
        return NULL;
    h.version = LPVP_VERSION;
    h.type = type;
    h.request_id = request_id;
    h.flags = 0;
    h.json_length = (uint32_t)json_len;
    h.attachment_length = (uint32_t)att_len;
    lpvp_header_encode(&h, out);
    memcpy(out + LPVP_HEADER_SIZE, json, json_len);
    if (copy_att && att_len)
        memcpy(out + LPVP_HEADER_SIZE + json_len, attachment, att_len);
    if (out_len)
        *out_len = total;
    return out;
}

uint8_t *lpvp_frame_build(uint16_t type, uint32_t request_id, const char *json, size_t json_len,
                          const void *attachment, size_t att_len, size_t *out_len)
{
    if (att_len && !attachment)
        return NULL;
    return build(type, request_id, json, json_len, attachment, att_len, 1, out_len);
}

uint8_t *lpvp_frame_build_head(uint16_t type, uint32_t request_id, const char *json,
                               size_t json_len, size_t att_len, size_t *out_len)
{
    return build(type, request_id, json, json_len, NULL, att_len, 0, out_len);
}

uint8_t *lpvp_frame_build_json(uint16_t type, uint32_t request_id, const json_t *body,
                               const void *attachment, size_t att_len, size_t *out_len)
{
    char *s;
    uint8_t *out;
    if (!body)
        return lpvp_frame_build(type, request_id, NULL, 0, attachment, att_len, out_len);
    if (!json_is_object(body))
        return NULL;
    s = json_dumps(body, JSON_COMPACT);
    if (!s)
        return NULL;
    out = lpvp_frame_build(type, request_id, s, strlen(s), attachment, att_len, out_len);
    free(s);
    return out;
}

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

uint8_t *lpvp_error_build(uint32_t request_id, int code, size_t *out_len, const char *fmt, ...)
{
    va_list ap;
    json_t *o;
    uint8_t *out;
    va_start(ap, fmt);
    o = lpvp_error_vbody(code, fmt, ap);
    va_end(ap);
    if (!o)
        return NULL;
    out = lpvp_frame_build_json(LPVP_ERROR, request_id, o, NULL, 0, out_len);
    json_decref(o);
    return out;
}

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

void lpvp_default_socket_path(char *out, size_t n)
{
    const char *xdg = getenv("XDG_RUNTIME_DIR");
    struct stat st;
    if (xdg && xdg[0] == '/' && stat(xdg, &st) == 0 && S_ISDIR(st.st_mode))
        snprintf(out, n, "%s/lpvd.sock", xdg);
    else
        snprintf(out, n, "/tmp/lpvd-%u.sock", (unsigned)getuid());
}

int lpvp_split_host_port(const char *address, char *host, size_t host_n, unsigned *port, char *err, size_t err_n)
{
    const char *s = address;
    const char *colon = strrchr(s, ':');
    const char *port_str = colon ? colon + 1 : s;
    size_t hl = colon ? (size_t)(colon - s) : 0;
    if (hl >= 2 && s[0] == '[' && s[hl - 1] == ']') {
        s += 1;
        hl -= 2;
    }
    if (hl >= host_n) {
        lpvp_set_error(err, err_n, "%s: host name too long", address);
        return -1;
    }
    memcpy(host, s, hl);
    host[hl] = '\0';
    if (!host[0])
        snprintf(host, host_n, "127.0.0.1");
    char *end = NULL;
    unsigned long p = strtoul(port_str, &end, 10);
    if (!port_str[0] || *end || p > 65535 || port_str[0] == '-' || port_str[0] == '+') {
        lpvp_set_error(err, err_n, "%s: expected HOST:PORT or PORT with a port 0..65535", address);
        return -1;
    }
    *port = (unsigned)p;
    return 0;
}
