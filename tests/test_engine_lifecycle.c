/*
 * test_engine_lifecycle.c - an engine that goes away leaves no GL object
 * behind (issue 31, item 1): `lpvd batch` runs scene after scene in one GL
 * context, and the daemon ran every world's engine in one for months (now
 * each world has its own, destroyed with it), so a texture, buffer,
 * framebuffer or program an engine forgets stays in its context for good (a
 * world that ticked with a light kept 20-26 MiB after it went away).
 *
 * The census counts the live names of every GL object type that has a glIs*
 * query, over the first LPVT_NAMES names of each (Mesa hands out the lowest
 * free name). One warm-up engine runs first, so that whatever the context
 * keeps once (shader caches, the driver's own objects) is there before the
 * first count; then each technique, with a point light, a spot light and the
 * box's emissive ceiling, ticks twice, renders and answers a query, and is
 * destroyed: the count after must equal the count before.
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
#include "gl.h"
#include "scene.h"
#include "scene_build.h"
#include "test_util.h"
#include "view.h"

#define LPVT_NAMES 20000u

typedef struct census {
    unsigned textures, buffers, framebuffers, renderbuffers, programs, shaders, arrays, queries, samplers;
} census;

static census count_objects(void)
{
    census c = {0};
    glUseProgram(0); /* a deleted program still in use lives until it is not */
    for (GLuint n = 1; n <= LPVT_NAMES; ++n) {
        c.textures += glIsTexture(n) == GL_TRUE;
        c.buffers += glIsBuffer(n) == GL_TRUE;
        c.framebuffers += glIsFramebuffer(n) == GL_TRUE;
        c.renderbuffers += glIsRenderbuffer(n) == GL_TRUE;
        c.programs += glIsProgram(n) == GL_TRUE;
        c.shaders += glIsShader(n) == GL_TRUE;
        c.arrays += glIsVertexArray(n) == GL_TRUE;
        c.queries += glIsQuery(n) == GL_TRUE;
        c.samplers += glIsSampler(n) == GL_TRUE;
    }
    return c;
}

static void print_census(const char *what, const census *c)
{
    printf("%-28s textures %u buffers %u framebuffers %u renderbuffers %u programs %u shaders %u "
           "vertex arrays %u queries %u samplers %u\n",
           what, c->textures, c->buffers, c->framebuffers, c->renderbuffers, c->programs, c->shaders, c->arrays,
           c->queries, c->samplers);
}

/* One world's life: the box with two more lights, ticked, drawn, queried,
 * then gone. Returns 0, or -1 with err. */
static int one_life(lpv_technique_id technique, char *err, size_t n)
{
    lpv_scene s;
    if (lpv_scene_builtin_cornell(&s) != 0)
        return snprintf(err, n, "no built-in box"), -1;
    if (!lpv_scene_add_point_light(&s, (float[3]){0.1f, 1.2f, 0.1f}, 2.0f) ||
        !lpv_scene_add_point_light(&s, (float[3]){-0.2f, 1.0f, 0.2f}, 2.0f))
        return lpv_scene_free(&s), snprintf(err, n, "no lights added"), -1;
    lpv_light *point = &s.lights[s.light_count - 2], *spot = &s.lights[s.light_count - 1]; /* after the last realloc */
    spot->type = LPV_LIGHT_SPOT;
    spot->direction[0] = 0.0f;
    spot->direction[1] = -1.0f;
    spot->direction[2] = 0.0f;
    spot->outer_cone = 0.6f;
    lpv_scene_compute_bounds(&s);
    lpv_engine *e = lpv_engine_create(err, n);
    if (!e)
        return lpv_scene_free(&s), -1;
    lpv_view v;
    lpv_view_look_at((float[3]){0.0f, 1.0f, 3.0f}, (float[3]){0.0f, 1.0f, 0.0f}, 0.8f, 48, 48, &v);
    lpv_settings set = {.technique = technique};
    float *rgba = malloc(48 * 48 * 4 * sizeof *rgba);
    int rc = rgba && lpv_engine_set_settings(e, &set, err, n) == 0 && lpv_engine_set_scene(e, &s, err, n) == 0 &&
                     lpv_engine_set_view(e, &v, err, n) == 0 && lpv_engine_tick(e, err, n) == 0 &&
                     lpv_engine_tick(e, err, n) == 0 && lpv_engine_render(e, LPV_TERMS_FULL, rgba, err, n) == 0
                 ? 0
                 : -1;
    if (rc == 0) {
        /* a light moved and the settings changed: the paths that remake storage */
        point->position[1] = 1.3f;
        set.rsm_size = 64;
        if (lpv_engine_set_settings(e, &set, err, n) != 0 || lpv_engine_set_scene(e, &s, err, n) != 0 ||
            lpv_engine_tick(e, err, n) != 0)
            rc = -1;
    }
    free(rgba);
    lpv_engine_destroy(e);
    lpv_scene_free(&s);
    return rc;
}

static void test_no_object_outlives_its_engine(void **state)
{
    (void)state;
    lpv_gl_context *ctx;
    lpv_engine *first;
    assert_int_equal(lpvt_gl_open(&ctx, &first), 0);
    lpv_engine_destroy(first); /* only the context stays */
    char err[1024] = "";
    if (one_life(LPV_TECHNIQUE_ID_LPV, err, sizeof err) != 0) /* the warm-up */
        fail_msg("warm-up: %s", err);
    const census before = count_objects();
    print_census("after the warm-up:", &before);
    const lpv_technique_id techniques[] = {LPV_TECHNIQUE_ID_LPV, LPV_TECHNIQUE_ID_OCTREE, LPV_TECHNIQUE_ID_IV,
                                           LPV_TECHNIQUE_ID_AUTO};
    const char *names[] = {"lpv", "octree", "iv", "auto"};
    int leaked = 0;
    for (size_t t = 0; t < sizeof techniques / sizeof techniques[0]; ++t) {
        if (one_life(techniques[t], err, sizeof err) != 0)
            fail_msg("%s: %s", names[t], err);
        const census after = count_objects();
        char what[64];
        snprintf(what, sizeof what, "after a world with %s:", names[t]);
        print_census(what, &after);
        if (memcmp(&after, &before, sizeof before) != 0) {
            printf("  %s left GL objects behind\n", names[t]);
            leaked = 1;
        }
    }
    lpv_gl_context_destroy(ctx);
    assert_false(leaked);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_no_object_outlives_its_engine)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
