/*
 * test_injection.c - the oracle's VPL injection as a light moves (settings
 * lpv.smooth_injection, grid.glsl vpl_stencil_at): a VPL that slides over a
 * surface changes the point-splat volume by its whole light where it
 * crosses a cell's border, and the smooth injection's volume by no more
 * than its step allows; both keep the VPL's light, and the smooth one never
 * puts it in another layer of cells along the normal (behind the surface or
 * further out) than the point splat does. test_gpu_oracle holds the shader
 * to this oracle.
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

#include "grid.h"
#include "lpv_shared.h"
#include "oracle.h"

enum { SIDE = 8 };

static double c0_sum(const lpv_cell *cells, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; ++i)
        s += cells[i].r[0];
    return s;
}

/* The largest change of any cell's red c0 between two volumes. */
static double largest_change(const lpv_cell *a, const lpv_cell *b, size_t n)
{
    double d = 0.0;
    for (size_t i = 0; i < n; ++i)
        d = fmax(d, fabs((double)a[i].r[0] - b[i].r[0]));
    return d;
}

/* A VPL on a floor (normal +y) and one on a wall (normal -x) slide 1 cm at
 * a time over two cells. */
static void test_a_sliding_vpl(void **state)
{
    (void)state;
    const lpv_grid g = {{SIDE, SIDE, SIDE}, {0.0f, 0.0f, 0.0f}, 0.25f}; /* 2 m, cells of 25 cm */
    const size_t n = lpv_grid_cell_count(&g);
    const struct {
        float start[3], step[3], normal[3];
        int axis; /* the normal's */
    } cases[] = {
        {{0.51f, 0.0f, 0.93f}, {0.01f, 0.0f, 0.004f}, {0.0f, 1.0f, 0.0f}, 1},
        {{1.5f, 0.62f, 0.3f}, {0.0f, 0.007f, 0.01f}, {-1.0f, 0.0f, 0.0f}, 0},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        lpv_cell *point[2], *smooth[2];
        for (int i = 0; i < 2; ++i) {
            point[i] = calloc(n, sizeof(lpv_cell));
            smooth[i] = calloc(n, sizeof(lpv_cell));
        }
        double point_jump = 0.0, smooth_jump = 0.0, total = 0.0;
        const int steps = 50;
        for (int s = 0; s <= steps; ++s) {
            lpv_vpl v;
            memset(&v, 0, sizeof v);
            for (int i = 0; i < 3; ++i) {
                v.position[i] = cases[k].start[i] + cases[k].step[i] * (float)s;
                v.normal[i] = cases[k].normal[i];
            }
            v.position[3] = 1.0f;
            v.flux[0] = v.flux[1] = v.flux[2] = 2.0f;
            lpv_cell *p = point[s % 2], *m = smooth[s % 2];
            memset(p, 0, n * sizeof *p);
            memset(m, 0, n * sizeof *m);
            assert_int_equal(lpv_oracle_inject_vpls(&g, &v, 1, p), 1);
            assert_int_equal(lpv_oracle_inject_vpls_spread(&g, &v, 1, m), 1);
            /* the same light, and in the point splat's layer along the normal */
            total = c0_sum(p, n);
            assert_true(fabs(c0_sum(m, n) - total) <= 1e-5 * total);
            int layer = -1;
            for (size_t i = 0; i < n; ++i)
                if (p[i].r[0] != 0.0f) {
                    int c[3] = {(int)(i % SIDE), (int)(i / SIDE % SIDE), (int)(i / (SIDE * SIDE))};
                    layer = c[cases[k].axis];
                }
            for (size_t i = 0; i < n; ++i)
                if (m[i].r[0] != 0.0f) {
                    int c[3] = {(int)(i % SIDE), (int)(i / SIDE % SIDE), (int)(i / (SIDE * SIDE))};
                    assert_int_equal(c[cases[k].axis], layer);
                }
            if (s) {
                point_jump = fmax(point_jump, largest_change(point[0], point[1], n));
                smooth_jump = fmax(smooth_jump, largest_change(smooth[0], smooth[1], n));
            }
        }
        /* a step of at most 1 cm in a 25 cm cell moves at most 4 % of the light
         * (bilinear: the weights' change per axis is step / cell, plus the
         * other axis's share), the point splat moves all of it at a border */
        const double step_cells = 0.01 / 0.25;
        printf("VPL %zu: largest change of a cell per step: point %.3f, smooth %.3f of the VPL's c0 (step %.3f cells)\n",
               k, point_jump / total, smooth_jump / total, step_cells);
        assert_true(point_jump >= 0.99 * total);
        assert_true(smooth_jump <= 2.0 * step_cells * total);
        for (int i = 0; i < 2; ++i) {
            free(point[i]);
            free(smooth[i]);
        }
    }
}

/* A VPL whose stencil reaches past the grid keeps what lands inside; one
 * outside gives nothing; a broken one is skipped. */
static void test_edges_and_bad_vpls(void **state)
{
    (void)state;
    const lpv_grid g = {{SIDE, SIDE, SIDE}, {0.0f, 0.0f, 0.0f}, 0.25f};
    const size_t n = lpv_grid_cell_count(&g);
    lpv_cell *m = calloc(n, sizeof *m);
    lpv_vpl v;
    memset(&v, 0, sizeof v);
    v.position[0] = 0.05f; /* a fifth of a cell from the grid's side: part of the stencil is outside */
    v.position[2] = 1.0f;
    v.position[3] = 1.0f;
    v.normal[1] = 1.0f;
    v.flux[0] = v.flux[1] = v.flux[2] = 1.0f;
    assert_int_equal(lpv_oracle_inject_vpls_spread(&g, &v, 1, m), 1);
    lpv_cell *p = calloc(n, sizeof *p);
    lpv_oracle_inject_vpls(&g, &v, 1, p);
    const double inside = c0_sum(m, n), all = c0_sum(p, n);
    assert_true(inside > 0.5 * all && inside < all); /* 0.55 of it: the corners at x = -1 dropped */
    memset(m, 0, n * sizeof *m);
    v.position[0] = -3.0f;
    assert_int_equal(lpv_oracle_inject_vpls_spread(&g, &v, 1, m), 0);
    v.position[0] = NAN;
    assert_int_equal(lpv_oracle_inject_vpls_spread(&g, &v, 1, m), 0);
    v.position[0] = 1.0f;
    v.normal[1] = 0.0f; /* no direction */
    assert_int_equal(lpv_oracle_inject_vpls_spread(&g, &v, 1, m), 0);
    assert_true(c0_sum(m, n) == 0.0);
    free(m);
    free(p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_a_sliding_vpl),
        cmocka_unit_test(test_edges_and_bad_vpls),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
