/*
 * test_flags.c - the getopt_long driver of core/flags.h and the flag groups
 * built on it: flags and positional arguments come back in the order given,
 * --flag=value and the shared groups are parsed, errors name the flag as
 * written, argv is left as it was, a second parse in the same process starts
 * afresh, and the settings group holds exactly the field table's flags.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "flags.h"
#include "settings_fields.h"
#include "settings_flags.h"
#include "view_choice.h"

enum { T_OUT, T_FULL, T_N, T_COUNT };
static const lpv_flag FLAGS[T_COUNT] = {
    [T_OUT] = {"output", 'o', "PATH", "output"},
    [T_FULL] = {"full", 0, NULL, "no value"},
    [T_N] = {"n", 0, "N", "a number"},
};

/* Parses argv with FLAGS, the settings and the camera groups; records what
 * came back as "o=PATH full pos=X ..." in log. Returns the last item. */
static lpv_flags_item parse(int argc, char **argv, int long_only, lpv_settings *s, lpv_view_choice *c, char *log,
                            size_t n, lpv_flags *p)
{
    lpv_flag_group g[3] = {{FLAGS, T_COUNT, NULL, NULL}, lpv_settings_flag_group(s), lpv_view_flag_group(c)};
    assert_int_equal(lpv_flags_begin(p, argc, argv, g, 3, long_only), 0);
    size_t len = 0;
    log[0] = '\0';
    int grp;
    const lpv_flag *f;
    const char *v;
    lpv_flags_item it;
    while ((it = lpv_flags_next(p, &grp, &f, &v)) > 0) {
        if (it == LPV_FLAGS_POSITIONAL)
            lpv_flags_append(log, n, &len, "pos=%s ", v);
        else
            lpv_flags_append(log, n, &len, "%s%s%s ", f->name, v ? "=" : "", v ? v : "");
    }
    return it;
}

static void test_order_values_and_groups(void **state)
{
    (void)state;
    const char *args[] = {"prog", "a.glb", "-o", "x.exr", "--grid=16x8x4", "--full", "b.glb", "--n", "-3",
                          "--iterations", "7", "--output=y.exr", "--eye", "1,2,3", "--", "--not-a-flag"};
    char *argv[sizeof args / sizeof args[0]];
    memcpy(argv, args, sizeof args);
    lpv_settings s = {0};
    lpv_view_choice c = {0};
    char log[512];
    lpv_flags p;
    assert_int_equal(parse(16, argv, 0, &s, &c, log, sizeof log, &p), LPV_FLAGS_END);
    assert_string_equal(log, "pos=a.glb output=x.exr full pos=b.glb n=-3 output=y.exr pos=--not-a-flag ");
    assert_int_equal(s.grid_dims[0], 16);
    assert_int_equal(s.grid_dims[2], 4);
    assert_int_equal(s.lpv.iterations, 7);
    assert_int_equal(c.has_eye, 1);
    assert_true(c.eye[2] == 3.0f);
    assert_memory_equal(argv, args, sizeof args); /* not permuted */

    /* a second command line in the same process starts afresh */
    char *again[] = {"prog", "--n", "1", "c.glb"};
    assert_int_equal(parse(4, again, 0, &s, &c, log, sizeof log, &p), LPV_FLAGS_END);
    assert_string_equal(log, "n=1 pos=c.glb ");
}

static void test_errors_name_the_flag(void **state)
{
    (void)state;
    lpv_settings s = {0};
    lpv_view_choice c = {0};
    char log[512];
    lpv_flags p;
    char *unknown[] = {"prog", "--full", "--nope", "x"};
    assert_int_equal(parse(4, unknown, 0, &s, &c, log, sizeof log, &p), LPV_FLAGS_UNKNOWN);
    assert_string_equal(p.arg, "--nope");
    assert_string_equal(log, "full ");
    assert_string_equal(lpv_flags_problem(&p, LPV_FLAGS_UNKNOWN), "unknown flag --nope");
    assert_null(lpv_flags_problem(&p, LPV_FLAGS_POSITIONAL));
    assert_null(lpv_flags_problem(&p, LPV_FLAGS_FLAG));
    assert_int_equal(lpv_flags_refuse(&p, LPV_FLAGS_POSITIONAL, "x", "prog", 1), 0); /* taken */
    assert_int_equal(lpv_flags_refuse(&p, LPV_FLAGS_POSITIONAL, "x", "prog", 0), 1); /* refused */
    assert_int_equal(lpv_flags_refuse(&p, LPV_FLAGS_FLAG, NULL, "prog", 0), 0);
    assert_int_equal(lpv_flags_refuse(&p, LPV_FLAGS_UNKNOWN, NULL, "prog", 1), 1);
    char *short_unknown[] = {"prog", "-x"};
    assert_int_equal(parse(2, short_unknown, 0, &s, &c, log, sizeof log, &p), LPV_FLAGS_UNKNOWN);
    assert_string_equal(p.arg, "-x");
    char *no_value[] = {"prog", "--grid"};
    assert_int_equal(parse(2, no_value, 0, &s, &c, log, sizeof log, &p), LPV_FLAGS_NO_VALUE);
    assert_string_equal(p.arg, "--grid");
    assert_string_equal(lpv_flags_problem(&p, LPV_FLAGS_NO_VALUE), "--grid needs a value");
    char *no_value_short[] = {"prog", "-o"};
    assert_int_equal(parse(2, no_value_short, 0, &s, &c, log, sizeof log, &p), LPV_FLAGS_NO_VALUE);
    assert_string_equal(p.arg, "-o");
    char *bad[] = {"prog", "--occlusion", "maybe"};
    assert_int_equal(parse(3, bad, 0, &s, &c, log, sizeof log, &p), LPV_FLAGS_BAD_VALUE);
    assert_non_null(strstr(p.err, "--occlusion maybe: expected on or off"));
    assert_ptr_equal(lpv_flags_problem(&p, LPV_FLAGS_BAD_VALUE), p.err); /* the group's own message */
    char *bad_size[] = {"prog", "--size=12"};
    assert_int_equal(parse(2, bad_size, 0, &s, &c, log, sizeof log, &p), LPV_FLAGS_BAD_VALUE);
    assert_non_null(strstr(p.err, "--size 12: expected WxH"));
    char *value_to_switch[] = {"prog", "--full=1"};
    assert_int_equal(parse(2, value_to_switch, 0, &s, &c, log, sizeof log, &p), LPV_FLAGS_UNKNOWN);
    assert_string_equal(p.arg, "--full=1");
}

/* lpvd-reference's long-only mode: "-full -n 3" as "--full --n 3", "-o" short. */
static void test_long_only(void **state)
{
    (void)state;
    lpv_settings s = {0};
    lpv_view_choice c = {0};
    char log[512];
    lpv_flags p;
    char *argv[] = {"prog", "-full", "-n", "3", "-o", "x.exr", "-size", "8x4"};
    assert_int_equal(parse(8, argv, 1, &s, &c, log, sizeof log, &p), LPV_FLAGS_END);
    assert_string_equal(log, "full n=3 output=x.exr ");
    assert_int_equal(c.width, 8);
    assert_int_equal(c.height, 4);
}

static void test_tables(void **state)
{
    (void)state;
    /* a flag in two tables is a programming error, caught before parsing */
    lpv_flag_group twice[2] = {{FLAGS, T_COUNT, NULL, NULL}, {FLAGS, 1, NULL, NULL}};
    lpv_flags p;
    char *argv[] = {"prog"};
    assert_int_equal(lpv_flags_begin(&p, 1, argv, twice, 2, 0), -1);
    assert_non_null(strstr(p.err, "--output"));

    /* the settings group: technique, preset, grid, bounds, then exactly the field table */
    size_t nf, ng;
    const lpv_field *fields = lpv_fields(&nf);
    const lpv_flag *flags = lpv_settings_flags(&ng);
    assert_int_equal(ng, nf + 4);
    assert_string_equal(flags[0].name, "technique");
    assert_string_equal(flags[1].name, "preset");
    for (size_t i = 0; i < nf; ++i) {
        assert_string_equal(flags[4 + i].name, fields[i].flag);
        assert_non_null(flags[4 + i].metavar);
        char line[96], dflt[32];
        snprintf(line, sizeof line, "default %s)", lpv_field_default_words(&fields[i], dflt, sizeof dflt));
        if (!strstr(lpv_settings_flags_help(), line))
            fail_msg("help gives no default for --%s", fields[i].flag);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_order_values_and_groups),
        cmocka_unit_test(test_errors_name_the_flag),
        cmocka_unit_test(test_long_only),
        cmocka_unit_test(test_tables),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
