/*
 * test_emissive.c - emissive surfaces as VPLs: the samples carry exactly
 * the surfaces' emitted flux (pi * L * A), sit on the emitters, face the way
 * the emitter faces, and are the same every time.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "emissive.h"
#include "scene.h"

static void test_cornell_light_quad(void **state)
{
    (void)state;
    lpv_scene s;
    assert_int_equal(lpv_scene_builtin_cornell(&s), 0);
    double total[3];
    lpv_emissive_total_flux(&s, total);
    /* The quad is 0.47 m x 0.38 m at radiance (17, 12, 4) / 683 W/(m^2 sr). */
    double area = 0.47 * 0.38;
    assert_true(fabs(total[0] - M_PI * 17.0 / 683.0 * area) < 1e-3 * total[0]);

    enum { MAX = 10000 };
    lpv_vpl *a = calloc(MAX, sizeof *a), *b = calloc(MAX, sizeof *b);
    size_t n = lpv_emissive_sample(&s, 4096, a, MAX);
    assert_true(n >= 4000 && n <= 4200);
    double sum[3] = {0, 0, 0};
    for (size_t i = 0; i < n; ++i) {
        assert_true(fabsf(a[i].position[1] - 1.98f) < 1e-5f); /* on the quad */
        assert_true(a[i].position[0] >= -0.25f && a[i].position[0] <= 0.24f);
        assert_true(a[i].normal[1] < -0.99f); /* emitting down into the room */
        assert_true(a[i].position[3] == 1.0f);
        for (int c = 0; c < 3; ++c)
            sum[c] += a[i].flux[c];
    }
    for (int c = 0; c < 3; ++c)
        assert_true(fabs(sum[c] - total[c]) < 1e-5 * total[c]);
    /* deterministic */
    assert_int_equal(lpv_emissive_sample(&s, 4096, b, MAX), n);
    assert_memory_equal(a, b, n * sizeof *a);
    /* a small budget still covers every emissive triangle */
    assert_int_equal(lpv_emissive_sample(&s, 1, b, MAX), 2);
    /* no room: nothing written past max */
    assert_int_equal(lpv_emissive_sample(&s, 4096, b, 10), 10);
    free(a);
    free(b);
    lpv_scene_free(&s);
}

static void test_no_emitters(void **state)
{
    (void)state;
    lpv_scene s;
    assert_int_equal(lpv_scene_builtin_cornell(&s), 0);
    for (uint32_t m = 0; m < s.material_count; ++m)
        memset(s.materials[m].emission, 0, sizeof s.materials[m].emission);
    double total[3];
    lpv_emissive_total_flux(&s, total);
    assert_true(total[0] == 0.0 && total[1] == 0.0 && total[2] == 0.0);
    lpv_vpl v[4];
    assert_int_equal(lpv_emissive_sample(&s, 4096, v, 4), 0);
    lpv_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cornell_light_quad),
        cmocka_unit_test(test_no_emitters),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
