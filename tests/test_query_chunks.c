/*
 * test_query_chunks.c - irradiance queries of any size (issue 14, item 7).
 *
 * lpv_engine_irradiance ran one compute dispatch of 64-point work groups, and
 * the GL allows 65535 groups per dimension: 4,194,304 points or more failed
 * with a GL error, so the daemon answered QUERY_IRRADIANCE INTERNAL below its
 * advertised limit (max_message / 24 = 11,184,810 points at the defaults).
 * The engine now works in chunks. This test queries exactly that many points,
 * a pattern of 997 points repeated (997 divides no chunk, so each chunk
 * boundary falls elsewhere in it), and checks every answer equals the one a
 * single small (unchunked) query of the pattern gives.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "engine.h"
#include "scene.h"
#include "test_util.h"
#include "view.h"

#define PATTERN 997
#define DAEMON_MAX_POINTS ((size_t)(256u << 20) / 24u) /* lpvd serve's default --max-message / 24 bytes a point */

static void tick_cornell(void)
{
    lpv_scene scene;
    char err[1024] = "";
    lpv_settings s = {0};
    assert_int_equal(lpv_scene_builtin_cornell(&scene), 0);
    assert_int_equal(lpv_engine_set_settings(lpvt_engine, &s, err, sizeof err), 0);
    assert_int_equal(lpv_engine_set_scene(lpvt_engine, &scene, err, sizeof err), 0);
    lpv_view view;
    lpv_view_from_camera(&scene.cameras[0], 64, 64, &view);
    assert_int_equal(lpv_engine_set_view(lpvt_engine, &view, err, sizeof err), 0);
    if (lpv_engine_tick(lpvt_engine, err, sizeof err) != 0)
        fail_msg("tick: %s", err);
    lpv_scene_free(&scene);
}

static void test_query_up_to_the_daemon_limit(void **state)
{
    (void)state;
    tick_cornell();
    float pp[PATTERN * 3], pn[PATTERN * 3], small[PATTERN * 3];
    uint64_t rng = 14;
    for (int i = 0; i < PATTERN; ++i) {
        float n[3] = {(float)lpvt_rand(&rng, -1, 1), (float)lpvt_rand(&rng, -1, 1), (float)lpvt_rand(&rng, -1, 1)};
        float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) + 1e-6f;
        for (int k = 0; k < 3; ++k)
            pn[i * 3 + k] = n[k] / len;
        pp[i * 3 + 0] = (float)lpvt_rand(&rng, -0.95, 0.95); /* inside the box: x, z in [-1, 1], y in [0, 2] */
        pp[i * 3 + 1] = (float)lpvt_rand(&rng, 0.05, 1.95);
        pp[i * 3 + 2] = (float)lpvt_rand(&rng, -0.95, 0.95);
    }
    char err[512] = "";
    if (lpv_engine_irradiance(lpvt_engine, pp, pn, PATTERN, small, err, sizeof err) != 0)
        fail_msg("small query: %s", err);
    int lit = 0;
    for (int i = 0; i < PATTERN * 3; ++i)
        lit += small[i] > 0.0f;
    assert_true(lit > PATTERN); /* the pattern sees light: equal answers mean something */

    const size_t n = DAEMON_MAX_POINTS;
    float *p = malloc(n * 3 * sizeof *p), *nr = malloc(n * 3 * sizeof *nr), *out = malloc(n * 3 * sizeof *out);
    assert_non_null(p);
    assert_non_null(nr);
    assert_non_null(out);
    for (size_t i = 0; i < n; ++i) {
        memcpy(p + i * 3, pp + (i % PATTERN) * 3, 3 * sizeof *p);
        memcpy(nr + i * 3, pn + (i % PATTERN) * 3, 3 * sizeof *nr);
    }
    memset(out, 0xff, n * 3 * sizeof *out); /* NaN: a point the query skips shows */
    if (lpv_engine_irradiance(lpvt_engine, p, nr, n, out, err, sizeof err) != 0)
        fail_msg("query of %zu points: %s", n, err);
    size_t bad = 0, first = 0;
    for (size_t i = 0; i < n; ++i)
        if (memcmp(out + i * 3, small + (i % PATTERN) * 3, 3 * sizeof *out) != 0 && bad++ == 0)
            first = i;
    if (bad)
        fail_msg("%zu of %zu points differ from the small query's answer, the first at %zu", bad, n, first);
    printf("%zu points (over the 4,194,304 of one dispatch) answered as the %d-point query\n", n, PATTERN);
    free(p);
    free(nr);
    free(out);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_query_up_to_the_daemon_limit),
    };
    return cmocka_run_group_tests(tests, lpvt_gl_setup, lpvt_gl_teardown);
}
