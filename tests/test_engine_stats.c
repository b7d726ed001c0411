/*
 * test_engine_stats.c - a technique's own counts in the stats, by name
 * (gpu/engine_stats.c): put appends a new name and replaces a known one,
 * keeps the order names came in (the stats JSON's key order), stops at
 * LPV_TECHNIQUE_STATS_MAX, and get finds a name or says none.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "engine.h"

static void test_put_and_get(void **state)
{
    (void)state;
    lpv_engine_stats s;
    memset(&s, 0, sizeof s);
    assert_null(lpv_stats_get(&s, "points"));
    lpv_stats_put(&s, "points", LPV_STAT_INT, 33024, 0, 0);
    lpv_stats_put(&s, "tail", LPV_STAT_BOOL, 1, 0, 0);
    lpv_stats_put(&s, "tail_ratio", LPV_STAT_REAL3, 0.5, 0.25, 0.125);
    assert_int_equal(s.technique_stat_count, 3);
    lpv_stats_put(&s, "points", LPV_STAT_INT, 7, 0, 0); /* replaced in place */
    assert_int_equal(s.technique_stat_count, 3);
    assert_string_equal(s.technique_stats[0].name, "points");
    assert_true(lpv_stats_get(&s, "points")->v[0] == 7.0);
    const lpv_stat *r = lpv_stats_get(&s, "tail_ratio");
    assert_int_equal(r->kind, LPV_STAT_REAL3);
    assert_true(r->v[0] == 0.5 && r->v[1] == 0.25 && r->v[2] == 0.125);
    assert_null(lpv_stats_get(&s, "tails"));

    static const char *const names[] = {"a", "b", "c", "d", "e", "f", "g", "h", "i", "j",
                                        "k", "l", "m", "n", "o", "p", "q", "r", "s", "t"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i)
        lpv_stats_put(&s, names[i], LPV_STAT_INT, (double)i, 0, 0);
    assert_int_equal(s.technique_stat_count, LPV_TECHNIQUE_STATS_MAX); /* the rest dropped, nothing overrun */
    assert_non_null(lpv_stats_get(&s, "a"));
    assert_null(lpv_stats_get(&s, "t"));
    lpv_stats_put(&s, "points", LPV_STAT_INT, 9, 0, 0); /* a known name still updates when full */
    assert_true(lpv_stats_get(&s, "points")->v[0] == 9.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_put_and_get)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
