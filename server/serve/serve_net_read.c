/*
 * serve_net_read.c - reading a connection: its bytes go through the
 * protocol's incremental parser (protocol/proto.h) under the connection's
 * frame limits (pre-auth ones before HELLO, R2.5a), each complete frame
 * becomes a pending request for the session's pump, and reading stops while
 * too many requests wait or a frame waits for memory (serve_net_reserve.c).
 * The network layer's design is in serve_net_internal.h.
 */
#include "serve.h"
#include "serve_net_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SV_MAX_PENDING 64
#define SV_MAX_PENDING_BYTES (512u << 20)

/* ---- reading ------------------------------------------------------------ */
/* The frame limits of a connection: the configured ones once it has said
 * HELLO, the pre-auth ones before (R2.5a). */
lpvp_limits sv_net_conn_limits(const sv_server *s, int authenticated)
{
    lpvp_limits lim = {.max_body = (uint32_t)s->cfg.max_body, .max_message = s->cfg.max_message};
    if (!authenticated) {
        if (s->cfg.max_preauth_body < lim.max_body)
            lim.max_body = (uint32_t)s->cfg.max_preauth_body;
        lim.max_message = lim.max_body;
        lim.no_attachment = 1;
    }
    return lim;
}

/* The ERROR for a frame refused before HELLO names the pre-auth limit and
 * the header's values rather than the configured limits. */
static void preauth_refusal(sv_conn *c, char *msg, size_t n)
{
    const lpvp_header *h = &c->parser.header;
    snprintf(msg, n,
             "before HELLO the server accepts frames of at most %llu bytes of JSON and no attachment "
             "(--max-preauth-body %llu); this one declared json_length %u and attachment_length %u",
             (unsigned long long)c->parser.limits.max_body, (unsigned long long)c->srv->cfg.max_preauth_body,
             (unsigned)h->json_length, (unsigned)h->attachment_length);
}

void sv_net_on_alloc(uv_handle_t *h, size_t suggested, uv_buf_t *buf)
{
    (void)suggested;
    sv_conn *c = h->data;
    *buf = uv_buf_init((char *)c->rbuf, sizeof c->rbuf);
}

static int enqueue_frame(sv_conn *c, const lpvp_frame *f)
{
    sv_request *r = calloc(1, sizeof *r);
    if (!r)
        return -1;
    r->type = f->header.type;
    r->request_id = f->header.request_id;
    r->json_len = f->body_len;
    r->json = malloc(f->body_len + 1);
    r->att_len = f->attachment_len;
    r->att = f->attachment_len ? malloc(f->attachment_len) : NULL;
    if (!r->json || (f->attachment_len && !r->att)) {
        free(r->json);
        free(r->att);
        free(r);
        return -1;
    }
    memcpy(r->json, f->body, f->body_len);
    r->json[f->body_len] = '\0';
    if (f->attachment_len)
        memcpy(r->att, f->attachment, f->attachment_len);
    if (c->pending_tail)
        c->pending_tail->next = r;
    else
        c->pending_head = r;
    c->pending_tail = r;
    c->pending_count++;
    c->pending_bytes += r->json_len + r->att_len;
    /* the reservation, if the frame had one, becomes the pending request */
    sv_memory_add(&c->srv->mem, SV_MEM_REQUESTS, r->json_len + r->att_len);
    sv_memory_sub(&c->srv->mem, SV_MEM_REQUESTS, c->reserved);
    c->reserved = 0;
    c->reserve_shrunk = 0;
    return 0;
}

void sv_net_on_read(uv_stream_t *st, ssize_t nread, const uv_buf_t *buf)
{
    sv_conn *c = st->data;
    if (nread < 0) {
        /* EOF or error: a frame cut mid-way has no effect (R2.6) */
        sv_conn_close(c);
        return;
    }
    if (nread == 0)
        return;
    size_t off = 0, len = (size_t)nread;
    c->refs++;
    while (off < len && !c->closing && !c->close_after_write) {
        size_t used = 0;
        lpvp_frame f;
        const uint64_t had = lpvp_parser_payload_have(&c->parser);
        int stt = lpvp_parser_feed(&c->parser, buf->base + off, len - off, &used, &f);
        off += used;
        if (stt == LPVP_PARSE_NEED_MORE && lpvp_parser_payload_have(&c->parser) > had)
            c->payload_ms = sv_now_ms(); /* the sender is not stalled (sv_net_shrink_stalled) */
        if (stt == LPVP_PARSE_NEED_MORE && sv_net_reserve_frame(c) != 0)
            c->wait_memory = ++c->srv->memory_waits; /* all of this read is in the parser: stop reading below */
        if (stt == LPVP_PARSE_FRAME) {
            c->idle_since_ms = sv_now_ms(); /* R4.9: idle counts from the last complete frame (or answer) */
            if (enqueue_frame(c, &f) != 0) {
                sv_send_error(c, f.header.request_id, LPVP_E_INTERNAL, "out of memory for the request");
                sv_conn_close_after_write(c);
                break;
            }
            if (!c->hello) {
                /* Answer it before reading the next header: after a HELLO
                 * that succeeds the configured limits apply (R2.5a). Before
                 * HELLO nothing makes a session busy, so this empties the
                 * queue. */
                c->srv->session.pump(c);
                if (c->hello && !c->closing)
                    c->parser.limits = sv_net_conn_limits(c->srv, 1);
            }
        } else if (stt == LPVP_PARSE_ERROR) {
            char pre[320];
            const char *why = c->parser.error_message;
            if (!c->hello && c->parser.error_code == LPVP_E_TOO_LARGE) {
                preauth_refusal(c, pre, sizeof pre);
                why = pre;
            }
            json_t *b = lpvp_error_body(c->parser.error_code, "%s", why);
            sv_send(c, LPVP_ERROR, c->parser.error_request_id, b, NULL, 0, SV_STREAM_NONE);
            sv_conn_close_after_write(c);
            break;
        }
    }
    if (!c->closing && !c->close_after_write) {
        if (c->wait_memory || c->pending_count >= SV_MAX_PENDING || c->pending_bytes >= SV_MAX_PENDING_BYTES) {
            uv_read_stop(&c->h.stream);
            c->reading = 0;
        }
        c->srv->session.pump(c);
    }
    sv_conn_unref(c);
}

void sv_net_resume_reading(sv_conn *c)
{
    if (c->closing || c->close_after_write || c->reading || c->srv->stopping || c->wait_memory)
        return;
    if (c->pending_count < SV_MAX_PENDING / 2 && c->pending_bytes < SV_MAX_PENDING_BYTES / 2) {
        if (uv_read_start(&c->h.stream, sv_net_on_alloc, sv_net_on_read) == 0)
            c->reading = 1;
    }
}
