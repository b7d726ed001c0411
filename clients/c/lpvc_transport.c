/*
 * lpvc_transport.c - the C client's transport (see lpvc_internal.h):
 * sockets, framing (protocol/proto.h builds and checks the frames), sending
 * and receiving, request/reply matching, the stream queue, connect / close
 * and the error state every call reports through. Decoding what a stream
 * brings is above it, in lpvc_stream.c.
 */
#include <errno.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <sys/un.h>
#include <unistd.h>

#include "lpvc_internal.h"

/* ---- errors ---------------------------------------------------------------- */

static const char *client_err_name(int code)
{
    switch (code) {
    case LPVC_ERR_IO: return "IO";
    case LPVC_ERR_PROTOCOL: return "PROTOCOL";
    case LPVC_ERR_USAGE: return "USAGE";
    case LPVC_ERR_TIMEOUT: return "TIMEOUT";
    case LPVC_ERR_CLOSED: return "CLOSED";
    default: return "ERROR";
    }
}

#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
int lpvci_fail(lpvc *c, int code, const char *fmt, ...)
{
    c->err_code = code;
    snprintf(c->err_name, sizeof c->err_name, "%s", code > 0 ? lpvp_error_name(code) : client_err_name(code));
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->err_msg, sizeof c->err_msg, fmt, ap);
    va_end(ap);
    return -1;
}

void lpvci_clear_error(lpvc *c)
{
    c->err_code = 0;
    c->err_name[0] = '\0';
    c->err_msg[0] = '\0';
}

int lpvc_error_code(const lpvc *c) { return c ? c->err_code : LPVC_ERR_USAGE; }
const char *lpvc_error_name(const lpvc *c) { return c ? c->err_name : "USAGE"; }
const char *lpvc_error_message(const lpvc *c) { return c ? c->err_msg : "no connection"; }
const char *lpvc_last_reply(const lpvc *c) { return c && c->last_reply ? c->last_reply : "{}"; }
int64_t lpvc_last_revision(const lpvc *c) { return c ? c->last_revision : -1; }
const char *lpvc_hello_reply(const lpvc *c) { return c && c->hello ? c->hello : "{}"; }
void lpvc_set_auto_ack(lpvc *c, bool on) { if (c) c->auto_ack = on; }

void lpvci_close_fd(lpvc *c)
{
    if (c->fd >= 0) {
        close(c->fd);
        c->fd = -1;
    }
}

/* ---- sockets --------------------------------------------------------------- */

const char *lpvc_default_address(char *buf, size_t n)
{
    lpvp_default_socket_path(buf, n);
    return buf;
}

static int open_socket(const char *address, char *err, size_t n)
{
    char defbuf[512];
    if (!address || !*address)
        address = lpvc_default_address(defbuf, sizeof defbuf);
    int is_unix;
    const char *rest = address;
    if (strncmp(address, "unix:", 5) == 0) {
        is_unix = 1;
        rest = address + 5;
    } else if (strncmp(address, "tcp:", 4) == 0) {
        is_unix = 0;
        rest = address + 4;
    } else {
        is_unix = strchr(address, '/') != NULL || strchr(address, ':') == NULL;
    }

    if (is_unix) {
        struct sockaddr_un sa;
        memset(&sa, 0, sizeof sa);
        sa.sun_family = AF_UNIX;
        if (strlen(rest) >= sizeof sa.sun_path) {
            snprintf(err, n, "socket path too long: %s", rest);
            return -1;
        }
        memcpy(sa.sun_path, rest, strlen(rest) + 1);
        int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
        if (fd < 0) {
            snprintf(err, n, "socket: %s", strerror(errno));
            return -1;
        }
        if (connect(fd, (struct sockaddr *)&sa, sizeof sa) != 0) {
            snprintf(err, n, "cannot connect to %s: %s", rest, strerror(errno));
            close(fd);
            return -1;
        }
        return fd;
    }

    char host[256], port_str[8];
    unsigned port;
    if (lpvp_split_host_port(rest, host, sizeof host, &port, err, n) != 0)
        return -1;
    snprintf(port_str, sizeof port_str, "%u", port);
    struct addrinfo hints, *res = NULL;
    memset(&hints, 0, sizeof hints);
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    int rc = getaddrinfo(host, port_str, &hints, &res);
    if (rc != 0) {
        snprintf(err, n, "cannot resolve '%s': %s", address, gai_strerror(rc));
        return -1;
    }
    int fd = -1;
    int last_errno = 0;
    for (struct addrinfo *ai = res; ai; ai = ai->ai_next) {
        fd = socket(ai->ai_family, ai->ai_socktype | SOCK_CLOEXEC, ai->ai_protocol);
        if (fd < 0) {
            last_errno = errno;
            continue;
        }
        if (connect(fd, ai->ai_addr, ai->ai_addrlen) == 0)
            break;
        last_errno = errno;
        close(fd);
        fd = -1;
    }
    freeaddrinfo(res);
    if (fd < 0) {
        snprintf(err, n, "cannot connect to %s: %s", address, strerror(last_errno));
        return -1;
    }
    int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    return fd;
}

static int send_all(lpvc *c, const void *data, size_t len)
{
    const uint8_t *p = data;
    while (len > 0) {
        ssize_t k = send(c->fd, p, len, MSG_NOSIGNAL);
        if (k < 0) {
            if (errno == EINTR)
                continue;
            int e = errno;
            lpvci_close_fd(c);
            return lpvci_fail(c, LPVC_ERR_IO, "send: %s", strerror(e));
        }
        p += k;
        len -= (size_t)k;
    }
    return 0;
}

static int recv_all(lpvc *c, void *data, size_t len)
{
    uint8_t *p = data;
    size_t total = len;
    while (len > 0) {
        ssize_t k = recv(c->fd, p, len, 0);
        if (k == 0) {
            lpvci_close_fd(c);
            return lpvci_fail(c, LPVC_ERR_IO, "connection closed by the server (%zu of %zu bytes read)", total - len, total);
        }
        if (k < 0) {
            if (errno == EINTR)
                continue;
            int e = errno;
            if (e == EAGAIN || e == EWOULDBLOCK) {
                lpvci_close_fd(c); /* mid-frame: the stream position is lost */
                return lpvci_fail(c, LPVC_ERR_TIMEOUT, "no reply within %d ms", c->timeout_ms);
            }
            lpvci_close_fd(c);
            return lpvci_fail(c, LPVC_ERR_IO, "recv: %s", strerror(e));
        }
        p += k;
        len -= (size_t)k;
    }
    return 0;
}

/* ---- frames ---------------------------------------------------------------- */

/* Sends one frame built by proto.h: header + JSON, then the attachment from
 * the caller's buffer (no copy). Returns the request_id, or 0 on failure. */
uint32_t lpvci_send_frame(lpvc *c, uint16_t type, const json_t *body, const void *att, size_t att_len)
{
    if (c->fd < 0) {
        lpvci_fail(c, LPVC_ERR_CLOSED, "the connection is closed");
        return 0;
    }
    char *js = json_dumps(body, JSON_COMPACT);
    if (!js) {
        lpvci_fail(c, LPVC_ERR_USAGE, "cannot serialise the request body");
        return 0;
    }
    uint32_t id = c->next_id++;
    if (c->next_id == 0)
        c->next_id = 1;
    size_t head_len = 0;
    uint8_t *head = lpvp_frame_build_head(type, id, js, strlen(js), att_len, &head_len);
    free(js);
    if (!head) {
        lpvci_fail(c, LPVC_ERR_USAGE, "frame too large (attachment %zu bytes)", att_len);
        return 0;
    }
    int rc = send_all(c, head, head_len);
    free(head);
    if (rc == 0 && att_len)
        rc = send_all(c, att, att_len);
    return rc == 0 ? id : 0;
}

void lpvci_rx_free(lpvci_rx *r)
{
    json_decref(r->body);
    free(r->att);
    memset(r, 0, sizeof *r);
}

/* Receives one frame. timeout_ms: -1 the connection's reply timeout, < -1
 * forever, >= 0 that many ms before the first byte. */
int lpvci_recv_frame(lpvc *c, lpvci_rx *out, int timeout_ms)
{
    memset(out, 0, sizeof *out);
    if (c->fd < 0)
        return lpvci_fail(c, LPVC_ERR_CLOSED, "the connection is closed");
    int wait = timeout_ms >= 0 ? timeout_ms : (timeout_ms == -1 && c->timeout_ms > 0 ? c->timeout_ms : -1);
    if (wait >= 0) {
        struct pollfd pfd = {.fd = c->fd, .events = POLLIN};
        int pr;
        do
            pr = poll(&pfd, 1, wait);
        while (pr < 0 && errno == EINTR);
        if (pr < 0)
            return lpvci_fail(c, LPVC_ERR_IO, "poll: %s", strerror(errno));
        if (pr == 0)
            return lpvci_fail(c, LPVC_ERR_TIMEOUT, "nothing received within %d ms", wait);
    }
    uint8_t hb[LPVP_HEADER_SIZE];
    if (recv_all(c, hb, sizeof hb) != 0)
        return -1;
    /* Replies are small JSON, but a volume attachment may be large. */
    lpvp_limits lim = {.max_body = 64u << 20, .max_message = (uint64_t)16 << 30};
    char err[256];
    if (lpvp_header_check(hb, &lim, &out->h, err, sizeof err) != 0) {
        lpvci_close_fd(c);
        return lpvci_fail(c, LPVC_ERR_PROTOCOL, "bad frame from the server: %s", err);
    }
    char *js = malloc(out->h.json_length + 1u);
    if (!js)
        return lpvci_fail(c, LPVC_ERR_IO, "out of memory (%u-byte body)", out->h.json_length);
    if (recv_all(c, js, out->h.json_length) != 0) {
        free(js);
        return -1;
    }
    out->att_len = out->h.attachment_length;
    if (out->att_len) {
        out->att = malloc(out->att_len);
        if (!out->att) {
            free(js);
            lpvci_close_fd(c);
            return lpvci_fail(c, LPVC_ERR_IO, "out of memory (%zu-byte attachment)", out->att_len);
        }
        if (recv_all(c, out->att, out->att_len) != 0) {
            free(js);
            free(out->att);
            out->att = NULL;
            return -1;
        }
    }
    out->body = lpvp_body_parse(js, out->h.json_length, err, sizeof err);
    free(js);
    if (!out->body) {
        free(out->att);
        out->att = NULL;
        lpvci_close_fd(c);
        return lpvci_fail(c, LPVC_ERR_PROTOCOL, "bad JSON body from the server (type 0x%04x): %s", out->h.type, err);
    }
    return 0;
}

void lpvci_set_last_reply(lpvc *c, const json_t *body)
{
    free(c->last_reply);
    c->last_reply = json_dumps(body, JSON_COMPACT);
    json_t *rev = json_object_get(body, "revision");
    if (json_is_integer(rev))
        c->last_revision = json_integer_value(rev);
}

/* An ERROR frame: record its code, name and message; close if it closes. */
int lpvci_take_error(lpvc *c, const json_t *body, uint16_t request_type)
{
    json_t *code = json_object_get(body, "code");
    json_t *name = json_object_get(body, "name");
    json_t *msg = json_object_get(body, "message");
    int k = json_is_integer(code) ? (int)json_integer_value(code) : LPVC_ERR_PROTOCOL;
    lpvci_set_last_reply(c, body);
    lpvci_fail(c, k, "%s", json_is_string(msg) ? json_string_value(msg) : "");
    if (json_is_string(name))
        snprintf(c->err_name, sizeof c->err_name, "%s", json_string_value(name));
    /* R3.4 "closes"; a HELLO's BAD_VERSION leaves the connection open (R4.1). */
    if (lpvp_error_closes(k) && !(k == LPVP_E_BAD_VERSION && request_type == LPVP_HELLO))
        lpvci_close_fd(c);
    return -1;
}

static void enqueue(lpvc *c, lpvci_rx *r)
{
    lpvc_queued *q = calloc(1, sizeof *q);
    if (!q) {
        lpvci_rx_free(r);
        return;
    }
    q->type = r->h.type;
    q->body = r->body;
    q->att = r->att;
    q->att_len = r->att_len;
    memset(r, 0, sizeof *r);
    if (c->q_tail)
        c->q_tail->next = q;
    else
        c->q_head = q;
    c->q_tail = q;
}

int lpvci_request(lpvc *c, uint16_t type, const json_t *body, const void *att, size_t att_len, json_t **reply,
                  uint8_t **ratt, size_t *ratt_len)
{
    lpvci_clear_error(c);
    if (reply)
        *reply = NULL;
    if (ratt)
        *ratt = NULL;
    if (ratt_len)
        *ratt_len = 0;
    uint32_t id = lpvci_send_frame(c, type, body, att, att_len);
    if (!id)
        return -1;
    for (;;) {
        lpvci_rx r;
        if (lpvci_recv_frame(c, &r, -1) != 0)
            return -1;
        uint16_t t = r.h.type;
        if (t == LPVP_REPLY(type) && r.h.request_id == id) {
            lpvci_set_last_reply(c, r.body);
            if (reply)
                *reply = json_incref(r.body);
            if (ratt) {
                *ratt = r.att;
                r.att = NULL;
            }
            if (ratt_len)
                *ratt_len = r.att_len;
            lpvci_rx_free(&r);
            return 0;
        }
        if (t == LPVP_ERROR && (r.h.request_id == id || r.h.request_id == 0)) {
            lpvci_take_error(c, r.body, type);
            if (r.h.request_id == 0)
                lpvci_close_fd(c); /* unsolicited: SHUTTING_DOWN and the like */
            lpvci_rx_free(&r);
            return -1;
        }
        if (t == LPVP_VOLUME || t == LPVP_FRAME) {
            enqueue(c, &r);
            continue;
        }
        if (t == LPVP_BYE_REPLY && r.h.request_id == 0) {
            lpvci_rx_free(&r);
            lpvci_close_fd(c);
            return lpvci_fail(c, LPVC_ERR_CLOSED, "the server said BYE");
        }
        lpvci_fail(c, LPVC_ERR_PROTOCOL, "unexpected %s (type 0x%04x, request_id %u) while waiting for the reply to %s #%u",
             lpvp_type_name(t), t, r.h.request_id, lpvp_type_name(type), id);
        lpvci_rx_free(&r);
        lpvci_close_fd(c);
        return -1;
    }
}

int lpvci_simple(lpvc *c, uint16_t type, json_t *body_stolen)
{
    if (!body_stolen)
        return lpvci_fail(c, LPVC_ERR_USAGE, "out of memory building the request");
    int rc = lpvci_request(c, type, body_stolen, NULL, 0, NULL, NULL, NULL);
    json_decref(body_stolen);
    return rc;
}

/* ---- connection ------------------------------------------------------------ */

lpvc *lpvc_connect_with(const lpvc_connect_desc *desc, char *err, size_t n)
{
    char dummy[8];
    if (!err || n == 0) {
        err = dummy;
        n = sizeof dummy;
    }
    err[0] = '\0';
    lpvc_connect_desc d = {0};
    if (desc)
        d = *desc;
    int fd = open_socket(d.address, err, n);
    if (fd < 0)
        return NULL;
    lpvc *c = calloc(1, sizeof *c);
    if (!c) {
        close(fd);
        snprintf(err, n, "out of memory");
        return NULL;
    }
    c->fd = fd;
    c->next_id = 1;
    c->timeout_ms = d.timeout_ms;
    c->auto_ack = true;
    c->last_revision = -1;
    for (int i = 0; i < LPVC_KEEP_ACKED; i++)
        c->acked[i].tick = -1;
    if (d.timeout_ms > 0) {
        struct timeval tv = {.tv_sec = d.timeout_ms / 1000, .tv_usec = (d.timeout_ms % 1000) * 1000};
        setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    }

    json_t *body = json_pack("{s:i, s:s}", "version", LPVP_VERSION, "client", d.client_name ? d.client_name : "lpvc");
    if (body && d.token)
        json_object_set_new(body, "token", json_string(d.token));
    json_t *reply = NULL;
    int rc = body ? lpvci_request(c, LPVP_HELLO, body, NULL, 0, &reply, NULL, NULL)
                  : lpvci_fail(c, LPVC_ERR_USAGE, "out of memory");
    json_decref(body);
    if (rc != 0) {
        snprintf(err, n, "HELLO refused: %s (%d): %s", c->err_name, c->err_code, c->err_msg);
        lpvc_close(c);
        return NULL;
    }
    c->hello = json_dumps(reply, JSON_COMPACT);
    rc = lpvc_knobset_read(&c->knobs, reply, err, n);
    json_decref(reply);
    if (rc != 0) {
        lpvc_close(c);
        return NULL;
    }
    return c;
}

lpvc *lpvc_connect(const char *address, const char *token, char *err, size_t n)
{
    lpvc_connect_desc d = {.address = address, .token = token};
    return lpvc_connect_with(&d, err, n);
}

void lpvc_close(lpvc *c)
{
    if (!c)
        return;
    lpvci_close_fd(c);
    while (c->q_head) {
        lpvc_queued *q = c->q_head;
        c->q_head = q->next;
        json_decref(q->body);
        free(q->att);
        free(q);
    }
    for (int i = 0; i < LPVC_KEEP_ACKED; i++)
        free(c->acked[i].raw);
    free(c->last_reply);
    free(c->hello);
    lpvc_knobset_free(&c->knobs);
    free(c);
}
