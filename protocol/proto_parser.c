/*
 * proto_parser.c - the incremental frame parser (R2.1-R2.6): bytes in as
 * the socket delivers them, whole frames out; the magic is checked byte by
 * byte and the header before the body is read, a frame lying whole in one
 * chunk is returned without a copy, and buffers are bounded by what the
 * limits allow and what was received. See proto.h.
 */
#include "proto.h"
#include "proto_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- Parser --------------------------------------------------------------- */

void lpvp_parser_init(lpvp_parser *p, const lpvp_limits *lim)
{
    memset(p, 0, sizeof *p);
    p->limits = lpvp_limits_or_default(lim);
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
