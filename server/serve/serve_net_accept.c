#define _GNU_SOURCE /* struct ucred */
/*
 * serve_net_accept.c - accepting connections and the quotas on them: the
 * pre-HELLO list and --max-preauth (R4.1a; when it is full the oldest
 * connection of the peer holding the most goes, not the newcomer), and
 * --max-clients for the connections whose HELLO succeeded. The network
 * layer's design is in serve_net_internal.h; the pre-HELLO list itself is
 * serve_net_conn.c's (a closing connection leaves it).
 */
#include "serve.h"
#include "serve_net_internal.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>

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

/* The connection waiting for HELLO that goes (sv_net_on_connection), or NULL:
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

void sv_net_on_connection(uv_stream_t *server, int status)
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
    lpvp_limits lim = sv_net_conn_limits(s, 0);
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
    c->idle_since_ms = c->accepted_ms = sv_now_ms();
    s->session.open(c);
    sv_net_preauth_join(c);
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
    if (uv_read_start(&c->h.stream, sv_net_on_alloc, sv_net_on_read) == 0)
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
