/*
 * serve_dispatch.c - the dispatch of a session's requests, strictly one at a
 * time in arrival order (R3.2), to one handler per request type (listed in
 * serve_session_internal.h), and the start of a session, which points its
 * world's reports at the handlers' (sv_world_listener). Requests that need
 * the GL thread (TICK, GET_FRAME, QUERY_IRRADIANCE) or a worker (SCENE_LOAD,
 * SCENE_UPDATE of nodes) mark the session busy; its next request waits until
 * the reply has been queued, and the handler that queues it goes on through
 * the server's sv_session_hooks (serve.h), this file's sv_session_pump: the
 * dispatcher is the one file of the session layer above the handlers.
 */
#include "serve_session_internal.h"

#include <stdlib.h>

/* What the session's world calls when its GL jobs come back and after each
 * tick (serve.h); set before anything can submit a job. */
static const sv_world_listener world_listener = {
    .job_done = sv_session_job_done,
    .tick_result = sv_session_stream,
};

void sv_session_open(sv_conn *c)
{
    c->listener = &world_listener;
    sv_session_init(c);
}

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
