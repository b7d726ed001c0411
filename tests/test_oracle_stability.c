/*
 * test_oracle_stability.c - the whole oracle pipeline (inject -> GV ->
 * transmittance -> propagate -> irradiance) on hostile input: degenerate
 * normals, positions and flux, VPLs on cell corners, faces and the grid
 * boundary, a 10^6 dynamic range, 1000 steps, 1-cell and 1x1x64 grids,
 * values up to 1e30, and queries outside the grid. Run it under ASan too
 * (-DLPVD_SANITIZE=ON): several cases exist to catch out-of-bounds indexing.
 */
#include <float.h>
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
#include "settings.h"
#include "sh.h"
#include "test_util.h"

/* Per-step allowance for float rounding in the flux sums (see
 * test_propagation.c and docs/propagation.md). */
#define ENERGY_RTOL 1e-6

static uint64_t rng_state = 0x2545F4914F6CDD1Dull;

static double rnd(double lo, double hi) { return lpvt_rand(&rng_state, lo, hi); }

static void *xcalloc(size_t n, size_t size)
{
    void *p = calloc(n, size);
    assert_non_null(p);
    return p;
}

/* A grid with origin (0, 0, 0) and cell size 1. */
static lpv_grid unit_grid(int nx, int ny, int nz)
{
    lpv_grid g = {.dims = {nx, ny, nz}, .origin = {0.0f, 0.0f, 0.0f}, .cell_size = 1.0f};
    return g;
}

static lpv_vpl vpl(float x, float y, float z, float nx, float ny, float nz, float r, float gr, float b)
{
    lpv_vpl v = {{x, y, z, 1.0f}, {nx, ny, nz, 0.0f}, {r, gr, b, 0.0f}};
    return v;
}

static lpv_surfel surfel(float x, float y, float z, float area, float nx, float ny, float nz)
{
    lpv_surfel s = {{x, y, z, area}, {nx, ny, nz, 0.0f}};
    return s;
}

static int cell_finite(const lpv_cell *c)
{
    for (int k = 0; k < 4; k++)
        if (!isfinite(c->r[k]) || !isfinite(c->g[k]) || !isfinite(c->b[k]))
            return 0;
    return 1;
}

static void assert_cells_sane(const lpv_grid *g, const lpv_cell *cells, const char *what)
{
    size_t n = lpv_grid_cell_count(g);
    for (size_t i = 0; i < n; i++) {
        if (!cell_finite(&cells[i]))
            fail_msg("%s: cell %zu is not finite", what, i);
        if (!(cells[i].r[0] >= 0.0f && cells[i].g[0] >= 0.0f && cells[i].b[0] >= 0.0f))
            fail_msg("%s: cell %zu has a negative c0", what, i);
    }
}

/* ---- the pipeline ------------------------------------------------------- */

typedef struct pipeline {
    lpv_grid g;
    lpv_cell *injected;
    lpv_cell *acc;
    lpv_gv_point *gv;
    float *t;
    size_t vpls_injected;
    size_t surfels_injected;
} pipeline;

/* Surfels go into two buffers' GVs (even and odd array positions), merged
 * into the total as the engine merges camera and RSM volumes. */
static void build_gv(pipeline *p, const lpv_surfel *s, size_t ns)
{
    size_t count = lpv_grid_gv_count(&p->g);
    vec4 *even = xcalloc(count, sizeof(vec4)), *odd = xcalloc(count, sizeof(vec4));
    p->surfels_injected = 0;
    for (size_t i = 0; i < ns; i++)
        p->surfels_injected += lpv_oracle_inject_surfels(&p->g, &s[i], 1, (i & 1) ? odd : even);
    p->gv = xcalloc(count, sizeof(lpv_gv_point));
    lpv_oracle_gv_merge(&p->g, even, p->gv);
    lpv_oracle_gv_merge(&p->g, odd, p->gv);
    free(even);
    free(odd);
    for (size_t i = 0; i < count; i++)
        for (int d = 0; d < LPV_DIR_COUNT; d++)
            assert_true(isfinite(p->gv[i].blocking[d / 4][d % 4]));
}

static void pipeline_run(pipeline *p, const lpv_grid *g, const lpv_vpl *v, size_t nv, const lpv_surfel *s, size_t ns,
                         int iterations)
{
    memset(p, 0, sizeof *p);
    p->g = *g;
    size_t cells = lpv_grid_cell_count(g);
    p->injected = xcalloc(cells, sizeof(lpv_cell));
    p->acc = xcalloc(cells, sizeof(lpv_cell));
    p->vpls_injected = lpv_oracle_inject_vpls(g, v, nv, p->injected);
    assert_cells_sane(g, p->injected, "injected");
    build_gv(p, s, ns);
    p->t = xcalloc(cells * LPV_DIR_COUNT, sizeof(float));
    lpv_oracle_transmittance(g, p->gv, p->t);
    for (size_t i = 0; i < cells * LPV_DIR_COUNT; i++)
        assert_true(p->t[i] >= 0.0f && p->t[i] <= 1.0f);
    assert_int_equal(lpv_oracle_propagate(g, p->injected, p->t, iterations, p->acc), 0);
    assert_cells_sane(g, p->acc, "accumulated");
}

static void pipeline_free(pipeline *p)
{
    free(p->injected);
    free(p->acc);
    free(p->gv);
    free(p->t);
}

static void irradiance(const pipeline *p, float x, float y, float z, float nx, float ny, float nz, float rgb[3])
{
    const float pos[3] = {x, y, z}, n[3] = {nx, ny, nz};
    lpv_oracle_irradiance(&p->g, p->acc, pos, n, rgb);
    for (int c = 0; c < 3; c++)
        if (!(isfinite(rgb[c]) && rgb[c] >= 0.0f))
            fail_msg("irradiance at (%g, %g, %g) channel %d = %g", (double)x, (double)y, (double)z, c,
                     (double)rgb[c]);
}

/* Steps from the injected grid, first step unoccluded: every step's output is
 * finite with c0 >= 0 and its flux does not exceed the previous step's. */
static void check_steps(const lpv_grid *g, const lpv_cell *injected, const float *t, int steps)
{
    size_t n = lpv_grid_cell_count(g);
    lpv_cell *cur = xcalloc(n, sizeof *cur), *next = xcalloc(n, sizeof *next);
    memcpy(cur, injected, n * sizeof *cur);
    double prev[3];
    lpv_oracle_total_flux(g, cur, prev);
    for (int i = 0; i < steps; i++) {
        lpv_oracle_propagate_step(g, cur, i == 0 ? NULL : t, next);
        assert_cells_sane(g, next, "step");
        double e[3];
        lpv_oracle_total_flux(g, next, e);
        for (int c = 0; c < 3; c++) {
            if (!(e[c] <= prev[c] * (1.0 + ENERGY_RTOL)))
                fail_msg("step %d channel %d: flux grew from %.10g to %.10g", i, c, prev[c], e[c]);
            prev[c] = e[c];
        }
        lpv_cell *tmp = cur;
        cur = next;
        next = tmp;
    }
    free(cur);
    free(next);
}

/* ---- degenerate input ----------------------------------------------------- */

static void test_degenerate_normals_dropped(void **state)
{
    (void)state;
    lpv_grid g = unit_grid(8, 8, 8);
    const float nan = NAN, inf = INFINITY;
    lpv_vpl v[] = {
        vpl(4, 4, 4, 0, 0, 0, 1, 1, 1),    vpl(4, 4, 4, nan, 0, 1, 1, 1, 1),  vpl(4, 4, 4, 0, nan, 0, 1, 1, 1),
        vpl(4, 4, 4, inf, 0, 0, 1, 1, 1),  vpl(4, 4, 4, 1e-9f, 0, 0, 1, 1, 1),
        vpl(4, 4, 4, 0, 0, 3.0f, 1, 2, 3), /* valid, not unit length */
    };
    lpv_surfel s[] = {
        surfel(4, 4, 4, 1, 0, 0, 0),   surfel(4, 4, 4, 1, nan, 0, 0),    surfel(4, 4, 4, 1, 0, -inf, 0),
        surfel(4, 4, 4, 1, 0, 0, 1e-12f), surfel(4, 4, 4, 1, 0, 0, -2.0f), /* valid */
    };
    pipeline p;
    pipeline_run(&p, &g, v, sizeof v / sizeof v[0], s, sizeof s / sizeof s[0], 8);
    assert_int_equal(p.vpls_injected, 1);
    assert_int_equal(p.surfels_injected, 1);
    /* The valid VPL was normalised: its cell holds lobe(+z) * flux / pi. */
    const lpv_cell *c = &p.injected[lpv_grid_index(&g, 4, 4, 4)];
    assert_true(fabsf(c->b[0] - LPV_SH_LOBE0 * 3.0f / LPV_PI) < 1e-6f);
    assert_true(fabsf(c->b[2] - LPV_SH_LOBE1 * 3.0f / LPV_PI) < 1e-6f);
    float rgb[3];
    irradiance(&p, 4.5f, 4.5f, 6.0f, 0, 0, -1, rgb);
    assert_true(rgb[2] > 0.0f);
    irradiance(&p, 4.5f, 4.5f, 6.0f, 0, 0, 0, rgb); /* degenerate query normal */
    assert_true(rgb[0] == 0.0f && rgb[1] == 0.0f && rgb[2] == 0.0f);
    irradiance(&p, 4.5f, 4.5f, 6.0f, nan, 0, 1, rgb);
    assert_true(rgb[0] == 0.0f && rgb[1] == 0.0f && rgb[2] == 0.0f);
    pipeline_free(&p);

    /* A finite normal whose float length overflows: injected or dropped
     * (the shaders drop it), never NaN. */
    lpv_cell *cells = xcalloc(lpv_grid_cell_count(&g), sizeof(lpv_cell));
    lpv_vpl huge = vpl(4, 4, 4, 1e30f, 1e30f, 0, 1, 1, 1);
    assert_true(lpv_oracle_inject_vpls(&g, &huge, 1, cells) <= 1);
    assert_cells_sane(&g, cells, "huge normal");
    free(cells);
}

static void test_degenerate_positions_and_flux_dropped(void **state)
{
    (void)state;
    lpv_grid g = unit_grid(8, 8, 8);
    const float nan = NAN, inf = INFINITY;
    lpv_vpl v[] = {
        vpl(nan, 4, 4, 0, 0, 1, 1, 1, 1), vpl(4, inf, 4, 0, 0, 1, 1, 1, 1),  vpl(4, 4, -inf, 0, 0, 1, 1, 1, 1),
        vpl(4, 4, 4, 0, 0, 1, nan, 1, 1), vpl(4, 4, 4, 0, 0, 1, 1, inf, 1),  vpl(4, 4, 4, 0, 0, 1, 1, 1, -inf),
        vpl(1e30f, 4, 4, 0, 0, 1, 1, 1, 1), vpl(-1e30f, 4, 4, 0, 0, 1, 1, 1, 1), /* finite, far outside */
        vpl(2, 2, 2, 1, 0, 0, 5, 5, 5),   /* valid */
    };
    lpv_vpl skipped = vpl(3, 3, 3, 0, 1, 0, 1, 1, 1);
    skipped.position[3] = 0.0f; /* w = 0: skip */
    lpv_vpl all[sizeof v / sizeof v[0] + 1];
    memcpy(all, v, sizeof v);
    all[sizeof v / sizeof v[0]] = skipped;
    lpv_surfel s[] = {
        surfel(nan, 4, 4, 1, 0, 0, 1), surfel(4, 4, inf, 1, 0, 0, 1),  surfel(4, 4, 4, nan, 0, 0, 1),
        surfel(4, 4, 4, inf, 0, 0, 1), surfel(4, 4, 4, -1, 0, 0, 1),   surfel(4, 4, 4, 0, 0, 0, 1),
        surfel(1e30f, 4, 4, 1, 0, 0, 1), surfel(4, 4, 4, 0.5f, 0, 1, 0), /* valid */
    };
    pipeline p;
    pipeline_run(&p, &g, all, sizeof all / sizeof all[0], s, sizeof s / sizeof s[0], 16);
    assert_int_equal(p.vpls_injected, 1);
    assert_int_equal(p.surfels_injected, 1);
    float rgb[3];
    irradiance(&p, 3.5f, 2.5f, 2.5f, -1, 0, 0, rgb);
    assert_true(rgb[0] > 0.0f);
    pipeline_free(&p);
}

/* ---- exact positions ------------------------------------------------------ */

static void assert_only_cell(const lpv_grid *g, const lpv_cell *cells, int x, int y, int z)
{
    size_t n = lpv_grid_cell_count(g), want = lpv_grid_index(g, x, y, z);
    for (size_t i = 0; i < n; i++) {
        int lit = cells[i].r[0] != 0.0f;
        if (lit != (i == want))
            fail_msg("cell %zu lit = %d, expected only (%d, %d, %d)", i, lit, x, y, z);
    }
}

/* Injects one VPL and checks it lands in cell (x, y, z). */
static void check_lands(const lpv_grid *g, lpv_vpl v, int x, int y, int z)
{
    lpv_cell *cells = xcalloc(lpv_grid_cell_count(g), sizeof(lpv_cell));
    assert_int_equal(lpv_oracle_inject_vpls(g, &v, 1, cells), 1);
    assert_only_cell(g, cells, x, y, z);
    double flux[3];
    lpv_oracle_total_flux(g, cells, flux);
    assert_true(fabs(flux[0] - v.flux[0]) <= 1e-6 * v.flux[0]);
    free(cells);
}

static void test_vpl_on_cell_corner_and_face(void **state)
{
    (void)state;
    lpv_grid g = unit_grid(8, 8, 8);
    /* Shifted position exactly on a cell corner: floor picks the upper cell. */
    check_lands(&g, vpl(3, 4, 4.5f, 0, 0, 1, 2, 0, 0), 3, 4, 5);
    /* Raw position on a corner, shifted along an axis or obliquely. */
    check_lands(&g, vpl(3, 4, 5, 0, 0, 1, 2, 0, 0), 3, 4, 5);
    check_lands(&g, vpl(3, 4, 5, 0, 0, -1, 2, 0, 0), 3, 4, 4);
    check_lands(&g, vpl(2, 2, 2, 1, 1, 1, 2, 0, 0), 2, 2, 2);
    check_lands(&g, vpl(2, 2, 2, -1, -1, -1, 2, 0, 0), 1, 1, 1);
    /* Half a cell would put these exactly on a face (x = 6): the tie goes to
     * the cell in front of the surface whichever way it faces
     * (LPV_TIE_CELLS), not to the upper cell by floor's rounding. */
    check_lands(&g, vpl(5.5f, 2.5f, 2.5f, 1, 0, 0, 2, 0, 0), 6, 2, 2);
    check_lands(&g, vpl(6.5f, 2.5f, 2.5f, -1, 0, 0, 2, 0, 0), 5, 2, 2);
    /* ... and on an edge. */
    check_lands(&g, vpl(5.5f, 2, 2.5f, 1, 0, 0, 2, 0, 0), 6, 2, 2);

    /* A surfel exactly halfway between two GV points (x = 2.5) goes to the one
     * in front of it, whichever way it faces. */
    for (int side = 0; side < 2; ++side) {
        vec4 *tie = xcalloc(lpv_grid_gv_count(&g), sizeof(vec4));
        lpv_surfel t = surfel(2.5f, 2.2f, 2.2f, 1, side ? -1.0f : 1.0f, 0, 0);
        assert_int_equal(lpv_oracle_inject_surfels(&g, &t, 1, tie), 1);
        assert_true(tie[lpv_grid_gv_index(&g, side ? 2 : 3, 2, 2)][0] > 0.0f);
        free(tie);
    }

    /* Through the pipeline, lights on corners and faces give finite light. */
    lpv_vpl v[] = {vpl(3, 4, 5, 0, 0, 1, 1, 1, 1), vpl(6, 2.5f, 2.5f, 1, 0, 0, 1, 1, 1),
                   vpl(4, 4, 4, 1, 1, 1, 1, 1, 1)};
    lpv_surfel s[] = {surfel(3, 4, 5, 1, 0, 0, 1), surfel(6, 2.5f, 2.5f, 1, 1, 0, 0),
                      surfel(4.5f, 4.5f, 4.5f, 1, 0, 1, 0)}; /* exactly between GV points */
    pipeline p;
    pipeline_run(&p, &g, v, 3, s, 3, 12);
    assert_int_equal(p.vpls_injected, 3);
    assert_int_equal(p.surfels_injected, 3);
    float rgb[3];
    irradiance(&p, 3, 4, 5, 0, 0, 1, rgb);
    irradiance(&p, 6, 2.5f, 2.5f, -1, 0, 0, rgb);
    pipeline_free(&p);
}

/* VPLs whose shifted position is on the grid's lower corner (inside, cell 0)
 * or its upper faces (outside: cells span [i, i+1)), and surfels on the GV's
 * first and last points. Out-of-range indexing would show under ASan. */
static void test_grid_boundary(void **state)
{
    (void)state;
    lpv_grid g = unit_grid(8, 8, 8);
    lpv_cell *cells = xcalloc(lpv_grid_cell_count(&g), sizeof(lpv_cell));
    lpv_vpl on_min = vpl(0, 0, -0.5f, 0, 0, 1, 1, 1, 1);    /* shifted to (0, 0, 0) */
    lpv_vpl on_max = vpl(8, 8, 7.5f, 0, 0, 1, 1, 1, 1);     /* shifted to (8, 8, 8) */
    lpv_vpl max_face = vpl(3, 3, 7.5f, 0, 0, 1, 1, 1, 1);   /* shifted to z = 8 */
    lpv_vpl max_in = vpl(8, 8, 8, -1, -1, -1, 1, 1, 1);     /* corner, pointing in */
    lpv_vpl min_out = vpl(0, 0, 0, -1, 0, 0, 1, 1, 1);      /* corner, pointing out */
    lpv_vpl min_in = vpl(0, 0, 0, 1, 1, 1, 1, 1, 1);        /* corner, pointing in */
    assert_int_equal(lpv_oracle_inject_vpls(&g, &on_min, 1, cells), 1);
    assert_true(cells[lpv_grid_index(&g, 0, 0, 0)].r[0] > 0.0f);
    assert_int_equal(lpv_oracle_inject_vpls(&g, &on_max, 1, cells), 0);
    assert_int_equal(lpv_oracle_inject_vpls(&g, &max_face, 1, cells), 0);
    assert_int_equal(lpv_oracle_inject_vpls(&g, &max_in, 1, cells), 1);
    assert_true(cells[lpv_grid_index(&g, 7, 7, 7)].r[0] > 0.0f);
    assert_int_equal(lpv_oracle_inject_vpls(&g, &min_out, 1, cells), 0);
    assert_int_equal(lpv_oracle_inject_vpls(&g, &min_in, 1, cells), 1);

    /* GV points run 0..dims: round to nearest, drop beyond half a spacing. */
    vec4 *gv = xcalloc(lpv_grid_gv_count(&g), sizeof(vec4));
    lpv_surfel s[] = {surfel(0, 0, 0, 1, 0, 0, 1),       surfel(8, 8, 8, 1, 0, 0, 1),
                      surfel(8.49f, 8, 8, 1, 0, 0, 1),   surfel(-0.49f, 0, 0, 1, 0, 0, 1),
                      surfel(8.51f, 8, 8, 1, 0, 0, 1),   surfel(-0.51f, 0, 0, 1, 0, 0, 1)};
    assert_int_equal(lpv_oracle_inject_surfels(&g, s, 6, gv), 4);
    assert_true(gv[lpv_grid_gv_index(&g, 8, 8, 8)][0] > 0.0f);
    assert_true(gv[lpv_grid_gv_index(&g, 0, 0, 0)][0] > 0.0f);
    free(gv);
    free(cells);

    /* A grid with an awkward origin and cell size: VPLs at origin and at
     * origin + dims * cell with random normals land inside or are dropped. */
    int dims[3] = {13, 7, 5};
    float lo[3] = {-3.7f, 0.1f, 2.3f}, hi[3] = {12.1f, 4.4f, 5.9f};
    lpv_grid h;
    assert_int_equal(lpv_grid_place(dims, lo, hi, &h), 0);
    lpv_vpl v[200];
    for (int i = 0; i < 200; i++) {
        float corner[3];
        for (int a = 0; a < 3; a++)
            corner[a] = h.origin[a] + ((i >> a) & 1 ? (float)h.dims[a] * h.cell_size : 0.0f);
        v[i] = vpl(corner[0], corner[1], corner[2], (float)rnd(-1, 1), (float)rnd(-1, 1), (float)rnd(-1, 1), 1, 1, 1);
    }
    lpv_surfel hs[8];
    for (int i = 0; i < 8; i++)
        hs[i] = surfel(v[i].position[0], v[i].position[1], v[i].position[2], 1, 0, 1, 0);
    pipeline p;
    pipeline_run(&p, &h, v, 200, hs, 8, 20);
    assert_true(p.vpls_injected > 0 && p.vpls_injected < 200);
    assert_int_equal(p.surfels_injected, 8); /* GV points 0 and dims exist */
    float rgb[3];
    for (int i = 0; i < 8; i++)
        irradiance(&p, v[i].position[0], v[i].position[1], v[i].position[2], 0, 1, 0, rgb);
    pipeline_free(&p);
}

/* ---- dynamic range -------------------------------------------------------- */

/* Irradiance at the query point above the dim light (facing it) for a scene
 * of the given VPLs after `iterations` steps. */
static float dim_side_irradiance(const lpv_vpl *v, size_t nv, int iterations)
{
    lpv_grid g = unit_grid(40, 8, 8);
    pipeline p;
    pipeline_run(&p, &g, v, nv, NULL, 0, iterations);
    float rgb[3];
    irradiance(&p, 15.5f, 5.5f, 4.0f, 0, -1, 0, rgb);
    pipeline_free(&p);
    return rgb[0];
}

/* A light 10^6 times brighter than another, 12 cells away, in one grid must
 * neither erase nor distort the dim one.
 * (a) After 8 steps the bright light's light cannot have reached any cell
 *     that feeds the query (it moves one cell per step), so the dim side must
 *     equal the dim-only run exactly: no global normalisation or shared
 *     scale couples the two.
 * (b) After 64 steps the bright light dominates there (~10^3 times the dim
 *     light's irradiance), yet (both - bright only) must still recover the
 *     dim light's own contribution: the only coupling is the flux limiter's
 *     non-linearity (measured < 1 %; allowed 10 %), and float precision
 *     must hold across the range. */
static void test_dynamic_range(void **state)
{
    (void)state;
    lpv_vpl bright = vpl(2.5f, 4.0f, 4.0f, 1, 0, 0, 1e6f, 1e6f, 1e6f); /* cell (3, 4, 4) */
    lpv_vpl dim = vpl(15.5f, 3.5f, 4.0f, 0, 1, 0, 1, 1, 1);         /* cell (15, 4, 4) */
    lpv_vpl both[2] = {bright, dim};

    float d8 = dim_side_irradiance(&dim, 1, 8);
    float c8 = dim_side_irradiance(both, 2, 8);
    float b8 = dim_side_irradiance(&bright, 1, 8);
    assert_true(d8 > 0.0f && b8 == 0.0f);
    assert_true(c8 == d8);

    float d64 = dim_side_irradiance(&dim, 1, 64);
    float c64 = dim_side_irradiance(both, 2, 64);
    float b64 = dim_side_irradiance(&bright, 1, 64);
    print_message("dynamic range, 64 steps: dim %g, bright %g, both %g, both - bright %g\n", (double)d64, (double)b64,
                  (double)c64, (double)(c64 - b64));
    assert_true(d64 > 0.0f);
    assert_true(b64 > 100.0f * d64); /* the bright light does dominate here */
    double recovered = (double)c64 - (double)b64;
    assert_true(recovered >= 0.9 * d64 && recovered <= 1.1 * d64);
}

/* ---- long runs and small grids -------------------------------------------- */

/* A room-like scene: VPLs on a floor, a surfel box. */
static void scene(const lpv_grid *g, lpv_vpl *v, size_t nv, lpv_surfel *s, size_t ns)
{
    for (size_t i = 0; i < nv; i++)
        v[i] = vpl((float)rnd(0, g->dims[0]), (float)rnd(0, g->dims[1]), (float)rnd(0, 0.5),
                   (float)rnd(-0.3, 0.3), (float)rnd(-0.3, 0.3), 1, (float)rnd(0, 10), (float)rnd(0, 5), 1);
    for (size_t i = 0; i < ns; i++) {
        int side = (int)(i % 6), axis = side / 2;
        float p[3], n[3] = {0, 0, 0};
        for (int a = 0; a < 3; a++)
            p[a] = (float)rnd(0, g->dims[a]);
        p[axis] = (side & 1) ? (float)g->dims[axis] * 0.75f : (float)g->dims[axis] * 0.25f;
        n[axis] = (side & 1) ? 1.0f : -1.0f;
        s[i] = surfel(p[0], p[1], p[2], (float)rnd(0.1, 2.0), n[0], n[1], n[2]);
    }
}

static void test_1000_steps(void **state)
{
    (void)state;
    lpv_grid g = unit_grid(12, 12, 12);
    lpv_vpl v[400];
    lpv_surfel s[2000];
    scene(&g, v, 400, s, 2000);
    pipeline p;
    pipeline_run(&p, &g, v, 400, s, 2000, 1000);
    check_steps(&g, p.injected, p.t, 1000);
    float rgb[3];
    for (int i = 0; i < 50; i++)
        irradiance(&p, (float)rnd(-1, 13), (float)rnd(-1, 13), (float)rnd(-1, 13), (float)rnd(-1, 1),
                   (float)rnd(-1, 1), (float)rnd(-1, 1), rgb);
    pipeline_free(&p);
}

static void test_one_cell_grid(void **state)
{
    (void)state;
    lpv_grid g = unit_grid(1, 1, 1);
    lpv_vpl v[] = {vpl(0.5f, 0.5f, 0.2f, 0, 0, 1, 1, 2, 3), vpl(0.1f, 0.9f, 0.5f, 1, 0, 0, 1, 1, 1),
                   vpl(0.5f, 0.5f, 0.9f, 0, 0, 1, 1, 1, 1)}; /* shifted out */
    lpv_surfel s[] = {surfel(0.5f, 0.5f, 0.5f, 1, 0, 0, 1), surfel(1, 1, 1, 1, 1, 0, 0)};
    pipeline p;
    pipeline_run(&p, &g, v, 3, s, 2, 10);
    assert_int_equal(p.vpls_injected, 2);
    assert_int_equal(p.surfels_injected, 2);
    /* Everything leaves through the boundary in the first step. */
    for (int k = 0; k < 4; k++)
        assert_true(p.acc[0].r[k] == p.injected[0].r[k] && p.acc[0].g[k] == p.injected[0].g[k] &&
                    p.acc[0].b[k] == p.injected[0].b[k]);
    check_steps(&g, p.injected, p.t, 20);
    float rgb[3];
    irradiance(&p, 0.5f, 0.5f, 0.5f, 0, 0, -1, rgb);
    assert_true(rgb[1] > 0.0f);
    irradiance(&p, -5, 7, 1e9f, 0, 0, -1, rgb);
    pipeline_free(&p);
}

static void test_flat_grid(void **state)
{
    (void)state;
    lpv_grid g = unit_grid(1, 1, 64);
    lpv_vpl v[64];
    lpv_surfel s[64];
    for (int i = 0; i < 64; i++) {
        v[i] = vpl((float)rnd(0, 1), (float)rnd(0, 1), (float)rnd(-1, 65), (float)rnd(-1, 1), (float)rnd(-1, 1),
                   (float)rnd(-1, 1), 1, 1, 1);
        s[i] = surfel(0.5f, 0.5f, (float)i, 0.5f, 0, 0, i & 1 ? 1.0f : -1.0f);
    }
    pipeline p;
    pipeline_run(&p, &g, v, 64, s, 64, 200);
    assert_true(p.vpls_injected > 0);
    check_steps(&g, p.injected, p.t, 300);
    check_steps(&g, p.injected, NULL, 300);
    float rgb[3];
    for (int i = -2; i < 67; i++)
        irradiance(&p, 0.3f, 0.7f, (float)i + 0.25f, 0, 0, 1, rgb);
    pipeline_free(&p);
}

/* ---- large values ---------------------------------------------------------- */

/* Every cell a random lobe of the given magnitude (strongly directional, so
 * the limiter works), 200 steps: no Inf or NaN, flux never grows. */
static void check_magnitude(float magnitude)
{
    lpv_grid g = unit_grid(10, 10, 10);
    size_t n = lpv_grid_cell_count(&g);
    lpv_cell *cells = xcalloc(n, sizeof(lpv_cell)), *acc = xcalloc(n, sizeof(lpv_cell));
    for (size_t i = 0; i < n; i++) {
        float nrm[3] = {(float)rnd(-1, 1), (float)rnd(-1, 1), (float)rnd(-1, 1)};
        float len = sqrtf(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
        for (int a = 0; a < 3; a++)
            nrm[a] /= len;
        float lobe[4];
        lpv_sh_cosine_lobe(nrm, lobe);
        for (int k = 0; k < 4; k++) {
            cells[i].r[k] = lobe[k] * magnitude;
            cells[i].g[k] = lobe[k] * magnitude * (float)rnd(0, 1);
            cells[i].b[k] = k == 0 ? magnitude : 0.0f; /* isotropic */
        }
    }
    lpv_gv_point *gv = xcalloc(lpv_grid_gv_count(&g), sizeof(lpv_gv_point));
    float *t = xcalloc(n * 6, sizeof(float));
    for (size_t i = 0; i < lpv_grid_gv_count(&g); i++) {
        float b = (float)rnd(0, 2) * LPV_SH_C0; /* a random isotropic partial blocker */
        for (int d = 0; d < LPV_DIR_COUNT; d++)
            gv[i].blocking[d / 4][d % 4] = b;
    }
    lpv_oracle_transmittance(&g, gv, t);
    check_steps(&g, cells, t, 200);
    check_steps(&g, cells, NULL, 200);
    assert_int_equal(lpv_oracle_propagate(&g, cells, t, 100, acc), 0);
    assert_cells_sane(&g, acc, "accumulated");
    const float q[3] = {5.2f, 4.9f, 5.5f}, up[3] = {0, 1, 0};
    float rgb[3];
    lpv_oracle_irradiance(&g, acc, q, up, rgb);
    for (int c = 0; c < 3; c++)
        assert_true(isfinite(rgb[c]));
    free(cells);
    free(acc);
    free(gv);
    free(t);
}

static void test_large_values(void **state)
{
    (void)state;
    check_magnitude(LPV_FP16_MAX);
    check_magnitude(1e30f);
    /* Through injection: VPL flux of 1e30 W. */
    lpv_grid g = unit_grid(6, 6, 6);
    lpv_vpl v[] = {vpl(2, 2, 2, 0, 0, 1, 1e30f, 65504.0f, 1e-30f), vpl(3, 3, 3, 1, 0, 0, 1e30f, 1e30f, 1e30f)};
    pipeline p;
    pipeline_run(&p, &g, v, 2, NULL, 0, 50);
    check_steps(&g, p.injected, NULL, 100);
    float rgb[3];
    irradiance(&p, 2.5f, 2.5f, 4.5f, 0, 0, -1, rgb);
    assert_true(rgb[0] > 1e20f);
    pipeline_free(&p);
}

/* ---- queries outside -------------------------------------------------------- */

static void test_irradiance_outside_grid(void **state)
{
    (void)state;
    lpv_grid g = unit_grid(6, 5, 4);
    lpv_vpl v[50];
    for (int i = 0; i < 50; i++)
        v[i] = vpl((float)rnd(0, 6), (float)rnd(0, 5), (float)rnd(0, 4), (float)rnd(-1, 1), (float)rnd(-1, 1),
                   (float)rnd(-1, 1), 1, 2, 3);
    pipeline p;
    pipeline_run(&p, &g, v, 50, NULL, 0, 6);
    const float n[3] = {0.3f, -0.5f, 0.8f};
    /* Outside along each axis the lookup takes the value at the outermost
     * cell centre (clamp to edge). The lookup samples half a cell in front
     * of the surface (q = p + n/2), so the reference points sit at
     * centre - n/2 for the clamped axis. */
    const float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const float off[3] = {0.5f * n[0] / len, 0.5f * n[1] / len, 0.5f * n[2] / len};
    const float far[] = {-1e6f, -3.0f, -0.2f, 100.0f, 1e30f, -INFINITY, INFINITY};
    float edge[3], got[3];
    for (size_t i = 0; i < sizeof far / sizeof far[0]; i++) {
        float x = far[i], cx = (far[i] < 0 ? 0.5f : 5.5f) - off[0];
        irradiance(&p, x, 2.2f, 1.7f, n[0], n[1], n[2], got);
        irradiance(&p, cx, 2.2f, 1.7f, n[0], n[1], n[2], edge);
        for (int c = 0; c < 3; c++)
            assert_true(got[c] == edge[c]);
        float cz = (far[i] < 0 ? 0.5f : 3.5f) - off[2];
        irradiance(&p, 3.3f, 1.1f, x, n[0], n[1], n[2], got);
        irradiance(&p, 3.3f, 1.1f, cz, n[0], n[1], n[2], edge);
        for (int c = 0; c < 3; c++)
            assert_true(got[c] == edge[c]);
    }
    /* All three axes outside: the corner cell itself. */
    irradiance(&p, 50, 50, 50, n[0], n[1], n[2], got);
    float corner[3];
    irradiance(&p, 5.5f - off[0], 4.5f - off[1], 3.5f - off[2], n[0], n[1], n[2], corner);
    for (int c = 0; c < 3; c++)
        assert_true(got[c] == corner[c]);
    /* A NaN position gives no light rather than NaN. */
    irradiance(&p, NAN, 1, 1, 0, 0, 1, got);
    assert_true(got[0] == 0.0f && got[1] == 0.0f && got[2] == 0.0f);
    pipeline_free(&p);
}

/* ---- placement and settings on hostile input --------------------------------- */

static void test_grid_place_rejects_and_degenerates(void **state)
{
    (void)state;
    lpv_grid g;
    float lo[3] = {0, 0, 0}, hi[3] = {1, 2, 3};
    int bad_dims[][3] = {{0, 4, 4}, {4, -1, 4}, {4, 4, LPV_MAX_GRID_DIM + 1}};
    for (int i = 0; i < 3; i++)
        assert_int_equal(lpv_grid_place(bad_dims[i], lo, hi, &g), -1);
    int dims[3] = {4, 4, 4};
    float nan_lo[3] = {0, NAN, 0}, inf_hi[3] = {1, 1, INFINITY};
    assert_int_equal(lpv_grid_place(dims, nan_lo, hi, &g), -1);
    assert_int_equal(lpv_grid_place(dims, lo, inf_hi, &g), -1);

    /* A point: cell size 1, centred on it. */
    float pt[3] = {2, -3, 5};
    assert_int_equal(lpv_grid_place(dims, pt, pt, &g), 0);
    assert_true(g.cell_size == 1.0f);
    assert_true(g.origin[0] == 0.0f && g.origin[1] == -5.0f && g.origin[2] == 3.0f);
    /* Extents whose difference overflows float stay usable. */
    float huge_lo[3] = {-3e38f, 0, 0}, huge_hi[3] = {3e38f, 1, 1};
    assert_int_equal(lpv_grid_place(dims, huge_lo, huge_hi, &g), 0);
    assert_true(isfinite(g.cell_size) && g.cell_size > 0.0f);
    /* Ordinary bounds: max over axes of extent / max(dims - 1, 1), here
     * max(1/4, 2/2, 3/1) = 3, centred on the bounds. */
    int d2[3] = {5, 3, 1};
    assert_int_equal(lpv_grid_place(d2, lo, hi, &g), 0);
    assert_true(g.cell_size == 3.0f);
    assert_true(g.origin[0] == -7.0f && g.origin[1] == -3.5f && g.origin[2] == 0.0f);
}

static void test_settings_ranges(void **state)
{
    (void)state;
    char err[256];
    lpv_settings s = {0};
    lpv_settings_resolve(&s);
    assert_int_equal(lpv_settings_validate(&s, err, sizeof err), 0);
    lpv_settings balanced;
    assert_int_equal(lpv_preset_settings(LPV_PRESET_BALANCED, &balanced), 0);
    assert_int_equal(s.grid_dims[0], balanced.grid_dims[0]);
    assert_int_equal(s.lpv.iterations, balanced.lpv.iterations);
    assert_int_equal(s.lpv.occlusion, LPV_SWITCH_ON);
    assert_true(s.indirect_gain == 1.0f);

    lpv_settings bad;
    bad = s;
    bad.indirect_gain = NAN;
    assert_int_equal(lpv_settings_validate(&bad, err, sizeof err), -1);
    assert_non_null(strstr(err, "indirect_gain"));
    bad = s;
    bad.grid_dims[2] = LPV_MAX_GRID_DIM + 1;
    assert_int_equal(lpv_settings_validate(&bad, err, sizeof err), -1);
    assert_non_null(strstr(err, "grid_dims[2]"));
    assert_non_null(strstr(err, "1..256"));
    bad = s;
    bad.lpv.iterations = -1;
    assert_int_equal(lpv_settings_validate(&bad, err, sizeof err), -1);
    assert_non_null(strstr(err, "iterations"));
    bad.lpv.iterations = 0; /* injection only: valid when set after resolve */
    assert_int_equal(lpv_settings_validate(&bad, err, sizeof err), 0);
    bad = s;
    bad.rsm_size = 8;
    assert_int_equal(lpv_settings_validate(&bad, NULL, 0), -1);
    bad = s;
    bad.emissive_vpls = (1 << 20) + 1;
    assert_int_equal(lpv_settings_validate(&bad, err, sizeof err), -1);
    assert_non_null(strstr(err, "emissive_vpls"));
    bad = s;
    bad.bounds_min[1] = INFINITY;
    assert_int_equal(lpv_settings_validate(&bad, err, sizeof err), -1);
    assert_non_null(strstr(err, "bounds"));
    bad = s;
    bad.bounds_min[0] = 2.0f;
    bad.bounds_max[0] = 1.0f;
    assert_int_equal(lpv_settings_validate(&bad, err, 8), -1); /* truncated message, no overflow */
    assert_true(strlen(err) < 8);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_degenerate_normals_dropped),
        cmocka_unit_test(test_degenerate_positions_and_flux_dropped),
        cmocka_unit_test(test_vpl_on_cell_corner_and_face),
        cmocka_unit_test(test_grid_boundary),
        cmocka_unit_test(test_dynamic_range),
        cmocka_unit_test(test_1000_steps),
        cmocka_unit_test(test_one_cell_grid),
        cmocka_unit_test(test_flat_grid),
        cmocka_unit_test(test_large_values),
        cmocka_unit_test(test_irradiance_outside_grid),
        cmocka_unit_test(test_grid_place_rejects_and_degenerates),
        cmocka_unit_test(test_settings_ranges),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
