/*
 * lpvc.c - the C client library (see lpvc.h). Framing, JSON bodies, fp16,
 * XOR deltas and zstd all come from the protocol library (protocol/proto.h,
 * protocol/volume_codec.h); this file adds sockets, request/reply matching,
 * the stream queue and the acknowledged-volume cache.
 */
#include "lpvc.h"

#include <errno.h>
#include <math.h>
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

#include <jansson.h>

#include "lpvc_knobs.h"
#include "proto.h"
#include "volume_codec.h"
#include "volume_lookup.h"

/* Streamed volumes kept as possible XOR delta bases (R5.3). The server
 * deltas against a tick we acknowledged; ACKs are asynchronous, so it may use
 * one that is not our newest. */
#define LPVC_KEEP_ACKED 4

typedef struct queued {
    struct queued *next;
    uint16_t type;
    json_t *body;
    uint8_t *att;
    size_t att_len;
} queued;

typedef struct acked {
    int64_t tick;       /* -1: empty slot */
    uint8_t *raw;
    size_t len;
    uint64_t age;
} acked;

struct lpvc {
    int fd;
    uint32_t next_id;
    int timeout_ms;
    bool auto_ack;
    int err_code;
    char err_name[32];
    char err_msg[512];
    char *last_reply;
    int64_t last_revision;
    char *hello;
    lpvc_knobset knobs;     /* the server's knob description (HELLO, R4.12) */
    queued *q_head, *q_tail;
    acked acked[LPVC_KEEP_ACKED];
    uint64_t ack_clock;
};

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
static int fail(lpvc *c, int code, const char *fmt, ...)
{
    c->err_code = code;
    snprintf(c->err_name, sizeof c->err_name, "%s", code > 0 ? lpvp_error_name(code) : client_err_name(code));
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->err_msg, sizeof c->err_msg, fmt, ap);
    va_end(ap);
    return -1;
}

static void clear_error(lpvc *c)
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

static void close_fd(lpvc *c)
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
            close_fd(c);
            return fail(c, LPVC_ERR_IO, "send: %s", strerror(e));
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
            close_fd(c);
            return fail(c, LPVC_ERR_IO, "connection closed by the server (%zu of %zu bytes read)", total - len, total);
        }
        if (k < 0) {
            if (errno == EINTR)
                continue;
            int e = errno;
            if (e == EAGAIN || e == EWOULDBLOCK) {
                close_fd(c); /* mid-frame: the stream position is lost */
                return fail(c, LPVC_ERR_TIMEOUT, "no reply within %d ms", c->timeout_ms);
            }
            close_fd(c);
            return fail(c, LPVC_ERR_IO, "recv: %s", strerror(e));
        }
        p += k;
        len -= (size_t)k;
    }
    return 0;
}

/* ---- frames ---------------------------------------------------------------- */

/* Sends one frame built by proto.h: header + JSON, then the attachment from
 * the caller's buffer (no copy). Returns the request_id, or 0 on failure. */
static uint32_t send_frame(lpvc *c, uint16_t type, const json_t *body, const void *att, size_t att_len)
{
    if (c->fd < 0) {
        fail(c, LPVC_ERR_CLOSED, "the connection is closed");
        return 0;
    }
    char *js = json_dumps(body, JSON_COMPACT);
    if (!js) {
        fail(c, LPVC_ERR_USAGE, "cannot serialise the request body");
        return 0;
    }
    uint32_t id = c->next_id++;
    if (c->next_id == 0)
        c->next_id = 1;
    size_t head_len = 0;
    uint8_t *head = lpvp_frame_build_head(type, id, js, strlen(js), att_len, &head_len);
    free(js);
    if (!head) {
        fail(c, LPVC_ERR_USAGE, "frame too large (attachment %zu bytes)", att_len);
        return 0;
    }
    int rc = send_all(c, head, head_len);
    free(head);
    if (rc == 0 && att_len)
        rc = send_all(c, att, att_len);
    return rc == 0 ? id : 0;
}

typedef struct rx {
    lpvp_header h;
    json_t *body;
    uint8_t *att;
    size_t att_len;
} rx;

static void rx_free(rx *r)
{
    json_decref(r->body);
    free(r->att);
    memset(r, 0, sizeof *r);
}

/* Receives one frame. timeout_ms: -1 the connection's reply timeout, < -1
 * forever, >= 0 that many ms before the first byte. */
static int recv_frame(lpvc *c, rx *out, int timeout_ms)
{
    memset(out, 0, sizeof *out);
    if (c->fd < 0)
        return fail(c, LPVC_ERR_CLOSED, "the connection is closed");
    int wait = timeout_ms >= 0 ? timeout_ms : (timeout_ms == -1 && c->timeout_ms > 0 ? c->timeout_ms : -1);
    if (wait >= 0) {
        struct pollfd pfd = {.fd = c->fd, .events = POLLIN};
        int pr;
        do
            pr = poll(&pfd, 1, wait);
        while (pr < 0 && errno == EINTR);
        if (pr < 0)
            return fail(c, LPVC_ERR_IO, "poll: %s", strerror(errno));
        if (pr == 0)
            return fail(c, LPVC_ERR_TIMEOUT, "nothing received within %d ms", wait);
    }
    uint8_t hb[LPVP_HEADER_SIZE];
    if (recv_all(c, hb, sizeof hb) != 0)
        return -1;
    /* Replies are small JSON, but a volume attachment may be large. */
    lpvp_limits lim = {.max_body = 64u << 20, .max_message = (uint64_t)16 << 30};
    char err[256];
    if (lpvp_header_check(hb, &lim, &out->h, err, sizeof err) != 0) {
        close_fd(c);
        return fail(c, LPVC_ERR_PROTOCOL, "bad frame from the server: %s", err);
    }
    char *js = malloc(out->h.json_length + 1u);
    if (!js)
        return fail(c, LPVC_ERR_IO, "out of memory (%u-byte body)", out->h.json_length);
    if (recv_all(c, js, out->h.json_length) != 0) {
        free(js);
        return -1;
    }
    out->att_len = out->h.attachment_length;
    if (out->att_len) {
        out->att = malloc(out->att_len);
        if (!out->att) {
            free(js);
            close_fd(c);
            return fail(c, LPVC_ERR_IO, "out of memory (%zu-byte attachment)", out->att_len);
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
        close_fd(c);
        return fail(c, LPVC_ERR_PROTOCOL, "bad JSON body from the server (type 0x%04x): %s", out->h.type, err);
    }
    return 0;
}

static void set_last_reply(lpvc *c, const json_t *body)
{
    free(c->last_reply);
    c->last_reply = json_dumps(body, JSON_COMPACT);
    json_t *rev = json_object_get(body, "revision");
    if (json_is_integer(rev))
        c->last_revision = json_integer_value(rev);
}

/* An ERROR frame: record its code, name and message; close if it closes. */
static int take_error(lpvc *c, const json_t *body, uint16_t request_type)
{
    json_t *code = json_object_get(body, "code");
    json_t *name = json_object_get(body, "name");
    json_t *msg = json_object_get(body, "message");
    int k = json_is_integer(code) ? (int)json_integer_value(code) : LPVC_ERR_PROTOCOL;
    set_last_reply(c, body);
    fail(c, k, "%s", json_is_string(msg) ? json_string_value(msg) : "");
    if (json_is_string(name))
        snprintf(c->err_name, sizeof c->err_name, "%s", json_string_value(name));
    /* R3.4 "closes"; a HELLO's BAD_VERSION leaves the connection open (R4.1). */
    if (lpvp_error_closes(k) && !(k == LPVP_E_BAD_VERSION && request_type == LPVP_HELLO))
        close_fd(c);
    return -1;
}

static void enqueue(lpvc *c, rx *r)
{
    queued *q = calloc(1, sizeof *q);
    if (!q) {
        rx_free(r);
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

/* Sends a request and waits for its reply; stream messages are queued.
 * On success *reply (if non-NULL) receives the reply body (owned by the
 * caller) and *ratt / *ratt_len its attachment (malloc'd, owned by the caller). */
static int request(lpvc *c, uint16_t type, const json_t *body, const void *att, size_t att_len, json_t **reply,
                   uint8_t **ratt, size_t *ratt_len)
{
    clear_error(c);
    if (reply)
        *reply = NULL;
    if (ratt)
        *ratt = NULL;
    if (ratt_len)
        *ratt_len = 0;
    uint32_t id = send_frame(c, type, body, att, att_len);
    if (!id)
        return -1;
    for (;;) {
        rx r;
        if (recv_frame(c, &r, -1) != 0)
            return -1;
        uint16_t t = r.h.type;
        if (t == LPVP_REPLY(type) && r.h.request_id == id) {
            set_last_reply(c, r.body);
            if (reply)
                *reply = json_incref(r.body);
            if (ratt) {
                *ratt = r.att;
                r.att = NULL;
            }
            if (ratt_len)
                *ratt_len = r.att_len;
            rx_free(&r);
            return 0;
        }
        if (t == LPVP_ERROR && (r.h.request_id == id || r.h.request_id == 0)) {
            take_error(c, r.body, type);
            if (r.h.request_id == 0)
                close_fd(c); /* unsolicited: SHUTTING_DOWN and the like */
            rx_free(&r);
            return -1;
        }
        if (t == LPVP_VOLUME || t == LPVP_FRAME) {
            enqueue(c, &r);
            continue;
        }
        if (t == LPVP_BYE_REPLY && r.h.request_id == 0) {
            rx_free(&r);
            close_fd(c);
            return fail(c, LPVC_ERR_CLOSED, "the server said BYE");
        }
        fail(c, LPVC_ERR_PROTOCOL, "unexpected %s (type 0x%04x, request_id %u) while waiting for the reply to %s #%u",
             lpvp_type_name(t), t, r.h.request_id, lpvp_type_name(type), id);
        rx_free(&r);
        close_fd(c);
        return -1;
    }
}

/* request() for replies whose body only matters through lpvc_last_reply. */
static int simple(lpvc *c, uint16_t type, json_t *body_stolen)
{
    if (!body_stolen)
        return fail(c, LPVC_ERR_USAGE, "out of memory building the request");
    int rc = request(c, type, body_stolen, NULL, 0, NULL, NULL, NULL);
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
    int rc = body ? request(c, LPVP_HELLO, body, NULL, 0, &reply, NULL, NULL) : fail(c, LPVC_ERR_USAGE, "out of memory");
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
    close_fd(c);
    while (c->q_head) {
        queued *q = c->q_head;
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

size_t lpvc_knobs(const lpvc *c, const lpvc_knob **knobs)
{
    if (knobs)
        *knobs = c ? c->knobs.knobs : NULL;
    return c ? c->knobs.count : 0;
}

const lpvc_knob *lpvc_knob_find(const lpvc *c, const char *name)
{
    return c ? lpvc_knobset_find(&c->knobs, name) : NULL;
}

const char *const *lpvc_presets(const lpvc *c, size_t *count)
{
    if (count)
        *count = c ? c->knobs.preset_count : 0;
    return c ? c->knobs.presets : NULL;
}

/* ---- requests -------------------------------------------------------------- */

static json_t *vec(const float *v, int n)
{
    json_t *a = json_array();
    for (int i = 0; i < n; i++)
        json_array_append_new(a, json_real(v[i]));
    return a;
}

static json_t *parse_object(lpvc *c, const char *text, const char *what)
{
    if (!text)
        text = "{}";
    char err[256];
    json_t *o = lpvp_body_parse(text, strlen(text), err, sizeof err);
    if (!o)
        fail(c, LPVC_ERR_USAGE, "%s: %s", what, err);
    return o;
}

int lpvc_scene_load_file(lpvc *c, const char *path)
{
    if (!c || !path)
        return c ? fail(c, LPVC_ERR_USAGE, "scene path is NULL") : -1;
    return simple(c, LPVP_SCENE_LOAD, json_pack("{s:s}", "path", path));
}

int lpvc_scene_load_glb(lpvc *c, const void *glb, size_t size)
{
    if (!c)
        return -1;
    if (!glb || size == 0)
        return fail(c, LPVC_ERR_USAGE, "empty .glb");
    json_t *body = json_object();
    int rc = request(c, LPVP_SCENE_LOAD, body, glb, size, NULL, NULL, NULL);
    json_decref(body);
    return rc;
}

int lpvc_scene_update(lpvc *c, const char *json)
{
    if (!c)
        return -1;
    json_t *o = parse_object(c, json, "scene update");
    return o ? simple(c, LPVP_SCENE_UPDATE, o) : -1;
}

int lpvc_light_set(lpvc *c, const lpvc_light *l)
{
    if (!c)
        return -1;
    if (!l || !l->id)
        return fail(c, LPVC_ERR_USAGE, "light id is required");
    json_t *o = json_pack("{s:s, s:s, s:f}", "id", l->id, "type", l->type ? l->type : "point", "intensity",
                          (double)l->intensity);
    if (!o)
        return fail(c, LPVC_ERR_USAGE, "out of memory");
    if (l->color)
        json_object_set_new(o, "color", vec(l->color, 3));
    if (l->position)
        json_object_set_new(o, "position", vec(l->position, 3));
    if (l->direction)
        json_object_set_new(o, "direction", vec(l->direction, 3));
    if (l->range != 0.0f)
        json_object_set_new(o, "range", json_real(l->range));
    if (l->inner_cone != 0.0f)
        json_object_set_new(o, "inner_cone", json_real(l->inner_cone));
    if (l->outer_cone != 0.0f)
        json_object_set_new(o, "outer_cone", json_real(l->outer_cone));
    return simple(c, LPVP_LIGHT_SET, o);
}

int lpvc_light_remove(lpvc *c, const char *id)
{
    if (!c)
        return -1;
    if (!id)
        return fail(c, LPVC_ERR_USAGE, "light id is required");
    return simple(c, LPVP_LIGHT_REMOVE, json_pack("{s:s}", "id", id));
}

int lpvc_camera_set(lpvc *c, const lpvc_camera *cam)
{
    if (!c)
        return -1;
    if (!cam)
        return fail(c, LPVC_ERR_USAGE, "camera is NULL");
    json_t *o;
    if (cam->scene_camera_name)
        o = json_pack("{s:s}", "camera", cam->scene_camera_name);
    else if (cam->scene_camera > 0)
        o = json_pack("{s:i}", "camera", cam->scene_camera - 1);
    else {
        if (!cam->eye || !cam->target)
            return fail(c, LPVC_ERR_USAGE, "camera needs eye and target, or a scene camera");
        o = json_object();
        json_object_set_new(o, "eye", vec(cam->eye, 3));
        json_object_set_new(o, "target", vec(cam->target, 3));
        if (cam->up)
            json_object_set_new(o, "up", vec(cam->up, 3));
        if (cam->fov_deg != 0.0f)
            json_object_set_new(o, "fov_deg", json_real(cam->fov_deg));
        if (cam->width > 0)
            json_object_set_new(o, "width", json_integer(cam->width));
        if (cam->height > 0)
            json_object_set_new(o, "height", json_integer(cam->height));
    }
    return simple(c, LPVP_CAMERA_SET, o);
}

int lpvc_config_set(lpvc *c, const lpvc_config *cfg)
{
    if (!c)
        return -1;
    lpvc_config z = {0};
    if (!cfg)
        cfg = &z;
    json_t *o = json_object();
    if (cfg->preset)
        json_object_set_new(o, "preset", json_string(cfg->preset));
    if (cfg->grid[0] || cfg->grid[1] || cfg->grid[2])
        json_object_set_new(o, "grid", json_pack("[i,i,i]", cfg->grid[0], cfg->grid[1], cfg->grid[2]));
    if (cfg->bounds)
        json_object_set_new(o, "bounds", vec(cfg->bounds, 6));
    if (cfg->tick_rate_hz != 0.0f)
        json_object_set_new(o, "tick_rate_hz", json_real(cfg->tick_rate_hz));
    char err[512];
    if (lpvc_knobset_add(&c->knobs, o, cfg->settings, cfg->settings ? cfg->setting_count : 0, err, sizeof err) != 0) {
        json_decref(o);
        return fail(c, LPVC_ERR_USAGE, "%s", err);
    }
    return simple(c, LPVP_CONFIG, o);
}

int lpvc_config_json(lpvc *c, const char *json)
{
    if (!c)
        return -1;
    json_t *o = parse_object(c, json, "config");
    return o ? simple(c, LPVP_CONFIG, o) : -1;
}

int lpvc_tick(lpvc *c, int64_t *tick)
{
    if (!c)
        return -1;
    json_t *body = json_object(), *reply = NULL;
    int rc = request(c, LPVP_TICK, body, NULL, 0, &reply, NULL, NULL);
    json_decref(body);
    if (rc == 0 && tick) {
        json_t *t = json_object_get(reply, "tick");
        *tick = json_is_integer(t) ? json_integer_value(t) : -1;
    }
    json_decref(reply);
    return rc;
}

static const char *stream_name(enum lpvc_stream s)
{
    return lpvp_stream_names[s == LPVC_STREAM_FRAME ? LPVP_STREAM_FRAME : LPVP_STREAM_VOLUME];
}

int lpvc_subscribe(lpvc *c, const lpvc_subscribe_desc *desc)
{
    if (!c)
        return -1;
    lpvc_subscribe_desc d = {0};
    if (desc)
        d = *desc;
    json_t *o = json_pack("{s:s}", "stream", stream_name(d.stream));
    if (d.format)
        json_object_set_new(o, "format", json_string(d.format));
    if (d.compression)
        json_object_set_new(o, "compression", json_string(d.compression));
    if (d.delta)
        json_object_set_new(o, "delta", json_true());
    return simple(c, LPVP_SUBSCRIBE, o);
}

int lpvc_unsubscribe(lpvc *c, enum lpvc_stream stream)
{
    if (!c)
        return -1;
    return simple(c, LPVP_UNSUBSCRIBE, json_pack("{s:s}", "stream", stream_name(stream)));
}

int lpvc_ack(lpvc *c, int64_t tick)
{
    if (!c)
        return -1;
    clear_error(c);
    json_t *o = json_pack("{s:s, s:I}", "stream", lpvp_stream_names[LPVP_STREAM_VOLUME], "tick", (json_int_t)tick);
    if (!o)
        return fail(c, LPVC_ERR_USAGE, "out of memory");
    uint32_t id = send_frame(c, LPVP_ACK, o, NULL, 0);
    json_decref(o);
    return id ? 0 : -1;
}

/* ---- volumes --------------------------------------------------------------- */

void lpvc_volume_free(lpvc_volume *v)
{
    if (!v)
        return;
    free(v->data);
    free(v->header_json);
    free(v->plan_json);
    memset(v, 0, sizeof *v);
}

static acked *find_acked(lpvc *c, int64_t tick)
{
    for (int i = 0; i < LPVC_KEEP_ACKED; i++)
        if (c->acked[i].tick == tick && c->acked[i].raw)
            return &c->acked[i];
    return NULL;
}

/* Keeps raw (taking ownership) as the acknowledged volume of tick. */
static void remember_acked(lpvc *c, int64_t tick, uint8_t *raw, size_t len)
{
    acked *slot = find_acked(c, tick);
    if (!slot) {
        slot = &c->acked[0];
        for (int i = 0; i < LPVC_KEEP_ACKED; i++) {
            if (c->acked[i].tick < 0) {
                slot = &c->acked[i];
                break;
            }
            if (c->acked[i].age < slot->age)
                slot = &c->acked[i];
        }
    }
    free(slot->raw);
    slot->tick = tick;
    slot->raw = raw;
    slot->len = len;
    slot->age = ++c->ack_clock;
}

/* Decodes a volume header + attachment. stream: remember and ACK it. */
static int decode_volume(lpvc *c, const json_t *hdr, const uint8_t *att, size_t att_len, bool stream,
                         lpvc_volume *out)
{
    memset(out, 0, sizeof *out);
    lpvp_volume_info vi;
    char err[256];
    if (lpvp_volume_header_parse(hdr, &vi, err, sizeof err) != 0)
        return fail(c, LPVC_ERR_PROTOCOL, "bad volume header: %s", err);
    /* every cascade's cells (R5.6); the parse checked raw_length against them */
    size_t cells = (size_t)lpvp_volume_total_cells(&vi);
    const acked *base = NULL;
    if (!vi.keyframe) {
        base = find_acked(c, vi.base_tick);
        if (!base)
            return fail(c, LPVC_ERR_PROTOCOL, "delta against tick %lld, which this client did not acknowledge or no longer holds",
                        (long long)vi.base_tick);
        if (base->len != vi.raw_length)
            return fail(c, LPVC_ERR_PROTOCOL, "delta of %llu bytes against a base of %zu bytes",
                        (unsigned long long)vi.raw_length, base->len);
    }
    uint8_t *raw = malloc(vi.raw_length ? (size_t)vi.raw_length : 1);
    float *data = malloc(cells * 12 * sizeof(float));
    if (!raw || !data) {
        free(raw);
        free(data);
        return fail(c, LPVC_ERR_IO, "out of memory for a %zu-cell volume", cells);
    }
    if (lpvp_volume_decode(&vi, att, att_len, base ? base->raw : NULL, base ? base->len : 0, raw, err, sizeof err) != 0) {
        free(raw);
        free(data);
        return fail(c, LPVC_ERR_PROTOCOL, "cannot decode the volume: %s", err);
    }
    lpvp_volume_unpack(raw, cells, vi.format, data);

    out->revision = vi.revision;
    out->tick = vi.tick;
    for (int a = 0; a < 3; a++) {
        out->dims[a] = (int)vi.dims[a];
        out->origin[a] = (float)vi.origin[a];
    }
    out->cell_size = (float)vi.cell_size;
    out->cells = (size_t)vi.dims[0] * (size_t)vi.dims[1] * (size_t)vi.dims[2];
    out->data = data;
    out->total_cells = cells;
    out->cascade_count = vi.cascade_count;
    for (int k = 0; k < vi.cascade_count && k < LPVC_MAX_CASCADES; k++) {
        lpvc_cascade *cs = &out->cascades[k];
        for (int a = 0; a < 3; a++) {
            cs->dims[a] = (int)vi.cascades[k].dims[a];
            cs->origin[a] = (float)vi.cascades[k].origin[a];
        }
        cs->cell_size = (float)vi.cascades[k].cell_size;
        cs->cells = (size_t)vi.cascades[k].cells;
        cs->data = data + 12 * (size_t)lpvp_volume_cascade_first_cell(&vi, k);
    }
    if (json_is_object(json_object_get(hdr, "plan")))
        out->plan_json = json_dumps(json_object_get(hdr, "plan"), JSON_COMPACT);
    snprintf(out->format, sizeof out->format, "%s", lpvp_volume_format_name(vi.format));
    snprintf(out->compression, sizeof out->compression, "%s", lpvp_compression_name(vi.compression));
    out->keyframe = vi.keyframe != 0;
    out->base_tick = vi.keyframe ? -1 : vi.base_tick;
    out->header_json = json_dumps(hdr, JSON_COMPACT);

    if (stream) {
        /* Kept as a possible delta base whether it is ACKed here or later by
         * the caller (lpvc_ack with auto-ACK off). */
        remember_acked(c, vi.tick, raw, (size_t)vi.raw_length);
        return c->auto_ack ? lpvc_ack(c, vi.tick) : 0;
    }
    free(raw);
    return 0;
}

int lpvc_get_volume(lpvc *c, const lpvc_volume_desc *desc, lpvc_volume *out)
{
    if (!c)
        return -1;
    if (!out)
        return fail(c, LPVC_ERR_USAGE, "out is NULL");
    memset(out, 0, sizeof *out);
    lpvc_volume_desc d = {0};
    if (desc)
        d = *desc;
    json_t *o = json_pack("{s:s, s:s}", "format", d.format ? d.format : lpvp_volume_format_names[LPVP_FMT_FP32],
                          "compression", d.compression ? d.compression : lpvp_compression_names[LPVP_COMP_ZSTD]);
    json_t *reply = NULL;
    uint8_t *att = NULL;
    size_t att_len = 0;
    int rc = request(c, LPVP_GET_VOLUME, o, NULL, 0, &reply, &att, &att_len);
    json_decref(o);
    if (rc == 0)
        rc = decode_volume(c, reply, att, att_len, false, out);
    json_decref(reply);
    free(att);
    return rc;
}

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

/* Decodes a frame header + attachment (takes ownership of att). */
static int decode_frame(lpvc *c, const json_t *hdr, uint8_t *att, size_t att_len, lpvc_frame *out)
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
            return fail(c, LPVC_ERR_PROTOCOL, "rgba8 frame %dx%d with raw_length %lld", out->width, out->height,
                        (long long)raw_length);
        }
        if (strcmp(comp, lpvp_compression_names[LPVP_COMP_ZSTD]) == 0) {
            uint8_t *raw = malloc(expect ? expect : 1);
            char err[256];
            if (!raw || lpvp_zstd_decompress_exact(att, att_len, raw, expect, err, sizeof err) != 0) {
                if (raw)
                    fail(c, LPVC_ERR_PROTOCOL, "cannot decompress the frame: %s", err);
                else
                    fail(c, LPVC_ERR_IO, "out of memory");
                free(raw);
                free(att);
                return -1;
            }
            free(att);
            att = raw;
            att_len = expect;
        } else if (att_len != expect) {
            free(att);
            return fail(c, LPVC_ERR_PROTOCOL, "rgba8 frame of %zu bytes, expected %zu", att_len, expect);
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
        return fail(c, LPVC_ERR_USAGE, "out is NULL");
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
    int rc = request(c, LPVP_GET_FRAME, o, NULL, 0, &reply, &att, &att_len);
    json_decref(o);
    if (rc == 0)
        rc = decode_frame(c, reply, att, att_len, out);
    else
        free(att);
    json_decref(reply);
    return rc;
}

/* ---- queries, stats, bye ------------------------------------------------------ */

int lpvc_query_irradiance(lpvc *c, const float *points, const float *normals, size_t n, float *rgb)
{
    if (!c)
        return -1;
    if (n && (!points || !normals || !rgb))
        return fail(c, LPVC_ERR_USAGE, "points, normals and rgb must not be NULL");
    if (n > UINT32_MAX / 24)
        return fail(c, LPVC_ERR_USAGE, "too many query points (%zu)", n);
    uint8_t *att = malloc(n ? n * 24 : 1);
    if (!att)
        return fail(c, LPVC_ERR_IO, "out of memory");
    for (size_t i = 0; i < n; i++) {
        float v[6] = {points[3 * i], points[3 * i + 1], points[3 * i + 2],
                      normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]};
        for (int k = 0; k < 6; k++) {
            uint32_t u;
            memcpy(&u, &v[k], 4);
            lpvp_put_u32(att + 24 * i + 4 * k, u);
        }
    }
    json_t *o = json_pack("{s:I}", "count", (json_int_t)n);
    uint8_t *ratt = NULL;
    size_t ratt_len = 0;
    int rc = request(c, LPVP_QUERY_IRRADIANCE, o, att, n * 24, NULL, &ratt, &ratt_len);
    json_decref(o);
    free(att);
    if (rc == 0) {
        if (ratt_len != n * 12) {
            rc = fail(c, LPVC_ERR_PROTOCOL, "QUERY_IRRADIANCE answered %zu bytes for %zu points", ratt_len, n);
        } else {
            for (size_t i = 0; i < n * 3; i++) {
                uint32_t u = lpvp_get_u32(ratt + 4 * i);
                memcpy(&rgb[i], &u, 4);
            }
        }
    }
    free(ratt);
    return rc;
}

int lpvc_stats(lpvc *c, char **json)
{
    if (!c)
        return -1;
    if (json)
        *json = NULL;
    int rc = simple(c, LPVP_STATS, json_object());
    if (rc == 0 && json) {
        *json = strdup(c->last_reply ? c->last_reply : "{}");
        if (!*json)
            return fail(c, LPVC_ERR_IO, "out of memory");
    }
    return rc;
}

int lpvc_bye(lpvc *c)
{
    if (!c)
        return -1;
    int rc = simple(c, LPVP_BYE, json_object());
    close_fd(c);
    return rc;
}

int lpvc_request_raw(lpvc *c, uint16_t type, const char *json, const void *attachment, size_t att_len, void **att,
                     size_t *att_n)
{
    if (!c)
        return -1;
    json_t *o = parse_object(c, json, "request body");
    if (!o)
        return -1;
    uint8_t *ratt = NULL;
    size_t rlen = 0;
    int rc;
    if (type == LPVP_ACK) {
        clear_error(c);
        rc = send_frame(c, type, o, attachment, att_len) ? 0 : -1;
    } else {
        rc = request(c, type, o, attachment, att_len, NULL, &ratt, &rlen);
    }
    json_decref(o);
    if (att)
        *att = ratt;
    else
        free(ratt);
    if (att_n)
        *att_n = rlen;
    return rc;
}

/* ---- streams ---------------------------------------------------------------- */

void lpvc_message_free(lpvc_message *m)
{
    if (!m)
        return;
    lpvc_volume_free(&m->volume);
    lpvc_frame_free(&m->frame);
    m->type = LPVC_MSG_NONE;
}

int lpvc_next_stream_message(lpvc *c, lpvc_message *out, int timeout_ms)
{
    if (!c)
        return -1;
    if (!out)
        return fail(c, LPVC_ERR_USAGE, "out is NULL");
    memset(out, 0, sizeof *out);
    clear_error(c);
    uint16_t type;
    json_t *body;
    uint8_t *att;
    size_t att_len;
    if (c->q_head) {
        queued *q = c->q_head;
        c->q_head = q->next;
        if (!c->q_head)
            c->q_tail = NULL;
        type = q->type;
        body = q->body;
        att = q->att;
        att_len = q->att_len;
        free(q);
    } else {
        for (;;) {
            rx r;
            if (recv_frame(c, &r, timeout_ms < 0 ? -2 : timeout_ms) != 0)
                return -1;
            if (r.h.type == LPVP_VOLUME || r.h.type == LPVP_FRAME) {
                type = r.h.type;
                body = r.body;
                att = r.att;
                att_len = r.att_len;
                break;
            }
            if (r.h.type == LPVP_BYE_REPLY) {
                rx_free(&r);
                close_fd(c);
                out->type = LPVC_MSG_BYE;
                return 0;
            }
            if (r.h.type == LPVP_ERROR) {
                take_error(c, r.body, 0);
                if (r.h.request_id == 0 && c->err_code == LPVP_E_SHUTTING_DOWN)
                    close_fd(c);
                rx_free(&r);
                return -1;
            }
            fail(c, LPVC_ERR_PROTOCOL, "unexpected %s (type 0x%04x, request_id %u) in the stream",
                 lpvp_type_name(r.h.type), r.h.type, r.h.request_id);
            rx_free(&r);
            return -1;
        }
    }
    set_last_reply(c, body);
    int rc;
    if (type == LPVP_VOLUME) {
        out->type = LPVC_MSG_VOLUME;
        rc = decode_volume(c, body, att, att_len, true, &out->volume);
        free(att);
    } else {
        out->type = LPVC_MSG_FRAME;
        rc = decode_frame(c, body, att, att_len, &out->frame);
    }
    json_decref(body);
    if (rc != 0)
        lpvc_message_free(out);
    return rc;
}

/* ---- local lookup: SPEC R5.7, the protocol library's (volume_lookup.h) ----- */

static lpvp_lookup_cascade lookup_cascade(const lpvc_cascade *cs)
{
    lpvp_lookup_cascade l = {.dims = {cs->dims[0], cs->dims[1], cs->dims[2]},
                             .origin = {cs->origin[0], cs->origin[1], cs->origin[2]},
                             .cell_size = cs->cell_size,
                             .cells = cs->data};
    return l;
}

void lpvc_cascade_irradiance(const lpvc_cascade *cs, const float p[3], const float n[3], float rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    if (!cs)
        return;
    lpvp_lookup_cascade l = lookup_cascade(cs);
    lpvp_cascade_irradiance(&l, p, n, rgb);
}

void lpvc_volume_irradiance(const lpvc_volume *v, const float p[3], const float n[3], float rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    if (!v || !v->data)
        return;
    lpvp_lookup_cascade l[LPVC_MAX_CASCADES];
    int count = v->cascade_count;
    if (count < 1 || count > LPVC_MAX_CASCADES) { /* a volume built by hand: the grid alone */
        l[0] = (lpvp_lookup_cascade){.dims = {v->dims[0], v->dims[1], v->dims[2]},
                                     .origin = {v->origin[0], v->origin[1], v->origin[2]},
                                     .cell_size = v->cell_size,
                                     .cells = v->data};
        count = 1;
    } else {
        for (int k = 0; k < count; k++)
            l[k] = lookup_cascade(&v->cascades[k]);
    }
    lpvp_volume_irradiance(l, count, p, n, rgb);
}
