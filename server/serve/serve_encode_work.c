/*
 * serve_encode_work.c - nothing heavy on the event loop (issue 14, item 4):
 * the payloads of GET_VOLUME, GET_FRAME, QUERY_IRRADIANCE and of the VOLUME /
 * FRAME streams are packed, compressed and encoded (fp16, XOR, zstd, PNG,
 * EXR: export_encode.c) on libuv's work threads; the loop only sends what
 * comes back. A 4096x4096 EXR took 14 s on the loop and held every other
 * client's STATS for seconds.
 *
 * Ordering: a reply's session stays busy until the reply is queued (R3.2),
 * exactly as when a GL job answers it; its revision is taken when the request
 * is handled (R3.3). A stream has at most one encoding in flight per session;
 * a newer tick's result waits for it and replaces an older waiting one
 * (R5.5's "newest replaces the unsent one").
 *
 * Size: a frame larger than the session's queue limit (--max-queue) is never
 * sent: a reply becomes ERROR LIMIT naming the size and the limit (the
 * connection stays open), a stream message becomes ERROR LIMIT with
 * request_id 0 (SPEC R3.5).
 *
 * Threads: a task owns its inputs (a reference to the immutable result, or
 * the rgba / query output taken from the finished GL job, a delta base lent
 * by the subscription) and touches nothing else; its outputs go back to the
 * loop in after_work. The connection is only referenced (refs on the loop).
 */
#include "serve_session_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef enum enc_kind { ENC_VOLUME, ENC_FRAME, ENC_QUERY } enc_kind;

typedef struct enc_task {
    uv_work_t work;
    sv_conn *c;             /* ref */
    enc_kind kind;
    uint16_t type;          /* the frame to send */
    uint32_t rid;           /* a reply's request_id (0 for a stream message) */
    int stream;             /* SV_STREAM_NONE: a reply */
    int on_worker;          /* a reply encoding on a libuv worker (sv_session_work_begin) */
    uint64_t revision;      /* the session's when the request was handled */
    sv_result *r;           /* ref: the volume, or the frame (r->frames) */
    /* volume */
    int content;
    sv_volume_coding how;
    int zstd;               /* frame */
    int unchanged;          /* an shq delta with nothing to send (R5.16) */
    uint64_t encode_ns;     /* the work thread's CPU time on a volume */
    int keep;               /* a delta subscriber: the client's volume comes back in kept */
    sv_sent base;           /* lent by the subscription (raw NULL: none) */
    uint32_t epoch;         /* the subscription's when the base was lent */
    sv_sent kept;
    /* frame */
    const float *rgba;      /* in r->frames or rgba_owned */
    float *rgba_owned;
    int w, h, fmt, terms;
    lpv_display display;
    uint64_t tick;          /* frame, query: the tick shown */
    lpv_plan plan;
    int has_plan;
    /* query */
    float *out;             /* 3 x count floats, owned */
    size_t count;
    /* results */
    json_t *body;
    uint8_t *att;
    size_t att_len;
    int failed;
    char err[512];
} enc_task;

/* The calling thread's CPU time: an encoding's cost, whatever else (the GL
 * thread, a client on the same machine) competes for the cores meanwhile. */
static uint64_t thread_cpu_ns(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0)
        return 0;
    return (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
}

static void work_cb(uv_work_t *w)
{
    enc_task *t = w->data;
    if (t->kind == ENC_VOLUME) {
        uint64_t t0 = thread_cpu_ns();
        sv_memory *m = &t->c->srv->mem;
        /* the caches may take what the budget leaves now (R7.6a) */
        const sv_encode_memory mem = {.bases = &m->held[SV_MEM_BASES],
                                      .encodings = &m->held[SV_MEM_ENCODINGS],
                                      .encodings_limit = sv_memory_room(m, SV_MEM_ENCODINGS)};
        int rc = sv_encode_volume(t->r, t->content, &t->how, t->base.raw ? &t->base : NULL, t->keep ? &t->kept : NULL,
                                  &mem, t->revision, &t->body, &t->att, &t->att_len, t->err, sizeof t->err);
        t->failed = rc < 0;
        t->unchanged = rc == 1;
        t->encode_ns = thread_cpu_ns() - t0;
    } else if (t->kind == ENC_FRAME) {
        t->failed = sv_encode_frame(t->rgba, t->w, t->h, t->fmt, t->zstd, t->terms, &t->display, t->revision, t->tick,
                                    t->has_plan ? &t->plan : NULL, &t->body, &t->att, &t->att_len, t->err,
                                    sizeof t->err) != 0;
    } else { /* query: count x 3 little-endian float32 */
        t->att = malloc(t->count ? t->count * 12 : 1);
        t->body = json_pack("{s:I, s:I, s:I}", "revision", (json_int_t)t->revision, "tick", (json_int_t)t->tick,
                            "count", (json_int_t)t->count);
        if (!t->att || !t->body) {
            t->failed = 1;
            snprintf(t->err, sizeof t->err, "out of memory for %zu answers", t->count);
            return;
        }
        for (size_t i = 0; i < t->count * 3; ++i) {
            uint32_t u;
            memcpy(&u, &t->out[i], 4);
            lpvp_put_u32(t->att + i * 4, u);
        }
        t->att_len = t->count * 12;
    }
}

static const char *what_of(const enc_task *t)
{
    if (t->stream == SV_STREAM_VOLUME)
        return "VOLUME stream message";
    if (t->stream == SV_STREAM_FRAME)
        return "FRAME stream message";
    return t->kind == ENC_VOLUME ? "GET_VOLUME reply" : t->kind == ENC_FRAME ? "GET_FRAME reply"
                                                                              : "QUERY_IRRADIANCE reply";
}

/* What the client can change to get a smaller frame. */
static const char *smaller_of(const enc_task *t)
{
    if (t->kind == ENC_VOLUME)
        return "a smaller grid, format \"fp16\" or compression \"zstd\"";
    if (t->kind == ENC_FRAME)
        return "a smaller camera width and height (CAMERA_SET), or format \"png\" or \"rgba8\" with compression "
               "\"zstd\"";
    return "fewer points per request";
}

static void stream_next(sv_conn *c, int stream);

/* The lent delta base back to its subscription (unless it was cleared or
 * has ACKed a newer volume meanwhile), and the sent raw volume remembered. */
static void volume_stream_state(sv_conn *c, enc_task *t, int sent)
{
    sv_sub *sub = &c->subs[SV_STREAM_VOLUME];
    int same = sub->epoch == t->epoch && sub->on;
    if (same && !sub->acked.raw && t->base.raw) {
        sub->acked = t->base;
        t->base.raw = NULL;
    }
    sv_blob_unref(t->base.raw);
    t->base.raw = NULL;
    if (same && sent && t->kept.raw)
        sv_sub_remember(sub, &t->kept);
    else
        sv_blob_unref(t->kept.raw);
    t->kept.raw = NULL;
}

static void after_work_cb(uv_work_t *w, int status)
{
    enc_task *t = w->data;
    sv_conn *c = t->c;
    const int reply = t->stream == SV_STREAM_NONE;
    int sent = 0;
    if (reply)
        sv_session_answered(c);
    if (reply && t->on_worker)
        sv_session_work_end(c);
    if (reply && !c->closing && c->close_after_write && c->srv->stopping) {
        /* SIGTERM came while this encoded on a worker: sv_session_shutdown
         * has answered it SHUTTING_DOWN already (R7.4), the reply is dropped */
    } else if (t->unchanged) {
        c->stream_unchanged++; /* R5.16: nothing moved beyond the bound, nothing is sent; the base stands */
    } else if (!c->closing && !c->close_after_write) {
        size_t json_len = t->body ? json_dumpb(t->body, NULL, 0, JSON_COMPACT) : 2;
        size_t frame = LPVP_HEADER_SIZE + json_len + t->att_len;
        if (status != 0 || t->failed) {
            if (reply)
                sv_reply_err(c, t->rid, LPVP_E_INTERNAL, 0, "%s", status ? "the encoding was cancelled" : t->err);
            else
                fprintf(stderr, "lpvd serve: client %llu: %s: %s\n", (unsigned long long)c->id, what_of(t), t->err);
        } else if (frame > c->srv->cfg.max_queue) { /* R3.5: never sent, the connection stays */
            if (!reply)
                c->stream_dropped++;
            sv_reply_err(c, t->rid, LPVP_E_LIMIT, 0,
                         "%s: %zu bytes is over this server's per-client queue limit of %llu bytes (--max-queue); "
                         "not sent: ask for %s",
                         what_of(t), frame, (unsigned long long)c->srv->cfg.max_queue, smaller_of(t));
        } else {
            sent = sv_send(c, t->type, t->rid, t->body, t->att, t->att_len, t->stream) == 0;
            t->body = NULL;
            t->att = NULL;
        }
    }
    if (t->kind == ENC_VOLUME) {
        c->srv->volumes_encoded++;
        c->srv->volume_encode_ns += t->encode_ns;
    }
    if (t->stream == SV_STREAM_VOLUME)
        volume_stream_state(c, t, sent);
    json_decref(t->body);
    free(t->att);
    free(t->rgba_owned);
    free(t->out);
    sv_blob_unref(t->base.raw);
    sv_blob_unref(t->kept.raw);
    sv_result_unref(t->r);
    if (reply) {
        if (!c->closing && !c->close_after_write)
            sv_session_go_on(c);
    } else {
        c->enc_busy[t->stream] = 0;
        stream_next(c, t->stream);
    }
    free(t);
    sv_conn_unref(c);
}

static enc_task *task_new(sv_conn *c, enc_kind kind, uint16_t type, uint32_t rid, int stream)
{
    enc_task *t = calloc(1, sizeof *t);
    if (!t)
        return NULL;
    t->work.data = t;
    t->c = c;
    c->refs++;
    t->kind = kind;
    t->type = type;
    t->rid = rid;
    t->stream = stream;
    t->revision = c->revision;
    return t;
}

static void start(enc_task *t)
{
    sv_conn *c = t->c;
    if (t->stream == SV_STREAM_NONE)
        c->busy = 1; /* until after_work_cb queues the reply (R3.2) */
    else
        c->enc_busy[t->stream] = 1;
    /* stopping: the replies of the jobs sv_gl_stop finishes go out before the
     * BYE that follows at once (R7.4), so they are encoded here */
    if (c->srv->stopping || uv_queue_work(c->srv->loop, &t->work, work_cb, after_work_cb) != 0) {
        work_cb(&t->work); /* no work thread: encode here rather than lose the reply */
        after_work_cb(&t->work, 0);
    } else if (t->stream == SV_STREAM_NONE) {
        t->on_worker = 1; /* SIGTERM answers it and bounds the wait for it, like a scene load */
        sv_session_work_begin(c, t->rid);
    }
}

/* Out of memory for a task: a reply still gets its ERROR. */
static void no_task(sv_conn *c, uint32_t rid)
{
    sv_reply_err(c, rid, LPVP_E_INTERNAL, 0, "out of memory");
}

void sv_reply_volume(sv_conn *c, uint32_t rid, sv_result *r, int content, const sv_volume_coding *how)
{
    enc_task *t = task_new(c, ENC_VOLUME, LPVP_REPLY(LPVP_GET_VOLUME), rid, SV_STREAM_NONE);
    if (!t) {
        no_task(c, rid);
        return;
    }
    t->r = sv_result_ref(r);
    t->content = content;
    t->how = *how;
    start(t);
}

void sv_reply_frame(sv_conn *c, uint32_t rid, sv_result *r, float *rgba_owned, int w, int h, int fmt, int zstd,
                    int terms, const lpv_display *display, uint64_t tick)
{
    enc_task *t = task_new(c, ENC_FRAME, LPVP_REPLY(LPVP_GET_FRAME), rid, SV_STREAM_NONE);
    if (!t) {
        free(rgba_owned);
        no_task(c, rid);
        return;
    }
    t->r = sv_result_ref(r);
    t->rgba_owned = rgba_owned;
    t->rgba = rgba_owned ? rgba_owned : r->frames[terms];
    t->w = w;
    t->h = h;
    t->fmt = fmt;
    t->zstd = zstd;
    t->terms = terms;
    t->display = *display;
    t->tick = tick;
    /* the plan of the tick shown, when it is still the world's latest */
    const sv_result *latest = c->world ? c->world->latest : NULL;
    if (latest && latest->tick == tick) {
        t->plan = latest->plan;
        t->has_plan = 1;
    }
    start(t);
}

void sv_reply_query(sv_conn *c, uint32_t rid, float *out_owned, size_t count, uint64_t tick)
{
    enc_task *t = task_new(c, ENC_QUERY, LPVP_REPLY(LPVP_QUERY_IRRADIANCE), rid, SV_STREAM_NONE);
    if (!t) {
        free(out_owned);
        no_task(c, rid);
        return;
    }
    t->out = out_owned;
    t->count = count;
    t->tick = tick;
    start(t);
}

/* Starts the stream's waiting result, if any and none is in flight. */
static void stream_next(sv_conn *c, int stream)
{
    sv_result *r = c->enc_next[stream];
    if (!r || c->enc_busy[stream])
        return;
    c->enc_next[stream] = NULL;
    sv_sub *sub = &c->subs[stream];
    if (c->closing || c->close_after_write || !sub->on || c->world_gen != r->gen ||
        (stream == SV_STREAM_FRAME && !r->frames[sub->terms])) {
        sv_result_unref(r);
        return;
    }
    enc_task *t = task_new(c, stream == SV_STREAM_VOLUME ? ENC_VOLUME : ENC_FRAME,
                           stream == SV_STREAM_VOLUME ? LPVP_VOLUME : LPVP_FRAME, 0, stream);
    if (!t) {
        sv_result_unref(r);
        return;
    }
    t->r = r; /* the reference enc_next held */
    t->zstd = sub->zstd;
    if (stream == SV_STREAM_VOLUME) {
        t->content = LPVP_CONTENT_MERGED;
        t->how = sub->vol;
        /* R7.6a: a volume more for the bases must fit the daemon's budget;
         * else the subscriber lets its bases go and gets a keyframe that it
         * does not keep, until memory frees (a new volume is at most the
         * fp32 cells; an index after them is small beside them) */
        const uint64_t need = (uint64_t)r->cell_count * LPVP_VALUES_PER_CELL * 4;
        t->keep = sub->delta;
        if (sub->delta && !sv_memory_fits(&c->srv->mem, SV_MEM_BASES, need)) {
            c->srv->bases_refused++;
            sv_sub_clear(sub);
            t->keep = 0;
        }
        t->epoch = sub->epoch;
        if (sub->delta) { /* lent for the XOR; back in volume_stream_state */
            t->base = sub->acked;
            sub->acked.raw = NULL;
        }
    } else {
        t->rgba = r->frames[sub->terms];
        t->w = r->width;
        t->h = r->height;
        t->fmt = sub->fmt;
        t->terms = sub->terms;
        t->display = sub->display;
        t->tick = r->tick;
        t->plan = r->plan;
        t->has_plan = 1;
    }
    start(t);
}

void sv_stream_result(sv_conn *c, int stream, sv_result *r)
{
    if (c->enc_next[stream]) /* never encoded: a newer tick replaces it (R5.5) */
        c->stream_dropped++;
    sv_result_unref(c->enc_next[stream]);
    c->enc_next[stream] = sv_result_ref(r);
    stream_next(c, stream);
}
