/*
 * test_yield_points.c - an engine's tick stops at its yield points, another
 * engine can run in another context there, and the tick computes what it
 * computes whole; a hook that asks it to stop abandons it, and the next tick
 * starts over (issue 31, item 2; gpu/timer.h "Yield points",
 * lpv_engine_set_yield). The daemon runs other worlds' jobs at these points
 * (serve_gl.c); tests/reliability/yield_points.py checks that end to end.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "context.h"
#include "engine.h"
#include "scene.h"
#include "scene_build.h"
#include "view.h"

#define NPTS 64

typedef struct world {
    lpv_gl_context *ctx;
    lpv_engine *engine;
    lpv_scene scene;
} world;

/* The box with a point light, at LPV grid 16 (16 propagation steps: as
 * many yield points) or iv; current context: its own. */
static void world_open(world *w, lpv_technique_id technique, float light_x)
{
    char err[1024] = "";
    lpv_gl_context_desc desc = {0};
    w->ctx = lpv_gl_context_create(&desc, err, sizeof err);
    if (!w->ctx)
        fail_msg("no GL context: %s", err);
    assert_int_equal(lpv_scene_builtin_cornell(&w->scene), 0);
    assert_non_null(lpv_scene_add_point_light(&w->scene, (float[3]){light_x, 1.2f, 0.1f}, 2.0f));
    lpv_scene_compute_bounds(&w->scene);
    w->engine = lpv_engine_create(err, sizeof err);
    if (!w->engine)
        fail_msg("engine: %s", err);
    lpv_settings s = {.technique = technique};
    if (technique == LPV_TECHNIQUE_ID_LPV)
        s.grid_dims[0] = s.grid_dims[1] = s.grid_dims[2] = 16;
    lpv_view v;
    lpv_view_look_at((float[3]){0.0f, 1.0f, 3.0f}, (float[3]){0.0f, 1.0f, 0.0f}, 0.8f, 48, 48, &v);
    if (lpv_engine_set_settings(w->engine, &s, err, sizeof err) != 0 ||
        lpv_engine_set_scene(w->engine, &w->scene, err, sizeof err) != 0 ||
        lpv_engine_set_view(w->engine, &v, err, sizeof err) != 0)
        fail_msg("set-up: %s", err);
}

static void world_close(world *w)
{
    lpv_gl_context_make_current(w->ctx);
    lpv_engine_destroy(w->engine);
    lpv_scene_free(&w->scene);
    lpv_gl_context_destroy(w->ctx);
}

/* Irradiance at NPTS points over the floor and the back wall. */
static void probe(lpv_engine *e, float out[NPTS * 3])
{
    float p[NPTS * 3], n[NPTS * 3];
    for (int i = 0; i < NPTS; ++i) {
        const int wall = i & 1;
        p[3 * i + 0] = -0.8f + 1.6f * (float)(i % 8) / 7.0f;
        p[3 * i + 1] = wall ? 0.2f + 1.6f * (float)(i / 8) / 7.0f : 0.02f;
        p[3 * i + 2] = wall ? -0.98f : -0.8f + 1.6f * (float)(i / 8) / 7.0f;
        n[3 * i + 0] = 0.0f;
        n[3 * i + 1] = wall ? 0.0f : 1.0f;
        n[3 * i + 2] = wall ? 1.0f : 0.0f;
    }
    char err[512] = "";
    if (lpv_engine_irradiance(e, p, n, NPTS, out, err, sizeof err) != 0)
        fail_msg("irradiance: %s", err);
}

typedef struct hook {
    world *self, *other; /* other: ticked at every yield, in its own context */
    int calls, stop_at;  /* stop_at > 0: ask to stop at that call */
    float light_x;
} hook;

static int on_yield(void *arg)
{
    hook *h = arg;
    ++h->calls;
    if (h->other) { /* another world's work, as the daemon's GL thread does */
        char err[512] = "";
        assert_int_equal(lpv_gl_context_make_current(h->other->ctx), 0);
        h->light_x = -h->light_x;
        h->other->scene.lights[h->other->scene.light_count - 1].position[0] = h->light_x;
        if (lpv_engine_set_scene(h->other->engine, &h->other->scene, err, sizeof err) != 0 ||
            lpv_engine_tick(h->other->engine, err, sizeof err) != 0)
            fail_msg("the other world's tick: %s", err);
        assert_int_equal(lpv_gl_context_make_current(h->self->ctx), 0);
    }
    return h->stop_at > 0 && h->calls >= h->stop_at;
}

static void same(const float *a, const float *b, const char *what)
{
    double worst = 0.0, peak = 0.0;
    for (int i = 0; i < NPTS * 3; ++i) {
        const double d = a[i] > b[i] ? a[i] - b[i] : b[i] - a[i];
        worst = d > worst ? d : worst;
        peak = a[i] > peak ? a[i] : peak;
    }
    printf("%s: largest difference %.3g W/m^2 (largest value %.3g)\n", what, worst, peak);
    assert_true(peak > 0.0);
    assert_true(worst == 0.0);
}

static void check_technique(lpv_technique_id technique, const char *name)
{
    float whole[NPTS * 3], cut[NPTS * 3], again[NPTS * 3];
    char err[1024] = "";

    /* the tick run whole: no hook */
    world a;
    world_open(&a, technique, 0.1f);
    if (lpv_engine_tick(a.engine, err, sizeof err) != 0)
        fail_msg("%s: %s", name, err);
    probe(a.engine, whole);
    world_close(&a);

    /* the same tick cut at every yield point, another world ticking there */
    world b, other;
    world_open(&other, LPV_TECHNIQUE_ID_LPV, 0.3f);
    world_open(&b, technique, 0.1f);
    hook h = {.self = &b, .other = &other, .light_x = 0.3f};
    lpv_engine_set_yield(b.engine, on_yield, &h, 0.0);
    if (lpv_engine_tick(b.engine, err, sizeof err) != 0)
        fail_msg("%s cut into pieces: %s", name, err);
    printf("%s: %d yield points, the other world ticked at each\n", name, h.calls);
    assert_true(h.calls >= 3);
    probe(b.engine, cut);
    char what[96];
    snprintf(what, sizeof what, "%s: cut into pieces vs whole", name);
    same(whole, cut, what);

    /* a hook that asks it to stop abandons the tick; the next one starts over */
    b.scene.lights[b.scene.light_count - 1].position[0] = 0.2f;
    if (lpv_engine_set_scene(b.engine, &b.scene, err, sizeof err) != 0)
        fail_msg("%s: %s", name, err);
    hook stop = {.self = &b, .stop_at = 2};
    lpv_engine_set_yield(b.engine, on_yield, &stop, 0.0);
    assert_int_not_equal(lpv_engine_tick(b.engine, err, sizeof err), 0);
    printf("%s: abandoned: %s\n", name, err);
    assert_int_equal(strncmp(err, LPV_TICK_ABANDONED, strlen(LPV_TICK_ABANDONED)), 0);
    assert_int_equal(stop.calls, 2); /* no yield point after it asked to stop */
    lpv_engine_set_yield(b.engine, NULL, NULL, 0.0);
    b.scene.lights[b.scene.light_count - 1].position[0] = 0.1f; /* back where the whole tick had it */
    if (lpv_engine_set_scene(b.engine, &b.scene, err, sizeof err) != 0 || lpv_engine_tick(b.engine, err, sizeof err) != 0)
        fail_msg("%s after the abandoned tick: %s", name, err);
    probe(b.engine, again);
    snprintf(what, sizeof what, "%s: after an abandoned tick vs whole", name);
    same(whole, again, what);
    world_close(&b);
    world_close(&other);
}

static void test_lpv_cut_and_abandoned(void **state)
{
    (void)state;
    check_technique(LPV_TECHNIQUE_ID_LPV, "lpv");
}

static void test_iv_cut_and_abandoned(void **state)
{
    (void)state;
    check_technique(LPV_TECHNIQUE_ID_IV, "iv");
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_lpv_cut_and_abandoned),
                                       cmocka_unit_test(test_iv_cut_and_abandoned)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
