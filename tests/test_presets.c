/*
 * test_presets.c - the named quality presets (core/settings.h): what zero
 * settings resolve to, each preset's values, explicit fields winning over a
 * preset (in lpv_settings and on the command line, in any flag order), the
 * names, and validation of the enum.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "options.h"
#include "lpv_shared.h"
#include "settings.h"

typedef struct expected {
    lpv_preset preset;
    const char *name;
    int grid, iterations, rsm_size;
    lpv_switch occlusion, central_transport, normal_bins, far_field, scene_surfels;
} expected;

#define ON LPV_SWITCH_ON
#define OFF LPV_SWITCH_OFF

/* The table chosen from the sweep's overall front (settings.c,
 * docs/accuracy.md); a change there must show up here. */
static const expected PRESETS[] = {
    {LPV_PRESET_FAST, "fast", 8, 4, 128, ON, ON, OFF, OFF, ON},
    {LPV_PRESET_BALANCED, "balanced", 8, 8, 128, ON, ON, ON, ON, ON},
    {LPV_PRESET_ACCURATE, "accurate", 16, 16, 128, ON, ON, ON, ON, ON},
};
#define NPRESETS ((int)(sizeof PRESETS / sizeof PRESETS[0]))

static void assert_knobs(const lpv_settings *s, int grid, int iterations, int rsm_size, lpv_switch occlusion)
{
    for (int i = 0; i < 3; ++i)
        assert_int_equal(s->grid_dims[i], grid);
    assert_int_equal(s->lpv.iterations, iterations);
    assert_int_equal(s->rsm_size, rsm_size);
    assert_int_equal(s->lpv.occlusion, occlusion);
}

static void assert_departures(const lpv_settings *s, const expected *e)
{
    assert_int_equal(s->lpv.central_transport, e->central_transport);
    assert_int_equal(s->lpv.normal_bins, e->normal_bins);
    assert_int_equal(s->lpv.far_field, e->far_field);
    assert_int_equal(s->scene_surfels, e->scene_surfels);
}

static void test_zero_resolves_to_balanced(void **state)
{
    (void)state;
    char err[256];
    lpv_settings s = {0};
    lpv_settings_resolve(&s);
    assert_int_equal(s.preset, LPV_PRESET_BALANCED);
    assert_knobs(&s, PRESETS[1].grid, PRESETS[1].iterations, PRESETS[1].rsm_size, PRESETS[1].occlusion);
    assert_departures(&s, &PRESETS[1]);
    assert_int_equal(lpv_settings_validate(&s, err, sizeof err), 0);
    /* the balanced preset's row, and the knob table's defaults */
    lpv_settings b;
    assert_int_equal(lpv_preset_settings(LPV_PRESET_BALANCED, &b), 0);
    assert_int_equal(s.grid_dims[0], b.grid_dims[0]);
    assert_int_equal(s.lpv.iterations, b.lpv.iterations);
    assert_int_equal(s.rsm_size, b.rsm_size);
    assert_int_equal(s.emissive_vpls, 4096);
    assert_true(s.indirect_gain == 1.0f);
}

static void test_each_preset(void **state)
{
    (void)state;
    char err[256];
    for (int i = 0; i < NPRESETS; ++i) {
        const expected *e = &PRESETS[i];
        lpv_settings s = {.preset = e->preset};
        lpv_settings_resolve(&s);
        assert_int_equal(s.preset, e->preset);
        assert_knobs(&s, e->grid, e->iterations, e->rsm_size, e->occlusion);
        assert_departures(&s, e);
        assert_int_equal(lpv_settings_validate(&s, err, sizeof err), 0);

        lpv_settings p;
        assert_int_equal(lpv_preset_settings(e->preset, &p), 0);
        assert_int_equal(p.preset, e->preset);
        assert_knobs(&p, e->grid, e->iterations, e->rsm_size, e->occlusion);
        assert_departures(&p, e);
        assert_int_equal(lpv_preset_match(&s), e->preset);
    }
    lpv_settings d;
    assert_int_equal(lpv_preset_settings(LPV_PRESET_DEFAULT, &d), 0);
    assert_int_equal(d.preset, LPV_PRESET_BALANCED);
    assert_int_equal(lpv_preset_settings((lpv_preset)99, &d), -1);
}

static void test_explicit_fields_override(void **state)
{
    (void)state;
    lpv_settings s = {.preset = LPV_PRESET_FAST, .grid_dims = {64, 64, 64}, .lpv.occlusion = LPV_SWITCH_OFF};
    lpv_settings_resolve(&s);
    assert_int_equal(s.preset, LPV_PRESET_FAST);
    assert_knobs(&s, 64, 32, 128, LPV_SWITCH_OFF); /* iterations (scaled to the grid) and rsm_size from fast */
    assert_int_equal(lpv_preset_match(&s), LPV_PRESET_DEFAULT); /* no preset has these values */

    lpv_settings t = {.preset = LPV_PRESET_ACCURATE, .lpv.iterations = 12, .rsm_size = 512, .lpv.normal_bins = OFF};
    lpv_settings_resolve(&t);
    assert_knobs(&t, PRESETS[2].grid, 12, 512, LPV_SWITCH_ON);
    assert_int_equal(t.lpv.normal_bins, OFF); /* explicit wins over the preset's on */
    assert_int_equal(t.lpv.far_field, ON);
}

/* Issue 30: an unset iteration count follows the grid, so the light reaches
 * as far in metres over the same bounds whatever the cell count (--grid 64
 * kept 8 steps and a dining room went half black). Cells over fixed bounds
 * are (bounds / longest axis) wide, so steps x cell size is the reach. */
static void test_iterations_follow_grid(void **state)
{
    (void)state;
    const double extent = 10.0; /* m, any bounds' longest side */
    const int grids[][3] = {{16, 16, 16}, {32, 32, 32}, {64, 64, 64}, {64, 16, 8}, {12, 12, 12}};
    for (int i = 0; i < NPRESETS; ++i) {
        const double reach = PRESETS[i].iterations * (extent / PRESETS[i].grid); /* m, the preset's own */
        for (size_t g = 0; g < sizeof grids / sizeof grids[0]; ++g) {
            lpv_settings s = {.preset = PRESETS[i].preset};
            memcpy(s.grid_dims, grids[g], sizeof s.grid_dims);
            lpv_settings_resolve(&s);
            const double cell = extent / grids[g][0]; /* the first axis is the longest */
            print_message("%s grid %d: %d steps, %.3f m (the preset's %.3f m)\n", PRESETS[i].name, grids[g][0],
                          s.lpv.iterations, s.lpv.iterations * cell, reach);
            /* rounded up to whole steps: at least the preset's reach, less than a cell more */
            assert_true(s.lpv.iterations * cell >= reach - 1e-9);
            assert_true(s.lpv.iterations * cell < reach + cell);
        }
    }
    /* an explicit count is honoured */
    lpv_settings t = {.grid_dims = {64, 64, 64}, .lpv.iterations = 8};
    lpv_settings_resolve(&t);
    assert_int_equal(t.lpv.iterations, 8);
}

/* The plan's sentence on the count: why it is what it is, and a warning
 * when the light stops short of the grid. */
static void test_iterations_note(void **state)
{
    (void)state;
    char why[256];
    lpv_settings s = {.grid_dims = {64, 64, 64}};
    lpv_settings_resolve(&s);
    assert_int_equal(s.lpv.iterations, 64);
    assert_int_equal(lpv_settings_iterations_note(&s, why, sizeof why), 0);
    assert_non_null(strstr(why, "scaled to grid 64"));
    lpv_settings t = {.grid_dims = {64, 64, 64}, .lpv.iterations = 8};
    lpv_settings_resolve(&t);
    assert_int_equal(lpv_settings_iterations_note(&t, why, sizeof why), 1); /* 8 of 64 cells */
    assert_non_null(strstr(why, "8 steps set explicitly"));
    t.lpv.iterations = 32; /* half the grid: no warning */
    assert_int_equal(lpv_settings_iterations_note(&t, why, sizeof why), 0);
    int wanted = 0; /* the clamp: a grid no validated setting reaches, to see it said */
    lpv_settings u = {.grid_dims = {100000, 1, 1}, .preset = LPV_PRESET_BALANCED};
    assert_int_equal(lpv_settings_scaled_iterations(&u, &wanted), LPV_MAX_ITERATIONS);
    assert_int_equal(wanted, 100000);
    u.lpv.iterations = LPV_MAX_ITERATIONS;
    assert_int_equal(lpv_settings_iterations_note(&u, why, sizeof why), 1);
    assert_non_null(strstr(why, "clamped"));
}

static void test_names_round_trip(void **state)
{
    (void)state;
    for (int i = 0; i < NPRESETS; ++i) {
        lpv_preset p = LPV_PRESET_DEFAULT;
        assert_int_equal(lpv_preset_from_name(PRESETS[i].name, &p), 0);
        assert_int_equal(p, PRESETS[i].preset);
        assert_string_equal(lpv_preset_name(p), PRESETS[i].name);
        assert_non_null(strstr(lpv_preset_names(), PRESETS[i].name));
    }
    assert_string_equal(lpv_preset_name(LPV_PRESET_DEFAULT), "balanced");
    assert_null(lpv_preset_name((lpv_preset)-1));
    assert_null(lpv_preset_name((lpv_preset)4));
}

static void test_bad_name_rejected(void **state)
{
    (void)state;
    lpv_preset p = LPV_PRESET_ACCURATE;
    const char *bad[] = {"", "Fast", "balanced ", "ultra", "default", NULL};
    for (int i = 0; bad[i]; ++i) {
        assert_int_equal(lpv_preset_from_name(bad[i], &p), -1);
        assert_int_equal(p, LPV_PRESET_ACCURATE); /* untouched */
    }
    assert_int_equal(lpv_preset_from_name(NULL, &p), -1);

    lpvd_options o = {0};
    char err[256] = "";
    assert_int_equal(lpvd_option_parse(&o, "preset", "ultra", err, sizeof err), -1);
    assert_non_null(strstr(err, "--preset ultra"));
    assert_non_null(strstr(err, "fast, balanced, accurate"));
    assert_int_equal(o.settings.preset, LPV_PRESET_DEFAULT);
}

static void test_validate_rejects_out_of_range(void **state)
{
    (void)state;
    char err[256];
    const int bad[] = {-1, LPV_PRESET_COUNT_, 42};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        lpv_settings s = {.preset = (lpv_preset)bad[i]};
        lpv_settings_resolve(&s); /* leaves the bad value for validate to name */
        err[0] = '\0';
        assert_int_equal(lpv_settings_validate(&s, err, sizeof err), -1);
        assert_non_null(strstr(err, "preset"));
    }
}

/* Shared flags: an explicit knob wins over --preset whichever comes first. */
static void test_flags_override_in_any_order(void **state)
{
    (void)state;
    char err[256];
    const char *orders[2][4] = {{"grid", "64", "preset", "fast"}, {"preset", "fast", "grid", "64"}};
    for (int k = 0; k < 2; ++k) {
        lpvd_options o = {0};
        assert_int_equal(lpvd_option_parse(&o, orders[k][0], orders[k][1], err, sizeof err), 1);
        assert_int_equal(lpvd_option_parse(&o, orders[k][2], orders[k][3], err, sizeof err), 1);
        lpv_settings s = o.settings;
        lpv_settings_resolve(&s);
        assert_int_equal(s.preset, LPV_PRESET_FAST);
        assert_knobs(&s, 64, 32, 128, LPV_SWITCH_ON); /* fast's 4 steps at grid 8, scaled to 64 */
    }
    assert_int_equal(lpvd_option_takes_value("preset"), 1);
    assert_non_null(strstr(LPVD_OPTIONS_HELP, "--preset"));
}

/* The techniques' capabilities (core/settings.c's table): ambient occlusion
 * is iv's alone, and needs its knob; the one rule names both when refused. */
static void test_ao_is_a_capability(void **state)
{
    (void)state;
    assert_true(lpv_technique_has(LPV_TECHNIQUE_ID_IV, LPV_CAP_AO));
    assert_false(lpv_technique_has(LPV_TECHNIQUE_ID_LPV, LPV_CAP_AO));
    assert_false(lpv_technique_has(LPV_TECHNIQUE_ID_OCTREE, LPV_CAP_AO));
    assert_false(lpv_technique_has(LPV_TECHNIQUE_ID_AUTO, LPV_CAP_AO)); /* not until the engine chose */
    assert_false(lpv_technique_has((lpv_technique_id)99, LPV_CAP_AO));
    lpv_settings s = {0};
    char err[256] = "";
    assert_int_equal(lpv_ao_check(&s, LPV_TECHNIQUE_ID_IV, err, sizeof err), -1);
    assert_non_null(strstr(err, "technique iv and iv_ao off"));
    s.iv.ao = LPV_SWITCH_ON;
    assert_int_equal(lpv_ao_check(&s, LPV_TECHNIQUE_ID_IV, err, sizeof err), 0);
    assert_int_equal(lpv_ao_check(&s, LPV_TECHNIQUE_ID_OCTREE, err, sizeof err), -1);
    assert_non_null(strstr(err, "needs technique iv with iv_ao on; this has technique octree and iv_ao on"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_zero_resolves_to_balanced), cmocka_unit_test(test_each_preset),
        cmocka_unit_test(test_explicit_fields_override),  cmocka_unit_test(test_names_round_trip),
        cmocka_unit_test(test_bad_name_rejected),         cmocka_unit_test(test_validate_rejects_out_of_range),
        cmocka_unit_test(test_flags_override_in_any_order),
        cmocka_unit_test(test_iterations_follow_grid),
        cmocka_unit_test(test_iterations_note),
        cmocka_unit_test(test_ao_is_a_capability),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
