/*
 * serve_streams.c - a session's subscriptions (SPEC sections 5 and 6):
 * SUBSCRIBE and UNSUBSCRIBE of the volume and frame streams, ACK of delta
 * volumes, and the delivery of VOLUME / FRAME messages after each tick of the
 * session's world (sv_session_stream, which the world calls through its
 * listener after the tick's replies). A delta subscriber's bases (sv_sub_*)
 * are serve_sub.c's.
 */
#include "serve_session_internal.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void sv_do_subscribe(sv_conn *c, sv_request *r, json_t *j, int on)
{
    char err[512];
    int stream = 0, fmt = -1, comp = -1, delta = 0, terms = 0;
    sv_volume_coding vol = {0};
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
    if ((!stream && sv_volume_coding_parse(j, &vol, err, sizeof err) != 0) ||
        (stream && lpvp_get_enum(j, "format", 0, lpvp_frame_format_names, LPVP_FRAME_FORMAT_COUNT, &fmt, err,
                                 sizeof err) == LPVP_FIELD_BAD) ||
        (stream && lpvp_get_enum(j, "compression", 0, lpvp_compression_names, 2, &comp, err, sizeof err) ==
                       LPVP_FIELD_BAD) ||
        lpvp_get_bool(j, "delta", 0, &delta, err, sizeof err) == LPVP_FIELD_BAD ||
        (stream && lpvp_get_enum(j, "terms", 0, lpvp_frame_terms_names, LPVP_TERMS_COUNT, &terms, err, sizeof err) == LPVP_FIELD_BAD) ||
        (stream && sv_get_display(j, &display, err, sizeof err) == LPVP_FIELD_BAD) ||
        (stream && sv_terms_check(c, terms, err, sizeof err) != 0))
        goto bad;
    if (stream && delta) {
        snprintf(err, sizeof err, "delta: only the volume stream has deltas");
        goto bad;
    }
    sv_sub_clear(sub);
    sub->on = 1;
    if (stream == SV_STREAM_VOLUME) {
        sub->vol = vol;
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

/* ---- streams ---------------------------------------------------------------- */
/* After every reply of a tick of c's world: the subscribed messages, encoded
 * on a work thread (serve_encode_work.c), newest first when it falls behind. */
void sv_session_stream(sv_conn *c, sv_result *r)
{
    if (!c->hello || c->close_after_write || c->world_gen != r->gen)
        return;
    if (c->subs[SV_STREAM_VOLUME].on)
        sv_stream_result(c, SV_STREAM_VOLUME, r);
    sv_sub *fs = &c->subs[SV_STREAM_FRAME];
    if (fs->on && r->frames[fs->terms] && !c->closing)
        sv_stream_result(c, SV_STREAM_FRAME, r);
}
