/*
 * test_serve_memory.c - the daemon's one memory budget (server/serve/serve_memory.h;
 * issue 31, daemon-wide memory; R7.6a): every term counts against one
 * budget, the terms but requests leave one message of headroom, and the
 * sums do not wrap.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "serve_memory.h"

#define MB 1000000ull

static void test_budget_from_flag_or_machine(void **state)
{
    (void)state;
    sv_memory m;
    char err[256] = "";
    assert_int_equal(sv_memory_init(&m, 500 * MB, 64 * MB, err, sizeof err), 0);
    assert_int_equal(m.budget, 500 * MB);
    assert_non_null(strstr(m.source, "--max-memory 500000000"));
    assert_int_equal(sv_memory_init(&m, 0, 64 * MB, err, sizeof err), 0);
    const uint64_t machine = sv_memory_machine();
    assert_true(machine > 0);
    assert_int_equal(m.budget, machine / 2);
    assert_non_null(strstr(m.source, "half of the machine's"));
    /* a budget that cannot hold one message beside the rest is refused */
    assert_int_equal(sv_memory_init(&m, 64 * MB, 64 * MB, err, sizeof err), -1);
    assert_non_null(strstr(err, "--max-message"));
}

static void test_terms_share_one_budget(void **state)
{
    (void)state;
    sv_memory m;
    char err[256] = "";
    assert_int_equal(sv_memory_init(&m, 500 * MB, 100 * MB, err, sizeof err), 0);
    /* worlds may take the budget less the headroom */
    assert_true(sv_memory_fits(&m, SV_MEM_WORLDS, 400 * MB));
    assert_false(sv_memory_fits(&m, SV_MEM_WORLDS, 400 * MB + 1));
    sv_memory_add(&m, SV_MEM_WORLDS, 300 * MB);
    /* the others' share shrinks by what the worlds hold */
    assert_int_equal(sv_memory_room(&m, SV_MEM_SCENES), 100 * MB);
    assert_true(sv_memory_fits(&m, SV_MEM_SCENES, 100 * MB));
    assert_false(sv_memory_fits(&m, SV_MEM_REPLIES, 100 * MB + 1));
    /* requests may use the headroom the others leave */
    assert_int_equal(sv_memory_room(&m, SV_MEM_REQUESTS), 200 * MB);
    sv_memory_add(&m, SV_MEM_SCENES, 100 * MB);
    assert_int_equal(sv_memory_room(&m, SV_MEM_WORLDS), 400 * MB - 100 * MB); /* its own included */
    assert_true(sv_memory_fits(&m, SV_MEM_REQUESTS, 100 * MB));
    assert_false(sv_memory_fits(&m, SV_MEM_REPLIES, 1));
    assert_int_equal(sv_memory_total(&m), 400 * MB);
    /* described for refusals: each term and the budget's source */
    char d[SV_MEMORY_DESCRIBE_SIZE];
    sv_memory_describe(&m, d, sizeof d);
    assert_non_null(strstr(d, "--max-memory 500000000"));
    assert_non_null(strstr(d, "worlds 0.300 GB"));
    assert_non_null(strstr(d, "scenes 0.100 GB"));
    sv_memory_sub(&m, SV_MEM_WORLDS, 300 * MB);
    sv_memory_sub(&m, SV_MEM_SCENES, 100 * MB);
    assert_int_equal(sv_memory_total(&m), 0);
    /* a size that would wrap the sum never fits */
    assert_false(sv_memory_fits(&m, SV_MEM_REQUESTS, UINT64_MAX));
    sv_memory_add(&m, SV_MEM_REQUESTS, 10 * MB);
    assert_false(sv_memory_fits(&m, SV_MEM_REQUESTS, UINT64_MAX - 5 * MB));
    assert_int_equal(strcmp(sv_mem_term_name(SV_MEM_REPLIES), "replies"), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_budget_from_flag_or_machine),
                                       cmocka_unit_test(test_terms_share_one_budget)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
