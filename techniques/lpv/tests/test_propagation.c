/*
 * test_propagation.c - the oracle's propagation step (docs/propagation.md):
 * flux bookkeeping including what leaves the grid, no hidden gain, energy
 * never growing over 1000 steps, c0 >= 0, linearity when the limiter is
 * idle, the accumulation loop, the direction of occlusion and the merge of
 * the geometry volume's buffers.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "grid.h"
#include "lpv_shared.h"
#include "oracle.h"
#include "sh.h"
#include "test_util.h"

#define SQRT_4PI 3.5449077018110318

/* Float rounding of the per-cell sums lets a step's total flux exceed the
 * previous one by a few ulps even though the scheme cannot gain energy in
 * exact arithmetic (docs/propagation.md); this is the allowance per step. */
#define ENERGY_RTOL 1e-6

static const int dirs[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
static const int axis_slot[3] = {3, 1, 2};

/* ---- helpers ------------------------------------------------------------- */

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;

static double rnd(double lo, double hi) { return lpvt_rand(&rng_state, lo, hi); }

static lpv_grid make_grid(int nx, int ny, int nz)
{
    lpv_grid g = {{nx, ny, nz}, {0.0f, 0.0f, 0.0f}, 1.0f};
    return g;
}

static void *xcalloc(size_t n, size_t size)
{
    void *p = calloc(n, size);
    assert_non_null(p);
    return p;
}

static lpv_cell *new_cells(const lpv_grid *g)
{
    return xcalloc(lpv_grid_cell_count(g), sizeof(lpv_cell));
}

static float *chan(lpv_cell *c, int ch)
{
    return ch == 0 ? c->r : ch == 1 ? c->g : c->b;
}

static const float *cchan(const lpv_cell *c, int ch)
{
    return ch == 0 ? c->r : ch == 1 ? c->g : c->b;
}

/* Random field: c0 in [0.1, 1], each band-1 coefficient up to ratio * c0.
 * ratio < A / B = 0.631 keeps every face flux positive (limiter idle). */
static void random_field(const lpv_grid *g, lpv_cell *cells, double ratio)
{
    size_t n = lpv_grid_cell_count(g);
    for (size_t i = 0; i < n; i++) {
        for (int ch = 0; ch < 3; ch++) {
            float *c = chan(&cells[i], ch);
            c[0] = (float)rnd(0.1, 1.0);
            for (int k = 1; k < 4; k++)
                c[k] = (float)(rnd(-ratio, ratio) * c[0]);
        }
    }
}

/* Random GV totals whose blocking goes below 0 and above LPV_GV_PEAK, so the
 * clamp is exercised on both sides (a merged total is never negative, but the
 * transmittance must clamp whatever it is given). */
static lpv_gv_point *random_gv(const lpv_grid *g)
{
    size_t n = lpv_grid_gv_count(g);
    lpv_gv_point *gv = xcalloc(n, sizeof(lpv_gv_point));
    for (size_t i = 0; i < n; i++)
        for (int d = 0; d < LPV_DIR_COUNT; d++)
            gv[i].blocking[d / 4][d % 4] = (float)rnd(-1.0, 2.0);
    return gv;
}

static float *transmittance_of(const lpv_grid *g, const lpv_gv_point *gv)
{
    float *t = xcalloc(lpv_grid_cell_count(g) * 6, sizeof(float));
    lpv_oracle_transmittance(g, gv, t);
    return t;
}

/* Independent double-precision limiter (docs/propagation.md). */
static double face_flux_ref(const float *c, int d)
{
    double s = (d & 1) ? -1.0 : 1.0;
    return (double)LPV_PROP_A * c[0] + s * (double)LPV_PROP_B * c[axis_slot[d / 2]];
}

static double sigma_ref(const float *c, int d)
{
    double p = 0.0;
    for (int e = 0; e < 6; e++)
        p += fmax(face_flux_ref(c, e), 0.0);
    if (!(c[0] > 0.0f) || !(p > 0.0))
        return 0.0;
    return face_flux_ref(c, d) > 0.0 ? c[0] / p : 0.0;
}

static int inside(const lpv_grid *g, const int p[3])
{
    for (int a = 0; a < 3; a++)
        if (p[a] < 0 || p[a] >= g->dims[a])
            return 0;
    return 1;
}

static void assert_all_finite(const lpv_grid *g, const lpv_cell *cells)
{
    size_t n = lpv_grid_cell_count(g);
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 4; k++)
            if (!isfinite(cells[i].r[k]) || !isfinite(cells[i].g[k]) || !isfinite(cells[i].b[k]))
                fail_msg("cell %zu coefficient %d is not finite", i, k);
}

static void assert_c0_non_negative(const lpv_grid *g, const lpv_cell *cells)
{
    size_t n = lpv_grid_cell_count(g);
    for (size_t i = 0; i < n; i++)
        if (!(cells[i].r[0] >= 0.0f && cells[i].g[0] >= 0.0f && cells[i].b[0] >= 0.0f))
            fail_msg("cell %zu has c0 (%g, %g, %g) < 0", i, (double)cells[i].r[0], (double)cells[i].g[0],
                     (double)cells[i].b[0]);
}

static void assert_rel(double got, double want, double rtol, const char *what)
{
    if (!(fabs(got - want) <= rtol * fabs(want)))
        fail_msg("%s: got %.10g, want %.10g (rel. error %.3g > %.3g)", what, got, want, fabs(got - want) / fabs(want),
                 rtol);
}

/* ---- (1) flux bookkeeping ------------------------------------------------ */

/* Flux that the step sends out of the grid: sigma_d F_d sqrt(4 pi) for every
 * source cell and every direction whose destination is outside. */
static void boundary_flux(const lpv_grid *g, const lpv_cell *in, double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    int x[3];
    for (x[2] = 0; x[2] < g->dims[2]; x[2]++)
        for (x[1] = 0; x[1] < g->dims[1]; x[1]++)
            for (x[0] = 0; x[0] < g->dims[0]; x[0]++) {
                const lpv_cell *c = &in[lpv_grid_index(g, x[0], x[1], x[2])];
                for (int d = 0; d < 6; d++) {
                    int y[3] = {x[0] + dirs[d][0], x[1] + dirs[d][1], x[2] + dirs[d][2]};
                    if (inside(g, y))
                        continue;
                    for (int ch = 0; ch < 3; ch++)
                        out[ch] += sigma_ref(cchan(c, ch), d) * face_flux_ref(cchan(c, ch), d) * SQRT_4PI;
                }
            }
}

static int any_face_flux_negative(const lpv_grid *g, const lpv_cell *in)
{
    size_t n = lpv_grid_cell_count(g);
    for (size_t i = 0; i < n; i++)
        for (int ch = 0; ch < 3; ch++)
            for (int d = 0; d < 6; d++)
                if (face_flux_ref(cchan(&in[i], ch), d) < 0.0)
                    return 1;
    return 0;
}

static void check_conservation(double ratio, int expect_limiting)
{
    lpv_grid g = make_grid(8, 7, 6);
    lpv_cell *in = new_cells(&g), *out = new_cells(&g);
    random_field(&g, in, ratio);
    assert_int_equal(any_face_flux_negative(&g, in), expect_limiting);

    lpv_oracle_propagate_step(&g, in, NULL, out);
    double fin[3], fout[3], fb[3];
    lpv_oracle_total_flux(&g, in, fin);
    lpv_oracle_total_flux(&g, out, fout);
    boundary_flux(&g, in, fb);
    for (int ch = 0; ch < 3; ch++) {
        assert_true(fb[ch] > 0.0);
        assert_rel(fout[ch] + fb[ch], fin[ch], 1e-5, "inside + left through the boundary = input");
    }
    free(in);
    free(out);
}

static void test_conservation_without_limiting(void **state)
{
    (void)state;
    check_conservation(0.6, 0);
}

static void test_conservation_with_limiting(void **state)
{
    (void)state;
    check_conservation(3.0, 1);
}

/* ---- (2) no hidden gain -------------------------------------------------- */

static void test_isotropic_cell_splits_in_six(void **state)
{
    (void)state;
    lpv_grid g = make_grid(5, 5, 5);
    lpv_cell *in = new_cells(&g), *out = new_cells(&g);
    size_t centre = lpv_grid_index(&g, 2, 2, 2);
    in[centre].r[0] = 1.0f;
    in[centre].g[0] = 2.0f;
    in[centre].b[0] = 1000.0f;
    double fin[3];
    lpv_oracle_total_flux(&g, in, fin);

    lpv_oracle_propagate_step(&g, in, NULL, out);
    for (int d = 0; d < 6; d++) {
        lpv_cell *n = &out[lpv_grid_index(&g, 2 + dirs[d][0], 2 + dirs[d][1], 2 + dirs[d][2])];
        float s = (d & 1) ? -1.0f : 1.0f;
        for (int ch = 0; ch < 3; ch++) {
            const float *c = chan(n, ch);
            float c0 = chan(&in[centre], ch)[0];
            assert_rel(c[0] * SQRT_4PI, fin[ch] / 6.0, 1e-6, "each neighbour gets 1/6 of the flux");
            for (int k = 1; k < 4; k++) {
                double want = k == axis_slot[d / 2] ? s * LPV_PROP_E * c0 : 0.0;
                assert_true(fabs(c[k] - want) <= 1e-6 * c0);
            }
        }
        memset(n, 0, sizeof *n);
    }
    /* Nothing anywhere else. */
    double rest[3];
    lpv_oracle_total_flux(&g, out, rest);
    for (int ch = 0; ch < 3; ch++)
        assert_true(rest[ch] == 0.0);
    free(in);
    free(out);
}

/* A cell whose face fluxes are all positive goes out as exactly M_d c. */
static void test_single_cell_matches_matrices(void **state)
{
    (void)state;
    lpv_grid g = make_grid(3, 3, 3);
    lpv_cell *in = new_cells(&g), *out = new_cells(&g);
    const float c[4] = {1.0f, 0.3f, -0.5f, 0.2f};
    memcpy(in[lpv_grid_index(&g, 1, 1, 1)].r, c, sizeof c);
    lpv_oracle_propagate_step(&g, in, NULL, out);
    for (int d = 0; d < 6; d++) {
        const float *o = out[lpv_grid_index(&g, 1 + dirs[d][0], 1 + dirs[d][1], 1 + dirs[d][2])].r;
        int k = axis_slot[d / 2];
        double s = (d & 1) ? -1.0 : 1.0;
        double want[4];
        want[0] = LPV_PROP_A * c[0] + s * LPV_PROP_B * c[k];
        for (int j = 1; j < 4; j++)
            want[j] = j == k ? s * LPV_PROP_E * c[0] + LPV_PROP_F * c[k] : LPV_PROP_G * c[j];
        for (int j = 0; j < 4; j++)
            assert_true(fabs(o[j] - want[j]) <= 1e-6);
    }
    free(in);
    free(out);
}

/* A strongly directional cell: the negative face flux is dropped and the
 * positive ones are scaled by c0 / P, so the neighbours receive exactly c0. */
static void test_limiter_by_hand(void **state)
{
    (void)state;
    lpv_grid g = make_grid(3, 3, 3);
    lpv_cell *in = new_cells(&g), *out = new_cells(&g);
    const float c[4] = {1.0f, 0.0f, 0.0f, 2.0f}; /* pointing along +x */
    memcpy(in[lpv_grid_index(&g, 1, 1, 1)].r, c, sizeof c);
    lpv_oracle_propagate_step(&g, in, NULL, out);

    double a = LPV_PROP_A, b = LPV_PROP_B;
    double p = (a + 2.0 * b) + 4.0 * a; /* F(-x) = a - 2b < 0 is dropped */
    double sigma = 1.0 / p;
    assert_true(a - 2.0 * b < 0.0);
    assert_true(fabs(out[lpv_grid_index(&g, 2, 1, 1)].r[0] - sigma * (a + 2.0 * b)) <= 1e-6);
    assert_true(out[lpv_grid_index(&g, 0, 1, 1)].r[0] == 0.0f);
    assert_true(fabs(out[lpv_grid_index(&g, 1, 2, 1)].r[0] - sigma * a) <= 1e-6);
    double total[3];
    lpv_oracle_total_flux(&g, out, total);
    assert_rel(total[0] / SQRT_4PI, 1.0, 1e-6, "limited cell sends out exactly c0");
    free(in);
    free(out);
}

/* ---- (3) energy over 1000 steps ------------------------------------------ */

static void run_energy(const float *t)
{
    lpv_grid g = make_grid(16, 16, 16);
    lpv_cell *cur = new_cells(&g), *next = new_cells(&g);
    random_field(&g, cur, 2.0); /* many cells limited */
    double prev[3];
    lpv_oracle_total_flux(&g, cur, prev);
    for (int step = 0; step < 1000; step++) {
        lpv_oracle_propagate_step(&g, cur, t, next);
        assert_all_finite(&g, next);
        double e[3];
        lpv_oracle_total_flux(&g, next, e);
        for (int ch = 0; ch < 3; ch++) {
            if (!(e[ch] <= prev[ch] * (1.0 + ENERGY_RTOL)))
                fail_msg("step %d channel %d: flux grew from %.10g to %.10g", step, ch, prev[ch], e[ch]);
            prev[ch] = e[ch];
        }
        lpv_cell *tmp = cur;
        cur = next;
        next = tmp;
    }
    free(cur);
    free(next);
}

static void test_energy_1000_steps_occluded(void **state)
{
    (void)state;
    lpv_grid g = make_grid(16, 16, 16);
    lpv_gv_point *gv = random_gv(&g);
    float *t = transmittance_of(&g, gv);
    run_energy(t);
    free(t);
    free(gv);
}

static void test_energy_1000_steps_open(void **state)
{
    (void)state;
    run_energy(NULL);
}

/* ---- (4) c0 >= 0 ---------------------------------------------------------- */

static void test_c0_stays_non_negative(void **state)
{
    (void)state;
    lpv_grid g = make_grid(10, 9, 8);
    lpv_cell *cur = new_cells(&g), *next = new_cells(&g), *acc = new_cells(&g);
    /* VPLs with random (non-negative) flux and random normals: single lobes
     * are the most directional non-negative input there is. */
    lpv_vpl vpls[300];
    for (int i = 0; i < 300; i++) {
        lpv_vpl v = {{(float)rnd(0, 10), (float)rnd(0, 9), (float)rnd(0, 8), 1.0f},
                     {(float)rnd(-1, 1), (float)rnd(-1, 1), (float)rnd(-1, 1), 0.0f},
                     {(float)rnd(0, 5), (float)rnd(0, 1), 0.0f, 0.0f}};
        vpls[i] = v;
    }
    assert_true(lpv_oracle_inject_vpls(&g, vpls, 300, cur) > 200);
    lpv_gv_point *gv = random_gv(&g);
    float *t = transmittance_of(&g, gv);
    assert_int_equal(lpv_oracle_propagate(&g, cur, t, 50, acc), 0);
    assert_c0_non_negative(&g, acc);
    for (int step = 0; step < 200; step++) {
        lpv_oracle_propagate_step(&g, cur, step & 1 ? t : NULL, next);
        assert_c0_non_negative(&g, next);
        lpv_cell *tmp = cur;
        cur = next;
        next = tmp;
    }
    free(t);
    free(gv);
    free(cur);
    free(next);
    free(acc);
}

/* ---- (5) linearity -------------------------------------------------------- */

static void check_linearity(const float *t)
{
    lpv_grid g = make_grid(7, 6, 5);
    size_t n = lpv_grid_cell_count(&g);
    lpv_cell *a = new_cells(&g), *b = new_cells(&g), *ab = new_cells(&g);
    lpv_cell *sa = new_cells(&g), *sb = new_cells(&g), *sab = new_cells(&g);
    random_field(&g, a, 0.6);
    random_field(&g, b, 0.6);
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 4; k++) {
            ab[i].r[k] = a[i].r[k] + b[i].r[k];
            ab[i].g[k] = a[i].g[k] + b[i].g[k];
            ab[i].b[k] = a[i].b[k] + b[i].b[k];
        }
    assert_false(any_face_flux_negative(&g, ab));
    lpv_oracle_propagate_step(&g, a, t, sa);
    lpv_oracle_propagate_step(&g, b, t, sb);
    lpv_oracle_propagate_step(&g, ab, t, sab);
    /* Inputs are O(1); the step's outputs are sums of O(1) terms. */
    for (size_t i = 0; i < n; i++)
        for (int ch = 0; ch < 3; ch++)
            for (int k = 0; k < 4; k++) {
                double sum = (double)chan(&sa[i], ch)[k] + chan(&sb[i], ch)[k];
                assert_true(fabs(chan(&sab[i], ch)[k] - sum) <= 1e-5);
            }
    free(a);
    free(b);
    free(ab);
    free(sa);
    free(sb);
    free(sab);
}

static void test_linearity(void **state)
{
    (void)state;
    check_linearity(NULL);
    lpv_grid g = make_grid(7, 6, 5);
    lpv_gv_point *gv = random_gv(&g);
    float *t = transmittance_of(&g, gv);
    check_linearity(t);
    free(t);
    free(gv);
}

/* ---- accumulation and occlusion ------------------------------------------- */

/* acc = injected + every step's output; the first step ignores occlusion. */
static void test_propagate_accumulates(void **state)
{
    (void)state;
    lpv_grid g = make_grid(6, 5, 4);
    size_t n = lpv_grid_cell_count(&g);
    lpv_cell *inj = new_cells(&g), *acc = new_cells(&g), *cur = new_cells(&g), *next = new_cells(&g);
    lpv_cell *sum = new_cells(&g);
    random_field(&g, inj, 1.0);
    lpv_gv_point *gv = random_gv(&g);
    float *t = transmittance_of(&g, gv);

    assert_int_equal(lpv_oracle_propagate(&g, inj, t, 5, acc), 0);
    memcpy(cur, inj, n * sizeof *cur);
    memcpy(sum, inj, n * sizeof *sum);
    for (int i = 0; i < 5; i++) {
        lpv_oracle_propagate_step(&g, cur, i == 0 ? NULL : t, next);
        for (size_t c = 0; c < n; c++)
            for (int k = 0; k < 4; k++) {
                sum[c].r[k] += next[c].r[k];
                sum[c].g[k] += next[c].g[k];
                sum[c].b[k] += next[c].b[k];
            }
        lpv_cell *tmp = cur;
        cur = next;
        next = tmp;
    }
    assert_memory_equal(acc, sum, n * sizeof *acc);

    /* Zero iterations: injection only. */
    assert_int_equal(lpv_oracle_propagate(&g, inj, t, 0, acc), 0);
    assert_memory_equal(acc, inj, n * sizeof *acc);

    /* Everything blocked: only the unoccluded first step gets through. */
    float *closed = xcalloc(n * 6, sizeof(float));
    assert_int_equal(lpv_oracle_propagate(&g, inj, closed, 4, acc), 0);
    lpv_oracle_propagate_step(&g, inj, NULL, next);
    for (size_t c = 0; c < n; c++)
        for (int k = 0; k < 4; k++)
            assert_true(acc[c].r[k] == inj[c].r[k] + next[c].r[k]);
    free(closed);
    free(t);
    free(gv);
    free(inj);
    free(acc);
    free(cur);
    free(next);
    free(sum);
}

/* One buffer's GV holding a wall of surfels of area 2 cell^2 on the GV plane
 * x = 3 (the face between cells 2 and 3), normals (nx, 0, 0), merged into the
 * total. Facing the light, each corner blocks B = 2 * 0.75 >= LPV_GV_PEAK;
 * its back (2 * -0.25) blocks nothing. */
static void merge_wall(const lpv_grid *g, float nx, lpv_gv_point *total)
{
    vec4 *sh = xcalloc(lpv_grid_gv_count(g), sizeof(vec4));
    lpv_surfel wall[25];
    int count = 0;
    for (int y = 0; y <= 4; y++)
        for (int z = 0; z <= 4; z++) {
            lpv_surfel s = {{3.0f, (float)y, (float)z, 2.0f}, {nx, 0.0f, 0.0f, 0.0f}};
            wall[count++] = s;
        }
    assert_int_equal(lpv_oracle_inject_surfels(g, wall, 25, sh), 25);
    lpv_oracle_gv_merge(g, sh, total);
    free(sh);
}

/* Propagates red from cell (1, 1, 1) and green from (5, 2, 2) past the wall
 * of merge_wall: whether each crossed it, and that something propagated. */
static void cross_wall(const lpv_grid *g, const float *t, int *red_crossed, int *green_crossed)
{
    size_t n = lpv_grid_cell_count(g);
    lpv_cell *inj = new_cells(g), *acc = new_cells(g);
    inj[lpv_grid_index(g, 1, 1, 1)].r[0] = 1.0f;
    inj[lpv_grid_index(g, 5, 2, 2)].g[0] = 1.0f;
    assert_int_equal(lpv_oracle_propagate(g, inj, t, 20, acc), 0);
    *red_crossed = *green_crossed = 0;
    for (size_t i = 0; i < n; i++) {
        int x = (int)(i % (size_t)g->dims[0]);
        *red_crossed |= x >= 3 && acc[i].r[0] != 0.0f;
        *green_crossed |= x < 3 && acc[i].g[0] != 0.0f;
    }
    assert_true(acc[lpv_grid_index(g, 0, 1, 1)].r[0] > 0.0f); /* red spread on its side */
    assert_true(acc[lpv_grid_index(g, 4, 2, 2)].g[0] > 0.0f);
    free(inj);
    free(acc);
}

/* A wall of surfels facing -x blocks light travelling +x into it and lets
 * light travelling -x (hitting its back) through. */
static void test_occlusion_direction(void **state)
{
    (void)state;
    lpv_grid g = make_grid(6, 4, 4);
    lpv_gv_point *gv = xcalloc(lpv_grid_gv_count(&g), sizeof(lpv_gv_point));
    merge_wall(&g, -1.0f, gv);
    float *t = transmittance_of(&g, gv);
    for (int y = 0; y < 4; y++)
        for (int z = 0; z < 4; z++) {
            assert_true(t[lpv_grid_index(&g, 3, y, z) * 6 + 0] == 0.0f); /* +x into the front */
            assert_true(t[lpv_grid_index(&g, 2, y, z) * 6 + 1] == 1.0f); /* -x out of the back */
            assert_true(t[lpv_grid_index(&g, 1, y, z) * 6 + 0] == 1.0f); /* away from the wall */
        }
    int red_crossed, green_crossed;
    cross_wall(&g, t, &red_crossed, &green_crossed);
    assert_false(red_crossed);  /* red starts at x = 1, in front */
    assert_true(green_crossed); /* green passed the back */
    free(t);
    free(gv);
}

/* A closed box's wall as the engine sees it: a lamp's RSM inside holds the
 * inner side (normals -x here), the scene surfels the outer side (+x), two
 * buffers with opposite lobes at the same GV points. Merged, the wall blocks
 * both ways, in either merge order: the whole-vector max this replaced (the
 * DC terms tie) kept one side's lobe and let light through the other way, so
 * a lamp in a box lit the room. A side merged twice blocks as once. */
static void test_wall_seen_from_both_sides(void **state)
{
    (void)state;
    lpv_grid g = make_grid(6, 4, 4);
    size_t gv_n = lpv_grid_gv_count(&g);
    lpv_gv_point *once = xcalloc(gv_n, sizeof *once), *twice = xcalloc(gv_n, sizeof *twice);
    merge_wall(&g, -1.0f, once);
    merge_wall(&g, -1.0f, twice);
    merge_wall(&g, -1.0f, twice);
    assert_memory_equal(once, twice, gv_n * sizeof *once);
    for (int order = 0; order < 2; order++) {
        lpv_gv_point *gv = xcalloc(gv_n, sizeof *gv);
        merge_wall(&g, order ? 1.0f : -1.0f, gv);
        merge_wall(&g, order ? -1.0f : 1.0f, gv);
        float *t = transmittance_of(&g, gv);
        for (int y = 0; y < 4; y++)
            for (int z = 0; z < 4; z++) {
                assert_true(t[lpv_grid_index(&g, 3, y, z) * 6 + 0] == 0.0f); /* +x into the inner side */
                assert_true(t[lpv_grid_index(&g, 2, y, z) * 6 + 1] == 0.0f); /* -x into the outer side */
                assert_true(t[lpv_grid_index(&g, 1, y, z) * 6 + 0] == 1.0f); /* away from the wall */
            }
        int red_crossed, green_crossed;
        cross_wall(&g, t, &red_crossed, &green_crossed);
        assert_false(red_crossed);
        assert_false(green_crossed);
        free(t);
        free(gv);
    }
    free(once);
    free(twice);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_conservation_without_limiting),
        cmocka_unit_test(test_conservation_with_limiting),
        cmocka_unit_test(test_isotropic_cell_splits_in_six),
        cmocka_unit_test(test_single_cell_matches_matrices),
        cmocka_unit_test(test_limiter_by_hand),
        cmocka_unit_test(test_energy_1000_steps_occluded),
        cmocka_unit_test(test_energy_1000_steps_open),
        cmocka_unit_test(test_c0_stays_non_negative),
        cmocka_unit_test(test_linearity),
        cmocka_unit_test(test_propagate_accumulates),
        cmocka_unit_test(test_occlusion_direction),
        cmocka_unit_test(test_wall_seen_from_both_sides),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
