/*
 * test_serve_limits.c - the daemon's limits table (server/serve/serve_limits.c;
 * issue 33, item 3): each row's default lies in its range, the flag sets
 * its field of sv_config and refuses a value outside the range naming the
 * flag and the range, --help shows the default, HELLO's limits carry the
 * value under the row's key, and docs/server.md's flag table lists the flag.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "serve.h"
#include "serve_limits.h"

/* The field of row l in cfg, as a double. */
static double field(const sv_config *cfg, const sv_limit *l)
{
    const char *at = (const char *)cfg + l->offset;
    if (l->type == SV_LIMIT_INT)
        return *(const int *)(const void *)at;
    if (l->type == SV_LIMIT_U64)
        return (double)*(const uint64_t *)(const void *)at;
    return *(const double *)(const void *)at;
}

static void test_defaults_in_range_and_unique(void **state)
{
    (void)state;
    sv_config cfg;
    memset(&cfg, 0xab, sizeof cfg);
    sv_limits_defaults(&cfg);
    assert_true(sv_limit_count >= 20);
    for (size_t i = 0; i < sv_limit_count; ++i) {
        const sv_limit *l = &sv_limits[i];
        assert_true(l->lo <= l->hi);
        /* 0 only where the note says what it stands for (--max-memory: from the machine) */
        assert_true((l->deflt >= l->lo && l->deflt <= l->hi) || (l->deflt == 0.0 && l->note));
        assert_true(field(&cfg, l) == l->deflt);
        for (size_t k = 0; k < i; ++k) {
            assert_string_not_equal(l->flag, sv_limits[k].flag);
            assert_true(!l->hello || !sv_limits[k].hello || strcmp(l->hello, sv_limits[k].hello) != 0);
            assert_true(l->offset != sv_limits[k].offset);
        }
    }
    assert_int_equal(cfg.max_clients, 64);
    assert_int_equal(cfg.max_tick_cost, SV_DEFAULT_MAX_TICK_COST);
}

/* Parses argv through the limits' group into cfg: 0, or -1 with err. */
static int parse(sv_config *cfg, int argc, char **argv, char *err, size_t n)
{
    lpv_flag_group g = sv_limits_flag_group(cfg);
    lpv_flags p;
    assert_int_equal(lpv_flags_begin(&p, argc, argv, &g, 1, 0), 0);
    int grp;
    const lpv_flag *fl;
    const char *v;
    for (lpv_flags_item it; (it = lpv_flags_next(&p, &grp, &fl, &v)) != LPV_FLAGS_END;)
        if (it != LPV_FLAGS_FLAG) {
            snprintf(err, n, "%s", it == LPV_FLAGS_BAD_VALUE ? p.err : p.arg);
            return -1;
        }
    return 0;
}

static void test_flags_set_and_refuse(void **state)
{
    (void)state;
    sv_config cfg;
    memset(&cfg, 0, sizeof cfg);
    sv_limits_defaults(&cfg);
    char err[1024] = "";
    char *ok[] = {"serve", "--max-clients", "7", "--max-queue=131072", "--idle-timeout", "12.5",
                  "--max-memory", "1073741824", "--max-grid", "256"};
    assert_int_equal(parse(&cfg, 10, ok, err, sizeof err), 0);
    assert_int_equal(cfg.max_clients, 7);
    assert_int_equal(cfg.max_queue, 131072);
    assert_true(cfg.idle_timeout == 12.5);
    assert_int_equal(cfg.max_memory, 1073741824ull);
    assert_int_equal(cfg.max_grid, 256);

    struct {
        const char *flag, *value, *says;
    } bad[] = {
        {"--max-clients", "0", "--max-clients 0: expected a whole number in 1..100000"},
        {"--max-clients", "-3", "1..100000"},
        {"--max-clients", "12x", "--max-clients 12x"},
        {"--max-clients", "1e3", "whole number"},
        {"--max-queue", "65535", "65536..2^40"},
        {"--max-grid", "257", "1..256"},
        {"--idle-timeout", "nan", "--idle-timeout nan: expected a number"},
        {"--idle-timeout", "-1", "0..1e+09"},
        {"--max-message", "99999999999999999999999", "--max-message"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        sv_config before = cfg;
        char *argv[] = {"serve", (char *)bad[i].flag, (char *)bad[i].value};
        err[0] = 0;
        assert_int_equal(parse(&cfg, 3, argv, err, sizeof err), -1);
        if (!strstr(err, bad[i].says))
            fail_msg("%s %s: \"%s\" does not say \"%s\"", bad[i].flag, bad[i].value, err, bad[i].says);
        assert_memory_equal(&before, &cfg, sizeof cfg); /* nothing written */
    }
}

static void test_help_and_hello_from_rows(void **state)
{
    (void)state;
    sv_config cfg;
    memset(&cfg, 0, sizeof cfg);
    sv_limits_defaults(&cfg);
    cfg.max_texture = 4096;
    cfg.handshake_timeout = 2.5;
    json_t *lim = json_object();
    sv_limits_hello(&cfg, lim);
    size_t reported = 0;
    for (size_t i = 0; i < sv_limit_count; ++i) {
        const sv_limit *l = &sv_limits[i];
        char help[4096] = "", want[128];
        size_t len = 0;
        sv_limits_help(help, sizeof help, &len, l->section);
        snprintf(want, sizeof want, "--%s %s", l->flag, l->metavar);
        assert_non_null(strstr(help, want));
        if (l->deflt != 0.0 || !l->note) {
            snprintf(want, sizeof want, "default %.0f", l->deflt);
            if (!strstr(help, want))
                fail_msg("--help of --%s lacks \"%s\"", l->flag, want);
        }
        if (!l->hello)
            continue;
        ++reported;
        const json_t *v = json_object_get(lim, l->hello);
        assert_non_null(v);
        assert_true(l->type == SV_LIMIT_REAL ? json_is_real(v) : json_is_integer(v));
        assert_true(json_number_value(v) == field(&cfg, l));
    }
    assert_int_equal(json_object_size(lim), reported);
    assert_int_equal(json_integer_value(json_object_get(lim, "max_texture")), 4096);
    assert_true(json_real_value(json_object_get(lim, "handshake_timeout")) == 2.5);
    json_decref(lim);
}

/* docs/server.md's flag table has a row for every limit. */
static void test_docs_list_every_limit(void **state)
{
    (void)state;
    const char *src = getenv("LPVD_SOURCE_DIR");
    char path[1024];
    snprintf(path, sizeof path, "%s/docs/server.md", src ? src : ".");
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    static char doc[1 << 20];
    size_t n = fread(doc, 1, sizeof doc - 1, f);
    fclose(f);
    doc[n] = 0;
    for (size_t i = 0; i < sv_limit_count; ++i) {
        char row[128];
        snprintf(row, sizeof row, "| `--%s %s` |", sv_limits[i].flag, sv_limits[i].metavar);
        if (!strstr(doc, row))
            fail_msg("docs/server.md has no flag-table row starting \"%s\"", row);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults_in_range_and_unique),
        cmocka_unit_test(test_flags_set_and_refuse),
        cmocka_unit_test(test_help_and_hello_from_rows),
        cmocka_unit_test(test_docs_list_every_limit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
