/*
 * proto_build.c - frames to send: header + JSON body + attachment in one
 * malloc'd buffer, or header and body only for a large attachment written
 * from its own buffer (writev, no copy), and ERROR frames. See proto.h.
 */
#include "proto.h"

#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

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

/* An ERROR frame (its body: proto_error.c). */
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
