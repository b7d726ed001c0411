/*
 * serve_world.c - worlds of `lpvd serve`, and the loop's side of the GL
 * thread's jobs.
 *
 * A world is one computation: an lpv_engine with a scene, lights, materials,
 * settings and a camera. Sessions whose inputs are byte-identical (the key
 * built by sv_inputs_build) share a world; a world whose only session changes
 * its inputs is updated in place (its generation bumps, and results of older
 * generations are no longer answered from). The GL thread (serve_gl.c) runs
 * the worlds' jobs; finished jobs come back here (sv_world_jobs_done, on the
 * loop, which the daemon hands sv_gl_start). The scenes and inputs worlds
 * are made of are serve_inputs.c's, below both. Replies and streams reach the sessions through each connection's
 * sv_world_listener (serve.h), never by calling the session layer.
 */
#include "serve.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ---- completions on the loop ------------------------------------------- */
static void world_free(sv_world *w)
{
    if (w->timer_init) {
        /* timer memory lives in the world: free it in the close callback */
        return;
    }
    sv_result_unref(w->latest);
    free(w);
}

static void timer_closed(uv_handle_t *h)
{
    sv_world *w = h->data;
    w->timer_init = 0;
    world_free(w);
}

static void tick_done(sv_server *s, sv_job *j)
{
    sv_world *w = j->world;
    if (j->periodic)
        w->periodic_pending = 0;
    if (w->queued_tick == j) /* before the replies: a session's next TICK must queue a new tick */
        w->queued_tick = NULL;
    if (j->result) {
        s->ticks++;
        w->ticks_computed++;
        if (!w->latest || j->result->tick > w->latest->tick) {
            sv_result_unref(w->latest);
            w->latest = sv_result_ref(j->result);
        }
    } else if (j->cancelled) {
        s->ticks_cancelled++;
    } else if (j->periodic && j->status) {
        fprintf(stderr, "lpvd serve: world %llu: tick failed: %s\n", (unsigned long long)w->id, j->err);
    }
    sv_job_reply_all(j);
    if (j->result && !w->dying)
        for (sv_conn *c = s->conns; c; c = c->next)
            if (c->world == w && !c->closing)
                c->listener->tick_result(c, j->result);
}

void sv_world_jobs_done(uv_async_t *a)
{
    sv_server *s = a->data;
    for (;;) {
        pthread_mutex_lock(&s->mu);
        sv_job *j = s->done_head;
        if (j) {
            s->done_head = j->next;
            if (!s->done_head)
                s->done_tail = NULL;
        }
        pthread_mutex_unlock(&s->mu);
        if (!j)
            break;
        switch (j->kind) {
        case SV_JOB_TICK: tick_done(s, j); break;
        case SV_JOB_RENDER:
        case SV_JOB_CONTENT:
        case SV_JOB_QUERY: sv_job_reply_all(j); break;
        case SV_JOB_DESTROY: {
            sv_world *w = j->world;
            sv_job_free(j);
            j = NULL;
            sv_inputs_release(s, w->inputs);
            w->inputs = NULL;
            if (w->timer_init)
                uv_close((uv_handle_t *)&w->timer, timer_closed);
            else
                world_free(w);
            break;
        }
        case SV_JOB_QUIT: break;
        }
        if (j)
            sv_job_free(j);
    }
}

/* ---- worlds ------------------------------------------------------------- */
unsigned sv_world_terms_mask(sv_world *w)
{
    unsigned m = 0;
    for (sv_conn *c = w->srv->conns; c; c = c->next)
        if (c->world == w && c->subs[SV_STREAM_FRAME].on && c->world_gen == w->gen)
            m |= 1u << c->subs[SV_STREAM_FRAME].terms;
    return m;
}

/* The world's tick job that the GL thread has not started yet, that was
 * queued for the world's current inputs and that is not cancelled (its
 * requesters left: sv_gl_cancel), or NULL. Call with srv->mu held: the
 * GL thread sets `started` under it. */
static sv_job *joinable_tick_locked(sv_world *w)
{
    sv_job *q = w->queued_tick;
    return q && !q->started && !q->cancelled && q->gen == w->gen ? q : NULL;
}

/* Tick coalescing (R7.2): a TICK for a world whose tick is still queued for
 * the same inputs (generation) is answered by that tick instead of queuing an
 * identical computation behind it: same tick number, each reply with its own
 * session's revision. Same generation = the session's applied state, so R3.3
 * holds. A tick the GL thread has started is never joined, so a reply never
 * comes from a computation that began before its request arrived. The caller
 * keeps the session busy until the reply, as for a tick of its own (R3.2). */
int sv_world_join_tick(sv_world *w, sv_conn *c, uint32_t request_id)
{
    sv_server *s = w->srv;
    sv_waiter *wt = calloc(1, sizeof *wt);
    if (!wt)
        return 0;
    unsigned mask = sv_world_terms_mask(w); /* frame subscriptions may be newer than the job's */
    pthread_mutex_lock(&s->mu);
    sv_job *q = joinable_tick_locked(w);
    if (q)
        q->terms_mask |= mask;
    pthread_mutex_unlock(&s->mu);
    if (!q) {
        free(wt);
        return 0;
    }
    wt->conn = c;
    c->refs++;
    wt->request_id = request_id;
    sv_waiter **p = &q->joined; /* in arrival order */
    while (*p)
        p = &(*p)->next;
    *p = wt;
    w->ticks_coalesced++;
    s->ticks_coalesced++;
    return 1;
}

static void world_timer_cb(uv_timer_t *t)
{
    sv_world *w = t->data;
    sv_server *s = w->srv;
    if (w->dying || s->stopping || w->periodic_pending)
        return;
    pthread_mutex_lock(&s->mu);
    int queued = joinable_tick_locked(w) != NULL;
    pthread_mutex_unlock(&s->mu);
    if (queued) /* a requested tick of these inputs has not started: it serves as this period's */
        return;
    sv_job *j = sv_job_new(SV_JOB_TICK, w);
    if (!j)
        return;
    j->periodic = 1;
    j->terms_mask = sv_world_terms_mask(w);
    w->periodic_pending = 1;
    w->queued_tick = j;
    sv_job_submit(s, j);
}

void sv_world_update_timer(sv_world *w)
{
    double rate = w->inputs ? w->inputs->tick_rate : 0.0;
    if (rate == w->timer_rate && w->timer_init)
        return;
    if (!w->timer_init) {
        if (uv_timer_init(w->srv->loop, &w->timer) != 0)
            return;
        w->timer.data = w;
        w->timer_init = 1;
    }
    w->timer_rate = rate;
    uv_timer_stop(&w->timer);
    if (rate > 0.0) {
        uint64_t ms = (uint64_t)llround(1000.0 / rate);
        if (ms < 1)
            ms = 1;
        uv_timer_start(&w->timer, world_timer_cb, ms, ms);
    }
}

static sv_world *world_find(sv_server *s, const sv_inputs *in)
{
    for (sv_world *w = s->worlds; w; w = w->next)
        if (!w->dying && w->inputs && w->inputs->key_hash == in->key_hash && w->inputs->key_len == in->key_len &&
            memcmp(w->inputs->key, in->key, in->key_len) == 0)
            return w;
    return NULL;
}

void sv_world_unref(sv_world *w)
{
    if (!w || --w->refs > 0)
        return;
    sv_server *s = w->srv;
    w->dying = 1;
    for (sv_world **p = &s->worlds; *p; p = &(*p)->next)
        if (*p == w) {
            *p = w->next;
            break;
        }
    s->world_count--;
    if (w->timer_init)
        uv_timer_stop(&w->timer);
    sv_job *d = sv_job_new(SV_JOB_DESTROY, w);
    if (d && s->gl_started) {
        sv_job_submit(s, d);
    } else {
        sv_job_free(d);
        sv_inputs_release(s, w->inputs);
        w->inputs = NULL;
        if (w->timer_init)
            uv_close((uv_handle_t *)&w->timer, timer_closed);
        else
            world_free(w);
    }
}

static int conn_listens(const sv_conn *c)
{
    return c && !c->closing && !c->close_after_write;
}

/* Whether anyone still wants queued job j of a world that keeps
 * (arg != NULL) or loses (arg == NULL) its last session: a request's session
 * that is still open, the world's tick timer (a periodic tick), or for a tick
 * a session of the world subscribed to a stream. */
static int job_wanted(const sv_job *j, void *arg)
{
    const sv_world *w = arg;
    if (!w)
        return 0;
    if (conn_listens(j->conn))
        return 1;
    for (const sv_waiter *wt = j->joined; wt; wt = wt->next)
        if (conn_listens(wt->conn))
            return 1;
    if (j->kind != SV_JOB_TICK)
        return 0;
    if (j->periodic)
        return 1;
    for (const sv_conn *c = w->srv->conns; c; c = c->next)
        if (c->world == w && conn_listens(c) && (c->subs[SV_STREAM_VOLUME].on || c->subs[SV_STREAM_FRAME].on))
            return 1;
    return 0;
}

void sv_world_detach(sv_conn *c)
{
    sv_world *w = c->world;
    c->world = NULL;
    /* a session that closes leaves its queued requests behind: nobody may
     * want them now (a tick of 20 s for a client that has gone) */
    if (w && c->closing && w->srv->gl_started)
        sv_gl_cancel(w->srv, w, job_wanted, w->refs > 1 ? w : NULL);
    sv_world_unref(w);
}

void sv_world_attach(sv_conn *c, sv_inputs *in)
{
    sv_server *s = c->srv;
    sv_world *found = world_find(s, in);
    if (found && found == c->world) {
        sv_inputs_release(s, in);
        return;
    }
    if (found) {
        found->refs++;
        sv_world_detach(c);
        c->world = found;
        c->world_gen = found->gen;
        sv_inputs_release(s, in);
        return;
    }
    if (c->world && c->world->refs == 1) { /* alone: update in place */
        sv_world *w = c->world;
        sv_inputs_release(s, w->inputs);
        w->inputs = in;
        w->gen++;
        c->world_gen = w->gen;
        sv_world_update_timer(w);
        return;
    }
    sv_world *w = calloc(1, sizeof *w);
    if (!w) {
        sv_inputs_release(s, in);
        return;
    }
    w->srv = s;
    w->refs = 1;
    w->id = ++s->next_world_id;
    w->gen = 1;
    w->inputs = in;
    w->next = s->worlds;
    s->worlds = w;
    s->world_count++;
    sv_world_detach(c);
    c->world = w;
    c->world_gen = w->gen;
    sv_world_update_timer(w);
}
