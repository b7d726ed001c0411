/*
 * lpvc_frame.c - the C client's frames (SPEC section 6): decoding a FRAME /
 * GET_FRAME header and attachment (rgba8 with zstd, or a PNG / EXR file as
 * sent) and GET_FRAME.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lpvc_internal.h"
#include "volume_codec.h"

/* ---- frames ---------------------------------------------------------------- */

void lpvc_frame_free(lpvc_frame *f)
{
    if (!f)
        return;
    free(f->data);
    free(f->header_json);
    free(f->plan_json);
    memset(f, 0, sizeof *f);
}

static int64_t get_i64(const json_t *o, const char *key, int64_t dflt)
{
    json_t *v = json_object_get(o, key);
    return json_is_integer(v) ? json_integer_value(v) : dflt;
}

static void get_str(const json_t *o, const char *key, char *buf, size_t n)
{
    json_t *v = json_object_get(o, key);
    snprintf(buf, n, "%s", json_is_string(v) ? json_string_value(v) : "");
}

int lpvci_decode_frame(lpvc *c, const json_t *hdr, uint8_t *att, size_t att_len, lpvc_frame *out)
{
    memset(out, 0, sizeof *out);
    out->revision = get_i64(hdr, "revision", -1);
    out->tick = get_i64(hdr, "tick", -1);
    out->width = (int)get_i64(hdr, "width", 0);
    out->height = (int)get_i64(hdr, "height", 0);
    get_str(hdr, "format", out->format, sizeof out->format);
    get_str(hdr, "terms", out->terms, sizeof out->terms);
    char comp[16];
    get_str(hdr, "compression", comp, sizeof comp);
    if (strcmp(out->format, lpvp_frame_format_names[LPVP_FRAME_RGBA8]) == 0) {
        int64_t raw_length = get_i64(hdr, "raw_length", -1);
        size_t expect = (size_t)out->width * (size_t)out->height * 4u;
        if (out->width <= 0 || out->height <= 0 || (raw_length >= 0 && (size_t)raw_length != expect)) {
            free(att);
            return lpvci_fail(c, LPVC_ERR_PROTOCOL, "rgba8 frame %dx%d with raw_length %lld", out->width, out->height,
                        (long long)raw_length);
        }
        if (strcmp(comp, lpvp_compression_names[LPVP_COMP_ZSTD]) == 0) {
            uint8_t *raw = malloc(expect ? expect : 1);
            char err[256];
            if (!raw || lpvp_zstd_decompress_exact(att, att_len, raw, expect, err, sizeof err) != 0) {
                if (raw)
                    lpvci_fail(c, LPVC_ERR_PROTOCOL, "cannot decompress the frame: %s", err);
                else
                    lpvci_fail(c, LPVC_ERR_IO, "out of memory");
                free(raw);
                free(att);
                return -1;
            }
            free(att);
            att = raw;
            att_len = expect;
        } else if (att_len != expect) {
            free(att);
            return lpvci_fail(c, LPVC_ERR_PROTOCOL, "rgba8 frame of %zu bytes, expected %zu", att_len, expect);
        }
    }
    out->data = att;
    out->size = att_len;
    out->header_json = json_dumps(hdr, JSON_COMPACT);
    if (json_is_object(json_object_get(hdr, "plan")))
        out->plan_json = json_dumps(json_object_get(hdr, "plan"), JSON_COMPACT);
    return 0;
}

int lpvc_get_frame(lpvc *c, const lpvc_frame_desc *desc, lpvc_frame *out)
{
    if (!c)
        return -1;
    if (!out)
        return lpvci_fail(c, LPVC_ERR_USAGE, "out is NULL");
    memset(out, 0, sizeof *out);
    lpvc_frame_desc d = {0};
    if (desc)
        d = *desc;
    json_t *o = json_object();
    if (d.format)
        json_object_set_new(o, "format", json_string(d.format));
    if (d.compression)
        json_object_set_new(o, "compression", json_string(d.compression));
    if (d.terms)
        json_object_set_new(o, "terms", json_string(d.terms));
    if (d.exposure) {
        char *end = NULL;
        double ev = strtod(d.exposure, &end);
        json_object_set_new(o, "exposure",
                            end != d.exposure && *end == '\0' ? json_real(ev) : json_string(d.exposure));
    }
    if (d.transparent)
        json_object_set_new(o, "transparent", json_true());
    json_t *reply = NULL;
    uint8_t *att = NULL;
    size_t att_len = 0;
    int rc = lpvci_request(c, LPVP_GET_FRAME, o, NULL, 0, &reply, &att, &att_len);
    json_decref(o);
    if (rc == 0)
        rc = lpvci_decode_frame(c, reply, att, att_len, out);
    else
        free(att);
    json_decref(reply);
    return rc;
}
