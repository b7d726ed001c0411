#define _GNU_SOURCE /* struct ucred */
/*
 * serve_net.c - the network side of `lpvd serve`, all on the libuv loop:
 * listeners (Unix socket, TCP), connections, frame reading through the
 * protocol's incremental parser (protocol/proto.h), and bounded writes.
 *
 * Back-pressure: reading stops while a connection has too many requests
 * waiting (SV_MAX_PENDING) and resumes when they drain; replies count
 * against the connection's write cap (--max-queue, default 64 MiB plus one
 * message) and a client over it is disconnected; stream messages (VOLUME,
 * FRAME) keep at most one frame in flight and one unsent per stream, a newer
 * one replacing the unsent older one (SPEC R5.5).
 *
 * Memory (SPEC R7.5): every connection's requests together hold at most
 * --max-request-memory bytes. A frame's payload is reserved once its header
 * is in; a connection whose frame does not fit stops being read (it holds
 * the header and at most one read buffer) until handled requests free
 * enough. A reserved frame is always read to its end, so reservations never
 * wait on each other: memory is freed by requests being handled, or by
 * connections closing (a trickling one at --idle-timeout).
 *
 * Before HELLO (SPEC R2.5a, R4.1a) a connection is held to the pre-auth
 * limits: frames of at most --max-preauth-body bytes of JSON and no
 * attachment (refused from the header, before the body is read), each frame
 * dispatched before the next header is looked at (so the limits change the
 * moment HELLO succeeds, even for frames pipelined behind it), replies capped
 * at SV_PREAUTH_MAX_QUEUE, and at most --max-preauth such connections; only a
 * HELLO that passes the token check takes one of the --max-clients slots.
 */
#include "serve.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#define SV_MAX_PENDING 64
#define SV_MAX_PENDING_BYTES (512u << 20)

typedef struct sv_wreq {
    uv_write_t req;
    sv_conn *c;
    uint8_t *head;
    size_t head_len;
    uint8_t *att;
    size_t att_len;
    int stream;
    sv_memory *mem;   /* the daemon's budget, once the frame counts in its replies' term */
    uint64_t counted;
} sv_wreq;

static void wreq_free(sv_wreq *w)
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
        wreq_free(c->stream_pending[i]);
    lpvp_parser_free(&c->parser);
    free(c);
}

/* Requests of c handled or dropped: their bytes leave the budget, and
 * connections waiting for memory are reserved for and resumed in order. */
static void release_request_bytes(sv_conn *c, uint64_t bytes);

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
    release_request_bytes(c, held);
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

static void preauth_join(sv_conn *c)
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
    wreq_free(w);
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
        wreq_free(w);
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
        wreq_free(w);
        sv_conn_close(c);
        return -1;
    }
    const size_t bytes = w->head_len + w->att_len;
    if (type != LPVP_ERROR && type != LPVP_BYE_REPLY && !sv_memory_fits(&c->srv->mem, SV_MEM_REPLIES, bytes)) {
        /* R7.6a: over the daemon's budget. A stream message is dropped, as
         * one a newer replaces would be; a reply becomes an ERROR */
        wreq_free(w);
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
            wreq_free(c->stream_pending[stream]);
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
        wreq_free(w);
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
        wreq_free(w);
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

/* ---- reading ------------------------------------------------------------ */
/* The frame limits of a connection: the configured ones once it has said
 * HELLO, the pre-auth ones before (R2.5a). */
static lpvp_limits conn_limits(const sv_server *s, int authenticated)
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

static void on_alloc(uv_handle_t *h, size_t suggested, uv_buf_t *buf)
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

/* Reserves the payload of the frame whose header has just been accepted
 * (R7.5). Returns 0 when c may read on, 1 when it must wait for memory. */
static int reserve_frame(sv_conn *c)
{
    sv_server *s = c->srv;
    uint64_t need = lpvp_parser_frame_payload(&c->parser);
    if (need == 0 || (c->reserved && !c->reserve_shrunk))
        return 0;
    const uint64_t more = need > c->reserved ? need - c->reserved : 0; /* a shrunk one holds what arrived */
    /* within --max-request-memory and the daemon's budget, whose other terms
     * always leave one --max-message free (serve_memory.h): so a frame waits
     * only for requests before it to be handled */
    if (sv_memory_held(&s->mem, SV_MEM_REQUESTS) + more > s->cfg.max_request_memory ||
        !sv_memory_fits(&s->mem, SV_MEM_REQUESTS, more))
        return 1;
    if (!c->reserved)
        c->payload_ms = sv_now_ms();
    c->reserved = need;
    c->reserve_shrunk = 0;
    sv_memory_add(&s->mem, SV_MEM_REQUESTS, more);
    return 0;
}

static void release_request_bytes(sv_conn *c, uint64_t bytes);

void sv_net_shrink_stalled(sv_conn *c, uint64_t now_ms)
{
    if (!c->reserved || c->reserve_shrunk || c->wait_memory || now_ms - c->payload_ms < SV_RESERVE_STALL_MS)
        return;
    const uint64_t have = lpvp_parser_payload_have(&c->parser);
    if (have >= c->reserved)
        return;
    const uint64_t freed = c->reserved - have;
    c->reserved = have;
    c->reserve_shrunk = 1;
    release_request_bytes(c, freed); /* the frames waiting get it, first come first served */
}

static void release_request_bytes(sv_conn *c, uint64_t bytes)
{
    sv_server *s = c->srv;
    if (bytes == 0) /* nothing freed, nobody newly fits (every close comes here: keep it cheap under a flood) */
        return;
    const uint64_t held = sv_memory_held(&s->mem, SV_MEM_REQUESTS);
    sv_memory_sub(&s->mem, SV_MEM_REQUESTS, bytes < held ? bytes : held);
    /* first come, first served: a big frame waiting is not overtaken by smaller ones behind it */
    for (;;) {
        sv_conn *first = NULL;
        for (sv_conn *w = s->conns; w; w = w->next)
            if (w->wait_memory && !w->closing && !w->close_after_write &&
                (!first || w->wait_memory < first->wait_memory))
                first = w;
        if (!first || reserve_frame(first) != 0)
            return;
        first->wait_memory = 0;
        sv_net_resume_reading(first);
    }
}

void sv_net_request_handled(sv_conn *c, uint64_t bytes)
{
    c->pending_bytes -= bytes;
    release_request_bytes(c, bytes);
}

static void on_read(uv_stream_t *st, ssize_t nread, const uv_buf_t *buf)
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
        if (stt == LPVP_PARSE_NEED_MORE && reserve_frame(c) != 0)
            c->wait_memory = ++c->srv->memory_waits; /* all of this read is in the parser: stop reading below */
        if (stt == LPVP_PARSE_FRAME) {
            c->last_rx_ms = sv_now_ms(); /* R4.9: idle counts from the last complete frame */
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
                sv_session_pump(c);
                if (c->hello && !c->closing)
                    c->parser.limits = conn_limits(c->srv, 1);
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
        sv_session_pump(c);
    }
    sv_conn_unref(c);
}

void sv_net_resume_reading(sv_conn *c)
{
    if (c->closing || c->close_after_write || c->reading || c->srv->stopping || c->wait_memory)
        return;
    if (c->pending_count < SV_MAX_PENDING / 2 && c->pending_bytes < SV_MAX_PENDING_BYTES / 2) {
        if (uv_read_start(&c->h.stream, on_alloc, on_read) == 0)
            c->reading = 1;
    }
}

/* ---- accepting ---------------------------------------------------------- */
/* Open connections (not closing) that have said HELLO (authenticated = 1:
 * they count against --max-clients) or not yet (0: against --max-preauth).
 * Before refusing a newcomer, connections whose peer has already gone (EOF
 * or reset waiting, not yet seen by the loop) are closed, so a slot freed by
 * a client that just disconnected is reusable at once. */
static int active_clients(sv_server *s, const sv_conn *except, int authenticated)
{
    if (!authenticated) /* the pre-HELLO list holds exactly those */
        return s->preauth_count - (except && except->in_preauth);
    int n = 0;
    for (sv_conn *c = s->conns; c; c = c->next)
        if (c != except && !c->closing && !c->close_after_write && !c->hello == !authenticated)
            n++;
    return n;
}

static void reap_gone(sv_server *s, const sv_conn *except, int authenticated)
{
    for (sv_conn *c = authenticated ? s->conns : s->preauth, *next; c; c = next) {
        next = authenticated ? c->next : c->pre_next; /* sv_conn_close takes c out of the pre-HELLO list */
        if (c == except || c->closing || !c->hello != !authenticated) /* only the quota in question's */
            continue;
        uv_os_fd_t fd;
        if (uv_fileno((uv_handle_t *)&c->h.stream, &fd) != 0)
            continue;
        char b;
        ssize_t r = recv(fd, &b, 1, MSG_PEEK | MSG_DONTWAIT);
        if (r == 0 || (r < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR))
            sv_conn_close(c);
    }
}

/* c->peer_key: the peer process on a Unix socket (SO_PEERCRED), its address
 * on TCP. */
static void peer_key_of(sv_conn *c, int is_tcp)
{
    uv_os_fd_t fd;
    if (!is_tcp && uv_fileno((uv_handle_t *)&c->h.stream, &fd) == 0) {
        struct ucred cred;
        socklen_t len = sizeof cred;
        if (getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &cred, &len) == 0) {
            snprintf(c->peer_key, sizeof c->peer_key, "pid %ld", (long)cred.pid);
            return;
        }
    }
    snprintf(c->peer_key, sizeof c->peer_key, "%s", c->peer);
}

static int has_bytes_waiting(sv_conn *c)
{
    uv_os_fd_t fd;
    char b;
    return uv_fileno((uv_handle_t *)&c->h.stream, &fd) == 0 && recv(fd, &b, 1, MSG_PEEK | MSG_DONTWAIT) == 1;
}

static int by_peer_then_age(const void *a, const void *b)
{
    const sv_conn *x = *(sv_conn *const *)a, *y = *(sv_conn *const *)b;
    const int k = strcmp(x->peer_key, y->peer_key);
    return k ? k : (x->id > y->id) - (x->id < y->id);
}

/* The connection waiting for HELLO that goes (on_connection), or NULL:
 * sorted by peer, so a flood of thousands costs n log n, not n^2. */
static sv_conn *preauth_victim(sv_server *s, const sv_conn *newcomer, int hard)
{
    const size_t n = (size_t)s->preauth_count;
    sv_conn **all = n ? malloc(n * sizeof *all) : NULL;
    if (!all)
        return NULL;
    size_t k = 0;
    for (sv_conn *o = s->preauth; o && k < n; o = o->pre_next)
        if (o != newcomer)
            all[k++] = o;
    qsort(all, k, sizeof *all, by_peer_then_age);
    const uint64_t now = sv_now_ms();
    sv_conn *victim = NULL;
    size_t victim_count = 0;
    for (size_t i = 0; i < k;) {
        size_t j = i;
        while (j < k && strcmp(all[j]->peer_key, all[i]->peer_key) == 0)
            j++;
        /* this peer holds j - i; its oldest that may go */
        for (size_t q = i; q < j; ++q) {
            sv_conn *o = all[q];
            if (!hard && (now - o->accepted_ms < SV_PREAUTH_GRACE_MS || has_bytes_waiting(o)))
                continue;
            if (!victim || j - i > victim_count || (j - i == victim_count && o->id < victim->id)) {
                victim = o;
                victim_count = j - i;
            }
            break;
        }
        i = j;
    }
    free(all);
    return victim;
}

static void on_connection(uv_stream_t *server, int status)
{
    sv_server *s = server->data;
    if (status < 0 || s->stopping)
        return;
    sv_conn *c = calloc(1, sizeof *c);
    if (!c)
        return;
    c->refs = 1;
    c->srv = s;
    c->id = ++s->next_conn_id;
    int is_tcp = server == (uv_stream_t *)&s->tcp_listener;
    int rc = is_tcp ? uv_tcp_init(s->loop, &c->h.tcp) : uv_pipe_init(s->loop, &c->h.pipe, 0);
    if (rc != 0) {
        free(c);
        return;
    }
    c->h.stream.data = c;
    c->next = s->conns;
    c->prev = NULL;
    if (s->conns)
        s->conns->prev = c;
    s->conns = c;
    s->conn_count++;
    lpvp_limits lim = conn_limits(s, 0);
    lpvp_parser_init(&c->parser, &lim);
    if (uv_accept(server, &c->h.stream) != 0) {
        sv_conn_close(c);
        return;
    }
    if (is_tcp) {
        struct sockaddr_storage ss;
        int sl = sizeof ss;
        char host[64] = "?";
        if (uv_tcp_getpeername(&c->h.tcp, (struct sockaddr *)&ss, &sl) == 0) {
            if (ss.ss_family == AF_INET6)
                uv_ip6_name((struct sockaddr_in6 *)&ss, host, sizeof host);
            else
                uv_ip4_name((struct sockaddr_in *)&ss, host, sizeof host);
        }
        snprintf(c->peer, sizeof c->peer, "tcp %s", host);
        uv_tcp_nodelay(&c->h.tcp, 1);
    } else {
        snprintf(c->peer, sizeof c->peer, "unix");
    }
    c->last_rx_ms = c->accepted_ms = sv_now_ms();
    sv_session_init(c);
    preauth_join(c);
    peer_key_of(c, is_tcp);
    /* R4.1a: connections that have not said HELLO have their own small
     * quota and never take a --max-clients slot. When it is full, one of them
     * goes, not the newcomer: refusing newcomers would let anyone who keeps
     * --max-preauth connections open shut every client out. Which one
     * (issue 31, item 4: 50 clients connecting at once lost 14-16, and a
     * flood of connections from one process evicted others' HELLOs): the
     * oldest of the peer that holds the most, among those that have had
     * SV_PREAUTH_GRACE_MS and have nothing waiting to be read (a HELLO in
     * flight); none such, the newcomer is let in up to
     * SV_PREAUTH_HARD_FACTOR x the quota, then the grace goes too. */
    if (active_clients(s, c, 0) >= s->cfg.max_preauth)
        reap_gone(s, c, 0);
    const int waiting = active_clients(s, c, 0);
    if (waiting >= s->cfg.max_preauth) {
        const int hard = waiting >= SV_PREAUTH_HARD_FACTOR * s->cfg.max_preauth;
        sv_conn *victim = preauth_victim(s, c, hard);
        if (victim) {
            sv_send_error(victim, 0, LPVP_E_LIMIT,
                          "closed to let a newer connection in: at most %d connections may wait for HELLO "
                          "(--max-preauth), and this was the oldest of the peer holding the most", s->cfg.max_preauth);
            sv_conn_close_after_write(victim);
        }
    }
    if (uv_read_start(&c->h.stream, on_alloc, on_read) == 0)
        c->reading = 1;
    else
        sv_conn_close(c);
}

int sv_net_admit_session(sv_conn *c, uint32_t request_id)
{
    sv_server *s = c->srv;
    if (active_clients(s, c, 1) >= s->cfg.max_clients)
        reap_gone(s, c, 1);
    if (active_clients(s, c, 1) < s->cfg.max_clients)
        return 0;
    sv_send_error(c, request_id, LPVP_E_LIMIT, "too many clients: the server accepts at most %d (--max-clients)",
                  s->cfg.max_clients);
    sv_conn_close_after_write(c);
    return -1;
}

/* ---- listeners ---------------------------------------------------------- */
static int unix_socket_in_use(const char *path)
{
    int fd = socket(AF_UNIX, SOCK_STREAM, 0);
    if (fd < 0)
        return 0;
    struct sockaddr_un sa;
    memset(&sa, 0, sizeof sa);
    sa.sun_family = AF_UNIX;
    snprintf(sa.sun_path, sizeof sa.sun_path, "%s", path);
    int used = connect(fd, (struct sockaddr *)&sa, sizeof sa) == 0;
    close(fd);
    return used;
}

static int is_loopback(const struct sockaddr *sa)
{
    if (sa->sa_family == AF_INET) {
        const uint8_t *b = (const uint8_t *)&((const struct sockaddr_in *)sa)->sin_addr;
        return b[0] == 127;
    }
    if (sa->sa_family == AF_INET6) {
        static const uint8_t lo[16] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1};
        return memcmp(&((const struct sockaddr_in6 *)sa)->sin6_addr, lo, 16) == 0;
    }
    return 0;
}

int sv_net_listen(sv_server *s, char *err, size_t n)
{
    sv_config *cfg = &s->cfg;
    if (cfg->want_unix) {
        struct stat st;
        if (strlen(cfg->socket_path) >= sizeof(((struct sockaddr_un *)0)->sun_path)) {
            snprintf(err, n, "--socket %s: path too long for a Unix socket", cfg->socket_path);
            return -1;
        }
        if (lstat(cfg->socket_path, &st) == 0) {
            if (!S_ISSOCK(st.st_mode)) {
                snprintf(err, n, "--socket %s: exists and is not a socket; refusing to replace it", cfg->socket_path);
                return -1;
            }
            if (unix_socket_in_use(cfg->socket_path)) {
                snprintf(err, n, "--socket %s: another server is listening there", cfg->socket_path);
                return -1;
            }
            unlink(cfg->socket_path); /* stale */
        }
        if (uv_pipe_init(s->loop, &s->unix_listener, 0) != 0) {
            snprintf(err, n, "uv_pipe_init failed");
            return -1;
        }
        s->unix_listener.data = s;
        s->unix_on = 1;
        mode_t old = umask(0077); /* created 0600 (R1.1), no window */
        int rc = uv_pipe_bind(&s->unix_listener, cfg->socket_path);
        umask(old);
        if (rc == 0)
            chmod(cfg->socket_path, 0600);
        if (rc == 0)
            rc = uv_listen((uv_stream_t *)&s->unix_listener, SV_LISTEN_BACKLOG, on_connection);
        if (rc != 0) {
            snprintf(err, n, "--socket %s: %s", cfg->socket_path, uv_strerror(rc));
            return -1;
        }
    }
    if (cfg->listen_host[0]) {
        struct sockaddr_storage ss;
        memset(&ss, 0, sizeof ss);
        const char *host = cfg->listen_host;
        if (strcmp(host, "localhost") == 0)
            host = "127.0.0.1";
        if (uv_ip4_addr(host, cfg->listen_port, (struct sockaddr_in *)&ss) != 0 &&
            uv_ip6_addr(host, cfg->listen_port, (struct sockaddr_in6 *)&ss) != 0) {
            snprintf(err, n, "--listen %s:%d: not a numeric IPv4/IPv6 address", cfg->listen_host, cfg->listen_port);
            return -1;
        }
        if (!is_loopback((struct sockaddr *)&ss) && !cfg->has_token) {
            snprintf(err, n,
                     "--listen %s:%d is not a loopback address: a token is required (--token-file FILE), "
                     "refusing to start",
                     cfg->listen_host, cfg->listen_port);
            return -1;
        }
        if (uv_tcp_init(s->loop, &s->tcp_listener) != 0) {
            snprintf(err, n, "uv_tcp_init failed");
            return -1;
        }
        s->tcp_listener.data = s;
        s->tcp_on = 1;
        int rc = uv_tcp_bind(&s->tcp_listener, (struct sockaddr *)&ss, 0);
        if (rc == 0)
            rc = uv_listen((uv_stream_t *)&s->tcp_listener, SV_LISTEN_BACKLOG, on_connection);
        if (rc != 0) {
            snprintf(err, n, "--listen %s:%d: %s", cfg->listen_host, cfg->listen_port, uv_strerror(rc));
            return -1;
        }
        if (cfg->listen_port == 0) { /* report the port the OS chose */
            struct sockaddr_storage b;
            int bl = sizeof b;
            if (uv_tcp_getsockname(&s->tcp_listener, (struct sockaddr *)&b, &bl) == 0)
                cfg->listen_port = ntohs(b.ss_family == AF_INET6 ? ((struct sockaddr_in6 *)&b)->sin6_port
                                                                 : ((struct sockaddr_in *)&b)->sin_port);
        }
    }
    return 0;
}

void sv_net_stop_listening(sv_server *s)
{
    if (s->unix_on) {
        uv_close((uv_handle_t *)&s->unix_listener, NULL);
        s->unix_on = 0;
        unlink(s->cfg.socket_path);
    }
    if (s->tcp_on) {
        uv_close((uv_handle_t *)&s->tcp_listener, NULL);
        s->tcp_on = 0;
    }
}
