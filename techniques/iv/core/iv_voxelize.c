/*
 * iv_voxelize.c - conservative voxelization of a triangle and how much of
 * it the point cloud reaches (see iv_voxelize.h).
 */
#include "iv_voxelize.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "iv_points.h"
#include "oracle_iv.h"

/* ---- Triangle / box overlap (Akenine-Moller 2001) --------------------------- */

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* 1 when the axis separates the triangle (vertices v, relative to the box
 * centre) from the box: the triangle's projection lies wholly beyond the
 * box's projection radius on one side. A zero axis never separates. */
static int separates(const double v[3][3], const double axis[3], const double half[3])
{
    double p0 = dot3(v[0], axis), p1 = dot3(v[1], axis), p2 = dot3(v[2], axis);
    double lo = fmin(p0, fmin(p1, p2)), hi = fmax(p0, fmax(p1, p2));
    double r = half[0] * fabs(axis[0]) + half[1] * fabs(axis[1]) + half[2] * fabs(axis[2]);
    return lo > r || hi < -r;
}

int lpv_iv_tri_box_overlap(const double centre[3], const double half[3], const double tri[3][3])
{
    double v[3][3];
    for (int i = 0; i < 3; i++)
        for (int a = 0; a < 3; a++)
            v[i][a] = tri[i][a] - centre[a];
    /* the box's face normals: the triangle's bounding box against the box */
    for (int a = 0; a < 3; a++) {
        double lo = fmin(v[0][a], fmin(v[1][a], v[2][a])), hi = fmax(v[0][a], fmax(v[1][a], v[2][a]));
        if (lo > half[a] || hi < -half[a])
            return 0;
    }
    double e[3][3];
    for (int a = 0; a < 3; a++) {
        e[0][a] = v[1][a] - v[0][a];
        e[1][a] = v[2][a] - v[1][a];
        e[2][a] = v[0][a] - v[2][a];
    }
    /* the triangle's plane */
    const double n[3] = {e[0][1] * e[1][2] - e[0][2] * e[1][1], e[0][2] * e[1][0] - e[0][0] * e[1][2],
                         e[0][0] * e[1][1] - e[0][1] * e[1][0]};
    if (separates(v, n, half))
        return 0;
    /* edge x box axis: e x x = (0, e.z, -e.y), e x y = (-e.z, 0, e.x), e x z = (e.y, -e.x, 0) */
    for (int i = 0; i < 3; i++) {
        const double ax[3][3] = {{0.0, e[i][2], -e[i][1]}, {-e[i][2], 0.0, e[i][0]}, {e[i][1], -e[i][0], 0.0}};
        for (int j = 0; j < 3; j++)
            if (separates(v, ax[j], half))
                return 0;
    }
    return 1;
}

/* ---- Conservative voxelization ------------------------------------------------ */

static int finite3(const float p[3]) { return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]); }

size_t lpv_iv_voxelize_triangle(const lpv_grid *g, const float a[3], const float b[3], const float c[3], size_t *out,
                                size_t max)
{
    if (!finite3(a) || !finite3(b) || !finite3(c))
        return 0;
    /* in voxel units: voxel (x, y, z) is the box (x, y, z) + [0, 1]^3 */
    const float *p[3] = {a, b, c};
    double tri[3][3];
    int lo[3], hi[3];
    for (int k = 0; k < 3; k++) {
        for (int i = 0; i < 3; i++)
            tri[i][k] = ((double)p[i][k] - (double)g->origin[k]) / (double)g->cell_size;
        double mn = fmin(tri[0][k], fmin(tri[1][k], tri[2][k])) - LPV_IV_VOXELIZE_EPS;
        double mx = fmax(tri[0][k], fmax(tri[1][k], tri[2][k])) + LPV_IV_VOXELIZE_EPS;
        if (!(mx >= 0.0 && mn < (double)g->dims[k]))
            return 0;
        lo[k] = mn < 0.0 ? 0 : (int)floor(mn);
        hi[k] = mx >= (double)g->dims[k] ? g->dims[k] - 1 : (int)floor(mx);
    }
    const double half[3] = {0.5 + LPV_IV_VOXELIZE_EPS, 0.5 + LPV_IV_VOXELIZE_EPS, 0.5 + LPV_IV_VOXELIZE_EPS};
    size_t count = 0;
    for (int z = lo[2]; z <= hi[2]; z++)
        for (int y = lo[1]; y <= hi[1]; y++)
            for (int x = lo[0]; x <= hi[0]; x++) {
                const double centre[3] = {x + 0.5, y + 0.5, z + 0.5};
                if (!lpv_iv_tri_box_overlap(centre, half, tri))
                    continue;
                if (count < max)
                    out[count] = lpv_grid_index(g, x, y, z);
                count++;
            }
    return count;
}

/* ---- Coverage by the points ---------------------------------------------------- */

typedef struct coverage_walk {
    const lpv_grid *g;
    const size_t *set;
    size_t count;
    unsigned char *hit;    /* per set entry */
    const float *tri[3];
    int n;
    uint32_t seed, key;
    float *points;         /* 3 n floats */
    lpv_iv_coverage *out;
} coverage_walk;

static int compare_index(const void *x, const void *y)
{
    size_t a = *(const size_t *)x, b = *(const size_t *)y;
    return a < b ? -1 : a > b;
}

static void coverage_piece(const double bary[3][3], void *user)
{
    coverage_walk *w = user;
    float corner[3][3];
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            corner[i][k] = (float)(bary[i][0] * w->tri[0][k] + bary[i][1] * w->tri[1][k] + bary[i][2] * w->tri[2][k]);
    lpv_iv_triangle_points(corner[0], corner[1], corner[2], w->n, w->seed, w->key + (uint32_t)w->out->pieces,
                           w->points);
    w->out->pieces++;
    for (int k = 0; k < w->n; k++) {
        w->out->points++;
        int v[3];
        if (!lpv_iv_voxel_of(w->g, &w->points[3 * k], v)) {
            w->out->stray++;
            continue;
        }
        size_t index = lpv_grid_index(w->g, v[0], v[1], v[2]);
        const size_t *at = bsearch(&index, w->set, w->count, sizeof *w->set, compare_index);
        if (!at) {
            w->out->stray++;
            continue;
        }
        size_t i = (size_t)(at - w->set);
        if (!w->hit[i]) {
            w->hit[i] = 1;
            w->out->hit++;
        }
    }
}

int lpv_iv_coverage_of_set(const lpv_grid *g, const size_t *set, size_t count, const float a[3], const float b[3],
                           const float c[3], int n, float split, uint32_t seed, uint32_t key, lpv_iv_coverage *out)
{
    memset(out, 0, sizeof *out);
    out->conservative = count;
    if (n < 1)
        return -1;
    coverage_walk w = {g, set, count, calloc(count ? count : 1, 1), {a, b, c}, n, seed, key,
                       malloc(3 * (size_t)n * sizeof(float)), out};
    int rc = -1;
    if (w.hit && w.points) {
        if (split > 0.0f) {
            lpv_iv_split_triangle(a, b, c, (double)split * (double)g->cell_size, coverage_piece, &w);
        } else {
            const double whole[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
            coverage_piece(whole, &w);
        }
        rc = 0;
    } else {
        memset(out, 0, sizeof *out);
        out->conservative = count;
    }
    free(w.hit);
    free(w.points);
    return rc;
}

int lpv_iv_triangle_coverage(const lpv_grid *g, const float a[3], const float b[3], const float c[3], int n,
                             float split, uint32_t seed, uint32_t key, lpv_iv_coverage *out)
{
    memset(out, 0, sizeof *out);
    size_t count = lpv_iv_voxelize_triangle(g, a, b, c, NULL, 0);
    size_t *set = malloc((count ? count : 1) * sizeof *set);
    if (!set)
        return -1;
    lpv_iv_voxelize_triangle(g, a, b, c, set, count);
    int rc = lpv_iv_coverage_of_set(g, set, count, a, b, c, n, split, seed, key, out);
    free(set);
    return rc;
}
