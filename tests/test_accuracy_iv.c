/* test_accuracy_iv.c - bench/accuracy/iv_knobs.h: the imperfect volume's
 * knobs as lpvd-accuracy sweeps them (--knobs names and value lists, the
 * --points form iv[:RES:POINTS:RAYS:BOUNCES:REPROJ:NEIGHBOURS]) and the
 * overall front keeping iv points apart from LPV points (overall.h).
 * Plain C, no GL. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <string.h>

#include "iv_knobs.h"
#include "knob_rows.h"
#include "overall.h"
#include "settings.h"

static void test_point_full(void **state)
{
    (void)state;
    lpv_acc_iv_knobs k;
    char err[256] = "";
    assert_int_equal(lpv_acc_iv_parse_point("iv:32:8:64:3:on:8", &k, err, sizeof err), 1);
    assert_int_equal(k.v[LPV_ACC_IV_RESOLUTION], 32);
    assert_int_equal(k.v[LPV_ACC_IV_POINTS], 8);
    assert_int_equal(k.v[LPV_ACC_IV_RAYS], 64);
    assert_int_equal(k.v[LPV_ACC_IV_BOUNCES], 3);
    assert_int_equal(k.v[LPV_ACC_IV_REPROJECTION], LPV_SWITCH_ON);
    assert_int_equal(k.v[LPV_ACC_IV_NEIGHBOURS], 8);
    assert_int_equal(lpv_acc_iv_parse_point("iv:16:19:100:1:off:6", &k, err, sizeof err), 1);
    assert_int_equal(k.v[LPV_ACC_IV_REPROJECTION], LPV_SWITCH_OFF);
    assert_int_equal(k.v[LPV_ACC_IV_NEIGHBOURS], 6);
}

/* Fields left out, empty or "-" stay unset (0): the base settings' value. */
static void test_point_partial(void **state)
{
    (void)state;
    lpv_acc_iv_knobs k;
    char err[256] = "";
    assert_int_equal(lpv_acc_iv_parse_point("iv", &k, err, sizeof err), 1);
    for (int i = 0; i < LPV_ACC_IV_KNOBS; ++i)
        assert_int_equal(k.v[i], 0);
    assert_int_equal(lpv_acc_iv_parse_point("iv:16:-::2", &k, err, sizeof err), 1);
    assert_int_equal(k.v[LPV_ACC_IV_RESOLUTION], 16);
    assert_int_equal(k.v[LPV_ACC_IV_POINTS], 0);
    assert_int_equal(k.v[LPV_ACC_IV_RAYS], 0);
    assert_int_equal(k.v[LPV_ACC_IV_BOUNCES], 2);
    assert_int_equal(k.v[LPV_ACC_IV_REPROJECTION], 0);

    lpv_iv_settings s = {.resolution = 32, .points = 8, .rays = 64, .bounces = 3, .reprojection = LPV_SWITCH_ON,
                         .neighbours = 8};
    lpv_acc_iv_apply(&k, &s);
    assert_int_equal(s.resolution, 16);
    assert_int_equal(s.points, 8);
    assert_int_equal(s.bounces, 2);
    assert_int_equal(s.reprojection, LPV_SWITCH_ON);
    lpv_acc_iv_knobs back = lpv_acc_iv_of_settings(&s);
    assert_int_equal(back.v[LPV_ACC_IV_RAYS], 64);
    assert_int_equal(back.v[LPV_ACC_IV_RESOLUTION], 16);
}

/* Not an iv point: 0 (the LPV's form is parsed elsewhere); malformed: -1. */
static void test_point_errors(void **state)
{
    (void)state;
    lpv_acc_iv_knobs k;
    char err[256] = "";
    assert_int_equal(lpv_acc_iv_parse_point("8:8:128:on:cbfs:iv", &k, err, sizeof err), 0);
    assert_int_equal(lpv_acc_iv_parse_point("ivy:3", &k, err, sizeof err), 0);
    const char *bad[] = {"iv:0", "iv:257", "iv:x", "iv:32:65", "iv:32:8:2000", "iv:32:8:64:9", "iv:32:8:64:3:maybe",
                         "iv:32:8:64:3:on:9", "iv:32:8:64:3:on:8:1", "iv:32:8:64:3:on:0", "iv:-1"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        err[0] = '\0';
        assert_int_equal(lpv_acc_iv_parse_point(bad[i], &k, err, sizeof err), -1);
        assert_true(strlen(err) > 0); /* says why */
    }
}

static void test_knob_lists(void **state)
{
    (void)state;
    assert_int_equal(lpv_acc_iv_knob_from_name("iv_resolution"), LPV_ACC_IV_RESOLUTION);
    assert_int_equal(lpv_acc_iv_knob_from_name("iv_neighbours"), LPV_ACC_IV_NEIGHBOURS);
    assert_int_equal(lpv_acc_iv_knob_from_name("grid"), -1);
    assert_string_equal(lpv_acc_iv_knob_name(LPV_ACC_IV_RAYS), "iv_rays");
    int v[16];
    assert_int_equal(lpv_acc_iv_parse_list(LPV_ACC_IV_RESOLUTION, "16/32/48", v, 16), 3);
    assert_int_equal(v[2], 48);
    assert_int_equal(lpv_acc_iv_parse_list(LPV_ACC_IV_REPROJECTION, "on/off", v, 16), 2);
    assert_int_equal(v[0], LPV_SWITCH_ON);
    assert_int_equal(v[1], LPV_SWITCH_OFF);
    assert_int_equal(lpv_acc_iv_parse_list(LPV_ACC_IV_NEIGHBOURS, "6/9", v, 16), -1);
    assert_int_equal(lpv_acc_iv_parse_list(LPV_ACC_IV_RAYS, "", v, 16), -1);
    assert_int_equal(lpv_acc_iv_parse_list(LPV_ACC_IV_RAYS, "1/2/3", v, 2), -1);
}

/* The sweep's knobs are rows of lpvd's knob table: a swept value is
 * accepted exactly when the row's range takes it, and the sweep's short
 * names stand for the rows (bench/accuracy/knob_rows.h). */
static void test_ranges_from_rows(void **state)
{
    (void)state;
    for (int k = 0; k < LPV_ACC_IV_KNOBS; ++k) {
        const lpv_field *f = lpv_field_by_key(lpv_acc_iv_knob_name(k));
        assert_non_null(f);
        if (f->kind == LPV_FIELD_SWITCH)
            continue;
        char tok[32];
        int v = 0;
        snprintf(tok, sizeof tok, "%d", (int)f->max);
        assert_int_equal(lpv_acc_iv_parse_value(k, tok, &v), 0);
        assert_int_equal(v, (int)f->max);
        snprintf(tok, sizeof tok, "%d", (int)f->max + 1);
        assert_int_equal(lpv_acc_iv_parse_value(k, tok, &v), -1);
    }
    assert_ptr_equal(acc_knob_row("rsm"), lpv_field_by_key("rsm_size"));
    assert_ptr_equal(acc_knob_row("rsm_size"), lpv_field_by_key("rsm_size"));
    assert_ptr_equal(acc_knob_row("bins"), lpv_field_by_key("normal_bins"));
    assert_null(acc_knob_row("bogus"));
    assert_string_equal(acc_knob_alias("camera_surfel_step"), "camera_step");
    double x;
    const lpv_field *rsm = acc_knob_row("rsm");
    char tok[32];
    snprintf(tok, sizeof tok, "%d", (int)rsm->max);
    assert_int_equal(acc_knob_value(rsm, tok, &x, NULL, 0), 0);
    snprintf(tok, sizeof tok, "%d", (int)rsm->max * 2);
    assert_int_equal(acc_knob_value(rsm, tok, &x, NULL, 0), -1);
    assert_int_equal(acc_knob_value(acc_knob_row("camera_step"), "auto", &x, NULL, 0), 0);
    assert_true(x == 0.0);
    assert_int_equal(acc_knob_value(acc_knob_row("occlusion"), "off", &x, NULL, 0), 0);
    assert_true(x == 0.0);
    assert_int_equal(acc_knob_value(acc_knob_row("occlusion"), "maybe", &x, NULL, 0), -1);
}

/* The overall front keys iv points by their iv knobs: two iv points that
 * differ only there are two points, and an LPV point is a third. */
static void test_overall_iv_keys(void **state)
{
    (void)state;
    lpv_acc_row rows[6] = {0};
    for (int s = 0; s < 2; ++s) {
        rows[3 * s + 0] = (lpv_acc_row){s, {8, 8, 128, 1, 15, 1}, 100.0, 1.0};
        rows[3 * s + 1] = (lpv_acc_row){s, {0, 0, 128, 0, 0, 3, 16, 8, 64, 3, 1, 8}, 50.0, 2.0};
        rows[3 * s + 2] = (lpv_acc_row){s, {0, 0, 128, 0, 0, 3, 32, 8, 64, 3, 1, 8}, 80.0, 0.5};
    }
    lpv_acc_overall o[6];
    size_t n = lpv_acc_overall_front(rows, 6, 2, o, 6);
    assert_int_equal(n, 3);
    assert_int_equal(o[1].key[LPV_ACC_KEY_TECHNIQUE], 3);
    assert_int_equal(o[1].key[LPV_ACC_KEY_IV], 16);
    assert_int_equal(o[2].key[LPV_ACC_KEY_IV], 32);
    assert_int_equal(o[0].pareto, 0); /* slower and worse than the 32-voxel iv point */
    assert_int_equal(o[1].pareto, 1);
    assert_int_equal(o[2].pareto, 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_point_full),  cmocka_unit_test(test_point_partial),
        cmocka_unit_test(test_point_errors), cmocka_unit_test(test_knob_lists),
        cmocka_unit_test(test_ranges_from_rows),
        cmocka_unit_test(test_overall_iv_keys),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
