/*
 * serve_net_listen.c - the daemon's listeners: the Unix socket (created
 * 0600, a stale one replaced, a live one never, R1.1) and TCP (a token
 * required off loopback), and closing them at shutdown. The network layer's
 * design is in serve_net_internal.h.
 */
#include "serve.h"
#include "serve_net_internal.h"

#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

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
    /* before any connection: the requests' memory resumes the reading of
     * a connection whose frame now fits through it */
    s->net_resume_reading = sv_net_resume_reading;
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
            rc = uv_listen((uv_stream_t *)&s->unix_listener, SV_LISTEN_BACKLOG, sv_net_on_connection);
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
            rc = uv_listen((uv_stream_t *)&s->tcp_listener, SV_LISTEN_BACKLOG, sv_net_on_connection);
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
