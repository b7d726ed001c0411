/*
 * serve_gl.c - the GL thread of `lpvd serve` and its job queue. The GL thread
 * is the only thread that touches GL: it creates the context, owns every
 * world's engine, and runs jobs (tick, render, query, destroy) one at a time;
 * finished jobs go back to the loop through done_async, where the world layer
 * (serve_world.c, sv_world_jobs_done, handed to sv_gl_start: this file is
 * below it and never calls it by name) replies and streams.
 */
#include "serve.h"
#include "memory_limits.h"

#include <malloc.h>
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Tick numbers come from one counter for the whole server, not one per
 * world: a session that moves to another world (its lights changed while
 * others share its world, R7.2) never meets a tick number it has seen, so
 * a delta's base_tick (R5.3, R5.16) names one volume. */
static uint64_t next_tick_number(void)
{
    static atomic_uint_fast64_t last = 0;
    return (uint64_t)atomic_fetch_add(&last, 1) + 1;
}

static double wall_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

/* ---- jobs --------------------------------------------------------------- */
sv_job *sv_job_new(sv_job_kind kind, sv_world *w)
{
    sv_job *j = calloc(1, sizeof *j);
    if (!j)
        return NULL;
    j->kind = kind;
    j->world = w;
    if (w) {
        j->inputs = w->inputs;
        if (j->inputs)
            j->inputs->refs++;
        j->gen = w->gen;
        w->jobs++;
    }
    return j;
}

/* Replies to the request of a job and to every request that joined it,
 * through each connection's sv_world_listener. */
void sv_job_reply_all(sv_job *j)
{
    if (j->conn)
        j->conn->listener->job_done(j, j->conn, j->request_id);
    for (sv_waiter *wt = j->joined; wt; wt = wt->next)
        wt->conn->listener->job_done(j, wt->conn, wt->request_id);
}

void sv_job_free(sv_job *j)
{
    if (!j)
        return;
    if (j->world) {
        j->world->jobs--;
        if (j->world->queued_tick == j)
            j->world->queued_tick = NULL;
        sv_inputs_release(j->world->srv, j->inputs);
    }
    if (j->conn)
        sv_conn_unref(j->conn);
    while (j->joined) {
        sv_waiter *wt = j->joined;
        j->joined = wt->next;
        sv_conn_unref(wt->conn);
        free(wt);
    }
    sv_result_unref(j->result);
    free(j->points);
    free(j->rgba);
    free(j->out);
    free(j);
}

void sv_job_submit(sv_server *s, sv_job *j)
{
    pthread_mutex_lock(&s->mu);
    j->next = NULL;
    if (s->jobs_tail)
        s->jobs_tail->next = j;
    else
        s->jobs_head = j;
    s->jobs_tail = j;
    s->jobs_queued++;
    pthread_cond_signal(&s->cv);
    pthread_mutex_unlock(&s->mu);
}

/* The settings, scene and view size a tick runs with: what its cost
 * depends on (a light moving does not change it). */
static uint64_t cost_sig(const sv_inputs *in)
{
    uint64_t h = lpv_hash_bytes(LPV_HASH_INIT, &in->settings, sizeof in->settings);
    h = lpv_hash_bytes(h, &in->scene, sizeof in->scene);
    h = lpv_hash_bytes(h, &in->light_count, sizeof in->light_count);
    h = lpv_hash_bytes(h, &in->view.width, sizeof in->view.width);
    return lpv_hash_bytes(h, &in->view.height, sizeof in->view.height);
}

/* Fair GL time: which queued job runs next, unlinked from the queue, or
 * NULL. Worlds take turns: the oldest job of the first world after the one
 * served last (by id, wrapping round) that has a job queued. So a world's
 * jobs still run in the order they were queued (its destroy job last), and a
 * world with many jobs (sessions sharing it, each with a request) delays
 * another world by at most a slice of the job running now (gl_yield), never
 * by its whole backlog. A job without a world (QUIT) goes when no world has
 * a job left. Only worlds with no job started are taken from (at a yield
 * point, the worlds whose jobs wait there), and at a yield point (`between`)
 * never QUIT. Call with s->mu held. */
static sv_job *take_next_locked(sv_server *s, int between)
{
    sv_job **best = NULL;
    uint64_t best_d = 0;
    for (sv_job **p = &s->jobs_head; *p; p = &(*p)->next) {
        if (!(*p)->world) {
            if (!best && !between)
                best = p;
            continue;
        }
        if ((*p)->world->gl_busy)
            continue;
        uint64_t d = (*p)->world->id - s->gl_last_world - 1; /* turns until this world's, wrapping */
        if (!best || !(*best)->world || d < best_d) {
            best = p;
            best_d = d;
        }
    }
    if (!best)
        return NULL;
    sv_job *j = *best;
    *best = j->next;
    if (s->jobs_tail == j) {
        s->jobs_tail = NULL;
        for (sv_job *q = s->jobs_head; q; q = q->next)
            s->jobs_tail = q;
    }
    j->next = NULL;
    s->jobs_queued--;
    j->started = 1; /* from now on no request joins it (sv_world_join_tick) */
    if (j->world) {
        s->gl_last_world = j->world->id;
        j->world->gl_busy = 1;
        s->gl_stack[s->gl_depth++] = j; /* sv_gl_cancel finds it there */
    }
    return j;
}

void sv_gl_cancel(sv_server *s, sv_world *w, int (*wanted)(const sv_job *j, void *arg), void *arg)
{
    pthread_mutex_lock(&s->mu);
    for (sv_job *j = s->jobs_head; j; j = j->next)
        if (j->world == w && !j->started && !j->cancelled && j->kind != SV_JOB_DESTROY && !wanted(j, arg))
            j->cancelled = 1;
    /* a tick under way stops at its next yield point (gl_yield) */
    for (int i = 0; i < s->gl_depth; ++i) {
        sv_job *j = s->gl_stack[i];
        if (j->world == w && j->kind == SV_JOB_TICK && !j->cancelled && !wanted(j, arg))
            j->cancelled = 1;
    }
    pthread_mutex_unlock(&s->mu);
}

size_t sv_jobs_queued(sv_server *s)
{
    pthread_mutex_lock(&s->mu);
    size_t n = s->jobs_queued;
    pthread_mutex_unlock(&s->mu);
    return n;
}

/* ---- GL thread ---------------------------------------------------------- */
static uint64_t scene_sig(const sv_inputs *in)
{
    uint64_t h = lpv_hash_bytes(LPV_HASH_INIT, &in->scene, sizeof in->scene);
    if (in->material_count)
        h = lpv_hash_bytes(h, in->materials, sizeof(lpv_material) * in->material_count);
    h = lpv_hash_bytes(h, &in->material_count, sizeof in->material_count);
    if (in->light_count)
        h = lpv_hash_bytes(h, in->lights, sizeof(lpv_light) * in->light_count);
    h = lpv_hash_bytes(h, &in->light_count, sizeof in->light_count);
    return h;
}

/* The world's cap: --max-world-memory, or what the daemon's budget leaves
 * it beside the other worlds, the scenes, the requests and the replies
 * (R7.6a, serve_memory.h), whichever is lower. */
static void set_world_cap(sv_world *w)
{
    sv_server *s = w->srv;
    const uint64_t room = sv_memory_room(&s->mem, SV_MEM_WORLDS); /* for all worlds together */
    const uint64_t others = sv_memory_held(&s->mem, SV_MEM_WORLDS) - w->gl_mem_bytes;
    const uint64_t left = room > others ? room - others : 0;
    char cap[SV_MEMORY_DESCRIBE_SIZE + 64];
    if (left < s->cfg.max_world_memory) {
        char held[SV_MEMORY_DESCRIBE_SIZE];
        sv_memory_describe(&s->mem, held, sizeof held);
        snprintf(cap, sizeof cap, "%s; this world holds %.3f GB of that", held, (double)w->gl_mem_bytes / 1e9);
        lpv_engine_set_memory_cap(w->engine, left, cap);
    } else { /* bounds the daemon's GPU memory: worlds x this (docs/server.md, "Worst-case memory") */
        snprintf(cap, sizeof cap, "--max-world-memory %llu", (unsigned long long)s->cfg.max_world_memory);
        lpv_engine_set_memory_cap(w->engine, s->cfg.max_world_memory, cap);
    }
}

/* Records what the world's engine holds now in the daemon's budget. */
static void note_world_bytes(sv_world *w, uint64_t bytes)
{
    sv_memory_sub(&w->srv->mem, SV_MEM_WORLDS, w->gl_mem_bytes);
    sv_memory_add(&w->srv->mem, SV_MEM_WORLDS, bytes);
    w->gl_mem_bytes = bytes;
}

/* Brings the world's engine to the job's inputs. */
static int gl_apply(sv_world *w, const sv_inputs *in, uint64_t gen, char *err, size_t n)
{
    if (!w->gl_ctx) { /* current once made; the daemon's backend */
        lpv_gl_context_desc desc = {.backend = lpv_gl_context_backend(w->srv->gl_ctx)};
        w->gl_ctx = lpv_gl_context_create(&desc, err, n);
        if (!w->gl_ctx)
            return -1;
    }
    if (!w->engine) {
        w->engine = lpv_engine_create(err, n);
        if (!w->engine)
            return -1;
        w->gl_has_applied = 0;
    }
    set_world_cap(w);
    if (w->gl_has_applied && w->gl_applied_gen == gen)
        return 0;
    uint64_t sig = scene_sig(in);
    int settings_changed = !w->gl_has_applied || memcmp(&w->gl_settings, &in->settings, sizeof in->settings) != 0;
    int scene_changed = !w->gl_has_applied || w->gl_scene_sig != sig;
    int view_changed = !w->gl_has_applied || memcmp(&w->gl_view, &in->view, sizeof in->view) != 0;
    w->gl_has_applied = 0;
    /* the engine re-samples the scene itself when a knob needs it: a CONFIG
     * sends no geometry again (lpv_engine_set_settings). The tick runs in
     * gl_tick, after this world's applied state is recorded: an abandoned
     * tick does not make the next one apply its inputs again. */
    lpv_scene sc;
    if (scene_changed) {
        sc = in->scene->scene;
        sc.materials = in->materials;
        sc.material_count = in->material_count;
        sc.lights = in->lights;
        sc.light_count = in->light_count;
    }
    const lpv_engine_item item = {.settings = settings_changed ? &in->settings : NULL,
                                  .scene = scene_changed ? &sc : NULL,
                                  .view = view_changed ? &in->view : NULL};
    if (lpv_engine_run_item(w->engine, &item, err, n) != 0)
        return -1;
    w->gl_settings = in->settings;
    w->gl_view = in->view;
    w->gl_scene_sig = sig;
    w->gl_applied_gen = gen;
    w->gl_has_applied = 1;
    w->gl_ticked = 0;
    return 0;
}

static int gl_yield(void *arg);

static void gl_tick(sv_server *s, sv_job *j)
{
    sv_world *w = j->world;
    const int changed = !w->gl_ticked || j->gen != w->gl_ticked_gen;
    const uint64_t sig = cost_sig(j->inputs);
    if (changed && s->cfg.max_tick_ms > 0.0 && w->gl_change_ms > s->cfg.max_tick_ms && w->gl_change_sig == sig) {
        /* measured, not estimated: refused before it holds the GL thread again */
        j->status = LPVP_E_LIMIT;
        snprintf(j->err, sizeof j->err,
                 "this world's last tick after a change took %.0f ms on the GL thread, over this server's %.0f ms "
                 "(--max-tick-ms): lower grid, iterations, cascades, rsm_size, the iv knobs or the camera size",
                 w->gl_change_ms, s->cfg.max_tick_ms);
        return;
    }
    double t0 = wall_ms();
    int rc = gl_apply(w, j->inputs, j->gen, j->err, sizeof j->err);
    if (rc == 0) {
        lpv_engine_set_yield(w->engine, gl_yield, j, SV_GL_SLICE_MS); /* a new engine has none yet */
        rc = lpv_engine_tick(w->engine, j->err, sizeof j->err);
    }
    if (rc != 0) {
        /* the engine's memory refusals name their budget's source: the cap
         * gl_apply set is the server's limit, so LIMIT (R7.6), not a fault */
        j->status = strstr(j->err, LPV_MEMORY_REFUSED) ? LPVP_E_LIMIT : LPVP_E_INTERNAL;
        return;
    }
    w->gl_ticked = 1;
    w->gl_ticked_gen = j->gen;
    note_world_bytes(w, lpv_engine_memory_bytes(w->engine));
    sv_result *r = sv_result_take(w->engine, j->inputs->view.width, j->inputs->view.height, j->terms_mask, j->err,
                                  sizeof j->err);
    if (!r) {
        j->status = LPVP_E_INTERNAL;
        return;
    }
    r->gen = j->gen;
    r->tick = w->gl_ticks = next_tick_number();
    r->tick_ms = wall_ms() - t0 - j->yielded_ms; /* its own GL time, not other worlds' */
    j->result = r;
    if (changed && w->gl_seen_sig == sig) { /* not its first with these settings: that one does one-time work */
        w->gl_change_ms = r->tick_ms;
        w->gl_change_sig = sig;
    }
    w->gl_seen_sig = sig;
}

static int gl_ready_for(sv_world *w, sv_job *j)
{
    if (!w->engine || !w->gl_ticked || w->gl_ticked_gen != j->gen || w->gl_applied_gen != j->gen) {
        j->status = LPVP_E_NOT_READY;
        snprintf(j->err, sizeof j->err, "no tick since the last change of this session's scene, lights, camera or "
                                        "config: send TICK first");
        return 0;
    }
    return 1;
}

static void gl_render(sv_job *j)
{
    sv_world *w = j->world;
    if (!gl_ready_for(w, j))
        return;
    j->width = j->inputs->view.width;
    j->height = j->inputs->view.height;
    j->rgba = malloc((size_t)j->width * (size_t)j->height * 4 * sizeof(float));
    if (!j->rgba) {
        j->status = LPVP_E_INTERNAL;
        snprintf(j->err, sizeof j->err, "out of memory for a %dx%d frame", j->width, j->height);
        return;
    }
    if (lpv_engine_render(w->engine, (lpv_frame_terms)j->terms, j->rgba, j->err, sizeof j->err) != 0)
        j->status = LPVP_E_INTERNAL;
    j->tick = w->gl_ticks;
}

/* GET_VOLUME content "levels" or "visibility" (j->count >> 8): the octree's
 * levels and index, or the probes' visibility, of the tick the world last
 * computed, read now (a tick reads only its merged volume). */
static void gl_content(sv_job *j)
{
    sv_world *w = j->world;
    if (!gl_ready_for(w, j))
        return;
    j->result = sv_result_take_content(w->engine, (int)(j->count >> 8), j->err, sizeof j->err);
    if (!j->result) {
        j->status = strstr(j->err, "out of memory") ? LPVP_E_INTERNAL : LPVP_E_BAD_FIELD;
        return;
    }
    j->result->gen = j->gen;
    j->result->tick = j->tick = w->gl_ticks;
}

static void gl_query(sv_job *j)
{
    sv_world *w = j->world;
    if (!gl_ready_for(w, j))
        return;
    size_t n = j->count;
    j->out = calloc(n ? n * 3 : 1, sizeof(float));
    float *p = malloc((n ? n : 1) * 3 * sizeof(float)), *nr = malloc((n ? n : 1) * 3 * sizeof(float));
    if (!j->out || !p || !nr) {
        free(p);
        free(nr);
        j->status = LPVP_E_INTERNAL;
        snprintf(j->err, sizeof j->err, "out of memory for %zu points", n);
        return;
    }
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) {
            p[i * 3 + k] = j->points[i * 6 + k];
            nr[i * 3 + k] = j->points[i * 6 + 3 + k];
        }
    if (n && lpv_engine_irradiance(w->engine, p, nr, n, j->out, j->err, sizeof j->err) != 0)
        j->status = LPVP_E_INTERNAL;
    for (size_t i = 0; i < n * 3; ++i)
        if (!isfinite(j->out[i]))
            j->out[i] = 0.0f;
    free(p);
    free(nr);
    j->tick = w->gl_ticks;
}

/* Runs one job of a world, taken by take_next_locked, on the GL thread in
 * the world's context, and hands it to the loop. Its world is busy until
 * then: no other job of it runs at one of this job's yield points. */
static void run_job(sv_server *s, sv_job *j)
{
    sv_world *w = j->world;
    pthread_mutex_lock(&s->mu);
    const int cancelled = j->cancelled;
    pthread_mutex_unlock(&s->mu);

    if (cancelled) { /* nobody wants it any more (sv_gl_cancel): no GL time */
        j->status = LPVP_E_INTERNAL;
        snprintf(j->err, sizeof j->err, "cancelled: every request for it is gone");
    } else if (w->gl_ctx && lpv_gl_context_make_current(w->gl_ctx) != 0) {
        j->status = LPVP_E_INTERNAL;
        snprintf(j->err, sizeof j->err, "cannot make this world's GL context current");
    } else {
        if (w->engine) /* a tick's gl_apply creates it and sets it too */
            lpv_engine_set_yield(w->engine, gl_yield, j, SV_GL_SLICE_MS);
        switch (j->kind) {
        case SV_JOB_TICK: gl_tick(s, j); break;
        case SV_JOB_RENDER: gl_render(j); break;
        case SV_JOB_CONTENT: gl_content(j); break;
        case SV_JOB_QUERY: gl_query(j); break;
        case SV_JOB_DESTROY:
            lpv_engine_destroy(w->engine);
            w->engine = NULL;
            lpv_gl_context_destroy(w->gl_ctx);
            w->gl_ctx = NULL;
            note_world_bytes(w, 0);
            malloc_trim(0); /* the heap's free pages back to the system (serve.c, mallopt) */
            break;
        case SV_JOB_QUIT: break;
        }
        if (w->engine)
            lpv_engine_set_yield(w->engine, NULL, NULL, 0.0);
    }

    pthread_mutex_lock(&s->mu);
    s->gl_depth--;
    w->gl_busy = 0;
    j->next = NULL;
    if (s->done_tail)
        s->done_tail->next = j;
    else
        s->done_head = j;
    s->done_tail = j;
    pthread_mutex_unlock(&s->mu);
    uv_async_send(&s->done_async);
}

/* A world's tick or render at a yield point (lpv_engine_set_yield): the
 * queued jobs of other worlds run here, each in its own world's context, for
 * up to SV_GL_YIELD_MS; then the paused job's context is current again.
 * Returns nonzero when the paused job is a tick nobody wants any more
 * (sv_gl_cancel): the engine abandons it. */
static int gl_yield(void *arg)
{
    sv_job *paused = arg;
    sv_world *w = paused->world;
    sv_server *s = w->srv;
    const double t0 = wall_ms();
    /* what the paused world's settings hold counts against the others' caps now */
    if (w->engine)
        note_world_bytes(w, lpv_engine_memory_bytes(w->engine));
    for (int ran = 0;; ran = 1) {
        pthread_mutex_lock(&s->mu);
        sv_job *j = s->gl_depth < SV_GL_MAX_DEPTH && (!ran || wall_ms() - t0 < SV_GL_YIELD_MS)
                        ? take_next_locked(s, 1)
                        : NULL;
        if (j)
            s->gl_jobs_between++;
        pthread_mutex_unlock(&s->mu);
        if (!j)
            break;
        run_job(s, j);
        lpv_gl_context_make_current(w->gl_ctx);
    }
    paused->yielded_ms += wall_ms() - t0;
    pthread_mutex_lock(&s->mu);
    const int stop = paused->kind == SV_JOB_TICK && paused->cancelled;
    pthread_mutex_unlock(&s->mu);
    return stop;
}

/* One tick and one small frame of the built-in box at the daemon's default
 * settings, in the daemon's own context, before the first client: a GL that
 * cannot build or run lpvd's passes fails the start with the reason, not
 * every client's TICK with INTERNAL. */
static int self_test(sv_server *s, char *err, size_t n)
{
    lpv_scene box;
    if (lpv_scene_builtin_cornell(&box) != 0) {
        snprintf(err, n, "self-test: cannot build the built-in box");
        return -1;
    }
    enum { W = 64, H = 48 };
    lpv_view view;
    lpv_view_frame_bounds(&box, W, H, &view);
    char why[512] = "";
    /* a context of its own, like a world's: what the driver keeps for a
     * context's programs goes with it (in the daemon's context, 88 MiB stayed) */
    lpv_gl_context_desc desc = {.backend = lpv_gl_context_backend(s->gl_ctx)};
    lpv_gl_context *ctx = lpv_gl_context_create(&desc, why, sizeof why);
    float *rgba = ctx ? malloc(sizeof(float) * 4 * W * H) : NULL;
    lpv_engine *e = rgba ? lpv_engine_create(why, sizeof why) : NULL;
    const lpv_engine_item item = {.settings = &s->cfg.settings, .scene = &box, .view = &view, .tick = 1};
    int rc = !e || lpv_engine_run_item(e, &item, why, sizeof why) != 0 ||
                     lpv_engine_render(e, LPV_TERMS_FULL, rgba, why, sizeof why) != 0
                 ? -1
                 : 0;
    if (rc != 0 && strstr(why, LPV_MEMORY_REFUSED)) { /* the GL works; its memory is small for the defaults */
        fprintf(stderr, "lpvd serve: warning: the built-in box at the default settings does not fit this GL's "
                        "memory (%s); clients need smaller settings\n", why);
        rc = 0;
    } else if (rc != 0) {
        snprintf(err, n, "the GL (%s) cannot run lpvd's passes on the built-in box at the default settings: %s",
                 s->gl_renderer, why[0] ? why : "out of memory");
    }
    lpv_engine_destroy(e);
    lpv_gl_context_destroy(ctx);
    lpv_gl_context_make_current(s->gl_ctx);
    free(rgba);
    lpv_scene_free(&box);
    malloc_trim(0);
    return rc;
}

static void *gl_main(void *arg)
{
    sv_server *s = arg;
    lpv_gl_context_desc desc = {.backend = s->cfg.backend};
    char err[1024] = "";
    lpv_gl_context *ctx = lpv_gl_context_create(&desc, err, sizeof err);
    pthread_mutex_lock(&s->mu);
    if (!ctx) {
        snprintf(s->gl_err, sizeof s->gl_err, "no OpenGL 4.5 context: %s", err);
        s->gl_ready = -1;
        pthread_cond_broadcast(&s->cv);
        pthread_mutex_unlock(&s->mu);
        return NULL;
    }
    s->gl_ctx = ctx;
    snprintf(s->gl_backend, sizeof s->gl_backend, "%s", lpv_backend_name(lpv_gl_context_backend(ctx)));
    snprintf(s->gl_renderer, sizeof s->gl_renderer, "%s", lpv_gl_context_renderer(ctx));
    lpv_memory_limits_query(&s->gl_limits);
    /* what one world can ever hold (CONFIG's floor check, --max-grid): the
     * least of the device's budget, --max-world-memory and the daemon's
     * budget less the room kept for one message */
    if (s->cfg.max_world_memory && s->cfg.max_world_memory < s->gl_limits.budget) {
        s->gl_limits.budget = s->cfg.max_world_memory;
        snprintf(s->gl_limits.budget_source, sizeof s->gl_limits.budget_source, "--max-world-memory %llu",
                 (unsigned long long)s->cfg.max_world_memory);
    }
    const uint64_t daemon = s->mem.budget - s->mem.headroom;
    if (daemon < s->gl_limits.budget) {
        s->gl_limits.budget = daemon;
        snprintf(s->gl_limits.budget_source, sizeof s->gl_limits.budget_source, "%s less --max-message",
                 s->mem.source);
    }
    /* mu is held: the loop waits for gl_ready, nothing else runs yet */
    if (self_test(s, err, sizeof err) != 0) {
        snprintf(s->gl_err, sizeof s->gl_err, "%s", err);
        s->gl_ready = -1;
        pthread_cond_broadcast(&s->cv);
        pthread_mutex_unlock(&s->mu);
        lpv_gl_context_destroy(ctx);
        s->gl_ctx = NULL;
        return NULL;
    }
    s->gl_ready = 1;
    pthread_cond_broadcast(&s->cv);
    for (;;) {
        while (!s->jobs_head)
            pthread_cond_wait(&s->cv, &s->mu);
        sv_job *j = take_next_locked(s, 0); /* no world is busy here: never NULL */
        if (!j)
            continue;
        if (j->kind == SV_JOB_QUIT) {
            free(j);
            break;
        }
        pthread_mutex_unlock(&s->mu);
        run_job(s, j);
        pthread_mutex_lock(&s->mu);
    }
    pthread_mutex_unlock(&s->mu);
    lpv_gl_context_destroy(ctx);
    return NULL;
}


int sv_gl_start(sv_server *s, uv_async_cb jobs_done, char *err, size_t n)
{
    s->gl_jobs_done = jobs_done;
    if (uv_async_init(s->loop, &s->done_async, jobs_done) != 0) {
        snprintf(err, n, "uv_async_init failed");
        return -1;
    }
    s->done_async.data = s;
    if (pthread_create(&s->gl_thread, NULL, gl_main, s) != 0) {
        snprintf(err, n, "cannot start the GL thread");
        return -1;
    }
    s->gl_started = 1;
    pthread_mutex_lock(&s->mu);
    while (s->gl_ready == 0)
        pthread_cond_wait(&s->cv, &s->mu);
    pthread_mutex_unlock(&s->mu);
    if (s->gl_ready < 0) {
        pthread_join(s->gl_thread, NULL);
        s->gl_started = 0;
        snprintf(err, n, "%s", s->gl_err);
        return -1;
    }
    return 0;
}

/* Drops the jobs not started yet (their requests get ERROR SHUTTING_DOWN),
 * lets the running one finish, runs the engines' destroy jobs, stops the GL
 * thread and runs every completion. The caller has detached every session
 * from its world first, so every world has a destroy job queued. */
void sv_gl_stop(sv_server *s)
{
    if (!s->gl_started)
        return;
    pthread_mutex_lock(&s->mu);
    sv_job *dropped = s->jobs_head;
    s->jobs_head = s->jobs_tail = NULL;
    s->jobs_queued = 0;
    pthread_mutex_unlock(&s->mu);
    while (dropped) {
        sv_job *next = dropped->next;
        dropped->next = NULL;
        if (dropped->kind == SV_JOB_DESTROY) {
            sv_job_submit(s, dropped); /* engines must still be destroyed on the GL thread */
        } else {
            if (dropped->periodic && dropped->world)
                dropped->world->periodic_pending = 0;
            dropped->status = LPVP_E_SHUTTING_DOWN;
            snprintf(dropped->err, sizeof dropped->err, "the server is stopping");
            sv_job_reply_all(dropped);
            sv_job_free(dropped);
        }
        dropped = next;
    }
    sv_job *q = calloc(1, sizeof *q);
    if (q) {
        q->kind = SV_JOB_QUIT;
        sv_job_submit(s, q);
        pthread_join(s->gl_thread, NULL);
    }
    s->gl_started = 0;
    s->gl_jobs_done(&s->done_async);
}

