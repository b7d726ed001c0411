/*
 * serve_session.c - one session per connection (SPEC section 7): its state
 * (scene, materials, lights, camera, config, revision, subscriptions), and
 * the dispatch of its requests, strictly one at a time in arrival order
 * (R3.2). Requests that need the GL thread (TICK, GET_FRAME,
 * QUERY_IRRADIANCE) or a worker (SCENE_LOAD, SCENE_UPDATE of nodes) mark the
 * session busy; its next request waits until the reply has been queued.
 */
#include "serve_session_internal.h"
#include "scene_defaults.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "gltf_load.h"
#include "settings_json.h"
#include "stats_json.h"
#include "settings_fields.h"
#include "volume_codec.h"


/* The names of formats, compressions, terms and streams are the protocol
 * library's (volume_codec.h), indexed by its enums. */

/* ---- replies ------------------------------------------------------------ */
void sv_reply_err(sv_conn *c, uint32_t rid, int code, int noclose, const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    sv_send(c, LPVP_ERROR, rid, lpvp_error_body(code, "%s", msg), NULL, 0, SV_STREAM_NONE);
    if (!noclose && lpvp_error_closes(code))
        sv_conn_close_after_write(c);
}

void sv_reply(sv_conn *c, uint16_t type, uint32_t rid, json_t *body)
{
    sv_send(c, LPVP_REPLY(type), rid, body ? body : json_object(), NULL, 0, SV_STREAM_NONE);
}

json_t *sv_rev_body(sv_conn *c)
{
    return json_pack("{s:I}", "revision", (json_int_t)c->revision);
}

/* ---- session state ------------------------------------------------------ */
static void name_lights(lpv_light *l, uint32_t n)
{
    for (uint32_t i = 0; i < n; ++i) {
        int dup = 0;
        for (uint32_t k = 0; k < i; ++k)
            if (strcmp(l[k].name, l[i].name) == 0)
                dup = 1;
        if (!l[i].name[0] || dup)
            snprintf(l[i].name, sizeof l[i].name, "light%u", i);
    }
}

static void default_view(sv_conn *c)
{
    const lpv_scene *sc = &c->scene->scene;
    int w = c->view_w ? c->view_w : SV_DEFAULT_VIEW_SIDE, h = c->view_h ? c->view_h : SV_DEFAULT_VIEW_SIDE;
    memset(&c->view, 0, sizeof c->view);
    if (c->view_camera >= 0 && (uint32_t)c->view_camera < sc->camera_count)
        lpv_view_from_camera(&sc->cameras[c->view_camera], w, h, &c->view);
    else if (sc->camera_count)
        lpv_view_from_camera(&sc->cameras[0], w, h, &c->view);
    else
        lpv_view_frame_bounds(sc, w, h, &c->view);
}

lpv_light *sv_named_lights(const lpv_scene *sc, int *fail)
{
    *fail = 0;
    if (!sc->light_count)
        return NULL;
    lpv_light *l = calloc(sc->light_count, sizeof *l);
    if (!l) {
        *fail = 1;
        return NULL;
    }
    memcpy(l, sc->lights, sizeof *l * sc->light_count);
    for (uint32_t i = 0; i < sc->light_count; ++i) { /* zero the name padding: lights are keys */
        char nm[LPV_NAME_MAX];
        snprintf(nm, sizeof nm, "%s", l[i].name);
        memset(l[i].name, 0, sizeof l[i].name);
        memcpy(l[i].name, nm, strlen(nm));
    }
    name_lights(l, sc->light_count);
    return l;
}

int sv_session_set_scene(sv_conn *c, sv_scene *sc)
{
    lpv_material *m = NULL;
    lpv_light *l = NULL;
    if (sc->scene.material_count) {
        m = malloc(sizeof *m * sc->scene.material_count);
        if (!m)
            return -1;
        memcpy(m, sc->scene.materials, sizeof *m * sc->scene.material_count);
    }
    int lfail = 0;
    l = sv_named_lights(&sc->scene, &lfail);
    if (lfail) {
        free(m);
        return -1;
    }
    if (c->scene)
        sv_scene_unref(c->srv, c->scene);
    c->scene = sc;
    free(c->materials);
    free(c->lights);
    c->materials = m;
    c->material_count = sc->scene.material_count;
    c->lights = l;
    c->light_count = sc->scene.light_count;
    if (!c->view_explicit) {
        if (c->view_camera >= 0 && (uint32_t)c->view_camera >= sc->scene.camera_count)
            c->view_camera = -1;
        default_view(c);
    }
    return 0;
}

void sv_session_changed(sv_conn *c)
{
    c->revision++;
    sv_inputs *in = sv_inputs_build(c);
    if (in)
        sv_world_attach(c, in);
}

void sv_session_init(sv_conn *c)
{
    sv_server *s = c->srv;
    c->view_camera = -1;
    c->settings = s->cfg.settings;
    c->tick_rate = s->cfg.tick_rate;
    c->subs[0].fp16 = 1;
    s->builtin->refs++;
    if (sv_session_set_scene(c, s->builtin) != 0) {
        sv_conn_close(c);
        return;
    }
    sv_inputs *in = sv_inputs_build(c);
    if (in)
        sv_world_attach(c, in);
}

void sv_session_free(sv_conn *c)
{
    sv_world_detach(c);
    if (c->scene)
        sv_scene_unref(c->srv, c->scene);
    c->scene = NULL;
    free(c->materials);
    free(c->lights);
    c->materials = NULL;
    c->lights = NULL;
    for (int i = 0; i < 2; ++i)
        sv_sub_clear(&c->subs[i]);
}

/* ---- stats -------------------------------------------------------------- */
/* The tick's stats in the one shape of lpvd_tick_stats_json (stats_json.h). */
static json_t *tick_stats(const sv_result *r)
{
    int one = r->cascade_count < 1;
    return lpvd_tick_stats_json(&r->stats, &r->plan, one ? &r->grid : r->cascades, one ? 1 : r->cascade_count,
                                r->tick_ms);
}

/* ---- ticks, volumes, frames, queries -------------------------------------- */
static int world_current(sv_conn *c)
{
    return c->world && c->world->latest && c->world->latest->gen == c->world_gen;
}

static void submit(sv_conn *c, sv_job *j)
{
    j->conn = c;
    c->refs++;
    c->busy = 1;
    sv_job_submit(c->srv, j);
}

void sv_do_tick(sv_conn *c, sv_request *r)
{
    if (c->world && sv_world_join_tick(c->world, c, r->request_id)) { /* shared with a queued tick (R7.2) */
        c->busy = 1;
        return;
    }
    sv_job *j = c->world ? sv_job_new(SV_JOB_TICK, c->world) : NULL;
    if (!j) {
        sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "out of memory");
        return;
    }
    j->request_id = r->request_id;
    j->terms_mask = sv_world_terms_mask(c->world);
    c->world->queued_tick = j;
    submit(c, j);
}

/* GET_FRAME's and SUBSCRIBE frame's "exposure" ("auto" or an EV number) and
 * "transparent" (SPEC R6.4). Returns LPVP_FIELD_BAD with err on a bad value. */
int sv_get_display(const json_t *j, lpv_display *d, char *err, size_t n)
{
    lpv_display_default(d);
    const json_t *e = json_object_get(j, "exposure");
    if (e) {
        char v[64];
        if (json_is_string(e))
            snprintf(v, sizeof v, "%s", json_string_value(e));
        else if (json_is_number(e))
            snprintf(v, sizeof v, "%.9g", json_number_value(e));
        else
            snprintf(v, sizeof v, "(not a string or number)");
        if (lpv_exposure_parse(v, d, err, n) != 0)
            return LPVP_FIELD_BAD;
    }
    return lpvp_get_bool(j, "transparent", 0, &d->transparent, err, n) == LPVP_FIELD_BAD ? LPVP_FIELD_BAD
                                                                                         : LPVP_FIELD_OK;
}

void sv_do_subscribe(sv_conn *c, sv_request *r, json_t *j, int on)
{
    char err[512];
    int stream = 0, fmt = -1, comp = -1, delta = 0, terms = 0;
    lpv_display display;
    lpv_display_default(&display);
    if (lpvp_get_enum(j, "stream", 1, lpvp_stream_names, LPVP_STREAM_COUNT, &stream, err, sizeof err) != LPVP_FIELD_OK)
        goto bad;
    sv_sub *sub = &c->subs[stream];
    if (!on) {
        sub->on = 0;
        sv_sub_clear(sub);
        sv_reply(c, LPVP_UNSUBSCRIBE, r->request_id, json_object());
        return;
    }
    if (lpvp_get_enum(j, "format", 0, stream ? lpvp_frame_format_names : lpvp_volume_format_names,
                      stream ? LPVP_FRAME_FORMAT_COUNT : 2, &fmt, err, sizeof err) ==
            LPVP_FIELD_BAD ||
        lpvp_get_enum(j, "compression", 0, lpvp_compression_names, 2, &comp, err, sizeof err) == LPVP_FIELD_BAD ||
        lpvp_get_bool(j, "delta", 0, &delta, err, sizeof err) == LPVP_FIELD_BAD ||
        (stream && lpvp_get_enum(j, "terms", 0, lpvp_frame_terms_names, LPVP_TERMS_COUNT, &terms, err, sizeof err) == LPVP_FIELD_BAD) ||
        (stream && sv_get_display(j, &display, err, sizeof err) == LPVP_FIELD_BAD))
        goto bad;
    if (stream && delta) {
        snprintf(err, sizeof err, "delta: only the volume stream has deltas");
        goto bad;
    }
    sv_sub_clear(sub);
    sub->on = 1;
    if (stream == SV_STREAM_VOLUME) {
        sub->fp16 = fmt != LPVP_FMT_FP32;
        sub->zstd = comp != LPVP_COMP_NONE; /* default zstd */
        sub->delta = delta;
    } else {
        sub->fmt = fmt < 0 ? LPVP_FRAME_PNG : fmt; /* default png */
        sub->zstd = comp == LPVP_COMP_ZSTD;         /* default none (rgba8 only) */
        sub->terms = terms;
        sub->display = display;
    }
    sv_reply(c, LPVP_SUBSCRIBE, r->request_id, json_object());
    return;
bad:
    sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
}

void sv_do_get_volume(sv_conn *c, sv_request *r, json_t *j)
{
    char err[512];
    int fmt = LPVP_FMT_FP16, comp = LPVP_COMP_ZSTD;
    if (lpvp_get_enum(j, "format", 0, lpvp_volume_format_names, 2, &fmt, err, sizeof err) == LPVP_FIELD_BAD ||
        lpvp_get_enum(j, "compression", 0, lpvp_compression_names, 2, &comp, err, sizeof err) == LPVP_FIELD_BAD) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
        return;
    }
    if (!world_current(c)) {
        sv_reply_err(c, r->request_id, LPVP_E_NOT_READY, 0,
                  "no volume yet for this session's current scene, lights, camera and config: send TICK first");
        return;
    }
    json_t *b = NULL;
    uint8_t *att = NULL;
    size_t alen = 0;
    if (sv_encode_volume(c->world->latest, fmt == LPVP_FMT_FP16, comp == LPVP_COMP_ZSTD, NULL, c->revision, &b, &att, &alen, err,
                         sizeof err) != 0) {
        sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "%s", err);
        return;
    }
    sv_send(c, LPVP_REPLY(LPVP_GET_VOLUME), r->request_id, b, att, alen, SV_STREAM_NONE);
}

static void send_frame_reply(sv_conn *c, uint32_t rid, const float *rgba, int w, int h, int fmt, int zstd, int terms,
                             const lpv_display *display, uint64_t tick)
{
    /* the plan of the tick shown, when it is still the world's latest */
    const lpv_plan *plan = c->world && c->world->latest && c->world->latest->tick == tick ? &c->world->latest->plan
                                                                                          : NULL;
    char err[512];
    json_t *b = NULL;
    uint8_t *att = NULL;
    size_t alen = 0;
    if (sv_encode_frame(rgba, w, h, fmt, zstd, terms, display, c->revision, tick, plan, &b, &att, &alen, err,
                        sizeof err) != 0) {
        sv_reply_err(c, rid, LPVP_E_INTERNAL, 0, "%s", err);
        return;
    }
    sv_send(c, LPVP_REPLY(LPVP_GET_FRAME), rid, b, att, alen, SV_STREAM_NONE);
}

void sv_do_get_frame(sv_conn *c, sv_request *r, json_t *j)
{
    char err[512];
    int fmt = LPVP_FRAME_PNG, comp = LPVP_COMP_NONE, terms = LPVP_TERMS_FULL;
    lpv_display display;
    if (lpvp_get_enum(j, "format", 0, lpvp_frame_format_names, LPVP_FRAME_FORMAT_COUNT, &fmt, err, sizeof err) == LPVP_FIELD_BAD ||
        lpvp_get_enum(j, "compression", 0, lpvp_compression_names, 2, &comp, err, sizeof err) == LPVP_FIELD_BAD ||
        lpvp_get_enum(j, "terms", 0, lpvp_frame_terms_names, LPVP_TERMS_COUNT, &terms, err, sizeof err) == LPVP_FIELD_BAD ||
        sv_get_display(j, &display, err, sizeof err) == LPVP_FIELD_BAD) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
        return;
    }
    if (!world_current(c)) {
        sv_reply_err(c, r->request_id, LPVP_E_NOT_READY, 0,
                  "no tick yet for this session's current scene, lights, camera and config: send TICK first");
        return;
    }
    const sv_result *res = c->world->latest;
    if (res->frames[terms]) { /* rendered with the tick already */
        send_frame_reply(c, r->request_id, res->frames[terms], res->width, res->height, fmt, comp == LPVP_COMP_ZSTD, terms,
                         &display, res->tick);
        return;
    }
    sv_job *jb = sv_job_new(SV_JOB_RENDER, c->world);
    if (!jb) {
        sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "out of memory");
        return;
    }
    jb->request_id = r->request_id;
    jb->terms = terms;
    jb->display = display;
    jb->count = (size_t)fmt | ((size_t)(comp == LPVP_COMP_ZSTD) << 4); /* encoding choice, read back in job_done */
    submit(c, jb);
}

void sv_do_query(sv_conn *c, sv_request *r, json_t *j)
{
    char err[512];
    int64_t count = 0;
    if (lpvp_get_int(j, "count", 1, 0, (int64_t)(c->srv->cfg.max_message / 24), &count, err, sizeof err) !=
        LPVP_FIELD_OK) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
        return;
    }
    if (r->att_len != (size_t)count * 24) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0,
                  "attachment: expected count x 24 = %lld bytes (px py pz nx ny nz float32 per point), got %zu",
                  (long long)count * 24, r->att_len);
        return;
    }
    if (!world_current(c)) {
        sv_reply_err(c, r->request_id, LPVP_E_NOT_READY, 0,
                  "no tick yet for this session's current scene, lights, camera and config: send TICK first");
        return;
    }
    sv_job *jb = sv_job_new(SV_JOB_QUERY, c->world);
    float *pts = malloc(count ? (size_t)count * 24 : 1);
    if (!jb || !pts) {
        free(pts);
        sv_job_free(jb);
        sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "out of memory");
        return;
    }
    for (int64_t i = 0; i < count * 6; ++i) { /* little-endian float32 */
        uint32_t u = lpvp_get_u32(r->att + i * 4);
        float f;
        memcpy(&f, &u, 4);
        pts[i] = f;
    }
    jb->points = pts;
    jb->count = (size_t)count;
    jb->request_id = r->request_id;
    submit(c, jb);
}

void sv_do_stats(sv_conn *c, sv_request *r)
{
    sv_server *s = c->srv;
    json_t *stages = json_array(), *plan = json_object();
    if (c->world && c->world->latest) {
        const sv_result *res = c->world->latest;
        json_decref(plan);
        plan = tick_stats(res);
        json_decref(stages); /* STATS keeps a top-level copy of the tick's stages (SPEC section 4) */
        stages = json_deep_copy(json_object_get(plan, "stages"));
        if (!plan || !stages) { /* out of memory: answer with what is left */
            json_decref(stages);
            stages = json_array();
            if (!plan)
                plan = json_object();
        }
        json_object_set_new(plan, "tick", json_integer((json_int_t)res->tick));
        json_object_set_new(plan, "current", json_boolean(res->gen == c->world_gen));
    }
    json_object_set_new(plan, "backend", json_string(s->gl_backend));
    json_object_set_new(plan, "gl_renderer", json_string(s->gl_renderer));
    json_object_set_new(plan, "config", sv_config_json(c));
    size_t pend = 0, wq = 0, drops = 0;
    int sessions = 0;
    for (sv_conn *o = s->conns; o; o = o->next) {
        pend += o->pending_count;
        wq += o->wq_bytes;
        drops += o->stream_dropped;
        if (o->hello)
            sessions++;
    }
    int shared = 0;
    if (c->world)
        shared = c->world->refs;
    json_t *b = json_pack(
        "{s:o, s:o, s:i, s:i, s:i, s:{s:I, s:I, s:I, s:I, s:I, s:I}, s:I, s:I, s:I, s:I, s:i, s:I}", "stages", stages,
        "plan", plan, "clients", s->conn_count, "sessions", sessions, "worlds", s->world_count, "queues", "gl_jobs",
        (json_int_t)sv_jobs_queued(s), "requests_pending", (json_int_t)pend, "write_bytes", (json_int_t)wq,
        "session_requests_pending", (json_int_t)c->pending_count, "session_write_bytes", (json_int_t)c->wq_bytes,
        "stream_dropped", (json_int_t)drops, "bytes_sent", (json_int_t)s->bytes_sent, "session_bytes_sent",
        (json_int_t)c->bytes_sent, "ticks", (json_int_t)s->ticks, "world_ticks",
        (json_int_t)(c->world && c->world->latest ? c->world->latest->tick : 0), "world_sessions", shared,
        "revision", (json_int_t)c->revision);
    /* tick coalescing (R7.2): computed ticks vs TICK requests answered by a tick queued for another */
    json_object_set_new(b, "ticks_computed", json_integer((json_int_t)s->ticks));
    json_object_set_new(b, "ticks_coalesced", json_integer((json_int_t)s->ticks_coalesced));
    json_object_set_new(b, "world_ticks_computed", json_integer((json_int_t)(c->world ? c->world->ticks_computed : 0)));
    json_object_set_new(b, "world_ticks_coalesced",
                        json_integer((json_int_t)(c->world ? c->world->ticks_coalesced : 0)));
    sv_reply(c, LPVP_STATS, r->request_id, b);
}

void sv_do_ack(sv_conn *c, sv_request *r, json_t *j)
{
    char err[512];
    int stream = 0;
    int64_t tick = 0;
    if (lpvp_get_enum(j, "stream", 1, lpvp_stream_names, 1, &stream, err, sizeof err) != LPVP_FIELD_OK ||
        lpvp_get_int(j, "tick", 1, 0, INT64_MAX, &tick, err, sizeof err) != LPVP_FIELD_OK) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err); /* ACK has no reply, but a bad one is an error */
        return;
    }
    sv_sub_ack(&c->subs[SV_STREAM_VOLUME], (uint64_t)tick);
}

/* ---- completions of GL jobs ---------------------------------------------- */
void sv_session_job_done(sv_job *j, sv_conn *c, uint32_t request_id)
{
    c->busy = 0;
    if (c->closing || c->close_after_write)
        return;
    if (j->status) {
        sv_reply_err(c, request_id, j->status, 0, "%s", j->err);
    } else if (j->kind == SV_JOB_TICK) {
        json_t *b = sv_rev_body(c);
        json_object_set_new(b, "tick", json_integer((json_int_t)j->result->tick));
        json_object_set_new(b, "stats", tick_stats(j->result));
        sv_reply(c, LPVP_TICK, request_id, b);
    } else if (j->kind == SV_JOB_RENDER) {
        send_frame_reply(c, request_id, j->rgba, j->width, j->height, (int)(j->count & 15), (int)(j->count >> 4),
                         j->terms, &j->display, j->tick);
    } else if (j->kind == SV_JOB_QUERY) {
        uint8_t *att = malloc(j->count ? j->count * 12 : 1);
        if (!att) {
            sv_reply_err(c, request_id, LPVP_E_INTERNAL, 0, "out of memory");
        } else {
            for (size_t i = 0; i < j->count * 3; ++i) {
                uint32_t u;
                memcpy(&u, &j->out[i], 4);
                lpvp_put_u32(att + i * 4, u);
            }
            json_t *b = json_pack("{s:I, s:I, s:I}", "revision", (json_int_t)c->revision, "tick", (json_int_t)j->tick,
                                  "count", (json_int_t)j->count);
            sv_send(c, LPVP_REPLY(LPVP_QUERY_IRRADIANCE), request_id, b, att, j->count * 12, SV_STREAM_NONE);
        }
    }
    sv_session_pump(c);
}

/* ---- streams ---------------------------------------------------------------- */
void sv_session_stream(sv_conn *c, sv_result *r)
{
    if (!c->hello || c->close_after_write || c->world_gen != r->gen)
        return;
    char err[512];
    sv_sub *vs = &c->subs[SV_STREAM_VOLUME];
    if (vs->on) {
        json_t *b = NULL;
        uint8_t *att = NULL;
        size_t alen = 0;
        if (sv_encode_volume(r, vs->fp16, vs->zstd, vs, c->revision, &b, &att, &alen, err, sizeof err) == 0)
            sv_send(c, LPVP_VOLUME, 0, b, att, alen, SV_STREAM_VOLUME);
        else
            fprintf(stderr, "lpvd serve: client %llu: volume: %s\n", (unsigned long long)c->id, err);
    }
    sv_sub *fs = &c->subs[SV_STREAM_FRAME];
    if (fs->on && r->frames[fs->terms] && !c->closing) {
        json_t *b = NULL;
        uint8_t *att = NULL;
        size_t alen = 0;
        if (sv_encode_frame(r->frames[fs->terms], r->width, r->height, fs->fmt, fs->zstd, fs->terms, &fs->display,
                            c->revision,
                            r->tick, &r->plan, &b, &att, &alen, err, sizeof err) == 0)
            sv_send(c, LPVP_FRAME, 0, b, att, alen, SV_STREAM_FRAME);
        else
            fprintf(stderr, "lpvd serve: client %llu: frame: %s\n", (unsigned long long)c->id, err);
    }
}

/* ---- dispatch ---------------------------------------------------------------- */
static void dispatch(sv_conn *c, sv_request *r)
{
    sv_server *s = c->srv;
    s->requests++;
    if (!lpvp_type_is_request(r->type)) {
        sv_reply_err(c, r->request_id, LPVP_E_UNKNOWN_TYPE, 0, "message type 0x%04x is not a request this server knows",
                  r->type);
        return;
    }
    char err[512];
    json_t *j = lpvp_body_parse(r->json, r->json_len, err, sizeof err);
    if (!j) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_JSON, 0, "%s", err);
        return;
    }
    if (s->stopping) {
        sv_reply_err(c, r->request_id, LPVP_E_SHUTTING_DOWN, 0, "the server is stopping");
    } else if (r->type == LPVP_HELLO) {
        sv_do_hello(c, r, j);
    } else if (!c->hello) {
        sv_reply_err(c, r->request_id, LPVP_E_HELLO_REQUIRED, 0, "%s before HELLO: send HELLO first",
                  lpvp_type_name(r->type));
    } else {
        switch (r->type) {
        case LPVP_SCENE_LOAD: sv_do_scene_load(c, r, j); break;
        case LPVP_SCENE_UPDATE: sv_do_scene_update(c, r, j); break;
        case LPVP_LIGHT_SET: sv_do_light_set(c, r, j); break;
        case LPVP_LIGHT_REMOVE: sv_do_light_remove(c, r, j); break;
        case LPVP_CAMERA_SET: sv_do_camera_set(c, r, j); break;
        case LPVP_CONFIG: sv_do_config(c, r, j); break;
        case LPVP_TICK: sv_do_tick(c, r); break;
        case LPVP_SUBSCRIBE: sv_do_subscribe(c, r, j, 1); break;
        case LPVP_UNSUBSCRIBE: sv_do_subscribe(c, r, j, 0); break;
        case LPVP_GET_VOLUME: sv_do_get_volume(c, r, j); break;
        case LPVP_GET_FRAME: sv_do_get_frame(c, r, j); break;
        case LPVP_QUERY_IRRADIANCE: sv_do_query(c, r, j); break;
        case LPVP_STATS: sv_do_stats(c, r); break;
        case LPVP_BYE:
            sv_reply(c, LPVP_BYE, r->request_id, json_object());
            sv_conn_close_after_write(c);
            break;
        case LPVP_ACK: sv_do_ack(c, r, j); break;
        default:
            sv_reply_err(c, r->request_id, LPVP_E_UNKNOWN_TYPE, 0, "message type 0x%04x is not handled", r->type);
        }
    }
    json_decref(j);
}

void sv_session_pump(sv_conn *c)
{
    if (c->closed)
        return;
    c->refs++;
    while (!c->busy && !c->closing && !c->close_after_write && c->pending_head) {
        sv_request *r = c->pending_head;
        c->pending_head = r->next;
        if (!c->pending_head)
            c->pending_tail = NULL;
        c->pending_count--;
        c->pending_bytes -= r->json_len + r->att_len;
        dispatch(c, r);
        free(r->json);
        free(r->att);
        free(r);
    }
    if (!c->closing)
        sv_net_resume_reading(c);
    sv_conn_unref(c);
}
