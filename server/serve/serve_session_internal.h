/*
 * serve_session_internal.h - what the files of the session layer share, and
 * nothing outside it includes (serve.h is the daemon's common header):
 *
 *   serve_reply.c     REPLY and ERROR, the revision body
 *   serve_session.c   session state and what changes it
 *   serve_sub.c       a delta subscriber's bases (sv_sub_*, serve.h)
 *   serve_hello.c     HELLO and the token check
 *   serve_scene.c     SCENE_LOAD, SCENE_UPDATE and their load worker
 *   serve_controls.c  LIGHT_SET, LIGHT_REMOVE, CAMERA_SET, CONFIG
 *   serve_results.c   TICK, GET_VOLUME, GET_FRAME, QUERY_IRRADIANCE, STATS
 *                     and the replies of GL jobs
 *   serve_streams.c   SUBSCRIBE, UNSUBSCRIBE, ACK and the VOLUME / FRAME
 *                     streams after each tick
 *   serve_encode_work.c  their payloads encoded on libuv's work threads
 *   serve_dispatch.c  dispatch to the handlers, the request pump
 *
 * Each file uses only those listed below it in serve.h's layering (no
 * circle of files): the handlers use the replies and the session state,
 * the dispatcher uses the handlers, and a handler that answers a busy
 * request later goes on with the session's next requests through
 * sv_session_go_on (the pump registered in sv_server.session).
 *
 * Everything here runs on the loop thread. Each sv_do_* handles one request
 * type for dispatch (serve_dispatch.c): it either replies before it returns or
 * marks the session busy and replies later (R3.2).
 */
#ifndef LPVD_SERVE_SESSION_INTERNAL_H
#define LPVD_SERVE_SESSION_INTERNAL_H

#include "serve.h"

/* The names of formats, compressions, terms and streams are the protocol
 * library's (volume_codec.h, through serve.h), indexed by its enums. */

/* the side of the default view, used until CAMERA_SET gives a size */
#define SV_DEFAULT_VIEW_SIDE 256

/* ---- replies (serve_reply.c) ---- */
/* ERROR reply; closes the connection when the code does (R3.4), unless
 * noclose (HELLO's BAD_VERSION, R4.1). */
void sv_reply_err(sv_conn *c, uint32_t rid, int code, int noclose, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
void sv_reply(sv_conn *c, uint16_t type, uint32_t rid, json_t *body); /* body NULL: {} */
json_t *sv_rev_body(sv_conn *c); /* {"revision": the session's} */

/* ---- session state (serve_session.c) ---- */
/* A busy request of c has been answered (or c may go on): handle its next
 * requests, through the pump the daemon registered (serve_dispatch.c's
 * sv_session_pump): the handlers are below the dispatcher. */
static inline void sv_session_go_on(sv_conn *c)
{
    c->srv->session.pump(c);
}
/* The scene's lights with clean names (their ids). NULL when it has none. */
lpv_light *sv_named_lights(const lpv_scene *sc, int *fail);
/* Takes the scene (a reference) as the session's, with its materials and
 * lights; resets the camera unless an explicit one was set. */
int sv_session_set_scene(sv_conn *c, sv_scene *sc);
/* After any change of the session's inputs: a new revision and the world of
 * the new inputs. */
void sv_session_changed(sv_conn *c);

/* ---- shapes shared by several replies ---- */
json_t *sv_config_json(sv_conn *c); /* CONFIG and STATS "config" (serve_controls.c) */
/* GET_FRAME's and SUBSCRIBE frame's "exposure" and "transparent"
 * (serve_results.c) */
int sv_get_display(const json_t *j, lpv_display *d, char *err, size_t n);
/* GET_FRAME's and SUBSCRIBE frame's "terms": 0 when the session's settings
 * render them; -1 with a message naming "terms" for "ao" without technique iv
 * and iv_ao on (SPEC section 6, BAD_FIELD). */
int sv_terms_check(const sv_conn *c, int terms, char *err, size_t n);

/* ---- encoding on libuv's work threads, sending on the loop (serve_encode_work.c) ----
 * A reply keeps the session busy until it is queued (R3.2) and carries the
 * revision of when the request was handled (R3.3); a frame over --max-queue
 * is not sent: ERROR LIMIT instead (R3.5). */
void sv_reply_volume(sv_conn *c, uint32_t rid, sv_result *r, int content, const sv_volume_coding *how);
/* rgba_owned: a rendered frame, taken; NULL: r's frames[terms], r referenced */
void sv_reply_frame(sv_conn *c, uint32_t rid, sv_result *r, float *rgba_owned, int w, int h, int fmt, int zstd,
                    int terms, const lpv_display *display, uint64_t tick);
void sv_reply_query(sv_conn *c, uint32_t rid, float *out_owned, size_t count, uint64_t tick); /* out: taken */
/* The stream's message of tick result r, after the one in flight (a newer
 * result replaces one still waiting, R5.5). */
void sv_stream_result(sv_conn *c, int stream, sv_result *r);

/* ---- what the world reports, through sv_world_listener (serve.h) ---- */
void sv_session_job_done(sv_job *j, sv_conn *c, uint32_t request_id); /* serve_results.c */
void sv_session_stream(sv_conn *c, sv_result *r);                     /* serve_streams.c */

/* ---- one handler per request type ---- */
void sv_do_hello(sv_conn *c, sv_request *r, json_t *j);        /* serve_hello.c */
void sv_do_scene_load(sv_conn *c, sv_request *r, json_t *j);   /* serve_scene.c */
void sv_do_scene_update(sv_conn *c, sv_request *r, json_t *j);
void sv_do_light_set(sv_conn *c, sv_request *r, json_t *j);    /* serve_controls.c */
void sv_do_light_remove(sv_conn *c, sv_request *r, json_t *j);
void sv_do_camera_set(sv_conn *c, sv_request *r, json_t *j);
void sv_do_config(sv_conn *c, sv_request *r, json_t *j);
void sv_do_tick(sv_conn *c, sv_request *r);                    /* serve_results.c */
void sv_do_get_volume(sv_conn *c, sv_request *r, json_t *j);
void sv_do_get_frame(sv_conn *c, sv_request *r, json_t *j);
void sv_do_query(sv_conn *c, sv_request *r, json_t *j);
void sv_do_stats(sv_conn *c, sv_request *r);
void sv_do_subscribe(sv_conn *c, sv_request *r, json_t *j, int on); /* serve_streams.c; on 0: UNSUBSCRIBE */
void sv_do_ack(sv_conn *c, sv_request *r, json_t *j);

#endif
