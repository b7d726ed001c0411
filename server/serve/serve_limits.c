/*
 * serve_limits.c - the daemon's limits, one row each (serve_limits.h). A
 * limit is added here and nowhere else: the flag, its check, its line in
 * `lpvd serve --help` and its key in HELLO's limits follow from the row.
 * The checks between limits (--max-body at most --max-message, ...) stay in
 * lpvd_cmd_serve, after every flag is read.
 */
#include "serve_limits.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "grid.h"
#include "proto.h"
#include "serve.h"

#define P2(k) ((double)((uint64_t)1 << (k)))
#define ROW(fld) .type = _Generic(((struct sv_config *)0)->fld, int: SV_LIMIT_INT, uint64_t: SV_LIMIT_U64, \
                                  double: SV_LIMIT_REAL), .offset = offsetof(struct sv_config, fld)

static const char LIMITS[] = "Limits";
static const char PREAUTH[] = "Before HELLO (a connection that has not yet said HELLO with the token)";
static const char SESSION[] = "Default CONFIG of every session";

const sv_limit sv_limits[] = {
    {"max-clients", "N", LIMITS, "max_clients", ROW(max_clients), 1, 100000, 64, "connections at once", NULL},
    {"max-message", "BYTES", LIMITS, "max_message", ROW(max_message), 64, P2(40), LPVP_DEFAULT_MAX_MESSAGE,
     "json + attachment of one message", NULL},
    {"max-body", "BYTES", LIMITS, "max_body", ROW(max_body), 64, UINT32_MAX, LPVP_DEFAULT_MAX_BODY,
     "json of one message", "lowered to --max-message"},
    /* at least 64 KiB: no reply over it is sent (R3.5), and HELLO's, which
     * describes every knob, takes ~15 KiB */
    {"max-queue", "BYTES", LIMITS, "max_queue", ROW(max_queue), 65536, P2(40), P2(26),
     "reply bytes queued for one client before it is dropped", NULL},
    {"max-world-memory", "BYTES", LIMITS, "max_world_memory", ROW(max_world_memory), P2(20), P2(44), P2(30),
     "GPU storage one world (one computation) may take", NULL},
    /* 0: sv_memory_init takes half of the machine's memory (or its cgroup's
     * limit); lpvd_cmd_serve then writes the budget back, which HELLO says */
    {"max-memory", "BYTES", LIMITS, "max_memory", ROW(max_memory), P2(20), P2(48), 0,
     "all worlds' storage, live scenes, requests, replies, delta bases and kept encodings together",
     "half of the machine's memory, or of its cgroup's limit;\nthe worlds also stay within half of the video memory"},
    {"max-request-memory", "BYTES", LIMITS, "max_request_memory", ROW(max_request_memory), 1024, P2(44), P2(30),
     "request bytes held for all clients together; a frame that\ndoes not fit waits, unread",
     "at least --max-message"},
    {"max-triangles", "N", LIMITS, "max_triangles", ROW(max_triangles), 1, P2(40), 10000000, "per scene", NULL},
    {"max-texture", "N", LIMITS, "max_texture", ROW(max_texture), 16, P2(20), 8192,
     "texels per texture side, and the largest rsm_size and\nshadow_size", NULL},
    /* 64 Mi texels is 256 MiB of RGBA8, eight 4096² or one 8192² texture */
    {"max-scene-texels", "N", LIMITS, "max_scene_texels", ROW(max_scene_texels), 1, P2(40), P2(26),
     "decoded texels of one scene's images, from their headers", NULL},
    /* 2 GiB holds a scene at the other defaults (a 256 MiB file, 256 MiB of
     * texels and the model of 10 M indexed triangles, ~1 GB), with room */
    {"max-scene-bytes", "BYTES", LIMITS, "max_scene_bytes", ROW(max_scene_bytes), 1024, P2(44), P2(31),
     "memory one parsed scene may take: file, buffers, texels,\nmodel", NULL},
    {"max-scenes-memory", "BYTES", LIMITS, "max_scenes_memory", ROW(max_scenes_memory), 1024, P2(44), P2(32),
     "all live scenes together, each counted once", "at least --max-scene-bytes"},
    {"max-grid", "N", LIMITS, "max_grid", ROW(max_grid), 1, LPV_MAX_GRID_DIM, 128, "LPV cells per axis",
     "lowered at start to the grid one world holds\nunder --max-world-memory: 120 at its default"},
    {"max-tick-rate", "HZ", LIMITS, "max_tick_rate", ROW(max_tick_rate), 0, 10000, 60, "CONFIG tick_rate_hz", NULL},
    {"max-tick-cost", "N", LIMITS, "max_tick_cost", ROW(max_tick_cost), 1, P2(50), SV_DEFAULT_MAX_TICK_COST,
     "cell-steps one tick may cost: CONFIG over it gets LIMIT", NULL},
    {"max-tick-ms", "MS", LIMITS, "max_tick_ms", ROW(max_tick_ms), 0, 1e9, SV_DEFAULT_MAX_TICK_MS,
     "a world whose tick after a change took longer on the GL\nthread is refused such ticks (LIMIT) until its "
     "settings or\ncamera size change", "0 = no limit"},
    {"idle-timeout", "S", LIMITS, "idle_timeout", ROW(idle_timeout), 0, 1e9, 300,
     "a session with no complete frame for S s is sent BYE and\nclosed", "0 = never"},
    {"max-preauth-body", "BYTES", PREAUTH, "max_preauth_body", ROW(max_preauth_body), 64, UINT32_MAX, 4096,
     "JSON of a frame; any attachment is refused", NULL},
    {"handshake-timeout", "S", PREAUTH, "handshake_timeout", ROW(handshake_timeout), 0, 1e9, 10,
     "no HELLO within S s of connecting: ERROR LIMIT, closed", "0 = none"},
    {"max-preauth", "N", PREAUTH, "max_preauth", ROW(max_preauth), 1, 100000, 16,
     "such connections at once, apart from --max-clients", NULL},
    {"tick-rate", "HZ", SESSION, NULL, ROW(tick_rate), 0, 10000, 0, "periodic ticks per second",
     "only TICK requests"},
};
const size_t sv_limit_count = sizeof sv_limits / sizeof sv_limits[0];

static void set_value(struct sv_config *cfg, const sv_limit *l, double v)
{
    char *at = (char *)cfg + l->offset;
    switch (l->type) {
    case SV_LIMIT_INT: *(int *)(void *)at = (int)v; break;
    case SV_LIMIT_U64: *(uint64_t *)(void *)at = (uint64_t)v; break;
    case SV_LIMIT_REAL: *(double *)(void *)at = v; break;
    }
}

static double get_value(const struct sv_config *cfg, const sv_limit *l)
{
    const char *at = (const char *)cfg + l->offset;
    switch (l->type) {
    case SV_LIMIT_INT: return *(const int *)(const void *)at;
    case SV_LIMIT_U64: return (double)*(const uint64_t *)(const void *)at;
    case SV_LIMIT_REAL: break;
    }
    return *(const double *)(const void *)at;
}

void sv_limits_defaults(struct sv_config *cfg)
{
    for (size_t i = 0; i < sv_limit_count; ++i)
        set_value(cfg, &sv_limits[i], sv_limits[i].deflt);
}

/* A bound as help writes it: powers of two from 2^20 as "2^k". */
static void fmt_bound(char *buf, size_t n, const sv_limit *l, double v)
{
    int k;
    if (l->type != SV_LIMIT_REAL && v >= P2(20) && frexp(v, &k) == 0.5)
        snprintf(buf, n, "2^%d", k - 1);
    else
        snprintf(buf, n, l->type == SV_LIMIT_REAL ? "%g" : "%.0f", v);
}

static lpv_flag limit_flags[sizeof sv_limits / sizeof sv_limits[0]];

static int parse_limit(void *target, const lpv_flag *f, const char *v, char *err, size_t n)
{
    const sv_limit *l = &sv_limits[f - limit_flags];
    char *end = NULL;
    double x;
    errno = 0;
    if (l->type == SV_LIMIT_REAL) {
        x = strtod(v, &end);
    } else {
        unsigned long long u = strtoull(v, &end, 10);
        x = v[0] == '-' || v[0] == '+' ? NAN : (double)u;
    }
    char lo[32], hi[32];
    fmt_bound(lo, sizeof lo, l, l->lo);
    fmt_bound(hi, sizeof hi, l, l->hi);
    if (!v[0] || end == v || *end || errno || !(x >= l->lo && x <= l->hi)) {
        snprintf(err, n, "--%s %s: expected %s in %s..%s", l->flag, v,
                 l->type == SV_LIMIT_REAL ? "a number" : "a whole number", lo, hi);
        return -1;
    }
    set_value(target, l, x);
    return 0;
}

lpv_flag_group sv_limits_flag_group(struct sv_config *cfg)
{
    for (size_t i = 0; i < sv_limit_count; ++i)
        limit_flags[i] = (lpv_flag){sv_limits[i].flag, 0, sv_limits[i].metavar, sv_limits[i].help};
    return (lpv_flag_group){limit_flags, sv_limit_count, parse_limit, cfg};
}

void sv_limits_help(char *buf, size_t size, size_t *len, const char *section)
{
    for (size_t i = 0; i < sv_limit_count; ++i) {
        const sv_limit *l = &sv_limits[i];
        if (strcmp(l->section, section) != 0)
            continue;
        char lo[32], hi[32], text[512];
        fmt_bound(lo, sizeof lo, l, l->lo);
        fmt_bound(hi, sizeof hi, l, l->hi);
        if (l->deflt == 0.0 && l->note && l->lo > 0.0) /* 0 is no value a user gives: the note says what it is */
            snprintf(text, sizeof text, "%s\n(%s..%s; default: %s)", l->help, lo, hi, l->note);
        else
            snprintf(text, sizeof text, "%s\n(%s..%s; default %.*f%s%s)", l->help, lo, hi,
                     l->deflt == floor(l->deflt) ? 0 : 3, l->deflt, l->note ? "; " : "", l->note ? l->note : "");
        lpv_flag f = {l->flag, 0, l->metavar, text};
        lpv_flags_help(buf, size, len, &f, 1);
    }
}

void sv_limits_hello(const struct sv_config *cfg, json_t *lim)
{
    for (size_t i = 0; i < sv_limit_count; ++i) {
        const sv_limit *l = &sv_limits[i];
        if (!l->hello)
            continue;
        const double v = get_value(cfg, l);
        json_object_set_new(lim, l->hello, l->type == SV_LIMIT_REAL ? json_real(v) : json_integer((json_int_t)v));
    }
}

/* QUERY_IRRADIANCE's largest count (serve.h): here with the limits it
 * follows from, for HELLO's limits and the query's check alike. */
uint64_t sv_query_points_by_message(const sv_config *cfg)
{
    return cfg->max_message > SV_QUERY_BODY_ROOM ? (cfg->max_message - SV_QUERY_BODY_ROOM) / 24 : 0;
}

uint64_t sv_query_points_by_queue(const sv_config *cfg)
{
    return cfg->max_queue > SV_QUERY_REPLY_ROOM ? (cfg->max_queue - SV_QUERY_REPLY_ROOM) / 12 : 0;
}

uint64_t sv_max_query_points(const sv_config *cfg)
{
    const uint64_t a = sv_query_points_by_message(cfg), b = sv_query_points_by_queue(cfg);
    return a < b ? a : b;
}
