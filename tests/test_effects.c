/*
 * test_effects.c - the paper's section 7 effects through the real GL path:
 * glossy reflections and participating media change the image only where the
 * scene has a glossy material or a medium, and a medium only removes light
 * from the volume (attenuation during propagation: in-scattering toward the
 * eye creates no energy).
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
#include "oracle.h"
#include "scene_build.h"
#include "test_util.h"

#define W 64
#define H 64

static const float GREY[3] = {0.6f, 0.6f, 0.6f};

/* Ticks scene s with settings set seen by view v, renders the full frame
 * into rgba (W*H*4), and returns the plan's run flag of pass id. */
static int run(const lpv_scene *s, const lpv_settings *set, const lpv_view *v, float *rgba, lpv_pass_id id)
{
    char err[256] = "";
    lpv_engine *e = lpvt_engine;
    if (lpv_engine_set_settings(e, set, err, sizeof err) != 0 || lpv_engine_set_scene(e, s, err, sizeof err) != 0 ||
        lpv_engine_set_view(e, v, err, sizeof err) != 0 || lpv_engine_tick(e, err, sizeof err) != 0 ||
        lpv_engine_render(e, LPV_TERMS_FULL, rgba, err, sizeof err) != 0)
        fail_msg("%s", err);
    for (size_t i = 0; i < (size_t)W * H * 4; ++i)
        assert_true(isfinite(rgba[i]));
    return lpv_engine_last_plan(e)->pass[id].run;
}

/* A closed 4 x 3 x 4 m room: blue-only floor (the only glossy candidate),
 * red and grey walls without any blue, a point light under the ceiling. */
static void room(lpv_scene *s, float floor_roughness)
{
    memset(s, 0, sizeof *s);
    int floor_m = lpv_scene_add_material(s, "floor", (float[3]){0.0f, 0.0f, 0.8f}, NULL);
    int red = lpv_scene_add_material(s, "red", (float[3]){0.8f, 0.1f, 0.0f}, NULL);
    int grey = lpv_scene_add_material(s, "grey", (float[3]){0.6f, 0.6f, 0.0f}, NULL);
    assert_int_equal(lpv_scene_set_material_roughness(s, floor_m, floor_roughness), 0);
    const float lo = -2.0f, hi = 2.0f, top = 3.0f;
    const float floor_q[4][3] = {{lo, 0, hi}, {hi, 0, hi}, {hi, 0, lo}, {lo, 0, lo}};
    const float ceil_q[4][3] = {{lo, top, lo}, {hi, top, lo}, {hi, top, hi}, {lo, top, hi}};
    const float left[4][3] = {{lo, 0, lo}, {lo, top, lo}, {lo, top, hi}, {lo, 0, hi}};
    const float right[4][3] = {{hi, 0, hi}, {hi, top, hi}, {hi, top, lo}, {hi, 0, lo}};
    const float back[4][3] = {{lo, 0, lo}, {hi, 0, lo}, {hi, top, lo}, {lo, top, lo}};
    assert_true(lpv_scene_add_quad(s, floor_m, floor_q, NULL) >= 0);
    assert_true(lpv_scene_add_quad(s, grey, ceil_q, NULL) >= 0);
    assert_true(lpv_scene_add_quad(s, red, left, NULL) >= 0);
    assert_true(lpv_scene_add_quad(s, grey, right, NULL) >= 0);
    assert_true(lpv_scene_add_quad(s, grey, back, NULL) >= 0);
    assert_non_null(lpv_scene_add_point_light(s, (float[3]){0.0f, 2.6f, 0.0f}, 20.0f));
    lpv_scene_compute_bounds(s);
}

static lpv_view room_view(void)
{
    lpv_view v;
    assert_int_equal(lpv_view_look_at((float[3]){0.0f, 2.2f, 3.8f}, (float[3]){0.0f, 0.6f, -1.0f}, 1.1f, W, H, &v), 0);
    return v;
}

static lpv_settings small_settings(void)
{
    /* the paper's effects on the LPV's volume (attenuation during its propagation): lpv named, the default
     * technique being auto since issue 30 */
    lpv_settings set = {
        .technique = LPV_TECHNIQUE_ID_LPV, .grid_dims = {16, 16, 16}, .rsm_size = 64, .lpv.iterations = 4};
    return set;
}

/* Glossy: with a glossy floor, turning the glossy pass on changes floor pixels
 * (some, by the reflection's F0 x radiance) and no other pixel (bit-exact: the
 * pass adds exactly 0 elsewhere and the diffuse factor kd is 1 there). The
 * floor is the only material with blue albedo and every other material has
 * none, so a pixel is a floor pixel iff its blue channel is lit in the
 * glossy-off frame (blue reaches other surfaces only by reflection off the
 * floor, and their albedo has no blue to reflect). */
static void test_glossy_only_where_glossy(void **state)
{
    (void)state;
    lpv_scene s;
    room(&s, 0.1f);
    lpv_view v = room_view();
    float *off = malloc(sizeof(float) * W * H * 4), *on = malloc(sizeof(float) * W * H * 4);
    lpv_settings set = small_settings();
    set.glossy = LPV_SWITCH_OFF;
    assert_int_equal(run(&s, &set, &v, off, LPV_PASS_GLOSSY), 0);
    set.glossy = LPV_SWITCH_ON;
    assert_int_equal(run(&s, &set, &v, on, LPV_PASS_GLOSSY), 1);
    size_t floor_px = 0, changed_floor = 0, other = 0;
    for (size_t i = 0; i < (size_t)W * H; ++i) {
        const float *a = off + 4 * i, *b = on + 4 * i;
        if (a[2] > 0.0f) {
            ++floor_px;
            changed_floor += memcmp(a, b, 3 * sizeof(float)) != 0;
        } else {
            ++other;
            assert_memory_equal(a, b, 4 * sizeof(float));
        }
    }
    print_message("glossy: %zu floor pixels, %zu changed; %zu other pixels unchanged\n", floor_px, changed_floor,
                  other);
    assert_true(floor_px > (size_t)W * H / 8 && other > (size_t)W * H / 8); /* the view sees both */
    /* The reflection of the red wall and the lit walls reaches most of the floor. */
    assert_true(changed_floor > floor_px / 2);

    /* The same room with a matte floor: the planner skips the glossy pass and
     * the frame equals the glossy-off frame everywhere. */
    lpv_scene_free(&s);
    room(&s, 1.0f);
    lpv_settings set_matte = small_settings();
    float *matte_off = malloc(sizeof(float) * W * H * 4);
    set_matte.glossy = LPV_SWITCH_OFF;
    run(&s, &set_matte, &v, matte_off, LPV_PASS_GLOSSY);
    set_matte.glossy = LPV_SWITCH_ON;
    assert_int_equal(run(&s, &set_matte, &v, on, LPV_PASS_GLOSSY), 0);
    assert_memory_equal(matte_off, on, sizeof(float) * W * H * 4);
    free(off);
    free(on);
    free(matte_off);
    lpv_scene_free(&s);
}

/* Media: a floor lit by a point light and a boxed medium above it, outside
 * the LPV's grid (the grid covers the scene's geometry), so the volume is
 * the same with and without the medium and only the media pass can change
 * the frame. Pixels whose view rays miss the box must be bit-identical (the
 * pass blends 0 + 1 x frame there); pixels through the box must brighten
 * (the light scatters in the medium). The box's screen rectangle is found by
 * projecting its corners; a pixel of margin covers rasterisation. */
static void test_media_only_where_medium(void **state)
{
    (void)state;
    lpv_scene s = {0};
    int grey = lpv_scene_add_material(&s, "grey", GREY, NULL);
    const float floor_q[4][3] = {{-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, {-2, 0, -2}};
    assert_true(lpv_scene_add_quad(&s, grey, floor_q, NULL) >= 0);
    assert_non_null(lpv_scene_add_point_light(&s, (float[3]){0.0f, 1.0f, 0.0f}, 10.0f));
    lpv_scene_compute_bounds(&s);
    lpv_view v;
    assert_int_equal(lpv_view_look_at((float[3]){0.0f, 3.0f, 6.0f}, (float[3]){0.0f, 1.2f, 0.0f}, 0.9f, W, H, &v), 0);

    float *off = malloc(sizeof(float) * W * H * 4), *on = malloc(sizeof(float) * W * H * 4);
    lpv_settings set = small_settings();
    assert_int_equal(run(&s, &set, &v, off, LPV_PASS_MEDIA), 0); /* no medium yet: skipped */
    lpv_cell *cells_off = malloc(sizeof(lpv_cell) * 16 * 16 * 16), *cells_on = malloc(sizeof(lpv_cell) * 16 * 16 * 16);
    assert_int_equal(lpv_engine_read_grid(lpvt_engine, LPV_GRID_ACCUMULATED, cells_off, 16 * 16 * 16), 16 * 16 * 16);

    const float box_lo[3] = {-0.6f, 2.4f, 0.5f}, box_hi[3] = {0.6f, 3.2f, 1.7f};
    const lpv_grid *g = lpv_engine_grid(lpvt_engine);
    for (int i = 0; i < 3; ++i) /* the box lies outside the grid (see above) */
        assert_true(box_lo[i] >= g->origin[i] + g->cell_size * (float)g->dims[i] || i != 1);
    assert_int_equal(lpv_scene_set_medium_box(&s, (float[3]){0.5f, 0.5f, 0.5f}, (float[3]){0.1f, 0.1f, 0.1f},
                                              box_lo, box_hi, NULL, NULL),
                     0);
    assert_int_equal(run(&s, &set, &v, on, LPV_PASS_MEDIA), 1);
    assert_int_equal(lpv_engine_read_grid(lpvt_engine, LPV_GRID_ACCUMULATED, cells_on, 16 * 16 * 16), 16 * 16 * 16);
    assert_memory_equal(cells_off, cells_on, sizeof(lpv_cell) * 16 * 16 * 16);

    float x0 = 1e30f, y0 = 1e30f, x1 = -1e30f, y1 = -1e30f;
    for (int k = 0; k < 8; ++k) {
        float p[3] = {(k & 1) ? box_hi[0] : box_lo[0], (k & 2) ? box_hi[1] : box_lo[1],
                      (k & 4) ? box_hi[2] : box_lo[2]};
        float px, py;
        assert_int_equal(lpv_view_project(&v, p, &px, &py), 0);
        x0 = fminf(x0, px);
        y0 = fminf(y0, py);
        x1 = fmaxf(x1, px);
        y1 = fmaxf(y1, py);
    }
    size_t outside = 0, inside = 0, brighter = 0;
    for (int y = 0; y < H; ++y) {
        for (int x = 0; x < W; ++x) {
            const float *a = off + 4 * ((size_t)y * W + x), *b = on + 4 * ((size_t)y * W + x);
            int out = x + 1 < x0 - 1.0f || x > x1 + 1.0f || y + 1 < y0 - 1.0f || y > y1 + 1.0f;
            if (out) {
                ++outside;
                assert_memory_equal(a, b, 4 * sizeof(float));
            } else {
                ++inside;
                brighter += b[0] > a[0] && b[1] > a[1] && b[2] > a[2];
            }
        }
    }
    print_message("media: box covers %zu pixels (%zu brighter), %zu pixels outside unchanged\n", inside, brighter,
                  outside);
    assert_true(outside > (size_t)W * H / 2);
    assert_true(brighter > inside / 4); /* the box's projection is a hexagon inside its rectangle */
    free(off);
    free(on);
    free(cells_off);
    free(cells_on);
    lpv_scene_free(&s);
}

static double volume_flux(lpv_engine *e, lpv_grid_which which)
{
    size_t n = lpv_grid_cell_count(lpv_engine_grid(e)) * (size_t)lpv_engine_cascade_count(e);
    lpv_cell *c = malloc(n * sizeof *c);
    assert_int_equal(lpv_engine_read_grid(e, which, c, n), n);
    double f[3];
    lpv_grid g = {.dims = {(int)n, 1, 1}, .cell_size = 1.0f};
    lpv_oracle_total_flux(&g, c, f);
    free(c);
    for (int i = 0; i < 3; ++i)
        assert_true(isfinite(f[i]) && f[i] >= 0.0);
    return f[0] + f[1] + f[2];
}

/* Media energy: fog filling the room only removes light from the volume.
 * Each propagation step's output with fog must not exceed the same step's
 * output without fog, and a denser fog removes more (exp(-sigma_t cell) per
 * step). Energy = total flux of the last step (sum of c0 sqrt(4 pi)). */
static void test_media_removes_energy(void **state)
{
    (void)state;
    lpv_scene s;
    room(&s, 1.0f);
    lpv_view v = room_view();
    float *rgba = malloc(sizeof(float) * W * H * 4);
    lpv_settings set = small_settings();
    set.lpv.iterations = 12;
    double last[3], acc[3];
    const float sigma[3] = {0.0f, 0.2f, 1.0f};
    for (int i = 0; i < 3; ++i) {
        set.fog_sigma_s = sigma[i];
        assert_int_equal(run(&s, &set, &v, rgba, LPV_PASS_MEDIA), i > 0);
        last[i] = volume_flux(lpvt_engine, LPV_GRID_LAST_STEP);
        acc[i] = volume_flux(lpvt_engine, LPV_GRID_ACCUMULATED);
    }
    print_message("last step flux: no fog %.4g W, sigma 0.2: %.4g W, sigma 1: %.4g W\n", last[0], last[1], last[2]);
    assert_true(last[1] < last[0] && last[2] < last[1]);
    assert_true(acc[1] < acc[0] && acc[2] < acc[1]);
    free(rgba);
    lpv_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_glossy_only_where_glossy),
        cmocka_unit_test(test_media_only_where_medium),
        cmocka_unit_test(test_media_removes_energy),
    };
    return cmocka_run_group_tests(tests, lpvt_gl_setup, lpvt_gl_teardown);
}
