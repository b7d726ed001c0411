/*
 * test_emissive.c - emissive surfaces as VPLs (area lights off) and as area
 * light samples (core/area_lights.h): either way the samples carry exactly
 * the surfaces' emitted flux (pi * L * A, per channel), sit on the emitters,
 * face the way the emitter faces, and are the same every time; area light
 * samples are exactly as many as asked for. A double-sided emitter emits
 * as much again from its back (glTF doubleSided, issue 30).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "area_lights.h"
#include "emissive.h"
#include "scene_build.h"
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

/* Flux per channel of the samples (pi x intensity, W). */
static void samples_flux(const lpv_area_sample *a, size_t n, double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c)
            out[c] += M_PI * a[i].intensity[c];
}

static void test_area_samples_cornell(void **state)
{
    (void)state;
    lpv_scene s;
    assert_int_equal(lpv_scene_builtin_cornell(&s), 0);
    lpv_emitter_list l;
    assert_int_equal(lpv_emitters_collect(&s, &l), 0);
    assert_int_equal(l.count, 2);
    assert_int_equal(l.surfaces, 1);
    double total[3];
    lpv_emissive_total_flux(&s, total);
    lpv_area_sample a[LPV_MAX_AREA_SAMPLES], b[LPV_MAX_AREA_SAMPLES];
    const size_t counts[] = {1, 2, 3, 8, 13, LPV_MAX_AREA_SAMPLES};
    for (size_t k = 0; k < sizeof counts / sizeof counts[0]; ++k) {
        size_t n = lpv_area_lights_sample(&l, counts[k], a);
        assert_int_equal(n, counts[k]);
        double f[3], area = 0.0;
        samples_flux(a, n, f);
        for (int c = 0; c < 3; ++c)
            assert_true(fabs(f[c] - total[c]) < 1e-5 * total[c]);
        for (size_t i = 0; i < n; ++i) {
            assert_true(fabsf(a[i].position[1] - 1.98f) < 1e-4f); /* on the quad */
            assert_true(a[i].position[0] >= -0.25f && a[i].position[0] <= 0.24f);
            assert_true(a[i].normal[1] < -0.99f);                  /* facing down into the room */
            assert_true(a[i].area > 0.0f);
            area += a[i].area;
        }
        assert_true(fabs(area - 0.47 * 0.38) < 2e-3 * 0.47 * 0.38); /* the quad's area, shared out */
        /* equal power each */
        for (size_t i = 0; i < n; ++i)
            assert_true(fabs(M_PI * a[i].intensity[0] - total[0] / (double)n) < 1e-4 * total[0]);
        assert_int_equal(lpv_area_lights_sample(&l, counts[k], b), n); /* deterministic */
        assert_memory_equal(a, b, n * sizeof *a);
    }
    /* one sample: the quad's centre (its two triangles are coplanar) */
    assert_int_equal(lpv_area_lights_sample(&l, 1, a), 1);
    double cx = 0.0, cz = 0.0;
    for (size_t t = 0; t < l.count; ++t)
        for (int v = 0; v < 3; ++v) {
            cx += l.tris[t].p[v][0] * l.tris[t].area;
            cz += l.tris[t].p[v][2] * l.tris[t].area;
        }
    double wsum = 3.0 * (l.tris[0].area + l.tris[1].area);
    assert_true(fabs(a[0].position[0] - cx / wsum) < 1e-3 && fabs(a[0].position[2] - cz / wsum) < 1e-3);
    /* four samples: four different places */
    assert_int_equal(lpv_area_lights_sample(&l, 4, a), 4);
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
            assert_true(hypotf(a[i].position[0] - a[j].position[0], a[i].position[2] - a[j].position[2]) > 0.05f);
    lpv_emitters_free(&l);
    lpv_scene_free(&s);
}

/* Two emitters of different colours and many small triangles: more
 * triangles than samples, and each channel's flux is still exact. */
static void test_area_samples_many_triangles(void **state)
{
    (void)state;
    lpv_scene s = {0};
    int warm = lpv_scene_add_material(&s, "warm", (float[3]){0, 0, 0}, (float[3]){3.0f, 1.0f, 0.2f});
    int cold = lpv_scene_add_material(&s, "cold", (float[3]){0, 0, 0}, (float[3]){0.1f, 0.5f, 2.0f});
    for (int i = 0; i < 40; ++i) { /* 40 small quads facing down in a row, then a box glowing all round */
        float x = 0.1f * (float)i;
        const float q[4][3] = {{x, 2, 0}, {x + 0.1f, 2, 0}, {x + 0.1f, 2, 0.1f}, {x, 2, 0.1f}};
        assert_true(lpv_scene_add_quad(&s, warm, q, NULL) >= 0);
    }
    assert_true(lpv_scene_add_box(&s, cold, (float[3]){-1, 0, -1}, (float[3]){-0.5f, 0.5f, -0.5f}) >= 0);
    lpv_scene_compute_bounds(&s);
    lpv_emitter_list l;
    assert_int_equal(lpv_emitters_collect(&s, &l), 0);
    assert_int_equal(l.count, 40 * 2 + 12);
    assert_int_equal(l.surfaces, 41);
    double total[3];
    lpv_emissive_total_flux(&s, total);
    lpv_area_sample a[LPV_MAX_AREA_SAMPLES];
    for (size_t k = 1; k <= LPV_MAX_AREA_SAMPLES; k *= 2) {
        assert_int_equal(lpv_area_lights_sample(&l, k, a), k);
        double f[3];
        samples_flux(a, k, f);
        for (int c = 0; c < 3; ++c)
            assert_true(fabs(f[c] - total[c]) < 1e-5 * total[c]);
        for (size_t i = 0; i < k; ++i) { /* on an emitter, facing out of it */
            int on_row = fabsf(a[i].position[1] - 2.0f) < 1e-4f && a[i].normal[1] < -0.99f;
            int on_box = a[i].position[0] >= -1.0001f && a[i].position[0] <= -0.4999f && a[i].position[1] >= -1e-4f &&
                         a[i].position[1] <= 0.5001f;
            assert_true(on_row || on_box);
        }
    }
    lpv_emitters_free(&l);
    lpv_scene_free(&s);
}

/* Issue 30: a double-sided emitter (glTF doubleSided) emits pi L A from each
 * side: VPLs and area light samples facing both ways, each side's summing to
 * pi L A. Code-built emitters stay single-sided (front only, as before). */
static void test_double_sided_both_sides(void **state)
{
    (void)state;
    lpv_scene s = {0};
    const float le[3] = {1.0f, 2.0f, 0.5f};
    int m = lpv_scene_add_material(&s, "panel", (float[3]){0.8f, 0.8f, 0.8f}, le);
    assert_int_equal(s.materials[m].double_sided, 0);
    const float q[4][3] = {{0, 2, 0.5f}, {1, 2, 0.5f}, {1, 2, 0}, {0, 2, 0}}; /* 1 x 0.5 m facing up */
    assert_true(lpv_scene_add_quad(&s, m, q, NULL) >= 0);
    lpv_scene_compute_bounds(&s);
    double one[3], two[3];
    lpv_emissive_total_flux(&s, one);
    for (int c = 0; c < 3; ++c)
        assert_true(fabs(one[c] - M_PI * le[c] * 0.5) < 1e-5 * one[c]);
    enum { MAX = 4096 };
    lpv_vpl *v = calloc(MAX, sizeof *v);
    size_t n = lpv_emissive_sample(&s, 1000, v, MAX);
    for (size_t i = 0; i < n; ++i)
        assert_true(v[i].normal[1] > 0.99f); /* single-sided: all up */

    s.materials[m].double_sided = 1;
    lpv_emissive_total_flux(&s, two);
    for (int c = 0; c < 3; ++c)
        assert_true(fabs(two[c] - 2.0 * one[c]) < 1e-5 * one[c]);
    n = lpv_emissive_sample(&s, 1000, v, MAX);
    assert_true(n >= 950 && n <= 1050);
    double up[3] = {0, 0, 0}, down[3] = {0, 0, 0};
    size_t n_up = 0;
    for (size_t i = 0; i < n; ++i) {
        assert_true(fabsf(v[i].position[1] - 2.0f) < 1e-5f);
        assert_true(fabsf(fabsf(v[i].normal[1]) - 1.0f) < 1e-5f);
        n_up += v[i].normal[1] > 0.0f;
        for (int c = 0; c < 3; ++c)
            *(v[i].normal[1] > 0.0f ? &up[c] : &down[c]) += v[i].flux[c];
    }
    assert_int_equal(2 * n_up, n);
    for (int c = 0; c < 3; ++c) {
        assert_true(fabs(up[c] - one[c]) < 1e-5 * one[c]);
        assert_true(fabs(down[c] - one[c]) < 1e-5 * one[c]);
    }
    free(v);

    lpv_emitter_list l;
    assert_int_equal(lpv_emitters_collect(&s, &l), 0);
    assert_int_equal(l.count, 4); /* two triangles, two sides */
    assert_int_equal(l.surfaces, 1);
    lpv_area_sample a[8];
    assert_int_equal(lpv_area_lights_sample(&l, 8, a), 8);
    for (int c = 0; c < 3; ++c)
        up[c] = down[c] = 0.0;
    for (int k = 0; k < 8; ++k) {
        assert_true(a[k].position[0] > 0.0f && a[k].position[0] < 1.0f && fabsf(a[k].position[1] - 2.0f) < 1e-5f);
        assert_int_equal(a[k].normal[1] > 0.99f, k < 4); /* the front's four first, then the back's */
        assert_int_equal(a[k].normal[1] < -0.99f, k >= 4);
        for (int c = 0; c < 3; ++c)
            *(k < 4 ? &up[c] : &down[c]) += M_PI * a[k].intensity[c];
    }
    for (int c = 0; c < 3; ++c) {
        assert_true(fabs(up[c] - one[c]) < 1e-5 * one[c]);
        assert_true(fabs(down[c] - one[c]) < 1e-5 * one[c]);
    }
    lpv_emitters_free(&l);
    lpv_scene_free(&s);
}

static void test_area_samples_none(void **state)
{
    (void)state;
    lpv_scene s = {0};
    int grey = lpv_scene_add_material(&s, "grey", (float[3]){0.5f, 0.5f, 0.5f}, NULL);
    const float q[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
    assert_true(lpv_scene_add_quad(&s, grey, q, NULL) >= 0);
    lpv_emitter_list l;
    assert_int_equal(lpv_emitters_collect(&s, &l), 0);
    assert_int_equal(l.count, 0);
    lpv_area_sample a[4];
    assert_int_equal(lpv_area_lights_sample(&l, 4, a), 0);
    assert_int_equal(lpv_area_lights_sample(NULL, 4, a), 0);
    lpv_emitters_free(&l);
    lpv_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cornell_light_quad),         cmocka_unit_test(test_no_emitters),
        cmocka_unit_test(test_area_samples_cornell),       cmocka_unit_test(test_area_samples_many_triangles),
        cmocka_unit_test(test_area_samples_none),          cmocka_unit_test(test_double_sided_both_sides),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
