/*
 * lpv_plane_reach.c - how the LPV's light above a lit floor depends on the
 * grid, in the C oracle alone (no GL, no occlusion, no walls): the question
 * behind the grid knob that makes the Cornell box worse at 32^3
 * (docs/accuracy.md, "Knobs that never make it worse").
 *
 *   lpvd-lpv-plane-reach [--paper] [--steps-per-cell K] [--max-grid N]
 *
 * A 1 m x 1 m patch of exitance 1 W/m^2 (50 x 50 VPLs facing +y) lies on the
 * floor of an open 2 m cube. For grids 8^3, 16^3, ... N^3 (default 32) the
 * VPLs are injected and propagated K x grid steps
 * (default 1 x grid, as iterations follow the grid; central transport unless
 * --paper). Printed: the irradiance on a surface facing down at the patch's
 * centre, at heights 0.1-1.9 m, over the exact one (the view factor of the
 * square), for the normal-bin lookup and the plain one. A scheme that
 * discretised the same light would print the same row for every grid.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "grid.h"
#include "oracle.h"

#define PATCH_VPLS 50
#define HEIGHTS 6

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

/* Every VPL faces +y, so the binned injection fills the +y bin alone and
 * that bin's field is also the plain (unbinned) one: one propagation serves
 * both lookups. */
static int run_grid(int n, int steps, int transport, const lpv_vpl *vpls, size_t nvpl)
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
    int rc = lpv_oracle_propagate_with(&g, inj + up, NULL, steps, transport, acc + up);
    if (rc == 0) {
        for (int lookup = 0; lookup < 2; lookup++) {
            printf("%4d %4d %-6s", n, steps, lookup == 0 ? "bins" : "plain");
            for (int k = 0; k < HEIGHTS; k++) {
                float p[3] = {1.0f, heights[k], 1.0f}, down[3] = {0.0f, -1.0f, 0.0f}, e[3];
                if (lookup == 0)
                    lpv_oracle_irradiance_binned(&g, acc, p, down, e);
                else
                    lpv_oracle_irradiance(&g, acc + up, p, down, e);
                double exact = 4.0 * corner_view_factor(0.5, 0.5, heights[k]);
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
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--paper") == 0) {
            transport = LPV_TRANSPORT_PAPER;
        } else if (strcmp(argv[i], "--steps-per-cell") == 0 && i + 1 < argc) {
            per_cell = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--max-grid") == 0 && i + 1 < argc) {
            max_grid = atoi(argv[++i]);
        } else {
            fprintf(stderr, "usage: lpvd-lpv-plane-reach [--paper] [--steps-per-cell K] [--max-grid N]\n");
            return 2;
        }
    }
    if (per_cell < 1 || per_cell > 64 || max_grid < 8 || max_grid > 128) {
        fprintf(stderr, "lpvd-lpv-plane-reach: --steps-per-cell must be 1..64 and --max-grid 8..128\n");
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
    printf("# E on a surface facing down above the patch's centre / exact; %s transport, %d step(s) a cell\n",
           transport == LPV_TRANSPORT_CENTRAL ? "central" : "paper", per_cell);
    printf("grid steps lookup");
    for (int k = 0; k < HEIGHTS; k++)
        printf("  %.2f m", heights[k]);
    printf("\n");
    for (int n = 8; n <= max_grid; n *= 2) {
        if (run_grid(n, per_cell * n, transport, vpls, sizeof vpls / sizeof vpls[0]) != 0) {
            fprintf(stderr, "lpvd-lpv-plane-reach: out of memory at grid %d\n", n);
            return 1;
        }
    }
    return 0;
}
