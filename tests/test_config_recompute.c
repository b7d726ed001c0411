/*
 * test_config_recompute.c - a change of settings or lights recomputes only
 * what it touches (issue 11: "a CONFIG recomputes only what its changed
 * knobs touch: a test counts scene uploads and passes").
 *
 * The table's lpv_touch column is checked knob by knob, then the engine on
 * the real GL path (llvmpipe in CI): scene uploads and samplings are counted
 * (lpv_engine_get_counters), the passes a tick ran are read from its plan and
 * stats, and every shortcut is checked against the long way round: a frame
 * from the cached volume under a shading-only change equals the frame after a
 * forced recompute, and a re-sampled scene equals a scene uploaded afresh,
 * bit for bit (the same shaders on the same inputs).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "engine.h"
#include "scene_build.h"
#include "settings_fields.h"
#include "test_util.h"

#define IMG 24

/* ---- the table ---------------------------------------------------------- */

/* A value of f other than the one in s, inside f's range. */
static void change_field(lpv_settings *s, const lpv_field *f)
{
    char err[256];
    double v = lpv_field_get(s, f);
    if (f->kind == LPV_FIELD_SWITCH) {
        assert_int_equal(lpv_field_set_bool(s, f, v != 1.0), 0);
        return;
    }
    double next = v + (f->kind == LPV_FIELD_INT ? 1.0 : 0.125 * (f->max - f->min > 1.0 ? 1.0 : f->max - f->min));
    if (next > f->max)
        next = f->min + (f->min_exclusive ? (f->kind == LPV_FIELD_INT ? 1.0 : 0.01) : 0.0);
    if (lpv_field_set_number(s, f, next, err, sizeof err) != 0)
        fail_msg("%s: %s", f->key, err);
    assert_true(lpv_field_get(s, f) != v);
}

static void test_every_knob_touches_something(void **state)
{
    (void)state;
    size_t n = 0;
    const lpv_field *fields = lpv_fields(&n);
    lpv_settings base = {0};
    lpv_settings_resolve(&base);
    for (size_t i = 0; i < n; ++i) {
        lpv_settings s = base;
        change_field(&s, &fields[i]);
        char first[32];
        unsigned t = lpv_settings_touches(&base, &s, first, sizeof first);
        if (t != fields[i].touches)
            fail_msg("%s: touches 0x%x, the table says 0x%x", fields[i].key, t, fields[i].touches);
        assert_true(t != 0);
        /* the planner's reason names the knob that reshaped the volume */
        if (t & LPV_TOUCH_VOLUME)
            assert_string_equal(first, fields[i].key);
        else
            assert_string_equal(first, "");
    }
    assert_int_equal(lpv_settings_touches(&base, &base, NULL, 0), 0);
}

static void test_what_the_shading_knobs_leave_alone(void **state)
{
    (void)state;
    const char *shading[] = {"damping", "indirect_gain", "glossy", "glossy_roughness", "media_step"};
    for (size_t i = 0; i < sizeof shading / sizeof shading[0]; ++i)
        assert_int_equal(lpv_field_by_key(shading[i])->touches, LPV_TOUCH_SHADING);
    assert_int_equal(lpv_field_by_key("shadow_size")->touches, LPV_TOUCH_SHADOWS);
    assert_true(lpv_field_by_key("scene_surfel_count")->touches & LPV_TOUCH_SAMPLES);
    assert_true(lpv_field_by_key("emissive_vpls")->touches & LPV_TOUCH_SAMPLES);

    /* the knobs outside the table reshape the volume */
    lpv_settings a = {0}, b;
    lpv_settings_resolve(&a);
    char first[32];
    b = a;
    b.grid_dims[1] += 1;
    assert_int_equal(lpv_settings_touches(&a, &b, first, sizeof first), LPV_TOUCH_VOLUME);
    assert_string_equal(first, "grid");
    b = a;
    b.bounds_max[0] = 3.0f;
    assert_int_equal(lpv_settings_touches(&a, &b, first, sizeof first), LPV_TOUCH_VOLUME);
    assert_string_equal(first, "bounds");
    /* a preset counts as the knobs it sets (resolved settings compared) */
    lpv_settings fast = {.preset = LPV_PRESET_FAST};
    lpv_settings_resolve(&fast);
    assert_true(lpv_settings_touches(&a, &fast, first, sizeof first) & LPV_TOUCH_VOLUME);
}

/* ---- the engine --------------------------------------------------------- */

/* A 2 m room lit by a point light, with an emissive patch (so emissive_vpls
 * has work) and a textured box (so a texture change can be told apart). */
static void build_room(lpv_scene *s, float light_x, uint8_t texel)
{
    memset(s, 0, sizeof *s);
    int grey = lpv_scene_add_material(s, "grey", (float[3]){0.7f, 0.7f, 0.7f}, NULL);
    int red = lpv_scene_add_material(s, "red", (float[3]){0.8f, 0.1f, 0.1f}, NULL);
    int lamp = lpv_scene_add_material(s, "lamp", (float[3]){0, 0, 0}, (float[3]){3.0f, 3.0f, 3.0f});
    int tex = lpv_scene_add_material(s, "textured", (float[3]){1, 1, 1}, NULL);
    assert_true(grey >= 0 && red >= 0 && lamp >= 0 && tex >= 0);
    assert_true(lpv_scene_add_box(s, grey, (float[3]){-1, -0.1f, -1}, (float[3]){1, 0, 1}) >= 0);
    assert_true(lpv_scene_add_box(s, grey, (float[3]){-1, 0, -1.1f}, (float[3]){1, 2, -1}) >= 0);
    assert_true(lpv_scene_add_box(s, red, (float[3]){-1.1f, 0, -1}, (float[3]){-1, 2, 1}) >= 0);
    assert_true(lpv_scene_add_box(s, tex, (float[3]){-0.3f, 0, -0.3f}, (float[3]){0.3f, 0.6f, 0.3f}) >= 0);
    const float q[4][3] = {{0.4f, 1.99f, -0.4f}, {0.8f, 1.99f, -0.4f}, {0.8f, 1.99f, 0.0f}, {0.4f, 1.99f, 0.0f}};
    assert_true(lpv_scene_add_quad(s, lamp, q, (float[3]){0, -1, 0}) >= 0);
    assert_non_null(lpv_scene_add_point_light(s, (float[3]){light_x, 1.5f, 0.3f}, 5.0f));
    s->textures = calloc(1, sizeof *s->textures);
    assert_non_null(s->textures);
    s->texture_count = 1;
    s->textures[0].width = s->textures[0].height = 1;
    s->textures[0].rgba8 = malloc(4);
    assert_non_null(s->textures[0].rgba8);
    memcpy(s->textures[0].rgba8, (uint8_t[4]){texel, 200, 200, 255}, 4);
    s->materials[tex].base_color_texture = 0;
    lpv_scene_compute_bounds(s);
}

static lpv_settings small_settings(void)
{
    lpv_settings s = {0};
    s.technique = LPV_TECHNIQUE_ID_LPV; /* the passes counted are the LPV's (inject, propagate); auto is the default
                                         * since issue 30 */
    s.grid_dims[0] = s.grid_dims[1] = s.grid_dims[2] = 8;
    s.rsm_size = 32;
    s.shadow_size = 64;
    s.scene_surfel_count = 4096;
    s.area_lights = LPV_SWITCH_OFF; /* the lamp's VPLs: emissive_vpls reaches the volume */
    s.emissive_vpls = 256;
    return s;
}

static void setup_view(void)
{
    lpv_view v;
    char err[512] = "";
    assert_int_equal(lpv_view_look_at((float[3]){0.1f, 1.0f, 2.5f}, (float[3]){0.1f, 0.6f, 0.0f}, 1.0f, IMG, IMG, &v),
                     0);
    if (lpv_engine_set_view(lpvt_engine, &v, err, sizeof err) != 0)
        fail_msg("%s", err);
}

static void settings(const lpv_settings *s)
{
    char err[512] = "";
    if (lpv_engine_set_settings(lpvt_engine, s, err, sizeof err) != 0)
        fail_msg("set_settings: %s", err);
}

static void scene(const lpv_scene *s)
{
    char err[512] = "";
    if (lpv_engine_set_scene(lpvt_engine, s, err, sizeof err) != 0)
        fail_msg("set_scene: %s", err);
}

static const lpv_plan *tick(void)
{
    char err[512] = "";
    if (lpv_engine_tick(lpvt_engine, err, sizeof err) != 0)
        fail_msg("tick: %s", err);
    return lpv_engine_last_plan(lpvt_engine);
}

static float *render(void) { return lpvt_render(IMG, IMG); }

static int stage_ran(const char *name)
{
    unsigned calls = 0;
    return lpvt_stage(name, &calls, NULL) && calls > 0;
}

static int same_image(const float *a, const float *b)
{
    return memcmp(a, b, sizeof(float) * IMG * IMG * 4) == 0;
}

static lpv_engine_counters counters(void) { return lpv_engine_get_counters(lpvt_engine); }

/* A fresh start: a scene the engine has not seen (one upload), ticked. */
static void start(lpv_scene *room, const lpv_settings *s)
{
    lpv_scene other;
    build_room(&other, -0.5f, 1); /* another texture: a different scene */
    settings(s);
    scene(&other);
    lpv_scene_free(&other);
    build_room(room, 0.2f, 90);
    scene(room);
    setup_view();
    tick();
}

static void test_shading_knob_uploads_and_propagates_nothing(void **state)
{
    (void)state;
    lpv_scene room;
    lpv_settings s = small_settings();
    start(&room, &s);
    float *before = render();
    const lpv_engine_counters c0 = counters();

    s.lpv.damping = 0.5f;
    s.indirect_gain = 2.0f;
    settings(&s);
    const lpv_plan *p = tick();
    assert_false(p->recompute);
    for (int i = LPV_PASS_RSM; i <= LPV_PASS_PROPAGATE; ++i)
        assert_false(p->pass[i].run);
    assert_false(stage_ran("inject"));
    assert_false(stage_ran("propagate"));
    assert_int_equal(counters().scene_uploads, c0.scene_uploads);
    assert_int_equal(counters().scene_samplings, c0.scene_samplings);
    float *cached = render();
    assert_false(same_image(before, cached)); /* the knobs did reach the frame */

    /* the long way round: the same settings with every pass run again */
    lpv_engine_invalidate(lpvt_engine);
    p = tick();
    assert_true(p->recompute);
    assert_true(stage_ran("propagate"));
    float *recomputed = render();
    assert_true(same_image(cached, recomputed));
    free(before);
    free(cached);
    free(recomputed);
    lpv_scene_free(&room);
}

static void test_sampling_knob_resamples_without_upload(void **state)
{
    (void)state;
    lpv_scene room;
    lpv_settings s = small_settings();
    start(&room, &s);
    const lpv_engine_counters c0 = counters();

    s.scene_surfel_count = 2048;
    s.emissive_vpls = 512;
    settings(&s);
    const lpv_plan *p = tick();
    assert_true(p->recompute);
    print_message("reason: %s\n", p->recompute_reason);
    assert_non_null(strstr(p->recompute_reason, "emissive_vpls"));
    assert_int_equal(counters().scene_uploads, c0.scene_uploads);
    assert_int_equal(counters().scene_samplings, c0.scene_samplings + 1);
    float *resampled = render();

    /* the same settings with the scene uploaded afresh */
    lpv_scene other;
    build_room(&other, -0.5f, 1);
    scene(&other);
    scene(&room);
    lpv_scene_free(&other);
    tick();
    assert_int_equal(counters().scene_uploads, c0.scene_uploads + 2);
    float *fresh = render();
    assert_true(same_image(resampled, fresh));
    free(resampled);
    free(fresh);
    lpv_scene_free(&room);
}

/* auto's choice changing with a knob (the fast preset: the probes, the
 * cascaded LPV before issue 34) is a change of technique: the scene is
 * sampled again for the chosen one (iv samples a point cloud, the probes
 * build their BVH, the LPV emissive VPLs and surfels), so the frame is
 * the one of the same settings on a scene uploaded afresh (issue 30: auto
 * being the default, `lpvd batch` items whose preset is fast after a scene
 * set under balanced read iv's samples with the LPV) */
static void test_auto_choice_change_resamples(void **state)
{
    (void)state;
    lpv_scene room;
    lpv_settings s = small_settings();
    s.technique = LPV_TECHNIQUE_ID_AUTO;
    start(&room, &s);
    assert_string_equal(lpv_engine_last_plan(lpvt_engine)->technique, LPV_TECHNIQUE_IV);
    const lpv_engine_counters c0 = counters();

    s.preset = LPV_PRESET_FAST;
    settings(&s);
    const lpv_plan *p = tick();
    assert_string_equal(p->technique, LPV_TECHNIQUE_PROBES);
    assert_true(p->recompute);
    assert_int_equal(counters().scene_uploads, c0.scene_uploads);
    assert_int_equal(counters().scene_samplings, c0.scene_samplings + 1);
    float *switched = render();

    lpv_scene other;
    build_room(&other, -0.5f, 1);
    scene(&other);
    scene(&room);
    lpv_scene_free(&other);
    /* the other room has the room's triangles, posed otherwise: the
     * probes would keep their light across it (a moved node); fresh means
     * without history too */
    lpv_engine_forget(lpvt_engine);
    tick();
    float *fresh = render();
    assert_true(same_image(switched, fresh));
    free(switched);
    free(fresh);
    lpv_scene_free(&room);
}

static void test_volume_knob_recomputes_without_upload(void **state)
{
    (void)state;
    lpv_scene room;
    lpv_settings s = small_settings();
    start(&room, &s);
    const lpv_engine_counters c0 = counters();
    s.lpv.iterations = 6;
    settings(&s);
    const lpv_plan *p = tick();
    assert_true(p->recompute);
    assert_string_equal(p->recompute_reason, "the settings changed (iterations)");
    assert_true(stage_ran("propagate"));
    assert_int_equal(counters().scene_uploads, c0.scene_uploads);
    assert_int_equal(counters().scene_samplings, c0.scene_samplings);
    lpv_scene_free(&room);
}

static void test_moved_light_uploads_nothing(void **state)
{
    (void)state;
    lpv_scene room, moved;
    lpv_settings s = small_settings();
    start(&room, &s);
    float *before = render();
    const lpv_engine_counters c0 = counters();
    build_room(&moved, 0.6f, 90);
    scene(&moved);
    const lpv_plan *p = tick();
    assert_true(p->recompute);
    assert_string_equal(p->recompute_reason, "the lights changed");
    assert_int_equal(counters().scene_uploads, c0.scene_uploads);
    assert_int_equal(counters().scene_samplings, c0.scene_samplings);
    float *after = render();
    assert_false(same_image(before, after));
    free(before);
    free(after);
    lpv_scene_free(&room);
    lpv_scene_free(&moved);
}

static void test_new_texture_is_uploaded(void **state)
{
    (void)state;
    lpv_scene room, retextured;
    lpv_settings s = small_settings();
    start(&room, &s);
    float *before = render();
    const lpv_engine_counters c0 = counters();
    build_room(&retextured, 0.2f, 250); /* only a texel differs */
    scene(&retextured);
    const lpv_plan *p = tick();
    assert_string_equal(p->recompute_reason, "the scene changed");
    assert_int_equal(counters().scene_uploads, c0.scene_uploads + 1);
    float *after = render();
    assert_false(same_image(before, after));
    free(before);
    free(after);
    lpv_scene_free(&room);
    lpv_scene_free(&retextured);
}

int main(void)
{
    const struct CMUnitTest table[] = {
        cmocka_unit_test(test_every_knob_touches_something),
        cmocka_unit_test(test_what_the_shading_knobs_leave_alone),
    };
    const struct CMUnitTest gl[] = {
        cmocka_unit_test(test_shading_knob_uploads_and_propagates_nothing),
        cmocka_unit_test(test_sampling_knob_resamples_without_upload),
        cmocka_unit_test(test_auto_choice_change_resamples),
        cmocka_unit_test(test_volume_knob_recomputes_without_upload),
        cmocka_unit_test(test_moved_light_uploads_nothing),
        cmocka_unit_test(test_new_texture_is_uploaded),
    };
    int failed = cmocka_run_group_tests_name("table", table, NULL, NULL);
    return failed + cmocka_run_group_tests_name("engine", gl, lpvt_gl_setup, lpvt_gl_teardown);
}
