/*
 * serve.c - `lpvd serve`: the daemon's command line, start-up, signals and
 * shutdown. The protocol is protocol/SPEC.md; the design is docs/server.md.
 */
#include "serve.h"
#include "scene_defaults.h"

#include <errno.h>
#include <fcntl.h>
#include <malloc.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "commands.h"
#include "options.h"
#include "scene_load.h"
#include "serve_limits.h"

enum { S_SOCKET, S_LISTEN, S_TOKEN_FILE, S_SCENE_ROOT, S_SCENE, S_HELP, S_COUNT };

/* The flags that are no limit: where the daemon listens and what it serves. */
static const lpv_flag SERVE_FLAGS[S_COUNT] = {
    [S_SOCKET] = {"socket", 0, "PATH", "Unix socket (mode 0600; default $XDG_RUNTIME_DIR/lpvd.sock,\n"
                                       "else /tmp/lpvd-$UID.sock); a stale socket file is replaced"},
    [S_LISTEN] = {"listen", 0, "HOST:PORT", "also (or only, without --socket) listen on TCP; default host\n"
                                            "127.0.0.1; a non-loopback host requires --token-file"},
    [S_TOKEN_FILE] = {"token-file", 0, "FILE", "every client must present this token in HELLO"},
    [S_SCENE_ROOT] = {"scene-root", 0, "DIR", "SCENE_LOAD paths resolve under DIR (none: paths are refused)"},
    [S_SCENE] = {"scene", 0, "FILE.glb", "the scene every session starts with (default: built-in Cornell box)"},
    [S_HELP] = {"help", 'h', NULL, "this text"},
};

static void usage(FILE *f)
{
    static char help[16384];
    if (!help[0]) {
        size_t len = 0, n = sizeof help;
        lpv_flags_append(help, n, &len, "usage: lpvd serve [flags]\n"
                         "Runs the lpvd daemon: clients speak the wire protocol (protocol/SPEC.md) over a Unix socket\n"
                         "(default) or TCP, load scenes, set lights, cameras and settings, tick, and stream volumes\n"
                         "and frames. See docs/server.md.\nListening:\n");
        lpv_flags_help(help, n, &len, &SERVE_FLAGS[S_SOCKET], 3);
        lpv_flags_append(help, n, &len, "Scenes:\n");
        lpv_flags_help(help, n, &len, &SERVE_FLAGS[S_SCENE_ROOT], 2);
        const char *section = NULL;
        for (size_t i = 0; i < sv_limit_count; ++i) /* the limits' sections, in the table's order */
            if (!section || strcmp(section, sv_limits[i].section) != 0) {
                section = sv_limits[i].section;
                lpv_flags_append(help, n, &len, "%s:\n", section);
                sv_limits_help(help, n, &len, section);
            }
        lpv_flags_append(help, n, &len, "%s", LPVD_OPTIONS_HELP);
    }
    fputs(help, f);
}

static int read_token(const char *path, sv_config *cfg, char *err, size_t n)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, n, "--token-file %s: %s", path, strerror(errno));
        return -1;
    }
    size_t got = fread(cfg->token, 1, sizeof cfg->token - 1, f);
    int more = fgetc(f) != EOF;
    fclose(f);
    if (more) {
        snprintf(err, n, "--token-file %s: longer than %zu bytes", path, sizeof cfg->token - 1);
        return -1;
    }
    cfg->token[got] = '\0';
    if (strlen(cfg->token) != got) {
        snprintf(err, n, "--token-file %s: contains a NUL byte", path);
        return -1;
    }
    while (got && (cfg->token[got - 1] == '\n' || cfg->token[got - 1] == '\r' || cfg->token[got - 1] == ' ' ||
                   cfg->token[got - 1] == '\t'))
        cfg->token[--got] = '\0';
    if (!got) {
        snprintf(err, n, "--token-file %s: empty token", path);
        return -1;
    }
    cfg->has_token = 1;
    return 0;
}

/* Loads the default scene: --scene, or the built-in Cornell box. */
static int load_default_scene(sv_server *s, char *err, size_t n)
{
    sv_scene *sc = calloc(1, sizeof *sc);
    if (!sc) {
        snprintf(err, n, "out of memory");
        return -1;
    }
    if (!s->cfg.scene_file) {
        if (lpv_scene_load(NULL, &sc->scene, err, n) != 0) {
            free(sc);
            return -1;
        }
        sc->hash = 0;
    } else {
        const char *path = s->cfg.scene_file;
        char *real = realpath(path, NULL);
        FILE *f = real ? fopen(real, "rb") : NULL;
        if (!f) {
            snprintf(err, n, "--scene %s: %s", path, strerror(errno));
            free(real);
            free(sc);
            return -1;
        }
        size_t cap = 1 << 16, len = 0;
        uint8_t *buf = malloc(cap);
        for (;;) {
            if (!buf)
                break;
            if (len == cap) {
                uint8_t *nb = realloc(buf, cap * 2);
                if (!nb) {
                    free(buf);
                    buf = NULL;
                    break;
                }
                buf = nb;
                cap *= 2;
            }
            size_t r = fread(buf + len, 1, cap - len, f);
            if (r == 0)
                break;
            len += r;
        }
        fclose(f);
        char *slash = real ? strrchr(real, '/') : NULL;
        char *dir = NULL;
        if (slash) {
            dir = strndup(real, (size_t)(slash - real) + (slash == real));
        }
        if (!buf || !dir ||
            lpv_gltf_load_memory_ex(buf, len, dir, path, NULL, 0, &sc->scene, err, n) != 0 ||
            lpv_scene_add_defaults(&sc->scene, err, n) != 0) {
            if (!buf || !dir)
                snprintf(err, n, "--scene %s: out of memory", path);
            lpv_scene_free(&sc->scene);
            free(buf);
            free(dir);
            free(real);
            free(sc);
            return -1;
        }
        free(real);
        sc->glb = buf;
        sc->glb_size = len;
        int external = 0; /* any "uri": the folder matters (as in serve_scene.c) */
        for (size_t i = 0; i + 5 <= len && !external; ++i)
            external = buf[i] == '"' && memcmp(buf + i, "\"uri\"", 5) == 0;
        if (!external) {
            free(dir);
            dir = NULL;
        }
        sc->base_dir = dir;
        sc->hash = lpv_hash_bytes(LPV_HASH_INIT, buf, len);
        if (dir)
            sc->hash = lpv_hash_bytes(sc->hash, dir, strlen(dir));
        if (!sc->hash)
            sc->hash = 1;
        uint64_t tris = sc->scene.index_count / 3;
        if (tris > s->cfg.max_triangles) {
            snprintf(err, n, "--scene %s: %llu triangles, over --max-triangles %llu", path, (unsigned long long)tris,
                     (unsigned long long)s->cfg.max_triangles);
            lpv_scene_free(&sc->scene);
            free(sc->glb);
            free(sc->base_dir);
            free(sc);
            return -1;
        }
    }
    sc->refs = 1;
    sc->next = s->scenes;
    s->scenes = sc;
    s->builtin = sc;
    return 0;
}

/* ---- timers, signals, shutdown ------------------------------------------- */
static void idle_cb(uv_timer_t *t)
{
    sv_server *s = t->data;
    uint64_t now = sv_now_ms();
    uint64_t limit = (uint64_t)(s->cfg.idle_timeout * 1000.0);
    uint64_t handshake = (uint64_t)(s->cfg.handshake_timeout * 1000.0);
    for (sv_conn *c = s->conns; c; c = c->next) {
        if (c->closing)
            continue;
        if (c->close_after_write) {
            if (now > c->close_deadline_ms) /* it never read what we wrote */
                sv_conn_close(c);
            continue;
        }
        if (!c->hello && handshake && now - c->accepted_ms > handshake) { /* R4.1a */
            fprintf(stderr, "lpvd serve: client %llu (%s) said no HELLO within %g s: closing it\n",
                    (unsigned long long)c->id, c->peer, s->cfg.handshake_timeout);
            sv_send_error(c, 0, LPVP_E_LIMIT, "no HELLO within %g s of connecting (--handshake-timeout %g)",
                          s->cfg.handshake_timeout, s->cfg.handshake_timeout);
            sv_conn_close_after_write(c);
            continue;
        }
        sv_net_shrink_stalled(c, now);
        if (limit && now - c->idle_since_ms > limit && !c->busy) {
            fprintf(stderr, "lpvd serve: client %llu (%s) idle for %g s: BYE\n", (unsigned long long)c->id, c->peer,
                    s->cfg.idle_timeout);
            sv_send(c, LPVP_BYE_REPLY, 0, json_object(), NULL, 0, SV_STREAM_NONE);
            sv_conn_close_after_write(c);
        }
    }
}

static void close_all_cb(uv_timer_t *t)
{
    sv_server *s = t->data;
    for (sv_conn *c = s->conns; c; c = c->next)
        sv_conn_close(c);
    uv_close((uv_handle_t *)t, NULL);
}

/* How long SIGTERM waits, after the tick in flight, for requests running on
 * libuv workers (scene loads) before the process exits without them. */
#define SV_SHUTDOWN_WAIT_MS 5000

/* The shutdown deadline passed and a scene load is still running on a worker
 * thread (a huge file being parsed; a load cannot be cancelled). By now every
 * client has had its replies or SHUTTING_DOWN and BYE, connections and
 * listeners are closed, the socket file is removed, and the GL thread has
 * destroyed every engine and been joined. A load only reads files and builds
 * a private in-memory scene: it writes no file, owns nothing outside the
 * process and holds no lock anything else waits for, so ending the process
 * under it loses only memory the kernel takes back. _exit, not exit: exit's
 * atexit handlers and C++ static destructors would tear down the loader's
 * libraries while the worker is still in them. */
static void exit_deadline_cb(uv_timer_t *t)
{
    const sv_server *s = t->data;
    if (s->works_inflight <= 0)
        return;
    fprintf(stderr, "lpvd serve: %d scene load(s) still running %d ms after the shutdown; exiting without them "
                    "(their clients were answered SHUTTING_DOWN)\n",
            s->works_inflight, SV_SHUTDOWN_WAIT_MS);
    fprintf(stderr, "lpvd serve: stopped (%llu ticks, %llu bytes sent)\n", (unsigned long long)s->ticks,
            (unsigned long long)s->bytes_sent);
    fflush(stderr);
    _exit(0);
}

static void begin_shutdown(sv_server *s, int signum)
{
    if (s->stopping) {
        /* a supervisor repeating its SIGTERM, or a ^C after it: the stop in
         * progress already answers every client; dying now would lose those
         * answers (issue 31, item 8) */
        fprintf(stderr, "lpvd serve: %s: already stopping\n", signum == SIGINT ? "SIGINT" : "SIGTERM");
        return;
    }
    s->stopping = 1;
    fprintf(stderr, "lpvd serve: %s: finishing the tick in flight, saying BYE to %d client(s)\n",
            signum == SIGINT ? "SIGINT" : "SIGTERM", s->conn_count);
    sv_net_stop_listening(s);
    uv_timer_stop(&s->idle_timer);
    uv_close((uv_handle_t *)&s->idle_timer, NULL);
    /* SIGTERM and SIGINT stay handled until the process ends (closed, their
     * default action would kill it); unref'd, they keep the loop from ending
     * no longer than the rest */
    uv_unref((uv_handle_t *)&s->sigterm);
    uv_unref((uv_handle_t *)&s->sigint);
    uv_close((uv_handle_t *)&s->sighup, NULL);
    for (sv_world *w = s->worlds; w; w = w->next)
        if (w->timer_init)
            uv_timer_stop(&w->timer);
    /* every session leaves its world: destroy jobs go to the GL thread */
    for (sv_conn *c = s->conns; c; c = c->next)
        sv_world_detach(c);
    sv_gl_stop(s); /* finishes the tick in flight and delivers its reply */
    /* the rest (a load on a worker, requests queued behind it) get SHUTTING_DOWN, then BYE (R3.1, R7.4) */
    for (sv_conn *c = s->conns; c; c = c->next)
        sv_session_shutdown(c);
    sv_scene_loads_drop(s); /* those not started: answered SHUTTING_DOWN just now */
    uv_close((uv_handle_t *)&s->done_async, NULL);
    if (uv_timer_init(s->loop, &s->exit_timer) == 0) { /* unref'd: only matters while a worker holds the loop */
        s->exit_timer.data = s;
        uv_timer_start(&s->exit_timer, exit_deadline_cb, SV_SHUTDOWN_WAIT_MS, 0);
        uv_unref((uv_handle_t *)&s->exit_timer);
    }
    /* clients that do not read get 2 s, then are closed */
    if (uv_timer_init(s->loop, &s->stop_timer) == 0) {
        s->stop_timer.data = s;
        uv_timer_start(&s->stop_timer, close_all_cb, 2000, 0);
        uv_unref((uv_handle_t *)&s->stop_timer);
    }
}

static void signal_cb(uv_signal_t *h, int signum)
{
    begin_shutdown(h->data, signum);
}

/* SIGHUP (a closed terminal, or a supervisor's "reload"): lpvd logs to
 * stderr, so there is no log file to reopen, and its settings come from the
 * command line; it notes the signal and serves on (docs/server.md,
 * "Signals"). Without a handler SIGHUP's default action would kill the
 * daemon without BYE and leave its socket file behind. */
static void sighup_cb(uv_signal_t *h, int signum)
{
    (void)signum;
    const sv_server *s = h->data;
    fprintf(stderr, "lpvd serve: SIGHUP: nothing to reload (logs go to stderr, settings come from the command "
                    "line); serving on with %d client(s)\n",
            s->conn_count);
}

static void close_walk(uv_handle_t *h, void *arg)
{
    (void)arg;
    if (!uv_is_closing(h))
        uv_close(h, NULL);
}

int lpvd_cmd_serve(int argc, char **argv)
{
    static sv_server srv; /* one per process; its address is stable for the handles */
    sv_server *s = &srv;
    /* A daemon that runs for months gives back what a world took when the
     * world goes: glibc's threshold for serving a block from mmap rises to
     * the largest block freed (up to 32 MiB on 64-bit), after which a world's
     * textures and buffers (llvmpipe's storage is malloc'ed) come from the
     * heap and stay in it. A fixed threshold keeps every block over it in
     * its own mapping, unmapped when freed (issue 31, item 1). */
    mallopt(M_MMAP_THRESHOLD, SV_MMAP_THRESHOLD);
    memset(s, 0, sizeof *s);
    sv_config *cfg = &s->cfg;
    sv_limits_defaults(cfg);
    s->root_fd = -1;
    lpvd_options opt;
    memset(&opt, 0, sizeof opt);
    char err[2048] = "";
    int have_socket = 0;
    const char *token_file = NULL;

    /* the daemon's own flags, its limits (serve_limits.c), the engine's
     * settings and backend (parsed there), and the camera's, refused: a
     * client sends CAMERA_SET */
    lpv_flag_group groups[6] = {{SERVE_FLAGS, S_COUNT, NULL, NULL}, sv_limits_flag_group(cfg)};
    int ngroups = 2 + lpvd_options_groups(&opt, LPVD_GROUP_SETTINGS | LPVD_GROUP_BACKEND, 1, groups + 2);
    const int camera_group = ngroups;
    ngroups += lpvd_options_groups(&opt, LPVD_GROUP_CAMERA, 0, groups + ngroups);
    lpv_flags p;
    if (lpv_flags_begin(&p, argc, argv, groups, ngroups, 0) != 0) {
        fprintf(stderr, "lpvd serve: %s\n", p.err);
        return 2;
    }
    int g;
    const lpv_flag *fl;
    const char *v;
    for (lpv_flags_item it; (it = lpv_flags_next(&p, &g, &fl, &v)) != LPV_FLAGS_END;) {
        if (lpv_flags_refuse(&p, it, v, "lpvd serve", 0))
            return 2;
        if (g == camera_group) {
            fprintf(stderr, "lpvd serve: --%s is not used by the daemon (clients send CAMERA_SET)\n", fl->name);
            return 2;
        }
        switch (fl - SERVE_FLAGS) {
        case S_HELP: usage(stdout); return 0;
        case S_SOCKET:
            if (!v[0] || strlen(v) >= sizeof cfg->socket_path) {
                fprintf(stderr, "lpvd serve: --socket: bad path\n");
                return 2;
            }
            snprintf(cfg->socket_path, sizeof cfg->socket_path, "%s", v);
            have_socket = 1;
            break;
        case S_LISTEN: {
            unsigned port;
            char perr[256];
            if (lpvp_split_host_port(v, cfg->listen_host, sizeof cfg->listen_host, &port, perr, sizeof perr) != 0) {
                fprintf(stderr, "lpvd serve: --listen %s\n", perr);
                return 2;
            }
            cfg->listen_port = (int)port;
            break;
        }
        case S_TOKEN_FILE: token_file = v; break;
        case S_SCENE_ROOT: {
            char *real = realpath(v, NULL);
            struct stat st;
            if (!real || stat(real, &st) != 0 || !S_ISDIR(st.st_mode) || strlen(real) >= sizeof cfg->scene_root) {
                fprintf(stderr, "lpvd serve: --scene-root %s: %s\n", v, real ? "not a folder" : strerror(errno));
                free(real);
                return 2;
            }
            snprintf(cfg->scene_root, sizeof cfg->scene_root, "%s", real);
            free(real);
            break;
        }
        case S_SCENE: cfg->scene_file = v; break;
        }
    }
    if (cfg->max_body > cfg->max_message)
        cfg->max_body = cfg->max_message;
    if (cfg->max_scenes_memory < cfg->max_scene_bytes) { /* else the largest scene could never load */
        fprintf(stderr, "lpvd serve: --max-scenes-memory %llu is under --max-scene-bytes %llu\n",
                (unsigned long long)cfg->max_scenes_memory, (unsigned long long)cfg->max_scene_bytes);
        return 2;
    }
    if (cfg->max_request_memory < cfg->max_message) { /* else the largest message could never be read */
        fprintf(stderr, "lpvd serve: --max-request-memory %llu is under --max-message %llu\n",
                (unsigned long long)cfg->max_request_memory, (unsigned long long)cfg->max_message);
        return 2;
    }
    if (cfg->tick_rate > cfg->max_tick_rate) {
        fprintf(stderr, "lpvd serve: --tick-rate %g is over --max-tick-rate %g\n", cfg->tick_rate,
                cfg->max_tick_rate);
        return 2;
    }
    if (opt.settings.preset != LPV_PRESET_DEFAULT) { /* a preset's grid counts like --grid */
        lpv_settings chk = opt.settings;
        lpv_settings_resolve(&chk);
        if (chk.grid_dims[0] > cfg->max_grid) {
            fprintf(stderr, "lpvd serve: --preset %s: grid %d is over --max-grid %d\n",
                    lpv_preset_name(chk.preset), chk.grid_dims[0], cfg->max_grid);
            return 2;
        }
    }
    for (int i = 0; i < 3; ++i)
        if (opt.settings.grid_dims[i] > cfg->max_grid) {
            fprintf(stderr, "lpvd serve: --grid is over --max-grid %d\n", cfg->max_grid);
            return 2;
        }
    cfg->settings = opt.settings;
    cfg->backend = opt.backend;
    lpv_settings resolved = cfg->settings;
    lpv_settings_resolve(&resolved);
    if (sv_tick_cost_check(cfg, &resolved, err, sizeof err) != 0) { /* every session starts with it */
        fprintf(stderr, "lpvd serve: the default CONFIG: %s\n", err);
        return 2;
    }
    if (token_file && read_token(token_file, cfg, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd serve: %s\n", err);
        return 2;
    }
    if (have_socket || !cfg->listen_host[0]) {
        cfg->want_unix = 1;
        if (!have_socket)
            lpvp_default_socket_path(cfg->socket_path, sizeof cfg->socket_path);
    }
    /* the root is opened once: every SCENE_LOAD path opens beneath this
     * descriptor (core/open_beneath.h), so renaming or relinking the root's
     * own path later changes nothing */
    if (cfg->scene_root[0] && (s->root_fd = open(cfg->scene_root, O_RDONLY | O_DIRECTORY | O_CLOEXEC)) < 0) {
        fprintf(stderr, "lpvd serve: --scene-root %s: %s\n", cfg->scene_root, strerror(errno));
        return 2;
    }
    if (sv_memory_init(&s->mem, cfg->max_memory, cfg->max_message, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd serve: %s\n", err);
        return 2;
    }
    cfg->max_memory = s->mem.budget; /* 0 meant "from the machine": HELLO says what it came to */
    signal(SIGPIPE, SIG_IGN);

    int rc = 1;
    s->loop = malloc(sizeof *s->loop);
    if (!s->loop || uv_loop_init(s->loop) != 0) {
        fprintf(stderr, "lpvd serve: cannot start the event loop\n");
        free(s->loop);
        return 1;
    }
    pthread_mutex_init(&s->mu, NULL);
    pthread_cond_init(&s->cv, NULL);
    /* what the network layer and the handlers call of the sessions (serve.h) */
    s->session = (sv_session_hooks){.open = sv_session_open, .free = sv_session_free, .pump = sv_session_pump};
    if (load_default_scene(s, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd serve: %s\n", err);
        goto out;
    }
    if (sv_gl_start(s, sv_world_jobs_done, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd serve: %s\n", err);
        goto out;
    }
    /* HELLO's max_grid and CONFIG's check say only what can run: a grid
     * whose storage alone is over one world's memory never could (issue 31,
     * item 11) */
    const int fits = sv_grid_that_fits(s, cfg->max_grid);
    if (fits < cfg->max_grid) {
        fprintf(stderr, "lpvd serve: --max-grid %d lowered to %d: a larger grid's LPV storage alone is over %s\n",
                cfg->max_grid, fits, s->gl_limits.budget_source);
        cfg->max_grid = fits;
    }
    if (sv_net_listen(s, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd serve: %s\n", err);
        sv_net_stop_listening(s);
        sv_gl_stop(s);
        goto out;
    }
    uv_timer_init(s->loop, &s->idle_timer);
    s->idle_timer.data = s;
    uv_timer_start(&s->idle_timer, idle_cb, 1000, 1000);
    uv_signal_init(s->loop, &s->sigterm);
    uv_signal_init(s->loop, &s->sigint);
    uv_signal_init(s->loop, &s->sighup);
    s->sigterm.data = s->sigint.data = s->sighup.data = s;
    uv_signal_start(&s->sigterm, signal_cb, SIGTERM);
    uv_signal_start(&s->sigint, signal_cb, SIGINT);
    uv_signal_start(&s->sighup, sighup_cb, SIGHUP);

    fprintf(stderr, "lpvd serve: lpvd %s, backend %s, GL_RENDERER %s\n", LPVD_VERSION, s->gl_backend,
            s->gl_renderer);
    fprintf(stderr, "lpvd serve: default scene %s (%u triangles)%s%s\n", s->builtin->scene.source,
            s->builtin->scene.index_count / 3, cfg->scene_root[0] ? ", scene root " : "", cfg->scene_root);
    if (cfg->want_unix)
        fprintf(stderr,
                "lpvd serve: listening on unix:%s (connect: lpvctl --address %s tick + volume, or the Python "
                "client: clients/python/lpvd_client.py --self-test %s)\n",
                cfg->socket_path, cfg->socket_path, cfg->socket_path);
    if (cfg->listen_host[0])
        fprintf(stderr, "lpvd serve: listening on tcp:%s:%d%s (connect: lpvctl --address %s:%d%s hello)\n",
                cfg->listen_host, cfg->listen_port, cfg->has_token ? " (token required)" : "", cfg->listen_host,
                cfg->listen_port, cfg->has_token ? " --token-file FILE" : "");
    fflush(stderr);

    uv_run(s->loop, UV_RUN_DEFAULT);
    rc = 0;
    fprintf(stderr, "lpvd serve: stopped (%llu ticks, %llu bytes sent)\n", (unsigned long long)s->ticks,
            (unsigned long long)s->bytes_sent);
out:
    uv_walk(s->loop, close_walk, NULL);
    uv_run(s->loop, UV_RUN_DEFAULT);
    signal(SIGTERM, SIG_IGN); /* closing their handles restored the default (kill); the rest is cleanup */
    signal(SIGINT, SIG_IGN);
    if (s->builtin)
        sv_scene_unref(s, s->builtin);
    while (s->scenes) { /* none should be left; free anyway */
        sv_scene *sc = s->scenes;
        sc->refs = 1;
        sv_scene_unref(s, sc);
    }
    uv_loop_close(s->loop);
    free(s->loop);
    if (s->root_fd >= 0)
        close(s->root_fd);
    pthread_mutex_destroy(&s->mu);
    pthread_cond_destroy(&s->cv);
    return rc;
}
