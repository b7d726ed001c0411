/*
 * serve_session.c - one session per connection (SPEC section 7): its state
 * (scene, materials, lights, camera, config, revision, subscriptions), the
 * reply helpers, and the dispatch of its requests, strictly one at a time in
 * arrival order (R3.2). The handlers live in one file per job (listed in
 * serve_session_internal.h). Requests that need the GL thread (TICK,
 * GET_FRAME, QUERY_IRRADIANCE) or a worker (SCENE_LOAD, SCENE_UPDATE of
 * nodes) mark the session busy; its next request waits until the reply has
 * been queued.
 */
#include "serve_session_internal.h"

#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- replies ------------------------------------------------------------ */
void sv_reply_err(sv_conn *c, uint32_t rid, int code, int noclose, const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    sv_send(c, LPVP_ERROR, rid, lpvp_error_body(code, "%s", msg), NULL, 0, SV_STREAM_NONE);
    /* SHUTTING_DOWN closes, but not yet: the requests queued behind this one
     * get their own, then BYE (sv_session_shutdown closes, R7.4) */
    if (!noclose && lpvp_error_closes(code) && code != LPVP_E_SHUTTING_DOWN)
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

/* What the session's world calls when its GL jobs come back and after each
 * tick (serve.h); set before anything can submit a job. */
static const sv_world_listener world_listener = {
    .job_done = sv_session_job_done,
    .tick_result = sv_session_stream,
};

void sv_session_init(sv_conn *c)
{
    sv_server *s = c->srv;
    c->listener = &world_listener;
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

/* ---- requests on worker threads, and shutdown ------------------------------ */
void sv_session_work_begin(sv_conn *c, uint32_t request_id)
{
    c->work_inflight = 1;
    c->work_request_id = request_id;
    c->srv->works_inflight++;
}

void sv_session_work_end(sv_conn *c)
{
    c->work_inflight = 0;
    c->srv->works_inflight--;
}

void sv_session_shutdown(sv_conn *c)
{
    if (c->closing || c->close_after_write)
        return;
    /* A load on a worker cannot be stopped: it is answered now and its
     * result dropped when it ends (the connection is closing by then). */
    if (c->work_inflight)
        sv_reply_err(c, c->work_request_id, LPVP_E_SHUTTING_DOWN, 1, "the server is stopping");
    for (sv_request *r = c->pending_head; r; r = r->next)
        if (lpvp_type_has_reply(r->type))
            sv_reply_err(c, r->request_id, LPVP_E_SHUTTING_DOWN, 1, "the server is stopping");
    sv_send(c, LPVP_BYE_REPLY, 0, json_object(), NULL, 0, SV_STREAM_NONE);
    sv_conn_close_after_write(c);
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
        sv_net_request_handled(c, r->json_len + r->att_len);
        dispatch(c, r);
        free(r->json);
        free(r->att);
        free(r);
    }
    if (!c->closing)
        sv_net_resume_reading(c);
    sv_conn_unref(c);
}
