/*
 * lpv_plane_reach.c - how the LPV's light above a lit floor depends on the
 * grid, in the C oracle alone (no GL, no occlusion, no walls): the question
 * behind the grid knob that makes the Cornell box worse at 32^3
 * (docs/accuracy.md, "Knobs that never make it worse").
 *
 *   lpvd-lpv-plane-reach [--paper | --closure | --ordinates K] [--steps-per-cell K]
 *                        [--max-grid N] [--offset X]
 *
 * A 1 m x 1 m patch of exitance 1 W/m^2 (50 x 50 VPLs facing +y) lies on the
 * floor of an open 2 m cube. For grids 8^3, 16^3, ... N^3 (default 32) the
 * VPLs are injected and propagated K x grid steps
 * (default 1 x grid, as iterations follow the grid; central transport unless
 * --paper). Printed: the irradiance on a surface facing down X m (default 0)
 * along x from the patch's centre, at heights 0.1-1.9 m, over the exact one
 * (the view factor of the square), for the normal-bin lookup and the plain
 * one. A scheme that discretised the same light would print the same row for
 * every grid.
 *
 * --closure is a trial transport kept here as the measurement behind
 * docs/accuracy.md's fifth trial, not an engine option: a kinetic scheme on
 * the same L1 cells. Each cell's light is read back as the von Mises-Fisher
 * lobe with the cell's mean direction and mean cosine (the M1 idea of
 * radiative transfer: the sharpest plausible distribution, not the broad L1
 * one), every direction of a quadrature is moved upwind (split between the
 * faces it points through by its direction cosines), and the neighbour
 * receives what went through each face as its flux and first moment, so a
 * beam stays a beam and the scheme's spread shrinks with the cell.
 *
 * --ordinates K is another trial (docs/accuracy.md's seventh): the
 * light in flight is K directions per cell (discrete ordinates on a
 * Fibonacci sphere) instead of four SH coefficients. The injected L1 cells
 * are spread over the directions (the clamped L1 lobe), each direction moves
 * upwind at the speed of light (a share LAMBDA |w_a| through the face its
 * axis a points at, the rest stays: LAMBDA = 1/sqrt(3) keeps every share
 * positive), and every step adds its L1 moments, times LAMBDA, to the same
 * accumulated volume, so the lookups are unchanged. Light crossing light
 * stays two directions, so nothing merges and nothing spreads but the
 * scheme's own O(cell) error.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "grid.h"
#include "oracle.h"

#define PATCH_VPLS 50
#define HEIGHTS 6
#define CLOSURE_DIRS 400 /* quadrature directions (a Fibonacci sphere) */
#define CLOSURE_MAX_F 0.995 /* the mean cosine the closure reads at most */
#define ORDINATES_MAX 512
#define ORDINATES_LAMBDA 0.57735026918962576 /* 1 / sqrt(3): a step moves light LAMBDA cells */

static const float heights[HEIGHTS] = {0.1f, 0.25f, 0.5f, 1.0f, 1.5f, 1.9f};

/* The view factor from a point at height h above a corner of an a x b
 * rectangle to the rectangle, for a receiver parallel to it (the standard
 * closed form; four of them make the patch's centre). */
static double corner_view_factor(double a, double b, double h)
{
    double x = a / h, y = b / h;
    return (x / sqrt(1.0 + x * x) * atan(y / sqrt(1.0 + x * x)) + y / sqrt(1.0 + y * y) * atan(x / sqrt(1.0 + y * y))) /
           (2.0 * M_PI);
}

/* The exact irradiance X m along x from the patch's centre, at height h:
 * the patch [0.5, 1.5]^2 as signed corner rectangles around the point. */
static double signed_corner(double a, double b, double h)
{
    double s = (a < 0.0 ? -1.0 : 1.0) * (b < 0.0 ? -1.0 : 1.0);
    a = fabs(a), b = fabs(b);
    return a > 0.0 && b > 0.0 ? s * corner_view_factor(a, b, h) : 0.0;
}

static double exact_irradiance(double offset, double h)
{
    double a0 = -0.5 - offset, a1 = 0.5 - offset, b0 = -0.5, b1 = 0.5;
    return signed_corner(a1, b1, h) - signed_corner(a0, b1, h) - signed_corner(a1, b0, h) + signed_corner(a0, b0, h);
}

/* ---- The closure trial -------------------------------------------------- */

static float closure_dirs[CLOSURE_DIRS][3];

/* k directions spread evenly over the sphere (a Fibonacci lattice). */
static void fibonacci_dirs(int k, float (*out)[3])
{
    const double golden = M_PI * (3.0 - sqrt(5.0));
    for (int i = 0; i < k; i++) {
        double y = 1.0 - 2.0 * (i + 0.5) / k, r = sqrt(1.0 - y * y);
        out[i][0] = (float)(r * cos(golden * i));
        out[i][1] = (float)y;
        out[i][2] = (float)(r * sin(golden * i));
    }
}

/* What one cell's channel c (c0, y, z, x) sends through each face d (+x -x
 * +y -y +z -z): flux[d] (as a c0) and first moment mom[d] (as c_x, c_y, c_z). */
static void closure_faces(const float c[4], float flux[6], float mom[6][3])
{
    memset(flux, 0, 6 * sizeof *flux);
    memset(mom, 0, 18 * sizeof **mom);
    if (!(c[0] > 0.0f))
        return;
    /* Mean direction vector m (|m| = mean cosine f) of the distribution
     * whose SH projection is c: c0 = C0 P, c1 = C1 P m. */
    double m[3] = {c[3] * LPV_SH_C0 / (LPV_SH_C1 * c[0]), c[1] * LPV_SH_C0 / (LPV_SH_C1 * c[0]),
                   c[2] * LPV_SH_C0 / (LPV_SH_C1 * c[0])};
    double f = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]), n[3] = {0.0, 1.0, 0.0};
    if (f > 1e-9)
        n[0] = m[0] / f, n[1] = m[1] / f, n[2] = m[2] / f;
    f = fmin(f, CLOSURE_MAX_F);
    double kappa = f * (3.0 - f * f) / (1.0 - f * f); /* the vMF concentration of mean cosine f (Banerjee) */
    static double w[CLOSURE_DIRS];
    double sum = 0.0;
    for (int k = 0; k < CLOSURE_DIRS; k++) {
        const float *o = closure_dirs[k];
        w[k] = exp(kappa * (n[0] * o[0] + n[1] * o[1] + n[2] * o[2] - 1.0));
        sum += w[k];
    }
    for (int k = 0; k < CLOSURE_DIRS; k++) {
        const float *o = closure_dirs[k];
        double l1 = fabs(o[0]) + fabs(o[1]) + fabs(o[2]);
        for (int a = 0; a < 3; a++) {
            int d = 2 * a + (o[a] < 0.0f);
            double share = c[0] * w[k] / sum * fabs(o[a]) / l1;
            flux[d] += (float)share;
            for (int j = 0; j < 3; j++)
                mom[d][j] += (float)(share * o[j] * LPV_SH_C1 / LPV_SH_C0);
        }
    }
}

/* One closure step of one channel (r), copied to g and b; no occlusion. */
static void closure_step(const lpv_grid *g, const lpv_cell *in, const float *t, void *ctx, lpv_cell *out)
{
    (void)t;
    (void)ctx;
    static const int dir[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    size_t cells = lpv_grid_cell_count(g);
    memset(out, 0, cells * sizeof *out);
    for (int z = 0; z < g->dims[2]; z++) {
        for (int y = 0; y < g->dims[1]; y++) {
            for (int x = 0; x < g->dims[0]; x++) {
                float flux[6], mom[6][3];
                closure_faces(in[lpv_grid_index(g, x, y, z)].r, flux, mom);
                for (int d = 0; d < 6; d++) {
                    int q[3] = {x + dir[d][0], y + dir[d][1], z + dir[d][2]};
                    if (flux[d] <= 0.0f || q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= g->dims[0] ||
                        q[1] >= g->dims[1] || q[2] >= g->dims[2])
                        continue;
                    float *o = out[lpv_grid_index(g, q[0], q[1], q[2])].r;
                    o[0] += flux[d], o[3] += mom[d][0], o[1] += mom[d][1], o[2] += mom[d][2];
                }
            }
        }
    }
    for (size_t i = 0; i < cells; i++) {
        memcpy(out[i].g, out[i].r, sizeof out[i].r);
        memcpy(out[i].b, out[i].r, sizeof out[i].r);
    }
}

#define TRANSPORT_CLOSURE (-1)
#define TRANSPORT_ORDINATES (-2)

/* ---- The ordinates trial ------------------------------------------------ */

static float ordinate_dirs[ORDINATES_MAX][3];
static int ordinate_count;

/* acc (channel r, copied to g and b) += LAMBDA x the L1 moments of the
 * directions' light p (ordinate_count per cell). */
static void ordinates_accumulate(size_t cells, const float *p, lpv_cell *acc)
{
    for (size_t c = 0; c < cells; c++) {
        double sum = 0.0, m[3] = {0.0, 0.0, 0.0};
        for (int k = 0; k < ordinate_count; k++) {
            double x = p[c * (size_t)ordinate_count + (size_t)k];
            sum += x;
            for (int j = 0; j < 3; j++)
                m[j] += x * ordinate_dirs[k][j];
        }
        float add[4] = {(float)(ORDINATES_LAMBDA * LPV_SH_C0 * sum), (float)(ORDINATES_LAMBDA * LPV_SH_C1 * m[1]),
                        (float)(ORDINATES_LAMBDA * LPV_SH_C1 * m[2]), (float)(ORDINATES_LAMBDA * LPV_SH_C1 * m[0])};
        for (int j = 0; j < 4; j++) {
            acc[c].r[j] += add[j];
            acc[c].g[j] += add[j];
            acc[c].b[j] += add[j];
        }
    }
}

/* One upwind step of every direction: p -> q (overwritten). */
static void ordinates_step(const lpv_grid *g, const float *p, float *q)
{
    const size_t k_count = (size_t)ordinate_count;
    memset(q, 0, lpv_grid_cell_count(g) * k_count * sizeof *q);
    for (int z = 0; z < g->dims[2]; z++) {
        for (int y = 0; y < g->dims[1]; y++) {
            for (int x = 0; x < g->dims[0]; x++) {
                const size_t c = lpv_grid_index(g, x, y, z);
                for (size_t k = 0; k < k_count; k++) {
                    const float v = p[c * k_count + k], *o = ordinate_dirs[k];
                    if (v == 0.0f)
                        continue;
                    q[c * k_count + k] += v * (float)(1.0 - ORDINATES_LAMBDA * (fabs(o[0]) + fabs(o[1]) + fabs(o[2])));
                    for (int a = 0; a < 3; a++) {
                        int r[3] = {x, y, z};
                        r[a] += o[a] > 0.0f ? 1 : -1;
                        if (r[a] >= 0 && r[a] < g->dims[a]) /* what leaves the grid is gone */
                            q[lpv_grid_index(g, r[0], r[1], r[2]) * k_count + k] +=
                                v * (float)(ORDINATES_LAMBDA * fabs(o[a]));
                    }
                }
            }
        }
    }
}

/* The injected L1 cells (channel r) spread over the directions as their
 * clamped L1 lobes, moved for the steps light needs to cross `steps` cells,
 * each step's moments accumulated. */
static int ordinates_propagate(const lpv_grid *g, const lpv_cell *injected, int steps, lpv_cell *acc)
{
    const size_t cells = lpv_grid_cell_count(g), k_count = (size_t)ordinate_count;
    float *p = calloc(cells * k_count, sizeof *p), *q = calloc(cells * k_count, sizeof *q);
    if (!p || !q) {
        free(p);
        free(q);
        return -1;
    }
    for (size_t c = 0; c < cells; c++) {
        const float *s = injected[c].r;
        double w[ORDINATES_MAX], sum = 0.0;
        for (size_t k = 0; k < k_count && s[0] > 0.0f; k++) {
            const float *o = ordinate_dirs[k];
            w[k] = fmax(LPV_SH_C0 * s[0] + LPV_SH_C1 * (s[3] * o[0] + s[1] * o[1] + s[2] * o[2]), 0.0);
            sum += w[k];
        }
        for (size_t k = 0; k < k_count && sum > 0.0; k++)
            p[c * k_count + k] = (float)(s[0] / LPV_SH_C0 * w[k] / sum);
    }
    memset(acc, 0, cells * sizeof *acc);
    ordinates_accumulate(cells, p, acc);
    for (int i = 0, n = (int)ceil(steps / ORDINATES_LAMBDA); i < n; i++) {
        ordinates_step(g, p, q);
        ordinates_accumulate(cells, q, acc);
        float *tmp = p;
        p = q;
        q = tmp;
    }
    free(p);
    free(q);
    return 0;
}

/* Every VPL faces +y, so the binned injection fills the +y bin alone and
 * that bin's field is also the plain (unbinned) one: one propagation serves
 * both lookups. */
static int run_grid(int n, int steps, int transport, double offset, const lpv_vpl *vpls, size_t nvpl)
{
    lpv_grid g = {{n, n, n}, {0.0f, 0.0f, 0.0f}, 2.0f / (float)n};
    size_t cells = lpv_grid_cell_count(&g);
    lpv_cell *inj = calloc(cells * LPV_NORMAL_BINS, sizeof *inj);
    lpv_cell *acc = calloc(cells * LPV_NORMAL_BINS, sizeof *acc);
    if (!inj || !acc) {
        free(inj);
        free(acc);
        return -1;
    }
    const float plus_y[3] = {0.0f, 1.0f, 0.0f};
    const size_t up = (size_t)lpv_oracle_normal_bin(plus_y) * cells; /* the +y bin */
    lpv_oracle_inject_vpls_binned(&g, vpls, nvpl, inj);
    int rc = transport == TRANSPORT_CLOSURE
                 ? lpv_oracle_propagate_steps(&g, inj + up, NULL, steps, closure_step, NULL, acc + up)
             : transport == TRANSPORT_ORDINATES
                 ? ordinates_propagate(&g, inj + up, steps, acc + up)
                 : lpv_oracle_propagate_with(&g, inj + up, NULL, steps, transport, acc + up);
    if (rc == 0) {
        for (int lookup = 0; lookup < 2; lookup++) {
            printf("%4d %4d %-6s", n, steps, lookup == 0 ? "bins" : "plain");
            for (int k = 0; k < HEIGHTS; k++) {
                float p[3] = {1.0f + (float)offset, heights[k], 1.0f}, down[3] = {0.0f, -1.0f, 0.0f}, e[3];
                if (lookup == 0)
                    lpv_oracle_irradiance_binned(&g, acc, p, down, e);
                else
                    lpv_oracle_irradiance(&g, acc + up, p, down, e);
                double exact = exact_irradiance(offset, heights[k]);
                printf(" %7.3f", e[0] / exact);
            }
            printf("\n");
        }
    }
    free(inj);
    free(acc);
    return rc;
}

int main(int argc, char **argv)
{
    int transport = LPV_TRANSPORT_CENTRAL, per_cell = 1, max_grid = 32;
    double offset = 0.0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--paper") == 0) {
            transport = LPV_TRANSPORT_PAPER;
        } else if (strcmp(argv[i], "--closure") == 0) {
            transport = TRANSPORT_CLOSURE;
        } else if (strcmp(argv[i], "--ordinates") == 0 && i + 1 < argc) {
            transport = TRANSPORT_ORDINATES;
            ordinate_count = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--offset") == 0 && i + 1 < argc) {
            offset = atof(argv[++i]);
        } else if (strcmp(argv[i], "--steps-per-cell") == 0 && i + 1 < argc) {
            per_cell = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--max-grid") == 0 && i + 1 < argc) {
            max_grid = atoi(argv[++i]);
        } else {
            fprintf(stderr, "usage: lpvd-lpv-plane-reach [--paper | --closure | --ordinates K] [--steps-per-cell K] "
                            "[--max-grid N] [--offset X]\n");
            return 2;
        }
    }
    if (per_cell < 1 || per_cell > 64 || max_grid < 8 || max_grid > 128 || !(fabs(offset) <= 0.9) ||
        (transport == TRANSPORT_ORDINATES && (ordinate_count < 6 || ordinate_count > ORDINATES_MAX))) {
        fprintf(stderr, "lpvd-lpv-plane-reach: --steps-per-cell must be 1..64, --max-grid 8..128, --offset "
                        "-0.9..0.9 (m) and --ordinates 6..%d\n", ORDINATES_MAX);
        return 2;
    }
    static lpv_vpl vpls[PATCH_VPLS * PATCH_VPLS];
    for (int i = 0; i < PATCH_VPLS; i++) {
        for (int j = 0; j < PATCH_VPLS; j++) {
            lpv_vpl *v = &vpls[i * PATCH_VPLS + j];
            memset(v, 0, sizeof *v);
            v->position[0] = 0.5f + ((float)i + 0.5f) / PATCH_VPLS;
            v->position[1] = 0.001f;
            v->position[2] = 0.5f + ((float)j + 0.5f) / PATCH_VPLS;
            v->position[3] = 1.0f;
            v->normal[1] = 1.0f;
            for (int c = 0; c < 3; c++) /* 1 W/m^2 over the 1 m^2 patch */
                v->flux[c] = 1.0f / (PATCH_VPLS * PATCH_VPLS);
        }
    }
    fibonacci_dirs(CLOSURE_DIRS, closure_dirs);
    if (transport == TRANSPORT_ORDINATES)
        fibonacci_dirs(ordinate_count, ordinate_dirs);
    printf("# E on a surface facing down %.2f m along x from the patch's centre / exact; %s transport, %d step(s) "
           "a cell\n",
           offset,
           transport == TRANSPORT_CLOSURE        ? "closure (trial)"
           : transport == TRANSPORT_ORDINATES   ? "ordinates (trial)"
           : transport == LPV_TRANSPORT_CENTRAL ? "central"
                                                : "paper",
           per_cell);
    printf("grid steps lookup");
    for (int k = 0; k < HEIGHTS; k++)
        printf("  %.2f m", heights[k]);
    printf("\n");
    for (int n = 8; n <= max_grid; n *= 2) {
        if (run_grid(n, per_cell * n, transport, offset, vpls, sizeof vpls / sizeof vpls[0]) != 0) {
            fprintf(stderr, "lpvd-lpv-plane-reach: out of memory at grid %d\n", n);
            return 1;
        }
    }
    return 0;
}
