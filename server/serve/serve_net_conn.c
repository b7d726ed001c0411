/*
 * serve_net_conn.c - closing connections: at once (sv_conn_close), or once
 * what is queued has been written (sv_conn_close_after_write, for an ERROR
 * that closes, R3.4), and what a closed connection gives back: its pending
 * requests' memory, its session, its place in the server's list. The network
 * layer's design is in serve_net_internal.h.
 */
#include "serve.h"
#include "serve_net_internal.h"

#include <stdlib.h>

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
    sv_session_free(c);
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
