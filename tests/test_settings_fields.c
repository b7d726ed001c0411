/*
 * test_settings_fields.c - the lpv_settings field table (core/settings_fields.h):
 * every entry is well formed and round-trips through the setters and the
 * getter, its range agrees with lpv_settings_validate(), and the shared
 * command-line flags (server/options.c) take every knob from the table.
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

#include "options.h"
#include "settings.h"
#include "settings_fields.h"

static const char *const NEW_KEYS[] = {"cascades", "cascade_size", "cascade_ratio", "cascade_offset", "bounces",
                                       "bounce_intensity", "damping", "glossy", "glossy_roughness", "media",
                                       "fog_sigma_s", "fog_sigma_a", "media_step", "planner"};

/* The values each field is exercised with: both ends of the range and the middle. */
static int test_values(const lpv_field *f, double v[3])
{
    if (f->kind == LPV_FIELD_SWITCH) {
        v[0] = 1.0;
        v[1] = 0.0;
        return 2;
    }
    double lo = f->min_exclusive ? (f->kind == LPV_FIELD_INT ? f->min + 1 : f->min + 1e-3 * (f->max - f->min))
                                 : f->min;
    if (f->min_exclusive && f->max > 1e6)
        lo = 1e-3; /* indirect_gain's 1e30 ceiling would make the step huge */
    v[0] = lo;
    v[1] = f->max;
    v[2] = f->kind == LPV_FIELD_INT ? floor(0.5 * (lo + f->max)) : 0.5 * (lo + f->max);
    return 3;
}

static void test_table_well_formed(void **state)
{
    (void)state;
    size_t n;
    const lpv_field *t = lpv_fields(&n);
    assert_true(n >= 19);
    for (size_t i = 0; i < n; ++i) {
        const lpv_field *f = &t[i];
        char kebab[64];
        snprintf(kebab, sizeof kebab, "%s", f->key);
        for (char *p = kebab; *p; ++p) {
            assert_true((*p >= 'a' && *p <= 'z') || (*p >= '0' && *p <= '9') || *p == '_');
            if (*p == '_')
                *p = '-';
        }
        assert_string_equal(f->flag, kebab); /* the flag is the key in kebab-case */
        assert_ptr_equal(lpv_field_by_key(f->key), f);
        assert_ptr_equal(lpv_field_by_flag(f->flag), f);
        assert_true(f->offset + sizeof(float) <= sizeof(lpv_settings));
        assert_true(f->kind == LPV_FIELD_SWITCH || f->min < f->max);
        assert_non_null(f->unit);
        assert_non_null(f->note);
        assert_true(f->help && f->help[0]);
        char words[32];
        assert_true(lpv_field_default_words(f, words, sizeof words)[0]);
        /* a value default is written as the value, the others in words */
        assert_true((f->dflt_rule == LPV_DEFAULT_VALUE) == (f->dflt_words == NULL));
        assert_true(f->dflt_rule != LPV_DEFAULT_PRESET || f->kind != LPV_FIELD_FLOAT); /* resolve copies ints */
        for (size_t k = 0; k < i; ++k)
            assert_int_not_equal(t[k].offset, f->offset);
    }
    for (size_t i = 0; i < sizeof NEW_KEYS / sizeof NEW_KEYS[0]; ++i)
        assert_non_null(lpv_field_by_key(NEW_KEYS[i]));
    assert_null(lpv_field_by_key("grid"));
    assert_null(lpv_field_by_key("no_such_knob"));
    assert_null(lpv_field_by_flag("cascade_size")); /* flags are kebab-case */
    assert_int_equal(lpv_field_by_key("damping")->offset, offsetof(lpv_settings, lpv.damping));
    assert_int_equal(lpv_field_by_key("planner")->kind, LPV_FIELD_SWITCH);
    assert_int_equal(lpv_field_by_key("cascades")->kind, LPV_FIELD_INT);
}

/* Every value the table accepts reads back as set, survives resolve and passes validate. */
static void test_round_trip_and_validate(void **state)
{
    (void)state;
    size_t n;
    const lpv_field *t = lpv_fields(&n);
    char err[256], str[64];
    for (size_t i = 0; i < n; ++i) {
        const lpv_field *f = &t[i];
        double v[3];
        int nv = test_values(f, v);
        for (int k = 0; k < nv; ++k) {
            lpv_settings a = {0}, b = {0};
            assert_int_equal(lpv_field_set_number(&a, f, v[k], err, sizeof err), 0);
            if (f->kind == LPV_FIELD_SWITCH)
                snprintf(str, sizeof str, "%s", v[k] != 0.0 ? "on" : "off");
            else if (f->kind == LPV_FIELD_INT) /* all digits: iv_seed's 2^31 - 1 has ten */
                snprintf(str, sizeof str, "%.0f", v[k]);
            else
                snprintf(str, sizeof str, "%.9g", v[k]);
            assert_int_equal(lpv_field_set_string(&b, f, str, err, sizeof err), 0);
            assert_memory_equal(&a, &b, sizeof a);
            assert_false(f->kind != LPV_FIELD_SWITCH && v[k] != 0.0 && lpv_field_is_default(&a, f));
            double got = lpv_field_get(&a, f);
            if (f->kind == LPV_FIELD_FLOAT)
                assert_true((float)got == (float)v[k]);
            else
                assert_true(got == v[k]);
            lpv_settings_resolve(&a);
            assert_true(lpv_field_get(&a, f) == got); /* a set value is not replaced by a default */
            err[0] = '\0';
            if (lpv_settings_validate(&a, err, sizeof err) != 0)
                fail_msg("%s = %g: validate says %s", f->key, v[k], err);
        }
        if (f->kind == LPV_FIELD_SWITCH) {
            lpv_settings a = {0};
            assert_int_equal(lpv_field_set_bool(&a, f, 0), 0);
            assert_true(lpv_field_get(&a, f) == 0.0);
            assert_int_equal(lpv_field_set_bool(&a, f, 1), 0);
            assert_true(lpv_field_get(&a, f) == 1.0);
            lpv_settings z = {0};
            assert_true(lpv_field_get(&z, f) == -1.0);
        } else {
            lpv_settings a = {0};
            assert_int_equal(lpv_field_set_bool(&a, f, 1), -1);
        }
    }
    /* floats read back as their shortest decimal */
    lpv_settings a = {0};
    assert_int_equal(lpv_field_set_number(&a, lpv_field_by_key("glossy_roughness"), 0.3, err, sizeof err), 0);
    assert_true(lpv_field_get(&a, lpv_field_by_key("glossy_roughness")) == 0.3);
    lpv_settings_resolve(&a);
    assert_true(lpv_field_get(&a, lpv_field_by_key("media_step")) == 0.5);
    assert_true(lpv_field_get(&a, lpv_field_by_key("cascade_size")) == 0.0); /* auto, relative to the scene */
}

/* The defaults come from the rows: a zero struct resolves every value row
 * to its value (which its own range accepts), keeps the zero rows at zero
 * and takes the preset rows from the balanced preset. */
static void test_defaults_from_rows(void **state)
{
    (void)state;
    size_t n;
    const lpv_field *t = lpv_fields(&n);
    lpv_settings z = {0}, balanced;
    lpv_settings_resolve(&z);
    assert_int_equal(lpv_preset_settings(LPV_PRESET_BALANCED, &balanced), 0);
    char err[256];
    assert_int_equal(lpv_settings_validate(&z, err, sizeof err), 0);
    for (size_t i = 0; i < n; ++i) {
        const lpv_field *f = &t[i];
        const double got = lpv_field_get(&z, f);
        switch (f->dflt_rule) {
        case LPV_DEFAULT_VALUE:
            if (f->kind == LPV_FIELD_SWITCH) {
                assert_true(got == (f->dflt != 0.0 ? 1.0 : 0.0));
            } else {
                if ((float)got != (float)f->dflt)
                    fail_msg("%s resolves to %g, its row says %g", f->key, got, f->dflt);
                lpv_settings a = {0};
                assert_int_equal(lpv_field_set_number(&a, f, f->dflt, err, sizeof err), 0);
            }
            break;
        case LPV_DEFAULT_ZERO: assert_true(got == 0.0 && lpv_field_is_default(&z, f)); break;
        case LPV_DEFAULT_PRESET:
            if (strcmp(f->key, "iterations") != 0) /* iterations: scaled to the grid (test_presets) */
                assert_true(got == lpv_field_get(&balanced, f));
            break;
        default: fail_msg("%s: unknown default rule %d", f->key, (int)f->dflt_rule);
        }
    }
    /* the words help and HELLO print */
    char w[32];
    assert_string_equal(lpv_field_default_words(lpv_field_by_key("iv_max_points"), w, sizeof w), "1048576");
    assert_string_equal(lpv_field_default_words(lpv_field_by_key("glossy_roughness"), w, sizeof w), "0.3");
    assert_string_equal(lpv_field_default_words(lpv_field_by_key("bounces"), w, sizeof w), "off");
    assert_string_equal(lpv_field_default_words(lpv_field_by_key("cascades"), w, sizeof w), "auto");
}

/* Values outside the table's range: the table refuses them, and so does validate
 * when they are written into the struct directly, naming the field. */
static void test_ranges_agree_with_validate(void **state)
{
    (void)state;
    size_t n;
    const lpv_field *t = lpv_fields(&n);
    char err[256];
    for (size_t i = 0; i < n; ++i) {
        const lpv_field *f = &t[i];
        lpv_settings s = {0};
        if (f->kind == LPV_FIELD_SWITCH) {
            *(int *)((char *)&s + f->offset) = 3;
            lpv_settings_resolve(&s);
            assert_int_equal(lpv_settings_validate(&s, err, sizeof err), -1);
            assert_non_null(strstr(err, f->key));
            continue;
        }
        /* just above the maximum; just below the minimum (for the fields whose zero
         * resolves to a default, the first value that resolve leaves alone) */
        double above = f->kind == LPV_FIELD_INT ? f->max + 1 : f->max + 0.01 * (f->max - f->min);
        double below = f->kind == LPV_FIELD_INT ? (f->min == 1 ? -1 : f->min - 1)
                       : f->min_exclusive       ? f->min - 1
                                                : f->min - 0.01 * (f->max - f->min);
        double out[2] = {above, below};
        for (int k = 0; k < 2; ++k) {
            lpv_settings a = {0};
            err[0] = '\0';
            assert_int_equal(lpv_field_set_number(&a, f, out[k], err, sizeof err), -1);
            assert_non_null(strstr(err, "out of range"));
            assert_true(lpv_field_is_default(&a, f)); /* untouched */
            char str[64];
            snprintf(str, sizeof str, "%.9g", out[k]);
            assert_int_equal(lpv_field_set_string(&a, f, str, err, sizeof err), -1);
            assert_non_null(strstr(err, "expected"));
            lpv_settings raw = {0};
            char *p = (char *)&raw + f->offset;
            if (f->kind == LPV_FIELD_INT)
                *(int *)p = (int)out[k];
            else
                *(float *)p = (float)out[k];
            lpv_settings_resolve(&raw);
            err[0] = '\0';
            if (lpv_settings_validate(&raw, err, sizeof err) != -1)
                fail_msg("%s = %g: outside the table's range but validate accepts it", f->key, out[k]);
            assert_non_null(strstr(err, f->key));
        }
    }
}

static void test_bad_strings(void **state)
{
    (void)state;
    char err[256];
    lpv_settings s = {0};
    const lpv_field *cascades = lpv_field_by_key("cascades"), *damping = lpv_field_by_key("damping"),
                    *glossy = lpv_field_by_key("glossy");
    const char *bad_num[] = {"", "abc", "1x", "nan", "inf", "0.5.1", NULL};
    for (int i = 0; bad_num[i]; ++i) {
        assert_int_equal(lpv_field_set_string(&s, damping, bad_num[i], err, sizeof err), -1);
        assert_int_equal(lpv_field_set_string(&s, cascades, bad_num[i], err, sizeof err), -1);
    }
    assert_int_equal(lpv_field_set_string(&s, cascades, "1.5", err, sizeof err), -1);
    assert_non_null(strstr(err, "integer"));
    assert_int_equal(lpv_field_set_number(&s, cascades, 1.5, err, sizeof err), -1);
    assert_int_equal(lpv_field_set_number(&s, damping, NAN, err, sizeof err), -1);
    assert_int_equal(lpv_field_set_string(&s, glossy, "yes", err, sizeof err), -1);
    assert_non_null(strstr(err, "on or off"));
    assert_int_equal(lpv_field_set_string(&s, glossy, NULL, err, sizeof err), -1);
    assert_int_equal(lpv_field_set_string(&s, cascades, "0", err, sizeof err), 0); /* 0 = auto */
    assert_int_equal(lpv_field_set_string(&s, lpv_field_by_key("cascade_offset"), "-0.5", err, sizeof err), 0);
    assert_true(lpv_field_get(&s, lpv_field_by_key("cascade_offset")) == -0.5);
    /* a value that would round to 0 in the float, where 0 means the default
     * (indirect_gain 1e-300 became 1.0; issue 31, item 12), is refused */
    const lpv_field *gain = lpv_field_by_key("indirect_gain");
    assert_int_equal(lpv_field_set_number(&s, gain, 1e-300, err, sizeof err), -1);
    assert_non_null(strstr(err, "too small"));
    assert_int_equal(lpv_field_set_string(&s, gain, "1e-40", err, sizeof err), -1); /* subnormal: digits lost */
    assert_non_null(strstr(err, "too small"));
    assert_int_equal(lpv_field_set_string(&s, gain, "1e-30", err, sizeof err), 0);
    assert_true(lpv_field_get(&s, gain) > 0.0);
    lpv_settings zero = {0};
    assert_memory_equal(&zero.glossy, &s.glossy, sizeof s.glossy); /* failures left it alone */
}

/* The shared flags: every table knob is a flag that takes a value, is listed in
 * the help, sets its field and refuses bad values naming the flag. */
static void test_cli_flags(void **state)
{
    (void)state;
    size_t n;
    const lpv_field *t = lpv_fields(&n);
    char err[256], flag[80];
    for (size_t i = 0; i < n; ++i) {
        const lpv_field *f = &t[i];
        assert_int_equal(lpvd_option_takes_value(f->flag), 1);
        snprintf(flag, sizeof flag, "--%s ", f->flag);
        if (!strstr(LPVD_OPTIONS_HELP, flag))
            fail_msg("help does not list %s", flag);
        lpvd_options o = {0};
        const char *good = f->kind == LPV_FIELD_SWITCH ? "off" : f->kind == LPV_FIELD_INT ? "2" : "0.5";
        if (f->kind == LPV_FIELD_INT && f->min > 2)
            good = "64";
        if (f->kind == LPV_FIELD_FLOAT && f->min > 0.5)
            good = "2";
        assert_int_equal(lpvd_option_parse(&o, f->flag, good, err, sizeof err), 1);
        double want = f->kind == LPV_FIELD_SWITCH ? 0.0 : atof(good);
        assert_true(lpv_field_get(&o.settings, f) == want);
        const char *bad = f->kind == LPV_FIELD_SWITCH ? "maybe" : "-5";
        err[0] = '\0';
        assert_int_equal(lpvd_option_parse(&o, f->flag, bad, err, sizeof err), -1);
        snprintf(flag, sizeof flag, "--%s %s: expected", f->flag, bad);
        if (!strstr(err, flag))
            fail_msg("error for --%s %s does not name the flag: %s", f->flag, bad, err);
        assert_true(lpv_field_get(&o.settings, f) == want); /* unchanged */
    }
    /* the flags with their own syntax keep working next to the table's */
    lpvd_options o = {0};
    assert_int_equal(lpvd_option_parse(&o, "grid", "16x32x8", err, sizeof err), 1);
    assert_int_equal(o.settings.grid_dims[1], 32);
    assert_int_equal(lpvd_option_parse(&o, "bounds", "0,0,0,1,2,3", err, sizeof err), 1);
    assert_true(o.settings.bounds_max[2] == 3.0f);
    assert_int_equal(lpvd_option_parse(&o, "preset", "fast", err, sizeof err), 1);
    assert_int_equal(lpvd_option_parse(&o, "technique", "photon-map", err, sizeof err), -1);
    assert_non_null(strstr(err, "--technique photon-map: unknown technique (allowed: lpv"));
    assert_int_equal(o.settings.technique, LPV_TECHNIQUE_ID_DEFAULT); /* unchanged */
    assert_int_equal(lpvd_option_parse(&o, "technique", LPV_TECHNIQUE_LPV, err, sizeof err), 1);
    assert_int_equal(lpvd_option_parse(&o, "cascade-size", "12", err, sizeof err), 1);
    assert_int_equal(lpvd_option_parse(&o, "bounces", "on", err, sizeof err), 1);
    assert_int_equal(lpvd_option_parse(&o, "fog-sigma-s", "0.02", err, sizeof err), 1);
    assert_int_equal(lpvd_option_parse(&o, "iterations", "0", err, sizeof err), -1);
    assert_non_null(strstr(err, "--iterations 0: expected"));
    assert_int_equal(lpvd_option_parse(&o, "no-such-flag", "1", err, sizeof err), 0);
    assert_int_equal(lpvd_option_takes_value("no-such-flag"), -1);
    lpv_settings s = o.settings;
    lpv_settings_resolve(&s);
    assert_int_equal(lpv_settings_validate(&s, err, sizeof err), 0);
    assert_int_equal(s.preset, LPV_PRESET_FAST);
    assert_int_equal(s.technique, LPV_TECHNIQUE_ID_LPV);
    assert_true(s.lpv.cascade_size == 12.0f && s.lpv.bounces == LPV_SWITCH_ON && s.fog_sigma_s == 0.02f);
    assert_int_equal(s.lpv.iterations, 16); /* fast's 4 at grid 8, scaled to the grid's longest axis (32) */
}

/* The technique table: every id has a name that maps back to it; an unset
 * technique resolves to auto (issue 30: the best light for the time on the
 * accuracy set against converged light, docs/accuracy.md "Which technique by
 * default"); an id outside the table is refused by name. */
static void test_techniques(void **state)
{
    (void)state;
    for (int t = LPV_TECHNIQUE_ID_DEFAULT + 1; t < LPV_TECHNIQUE_ID_COUNT_; ++t) {
        const char *name = lpv_technique_name((lpv_technique_id)t);
        assert_non_null(name);
        assert_non_null(strstr(lpv_technique_names(), name));
        lpv_technique_id back = LPV_TECHNIQUE_ID_DEFAULT;
        assert_int_equal(lpv_technique_from_name(name, &back), 0);
        assert_int_equal(back, t);
    }
    lpv_technique_id keep = LPV_TECHNIQUE_ID_LPV;
    assert_int_equal(lpv_technique_from_name("LPV", &keep), -1);
    assert_int_equal(lpv_technique_from_name(NULL, &keep), -1);
    assert_null(lpv_technique_name(LPV_TECHNIQUE_ID_COUNT_));
    lpv_settings s = {0};
    lpv_settings_resolve(&s);
    assert_int_equal(s.technique, LPV_TECHNIQUE_ID_AUTO); /* the default since issue 30 (was lpv) */
    assert_string_equal(lpv_technique_name(LPV_TECHNIQUE_ID_DEFAULT), LPV_TECHNIQUE_AUTO);
    char err[256];
    s.technique = LPV_TECHNIQUE_ID_COUNT_;
    assert_int_equal(lpv_settings_validate(&s, err, sizeof err), -1);
    assert_non_null(strstr(err, "technique"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_table_well_formed),
        cmocka_unit_test(test_defaults_from_rows),
        cmocka_unit_test(test_round_trip_and_validate),
        cmocka_unit_test(test_ranges_agree_with_validate),
        cmocka_unit_test(test_bad_strings),
        cmocka_unit_test(test_cli_flags),
        cmocka_unit_test(test_techniques),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
