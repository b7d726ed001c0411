/*
 * serve_net_conn.c - closing connections: at once (sv_conn_close), or once
 * what is queued has been written (sv_conn_close_after_write, for an ERROR
 * that closes, R3.4), and what a closed connection gives back: its pending
 * requests' memory, its session, its place in the server's list. Also its
 * last reference (sv_conn_unref, which frees its unsent stream frames) and
 * the pre-HELLO list it leaves on HELLO or close: both are used by every
 * file of the network layer, so they are here at its bottom. The network
 * layer's design is in serve_net_internal.h.
 */
#include "serve.h"
#include "serve_net_internal.h"

#include <stdlib.h>

/* ---- references ------------------------------------------------------------ */
void sv_net_wreq_free(sv_wreq *w)
{
    if (!w)
        return;
    if (w->mem)
        sv_memory_sub(w->mem, SV_MEM_REPLIES, w->counted);
    free(w->head);
    free(w->att);
    free(w);
}

void sv_conn_unref(sv_conn *c)
{
    if (!c || --c->refs > 0)
        return;
    for (int i = 0; i < 2; ++i)
        sv_net_wreq_free(c->stream_pending[i]);
    lpvp_parser_free(&c->parser);
    free(c);
}

/* ---- the pre-HELLO list ------------------------------------------------- */
void sv_net_preauth_leave(sv_conn *c)
{
    if (!c->in_preauth)
        return;
    sv_server *s = c->srv;
    if (c->pre_prev)
        c->pre_prev->pre_next = c->pre_next;
    else
        s->preauth = c->pre_next;
    if (c->pre_next)
        c->pre_next->pre_prev = c->pre_prev;
    c->pre_prev = c->pre_next = NULL;
    c->in_preauth = 0;
    s->preauth_count--;
}

void sv_net_preauth_join(sv_conn *c)
{
    sv_server *s = c->srv;
    c->pre_prev = NULL;
    c->pre_next = s->preauth;
    if (s->preauth)
        s->preauth->pre_prev = c;
    s->preauth = c;
    c->in_preauth = 1;
    s->preauth_count++;
}

/* ---- closing ------------------------------------------------------------ */
static void free_pending_requests(sv_conn *c)
{
    sv_request *r = c->pending_head;
    while (r) {
        sv_request *n = r->next;
        free(r->json);
        free(r->att);
        free(r);
        r = n;
    }
    c->pending_head = c->pending_tail = NULL;
    c->pending_count = 0;
    uint64_t held = c->pending_bytes + c->reserved;
    c->pending_bytes = 0;
    c->reserved = 0;
    c->wait_memory = 0;
    sv_net_release_request_bytes(c, held);
}

static void on_closed(uv_handle_t *h)
{
    sv_conn *c = h->data;
    sv_server *s = c->srv;
    c->closed = 1;
    if (c->prev) /* doubly linked: a flood's thousands of closes cost O(1) each */
        c->prev->next = c->next;
    else
        s->conns = c->next;
    if (c->next)
        c->next->prev = c->prev;
    s->conn_count--;
    free_pending_requests(c);
    s->session.free(c);
    sv_conn_unref(c);
}

void sv_conn_close(sv_conn *c)
{
    if (!c || c->closing)
        return;
    sv_net_preauth_leave(c);
    c->closing = 1;
    if (c->reading) {
        uv_read_stop(&c->h.stream);
        c->reading = 0;
    }
    free_pending_requests(c);
    uv_close((uv_handle_t *)&c->h.stream, on_closed);
}

void sv_conn_close_after_write(sv_conn *c)
{
    if (!c || c->closing)
        return;
    if (c->reading) {
        uv_read_stop(&c->h.stream);
        c->reading = 0;
    }
    free_pending_requests(c);
    sv_net_preauth_leave(c);
    c->close_after_write = 1;
    c->close_deadline_ms = sv_now_ms() + 5000;
    if (c->wq_count == 0)
        sv_conn_close(c);
}
