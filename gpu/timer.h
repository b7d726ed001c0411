/*
 * timer.h - per-stage GPU timing of one frame, for `--stats`.
 *
 * Usage, with the GL context current:
 *
 *     lpv_timer t;
 *     lpv_timer_init(&t);                  // no GL call; cheap
 *     ...
 *     lpv_timer_begin(&t, "inject");       // a frame starts at the first
 *     glDispatchCompute(...);              //   begin after init or collect
 *     lpv_timer_count(&t, 1);              // one dispatch in this stage
 *     lpv_timer_end(&t);
 *     lpv_timer_begin(&t, "propagate");
 *     ...
 *     lpv_timer_end(&t);
 *     int n = lpv_timer_collect(&t);       // waits for the GPU
 *     for (int i = 0; i < n; i++)
 *         printf("%s %.3f ms\n", t.stages[i].name, t.stages[i].gpu_ms);
 *     ...
 *     lpv_timer_destroy(&t);               // deletes the GL queries
 *
 * Spans are begin/end pairs; they do not nest (begin while a span is open
 * ends the open one first). Each span is timed twice:
 *   - gpu_ms: glQueryCounter(GL_TIMESTAMP) at begin and at end (after a
 *     glFinish, so deferred draws are billed to their own stage), read back
 *     by lpv_timer_collect; this is the time the GL implementation spent on
 *     the commands between the two, and the number that matters (on llvmpipe
 *     too);
 *   - cpu_ms: CLOCK_MONOTONIC around the same calls, i.e. the CPU time spent
 *     submitting them (no glFinish is added, so it is not the GPU cost).
 * Spans with the same stage name in one frame accumulate into one stage, in
 * the order the names first appear. Up to LPV_TIMER_MAX_STAGES names and
 * LPV_TIMER_MAX_SPANS spans per frame: spans beyond that are still counted
 * and CPU-timed but not GPU-timed (`dropped` says how many); stage names
 * beyond that are dropped entirely (also in `dropped`).
 *
 * Every function accepts a NULL timer and then does nothing (collect returns
 * 0), so passes can take an optional lpv_timer * and call it unconditionally.
 * The GL query objects are created at the first begin and belong to the
 * context that was current then; destroy with that context current.
 */
#ifndef LPV_TIMER_H
#define LPV_TIMER_H

#include "gl.h"

#define LPV_TIMER_MAX_STAGES 32
#define LPV_TIMER_MAX_SPANS 256
#define LPV_TIMER_NAME_MAX 32 /* longer names are truncated */

typedef struct lpv_timer_stage {
    char name[LPV_TIMER_NAME_MAX];
    double gpu_ms;  /* GPU time of the frame's spans of this stage; -1 if the
                       implementation has no timestamp queries */
    double cpu_ms;  /* CPU wall-clock time of the same spans (submission) */
    unsigned count; /* sum of lpv_timer_count calls (dispatches, draws) */
    unsigned spans; /* begin/end pairs */
} lpv_timer_stage;

typedef struct lpv_timer {
    /* Results: valid after lpv_timer_collect, until the next begin. */
    lpv_timer_stage stages[LPV_TIMER_MAX_STAGES];
    int stage_count;
    double gpu_total_ms; /* sum over stages (-1 without timestamp queries) */
    double cpu_total_ms;
    unsigned dropped;    /* spans not GPU-timed or stages dropped, see above */

    /* Private. */
    GLuint queries[2 * LPV_TIMER_MAX_SPANS]; /* begin, end per span */
    int span_stage[LPV_TIMER_MAX_SPANS];
    int span_count;
    int open_stage;    /* stage of the open span, -1 if none */
    int open_span;     /* its query pair, -1 if not GPU-timed */
    int last_stage;    /* the stage lpv_timer_count adds to when none is open */
    double open_cpu_ms;
    int queries_ready; /* 1 once the queries exist, -1 if timestamps are unsupported */
    int collected;     /* 1: the next begin starts a new frame */
    int (*yield_fn)(void *arg); /* lpv_timer_set_yield */
    void *yield_arg;
    double yield_every_ms, yield_last_ms;
    int yielding;      /* inside yield_fn: no nested yield */
    int abandoned;     /* yield_fn asked the work to stop; until the next frame */
} lpv_timer;

/* Zeroes the timer. No GL call. */
void lpv_timer_init(lpv_timer *t);

/* Opens a span of stage `stage` (copied) / closes the open one. */
void lpv_timer_begin(lpv_timer *t, const char *stage);
void lpv_timer_end(lpv_timer *t);

/* Adds n to the count of the open stage, else of the stage last ended. */
void lpv_timer_count(lpv_timer *t, unsigned n);

/* Closes an open span, waits for the GPU results and fills stages[],
 * stage_count and the totals. Returns stage_count, or -1 on a GL error while
 * reading the queries (the CPU times are still filled). The next begin starts
 * a new frame; collecting twice without a begin returns the same results. */
int lpv_timer_collect(lpv_timer *t);

/* The stage called `name` in the current results, or NULL. */
const lpv_timer_stage *lpv_timer_find(const lpv_timer *t, const char *name);

/*
 * Yield points. A caller that shares one thread among several timers' work
 * (the daemon's GL thread, one engine per world) registers fn: at a yield
 * point, once every_ms of wall time has passed since the frame began or
 * since the last yield, the timer ends the open span (its glFinish: the work
 * so far is done), calls fn(arg) and begins the span again under the same
 * name, so the time fn spends is billed to no stage. fn may make another
 * context current and run GL work there, as long as it makes this timer's
 * context current again before it returns; it returns nonzero when nobody
 * wants this work any more, and lpv_timer_abandoned says so until the next
 * frame. The end of every span is a yield point; passes add lpv_timer_yield
 * between the steps of a long stage (propagation iterations, chunks of one
 * big draw or dispatch). The timer holds the hook because every pass gets the
 * timer and marks its ends with it. Without a hook (fn NULL, the default)
 * a yield point costs a test.
 */
void lpv_timer_set_yield(lpv_timer *t, int (*fn)(void *arg), void *arg, double every_ms);
void lpv_timer_yield(lpv_timer *t);
int lpv_timer_abandoned(const lpv_timer *t);

/* Deletes the GL queries (the context that was current at the first begin
 * must be current) and zeroes the timer, the yield hook included. */
void lpv_timer_destroy(lpv_timer *t);

#endif /* LPV_TIMER_H */
