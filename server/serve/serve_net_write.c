/*
 * serve_net_write.c - bounded writes to a connection: every frame the
 * daemon sends goes through sv_send, which counts it against the daemon's
 * memory budget (R7.6a) and the connection's write cap (--max-queue, or
 * SV_PREAUTH_MAX_QUEUE before HELLO; R3.5), and keeps at most one stream
 * message in flight and one unsent per stream (R5.5). The writes in flight
 * hold references to their connection (sv_conn_unref, serve_net_conn.c).
 * The network layer's design is in serve_net_internal.h.
 */
#include "serve.h"
#include "serve_net_internal.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void write_start(sv_conn *c, sv_wreq *w);

static void on_written(uv_write_t *req, int status)
{
    sv_wreq *w = (sv_wreq *)req;
    sv_conn *c = w->c;
    c->wq_bytes -= w->head_len + w->att_len;
    c->wq_count--;
    if (status == 0) {
        c->bytes_sent += w->head_len + w->att_len;
        c->srv->bytes_sent += w->head_len + w->att_len;
    }
    int stream = w->stream;
    sv_net_wreq_free(w);
    if (stream != SV_STREAM_NONE) {
        c->stream_inflight[stream] = 0;
        if (!c->closing && !c->close_after_write && status == 0 && c->stream_pending[stream]) {
            sv_wreq *next = c->stream_pending[stream];
            c->stream_pending[stream] = NULL;
            write_start(c, next);
        }
    }
    if (status != 0 && status != UV_ECANCELED && !c->closing)
        sv_conn_close(c);
    else if (c->close_after_write && c->wq_count == 0)
        sv_conn_close(c);
    sv_conn_unref(c);
}

static void write_start(sv_conn *c, sv_wreq *w)
{
    uv_buf_t bufs[2];
    unsigned nb = 0;
    bufs[nb++] = uv_buf_init((char *)w->head, (unsigned)w->head_len);
    if (w->att_len)
        bufs[nb++] = uv_buf_init((char *)w->att, (unsigned)w->att_len);
    w->c = c;
    c->refs++;
    c->wq_bytes += w->head_len + w->att_len;
    c->wq_count++;
    if (w->stream != SV_STREAM_NONE)
        c->stream_inflight[w->stream] = 1;
    int rc = uv_write(&w->req, &c->h.stream, bufs, nb, on_written);
    if (rc != 0) {
        c->wq_bytes -= w->head_len + w->att_len;
        c->wq_count--;
        if (w->stream != SV_STREAM_NONE)
            c->stream_inflight[w->stream] = 0;
        sv_net_wreq_free(w);
        sv_conn_close(c);
        sv_conn_unref(c);
    }
}

int sv_send(sv_conn *c, uint16_t type, uint32_t request_id, json_t *body, uint8_t *att_owned, size_t att_len,
            int stream)
{
    if (!c || c->closing || (c->close_after_write && type != LPVP_BYE_REPLY && type != LPVP_ERROR)) {
        json_decref(body);
        free(att_owned);
        return -1;
    }
    sv_wreq *w = calloc(1, sizeof *w);
    char *json = body ? json_dumps(body, JSON_COMPACT) : NULL;
    json_decref(body);
    if (!w || (body && !json)) {
        free(w);
        free(json);
        free(att_owned);
        sv_conn_close(c);
        return -1;
    }
    w->head = lpvp_frame_build_head(type, request_id, json ? json : "{}", json ? strlen(json) : 2, att_len,
                                    &w->head_len);
    free(json);
    w->att = att_owned;
    w->att_len = att_len;
    w->stream = stream;
    if (!w->head) {
        sv_net_wreq_free(w);
        sv_conn_close(c);
        return -1;
    }
    const size_t bytes = w->head_len + w->att_len;
    if (type != LPVP_ERROR && type != LPVP_BYE_REPLY && !sv_memory_fits(&c->srv->mem, SV_MEM_REPLIES, bytes)) {
        /* R7.6a: over the daemon's budget. A stream message is dropped, as
         * one a newer replaces would be; a reply becomes an ERROR */
        sv_net_wreq_free(w);
        if (stream != SV_STREAM_NONE) {
            c->stream_dropped++;
            return 0;
        }
        char budget[SV_MEMORY_DESCRIBE_SIZE];
        sv_memory_describe(&c->srv->mem, budget, sizeof budget);
        return sv_send_error(c, request_id, LPVP_E_LIMIT, "the %s reply is %zu bytes; %s: not sent",
                             lpvp_type_name((uint16_t)(type & ~LPVP_REPLY_BIT)), bytes, budget);
    }
    w->mem = &c->srv->mem;
    w->counted = bytes;
    sv_memory_add(w->mem, SV_MEM_REPLIES, bytes);
    if (stream != SV_STREAM_NONE) {
        if (c->stream_inflight[stream]) { /* R5.5: newest replaces the unsent one */
            if (c->stream_pending[stream])
                c->stream_dropped++;
            sv_net_wreq_free(c->stream_pending[stream]);
            c->stream_pending[stream] = w;
            return 0;
        }
        write_start(c, w);
        return c->closing ? -1 : 0;
    }
    size_t len = w->head_len + w->att_len;
    uint64_t cap = c->hello ? c->srv->cfg.max_queue : SV_PREAUTH_MAX_QUEUE;
    if (len > cap && type != LPVP_ERROR && type != LPVP_BYE_REPLY) {
        /* R3.5 for every reply, the small ones too (a STATS under a tiny
         * --max-queue): never sent, an ERROR instead, the connection stays */
        sv_net_wreq_free(w);
        return sv_send_error(c, request_id, LPVP_E_LIMIT,
                             "the %s reply is %zu bytes, over this server's per-client queue limit of %llu bytes "
                             "(--max-queue): not sent", lpvp_type_name((uint16_t)(type & ~LPVP_REPLY_BIT)), len,
                             (unsigned long long)cap);
    }
    if (c->wq_bytes > 0 && c->wq_bytes + len > cap) {
        fprintf(stderr, "lpvd serve: client %llu (%s) is not reading: %zu bytes queued, over the %llu-byte cap%s; "
                        "disconnecting it\n",
                (unsigned long long)c->id, c->peer, c->wq_bytes, (unsigned long long)cap,
                c->hello ? "" : " before HELLO");
        sv_net_wreq_free(w);
        sv_conn_close(c);
        return -1;
    }
    write_start(c, w);
    return c->closing ? -1 : 0;
}

int sv_send_error(sv_conn *c, uint32_t request_id, int code, const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    json_t *b = lpvp_error_body(code, "%s", msg);
    int rc = sv_send(c, LPVP_ERROR, request_id, b, NULL, 0, SV_STREAM_NONE);
    if (lpvp_error_closes(code))
        sv_conn_close_after_write(c);
    return rc;
}
