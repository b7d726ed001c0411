/*
 * test_value_ranges.c - every value lpvd accepts, it can tick with (SPEC
 * R4.15, issue 14 item 7), at the level of core: the camera's look-at, the
 * scene's coordinate and light limits, CONFIG bounds that the grid would
 * have replaced, and cascades that cannot be placed far from the origin.
 * Pure C, no GL; the daemon's side is the conformance case "R4.15".
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "cascades.h"
#include "grid.h"
#include "plan.h"
#include "scene.h"
#include "settings.h"
#include "view.h"

/* fov 178-179 degrees is inside the documented range (CAMERA_SET fov_deg
 * 0.01..179) and was refused as "target: must differ from eye"; eye and
 * target 2e19 m apart overflowed float when squared and got the same. */
static void test_look_at_wide_and_far(void **state)
{
    (void)state;
    lpv_view v;
    const float eye[3] = {0, 0, 3}, target[3] = {0, 0, 0};
    assert_int_equal(lpv_view_look_at(eye, target, (float)(179.0 * M_PI / 180.0), 8, 8, &v), 0);
    assert_true(fabsf(v.forward[2] + 1.0f) < 1e-6f);
    const float far_eye[3] = {0, 0, 1e19f}, far_target[3] = {0, 0, -1e19f};
    assert_int_equal(lpv_view_look_at(far_eye, far_target, 1.0f, 8, 8, &v), 0);
    assert_true(fabsf(v.forward[2] + 1.0f) < 1e-6f);
    /* and what is wrong is told apart */
    assert_int_equal(lpv_view_look_at(eye, eye, 1.0f, 8, 8, &v), LPV_VIEW_EYE_IS_TARGET);
    assert_int_equal(lpv_view_look_at(eye, target, (float)M_PI, 8, 8, &v), LPV_VIEW_BAD_FOV);
    assert_int_equal(lpv_view_look_at(eye, target, 0.0f, 8, 8, &v), LPV_VIEW_BAD_FOV);
    const float nan_eye[3] = {NAN, 0, 0};
    assert_int_equal(lpv_view_look_at(nan_eye, target, 1.0f, 8, 8, &v), LPV_VIEW_NOT_FINITE);
}

static void one_triangle(lpv_scene *sc, lpv_vertex v[3], uint32_t idx[3], float scale)
{
    memset(sc, 0, sizeof *sc);
    memset(v, 0, 3 * sizeof *v);
    for (int i = 0; i < 3; ++i) {
        v[i].position[0] = (i == 1) * scale;
        v[i].position[1] = (i == 2) * scale;
        idx[i] = (uint32_t)i;
    }
    sc->vertices = v;
    sc->vertex_count = 3;
    sc->indices = idx;
    sc->index_count = 3;
}

/* A node scaled by 1e30 (SCENE_UPDATE) was accepted and then every TICK
 * failed with INTERNAL: such a scene is refused, naming the vertex. */
static void test_scene_coordinates(void **state)
{
    (void)state;
    lpv_scene sc;
    lpv_vertex v[3];
    uint32_t idx[3];
    char err[256] = "";
    one_triangle(&sc, v, idx, 1e9f);
    assert_int_equal(lpv_scene_check_ranges(&sc, err, sizeof err), 0);
    one_triangle(&sc, v, idx, 1e30f);
    assert_int_equal(lpv_scene_check_ranges(&sc, err, sizeof err), -1);
    assert_non_null(strstr(err, "vertex 1"));
    one_triangle(&sc, v, idx, INFINITY);
    assert_int_equal(lpv_scene_check_ranges(&sc, err, sizeof err), -1);
    one_triangle(&sc, v, idx, 1.0f);
    lpv_light l = {.type = LPV_LIGHT_POINT, .color = {1, 1, 1}, .intensity = 1e30f, .position = {0, 1, 0}};
    sc.lights = &l;
    sc.light_count = 1;
    assert_int_equal(lpv_scene_check_ranges(&sc, err, sizeof err), 0); /* 1e30 itself: the GPU hard case */
    l.position[1] = 2e9f;
    assert_int_equal(lpv_scene_check_ranges(&sc, err, sizeof err), -1);
    assert_non_null(strstr(err, "light 0"));
}

/* intensity 1e30 with colour 1e30 was accepted and lit nothing (1e60
 * overflows float). */
static void test_light_intensity(void **state)
{
    (void)state;
    char err[256] = "";
    lpv_light l = {.type = LPV_LIGHT_POINT, .color = {1e30f, 1e30f, 1e30f}, .intensity = 1e30f};
    assert_int_equal(lpv_light_check_intensity(&l, err, sizeof err), -1);
    assert_non_null(strstr(err, "W/sr"));
    l.type = LPV_LIGHT_DIRECTIONAL;
    assert_int_equal(lpv_light_check_intensity(&l, err, sizeof err), -1);
    assert_non_null(strstr(err, "W/m^2"));
    l.color[0] = l.color[1] = l.color[2] = 1.0f;
    assert_int_equal(lpv_light_check_intensity(&l, err, sizeof err), 0);
    l.color[1] = 2.0f; /* the largest channel counts */
    assert_int_equal(lpv_light_check_intensity(&l, err, sizeof err), -1);
    l.intensity = NAN;
    l.color[1] = 1.0f;
    assert_int_equal(lpv_light_check_intensity(&l, err, sizeof err), -1);
}

static lpv_settings with_bounds(float lo, float hi)
{
    lpv_settings s;
    memset(&s, 0, sizeof s);
    lpv_settings_resolve(&s);
    for (int i = 0; i < 3; ++i) {
        s.bounds_min[i] = lo;
        s.bounds_max[i] = hi;
    }
    return s;
}

/* Bounds of +-1e30 were echoed as effective, then the grid replaced them by
 * 1 m cells around the origin (its fallback for degenerate cells); a box
 * whose cells underflow got the same. Both are refused now. */
static void test_bounds_not_replaced(void **state)
{
    (void)state;
    char err[256] = "";
    lpv_settings s = with_bounds(-1.0f, 1.0f);
    assert_int_equal(lpv_settings_validate(&s, err, sizeof err), 0);
    s = with_bounds(-1e30f, 1e30f);
    assert_int_equal(lpv_settings_validate(&s, err, sizeof err), -1);
    assert_non_null(strstr(err, "bounds_min[0]"));
    s = with_bounds(0.0f, 1e-25f);
    assert_int_equal(lpv_settings_validate(&s, err, sizeof err), -1);
    assert_non_null(strstr(err, "smallest cell size"));
    /* whatever validates is placed as given, not replaced */
    s = with_bounds(-1e9f, 1e9f);
    assert_int_equal(lpv_settings_validate(&s, err, sizeof err), 0);
    lpv_grid g;
    assert_int_equal(lpv_grid_place(s.grid_dims, s.bounds_min, s.bounds_max, &g), 0);
    assert_true(g.origin[0] <= -1e9f && g.cell_size > 1e7f);
}

/* cascade_size 1e-30 with 2-4 cascades was accepted, then every TICK failed
 * with INTERNAL ("cannot be placed"). lpv_cascades_fit says so beforehand,
 * and the size it proposes does fit. */
static void test_cascades_fit(void **state)
{
    (void)state;
    lpv_settings s;
    memset(&s, 0, sizeof s);
    lpv_settings_resolve(&s);
    const float bmin[3] = {-1, 0, -1}, bmax[3] = {1, 2, 1};
    s.lpv.cascade_size = 0.0f; /* auto */
    assert_int_equal(lpv_cascades_fit(&s, bmin, bmax, 0.0f, NULL, 0), 1);
    lpv_cascade_set set;
    assert_int_equal(lpv_cascades_place(&s, 3, bmin, bmax, bmax, (float[3]){0, 0, -1}, 0.0f, &set), 0);
    s.lpv.cascade_size = 1e-30f;
    char why[320] = "";
    assert_int_equal(lpv_cascades_fit(&s, bmin, bmax, 0.0f, why, sizeof why), 0);
    assert_int_equal(lpv_cascades_place(&s, 3, bmin, bmax, bmax, (float[3]){0, 0, -1}, 0.0f, &set), -1);
    const char *at = strstr(why, "cascade_size ");
    assert_non_null(at);
    s.lpv.cascade_size = strtof(at + strlen("cascade_size "), NULL);
    assert_true(s.lpv.cascade_size > 0.0f);
    assert_int_equal(lpv_cascades_fit(&s, bmin, bmax, 0.0f, NULL, 0), 1);
    /* the farthest anchor the bounds allow, the camera at a corner */
    assert_int_equal(lpv_cascades_place(&s, 3, bmin, bmax, bmax, (float[3]){0, 0, -1}, 0.0f, &set), 0);
}

/* The planner's own choice of cascades (cascades 0) falls back to one grid
 * when they cannot be placed, and says why: the tick runs. */
static void test_planner_falls_back_to_one_grid(void **state)
{
    (void)state;
    lpv_settings s;
    memset(&s, 0, sizeof s);
    lpv_settings_resolve(&s);
    s.lpv.cascades = 3;
    lpv_plan_facts f = {0};
    f.scene_extent = 100.0f;
    f.scene_reach = 50.0f;
    char reason[LPV_PLAN_REASON_MAX];
    assert_int_equal(lpv_plan_cascades(&s, &f, reason, sizeof reason), 3);
    f.cascades_unfit = 1;
    assert_int_equal(lpv_plan_cascades(&s, &f, reason, sizeof reason), 1);
    assert_non_null(strstr(reason, "cannot be placed"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_look_at_wide_and_far),
        cmocka_unit_test(test_scene_coordinates),
        cmocka_unit_test(test_light_intensity),
        cmocka_unit_test(test_bounds_not_replaced),
        cmocka_unit_test(test_cascades_fit),
        cmocka_unit_test(test_planner_falls_back_to_one_grid),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
