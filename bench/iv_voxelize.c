/*
 * iv_voxelize.c - lpvd-iv-voxelize: the imperfect volume's voxelization
 * imperfection (Mavridis & Papaioannou 3.1). For triangle sizes (longest
 * edge / voxel) and points per triangle N, the fraction of the voxels a
 * conservative voxelization marks that the point cloud misses, over random
 * triangles, without splitting and with the default split (1 voxel), and
 * the points per conservative voxel. Prints Markdown. Not a test.
 *
 *   lpvd-iv-voxelize [--triangles N] [--seed S]
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "iv_voxelize.h"

static const double SIZES[] = {0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0};
static const int POINTS[] = {1, 3, 7, 12, 19, 32};
#define NSIZES (int)(sizeof SIZES / sizeof SIZES[0])
#define NPOINTS (int)(sizeof POINTS / sizeof POINTS[0])
#define VARIANTS 2 /* no splitting, split = 1 voxel */

static uint64_t rng;

static double uniform(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) * (1.0 / 9007199254740992.0);
}

/* A random triangle with longest edge `size` voxels: corners uniform in a
 * cube (random shape and orientation; near-degenerate ones, area under 1 %
 * of size^2, are drawn again), scaled, its centroid uniform in the voxel at
 * the grid's middle. */
static void random_triangle(const lpv_grid *g, double size, float tri[3][3])
{
    for (;;) {
        double v[3][3];
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
                v[i][k] = uniform();
        double e[3][3], longest = 0.0;
        for (int i = 0; i < 3; i++) {
            for (int k = 0; k < 3; k++)
                e[i][k] = v[(i + 1) % 3][k] - v[i][k];
            longest = fmax(longest, sqrt(e[i][0] * e[i][0] + e[i][1] * e[i][1] + e[i][2] * e[i][2]));
        }
        const double n[3] = {e[0][1] * e[1][2] - e[0][2] * e[1][1], e[0][2] * e[1][0] - e[0][0] * e[1][2],
                             e[0][0] * e[1][1] - e[0][1] * e[1][0]};
        double area = 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(longest > 0.0) || area < 0.01 * longest * longest)
            continue;
        double scale = size / longest, centre[3];
        for (int k = 0; k < 3; k++)
            centre[k] = floor(g->dims[k] / 2.0) + uniform();
        double mean[3];
        for (int k = 0; k < 3; k++)
            mean[k] = (v[0][k] + v[1][k] + v[2][k]) / 3.0;
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
                tri[i][k] = (float)(g->origin[k] + (centre[k] + (v[i][k] - mean[k]) * scale) * g->cell_size);
        return;
    }
}

typedef struct cell_sum {
    double conservative, hit, points, pieces;
} cell_sum;

static void table(const char *title, const char *what, cell_sum sums[NSIZES][NPOINTS], int miss)
{
    printf("\n### %s\n\n%s\n\n| longest edge / voxel |", title, what);
    for (int j = 0; j < NPOINTS; j++)
        printf(" N = %d |", POINTS[j]);
    printf("\n|---:|");
    for (int j = 0; j < NPOINTS; j++)
        printf("---:|");
    printf("\n");
    for (int i = 0; i < NSIZES; i++) {
        printf("| %g |", SIZES[i]);
        for (int j = 0; j < NPOINTS; j++) {
            const cell_sum *c = &sums[i][j];
            if (miss)
                printf(" %.4f |", (c->conservative - c->hit) / c->conservative);
            else
                printf(" %.2f |", c->points / c->conservative);
        }
        printf("\n");
    }
}

int main(int argc, char **argv)
{
    int triangles = 2000;
    uint64_t seed = 1;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--triangles") == 0 && i + 1 < argc)
            triangles = atoi(argv[++i]);
        else if (strcmp(argv[i], "--seed") == 0 && i + 1 < argc)
            seed = strtoull(argv[++i], NULL, 10);
        else {
            fprintf(stderr, "usage: %s [--triangles N] [--seed S]\n", argv[0]);
            return 2;
        }
    }
    if (triangles < 1 || seed == 0) {
        fprintf(stderr, "lpvd-iv-voxelize: --triangles must be >= 1 and --seed non-zero\n");
        return 2;
    }
    /* room for a 16-voxel triangle around the middle voxel, in any orientation */
    const lpv_grid g = {{40, 40, 40}, {-5.0f, 0.0f, 2.5f}, 0.25f};
    static cell_sum sums[VARIANTS][NSIZES][NPOINTS];
    double tri_voxels[NSIZES] = {0};
    size_t cap = 0;
    size_t *set = NULL;
    clock_t t0 = clock();
    for (int i = 0; i < NSIZES; i++) {
        rng = seed * 0x9E3779B97F4A7C15ull + (uint64_t)i;
        if (rng == 0)
            rng = 1;
        for (int t = 0; t < triangles; t++) {
            float tri[3][3];
            random_triangle(&g, SIZES[i], tri);
            size_t count = lpv_iv_voxelize_triangle(&g, tri[0], tri[1], tri[2], NULL, 0);
            if (count > cap) {
                cap = 2 * count;
                free(set);
                set = malloc(cap * sizeof *set);
                if (!set) {
                    fprintf(stderr, "lpvd-iv-voxelize: out of memory\n");
                    return 1;
                }
            }
            lpv_iv_voxelize_triangle(&g, tri[0], tri[1], tri[2], set, count);
            tri_voxels[i] += (double)count;
            for (int v = 0; v < VARIANTS; v++)
                for (int j = 0; j < NPOINTS; j++) {
                    lpv_iv_coverage cov;
                    /* the points' key: the triangle, so every N and variant samples the same triangles */
                    if (lpv_iv_coverage_of_set(&g, set, count, tri[0], tri[1], tri[2], POINTS[j], v ? 1.0f : 0.0f,
                                               1u, (uint32_t)t * 4096u, &cov) != 0) {
                        fprintf(stderr, "lpvd-iv-voxelize: out of memory\n");
                        return 1;
                    }
                    if (cov.stray != 0) {
                        fprintf(stderr, "lpvd-iv-voxelize: %zu points outside the conservative set (a bug)\n",
                                cov.stray);
                        return 1;
                    }
                    cell_sum *c = &sums[v][i][j];
                    c->conservative += (double)cov.conservative;
                    c->hit += (double)cov.hit;
                    c->points += (double)cov.points;
                    c->pieces += (double)cov.pieces;
                }
        }
    }
    free(set);
    double seconds = (double)(clock() - t0) / CLOCKS_PER_SEC;

    printf("## Imperfect volumes: voxelization imperfection\n\n");
    printf("%d random triangles per size (seed %llu: corners uniform in a cube, scaled to the longest edge, "
           "centroid uniform in a voxel; area >= 1 %% of longest edge^2), the same triangles for every N. "
           "Conservative voxelization: triangle/box overlap by the separating axis theorem "
           "(techniques/iv/core/iv_voxelize.c). Points: Turk's formula (techniques/iv/core/iv_points.c), N per piece. "
           "Ratios of sums over the triangles.\n\n",
           triangles, (unsigned long long)seed);
    printf("Conservative voxels per triangle:");
    for (int i = 0; i < NSIZES; i++)
        printf(" %g: %.2f%s", SIZES[i], tri_voxels[i] / triangles, i + 1 < NSIZES ? "," : ".\n");
    printf("Pieces per triangle with split = 1 voxel:");
    for (int i = 0; i < NSIZES; i++)
        printf(" %g: %.2f%s", SIZES[i], sums[1][i][0].pieces / triangles, i + 1 < NSIZES ? "," : ".");
    printf(" (A longest edge of exactly 1 voxel sits on the split threshold, edge > split: the float corners "
           "put about half of those triangles over it.)\n");
    table("Miss fraction, no splitting", "missed conservative voxels / conservative voxels", sums[0], 1);
    table("Miss fraction, split = 1 voxel (the default)",
          "missed conservative voxels / conservative voxels; triangles with an edge over 1 voxel are halved "
          "across the longest edge until none is, N points per piece",
          sums[1], 1);
    table("Points per conservative voxel, no splitting", "points / conservative voxels", sums[0], 0);
    table("Points per conservative voxel, split = 1 voxel (the default)", "points / conservative voxels", sums[1],
          0);
    printf("\n(%.1f s CPU)\n", seconds);
    return 0;
}
