/* timer.c - per-stage GPU timing with GL timestamp queries (see timer.h). */
#include "timer.h"

#include <string.h>
#include <time.h>

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

void lpv_timer_init(lpv_timer *t)
{
    if (!t)
        return;
    memset(t, 0, sizeof *t);
    t->open_stage = -1;
    t->open_span = -1;
    t->last_stage = -1;
}

static void new_frame(lpv_timer *t)
{
    t->stage_count = 0;
    t->span_count = 0;
    t->gpu_total_ms = 0.0;
    t->cpu_total_ms = 0.0;
    t->dropped = 0;
    t->last_stage = -1;
    t->collected = 0;
    t->abandoned = 0;
    t->yield_last_ms = now_ms();
    memset(t->stages, 0, sizeof t->stages);
}

static void ensure_queries(lpv_timer *t)
{
    if (t->queries_ready != 0)
        return;
    GLint bits = 0;
    glGetQueryiv(GL_TIMESTAMP, GL_QUERY_COUNTER_BITS, &bits);
    if (bits <= 0) {
        t->queries_ready = -1;
        return;
    }
    glGenQueries(2 * LPV_TIMER_MAX_SPANS, t->queries);
    t->queries_ready = 1;
}

static int find_stage(const lpv_timer *t, const char *name)
{
    for (int i = 0; i < t->stage_count; i++) {
        if (strncmp(t->stages[i].name, name, LPV_TIMER_NAME_MAX - 1) == 0)
            return i;
    }
    return -1;
}

void lpv_timer_begin(lpv_timer *t, const char *stage)
{
    if (!t)
        return;
    if (t->open_stage >= 0)
        lpv_timer_end(t);
    if (t->collected)
        new_frame(t);
    if (!stage)
        stage = "?";

    int s = find_stage(t, stage);
    if (s < 0) {
        if (t->stage_count >= LPV_TIMER_MAX_STAGES) {
            t->dropped++;
            return;
        }
        s = t->stage_count++;
        memset(&t->stages[s], 0, sizeof t->stages[s]);
        strncpy(t->stages[s].name, stage, LPV_TIMER_NAME_MAX - 1);
        t->stages[s].name[LPV_TIMER_NAME_MAX - 1] = '\0';
    }
    t->stages[s].spans++;
    t->open_stage = s;
    t->open_span = -1;

    ensure_queries(t);
    if (t->queries_ready == 1) {
        if (t->span_count < LPV_TIMER_MAX_SPANS) {
            int span = t->span_count++;
            t->span_stage[span] = s;
            t->open_span = span;
            glQueryCounter(t->queries[2 * span], GL_TIMESTAMP);
            glFlush(); /* stamped at the flush on llvmpipe (see lpv_timer_end) */
        } else {
            t->dropped++;
        }
    }
    t->open_cpu_ms = now_ms();
}

static void end_span(lpv_timer *t)
{
    if (t->open_span >= 0) {
        /* llvmpipe (and tiled GPUs) defer draws until a flush: without the
         * finish, a stage of draws would be billed to whichever later stage
         * flushes them (the shading absorbed the glossy and media passes). */
        glFinish();
        glQueryCounter(t->queries[2 * t->open_span + 1], GL_TIMESTAMP);
        /* llvmpipe stamps a timestamp query when the batch holding it is
         * flushed, not when it is issued: flush now, or the next stage's
         * work (a shader compile in its first draw) lands in this one. */
        glFlush();
    }
    t->stages[t->open_stage].cpu_ms += now_ms() - t->open_cpu_ms;
    t->last_stage = t->open_stage;
    t->open_stage = -1;
    t->open_span = -1;
}

void lpv_timer_end(lpv_timer *t)
{
    if (!t || t->open_stage < 0)
        return;
    end_span(t);
    lpv_timer_yield(t);
}

void lpv_timer_set_yield(lpv_timer *t, int (*fn)(void *arg), void *arg, double every_ms)
{
    if (!t)
        return;
    t->yield_fn = fn;
    t->yield_arg = arg;
    t->yield_every_ms = every_ms;
    t->yield_last_ms = now_ms();
}

void lpv_timer_yield(lpv_timer *t)
{
    if (!t || !t->yield_fn || t->yielding || t->abandoned || now_ms() - t->yield_last_ms < t->yield_every_ms)
        return;
    char stage[LPV_TIMER_NAME_MAX] = "";
    const int reopen = t->open_stage >= 0;
    if (reopen) {
        memcpy(stage, t->stages[t->open_stage].name, sizeof stage);
        end_span(t);
    } else {
        glFinish(); /* what was submitted since the last span is done before another's work */
    }
    t->yielding = 1;
    if (t->yield_fn(t->yield_arg) != 0)
        t->abandoned = 1;
    t->yielding = 0;
    t->yield_last_ms = now_ms();
    if (reopen)
        lpv_timer_begin(t, stage);
}

int lpv_timer_abandoned(const lpv_timer *t)
{
    return t && t->abandoned;
}

void lpv_timer_count(lpv_timer *t, unsigned n)
{
    if (!t)
        return;
    int s = t->open_stage >= 0 ? t->open_stage : t->last_stage;
    if (s >= 0 && !t->collected)
        t->stages[s].count += n;
}

int lpv_timer_collect(lpv_timer *t)
{
    if (!t)
        return 0;
    if (t->open_stage >= 0)
        end_span(t); /* no yield point: the frame is over */
    if (t->collected)
        return t->stage_count;

    int rc = 0;
    double gpu_init = t->queries_ready == -1 ? -1.0 : 0.0;
    for (int i = 0; i < t->stage_count; i++)
        t->stages[i].gpu_ms = gpu_init;
    if (t->queries_ready == 1) {
        while (glGetError() != GL_NO_ERROR) {
        }
        for (int i = 0; i < t->span_count; i++) {
            GLuint64 t0 = 0, t1 = 0;
            /* GL_QUERY_RESULT waits until the result is available. */
            glGetQueryObjectui64v(t->queries[2 * i], GL_QUERY_RESULT, &t0);
            glGetQueryObjectui64v(t->queries[2 * i + 1], GL_QUERY_RESULT, &t1);
            if (t1 > t0)
                t->stages[t->span_stage[i]].gpu_ms += (double)(t1 - t0) * 1e-6;
        }
        if (glGetError() != GL_NO_ERROR)
            rc = -1;
    }
    t->gpu_total_ms = gpu_init;
    t->cpu_total_ms = 0.0;
    for (int i = 0; i < t->stage_count; i++) {
        if (gpu_init >= 0.0)
            t->gpu_total_ms += t->stages[i].gpu_ms;
        t->cpu_total_ms += t->stages[i].cpu_ms;
    }
    t->collected = 1;
    return rc < 0 ? -1 : t->stage_count;
}

const lpv_timer_stage *lpv_timer_find(const lpv_timer *t, const char *name)
{
    if (!t || !name)
        return NULL;
    int s = find_stage(t, name);
    return s >= 0 ? &t->stages[s] : NULL;
}

void lpv_timer_destroy(lpv_timer *t)
{
    if (!t)
        return;
    if (t->queries_ready == 1 && glDeleteQueries)
        glDeleteQueries(2 * LPV_TIMER_MAX_SPANS, t->queries);
    lpv_timer_init(t);
}
