/*
 * oracle_iv_create.c - volume creation of the imperfect-volumes oracle
 * (3.1, oracle_iv.h lpv_iv_create): which voxel a point falls in, and the
 * per-voxel means of the points' radiance SH, normals, albedo, cover and
 * slab. The only part that reads the point cloud.
 */
#include <stdlib.h>
#include <string.h>

#include "oracle_iv_internal.h"
#include "sh.h"

/* The range test happens on the float before the int conversion, so no
 * position (huge, Inf, NaN) can make an out-of-range conversion. */
int lpv_iv_voxel_of(const lpv_grid *g, const float p[3], int cell[3])
{
    for (int a = 0; a < 3; a++) {
        float fc = floorf((p[a] - g->origin[a]) / g->cell_size);
        if (!(fc >= 0.0f && fc < (float)g->dims[a]))
            return 0;
        cell[a] = (int)fc;
    }
    return 1;
}

/* p in voxels from the grid's corner, moved LPV_IV_BEHIND against unit n
 * (iv_volume.glsl's iv_coords_of). */
static void surface_coords(const lpv_grid *g, const float p[3], const float n[3], float u[3])
{
    float nh[3] = {0.0f, 0.0f, 0.0f};
    if (!lpv_unit_direction(n, nh))
        nh[0] = nh[1] = nh[2] = 0.0f;
    for (int a = 0; a < 3; a++)
        u[a] = (p[a] - g->origin[a]) / g->cell_size - LPV_IV_BEHIND * nh[a];
}

int lpv_iv_surface_voxel_of(const lpv_grid *g, const float p[3], const float n[3], int cell[3])
{
    float u[3];
    surface_coords(g, p, n, u);
    for (int a = 0; a < 3; a++) {
        float fc = floorf(u[a]);
        if (!(fc >= 0.0f && fc < (float)g->dims[a]))
            return 0;
        cell[a] = (int)fc;
    }
    return 1;
}

/* ---- Creation (3.1) -------------------------------------------------------- */

/* Accumulators per voxel: 12 SH, 3 normal, 3 albedo, 1 count, 3 folded normal. */
/* per voxel: 12 SH, normal (3), albedo (3), count, fold (3), area, signed area,
 * greatest place (3), 1 - least place (3) */
#define ACC 30

/* LPV_IV_FOLD (lpv_shared.h): n times the sign of its largest component,
 * ties x before y before z, as iv_splat.vert folds it. */
static float fold(const float n[3], float out[3])
{
    const float ax = fabsf(n[0]), ay = fabsf(n[1]), az = fabsf(n[2]);
    const float major = ax >= ay && ax >= az ? n[0] : ay >= az ? n[1] : n[2];
    const float s = major >= 0.0f ? 1.0f : -1.0f;
    for (int k = 0; k < 3; k++)
        out[k] = s * n[k];
    return s;
}

int lpv_iv_create(const lpv_grid *g, const lpv_iv_point *points, const float (*radiosity)[3], size_t n,
                  lpv_iv_voxel *voxels, size_t *taken)
{
    size_t cells = lpv_grid_cell_count(g);
    memset(voxels, 0, cells * sizeof *voxels);
    if (taken)
        *taken = 0;
    double *acc = calloc(cells, ACC * sizeof *acc);
    if (!acc)
        return -1;
    size_t used = 0;
    for (size_t i = 0; i < n; i++) {
        const lpv_iv_point *pt = &points[i];
        const float zero[3] = {0.0f, 0.0f, 0.0f};
        const float *B = radiosity ? radiosity[i] : zero;
        if (pt->position[3] == 0.0f || !finite3(pt->position) || !finite3(pt->normal) || !finite3(pt->albedo) ||
            !finite3(B))
            continue;
        int v[3];
        if (!lpv_iv_surface_voxel_of(g, pt->position, pt->normal, v))
            continue;
        double *a = &acc[ACC * lpv_grid_index(g, v[0], v[1], v[2])];
        float h[4];
        hemi(pt->normal, h);
        for (int ch = 0; ch < 3; ch++)
            for (int k = 0; k < 4; k++)
                a[4 * ch + k] += (double)B[ch] * (double)h[k];
        float f[3];
        const float fs = fold(pt->normal, f);
        const float area = pt->normal[3] >= 0.0f && isfinite(pt->normal[3]) ? pt->normal[3] : 0.0f;
        float u[3];
        surface_coords(g, pt->position, pt->normal, u);
        for (int k = 0; k < 3; k++) {
            a[12 + k] += pt->normal[k];
            a[15 + k] += pt->albedo[k];
            a[19 + k] += f[k];
            float local = u[k] - (float)v[k];
            local = local < 0.0f ? 0.0f : local > 1.0f ? 1.0f : local;
            a[24 + k] = local > a[24 + k] ? local : a[24 + k];
            a[27 + k] = 1.0f - local > a[27 + k] ? 1.0f - local : a[27 + k];
        }
        a[18] += 1.0;
        a[22] += area;
        a[23] += fs * area;
        used++;
    }
    for (size_t c = 0; c < cells; c++) {
        const double *a = &acc[ACC * c];
        if (a[18] == 0.0)
            continue;
        lpv_iv_voxel *o = &voxels[c];
        for (int k = 0; k < 4; k++) {
            o->r[k] = (float)(a[k] / a[18]);
            o->g[k] = (float)(a[4 + k] / a[18]);
            o->b[k] = (float)(a[8 + k] / a[18]);
        }
        for (int k = 0; k < 3; k++) {
            o->normal[k] = (float)(a[12 + k] / a[18]);
            o->albedo[k] = (float)(a[15 + k] / a[18]);
            o->fold[k] = (float)(a[19 + k] / a[18]);
        }
        o->normal[3] = (float)a[18];
        /* LPV_IV_COVER: the cloud's area over a voxel face's, plain and
         * signed; the points' extent, widened by (N + 1) / (N - 1) */
        const double face = 1.0 / ((double)g->cell_size * (double)g->cell_size);
        o->albedo[3] = (float)(a[22] * face);
        o->fold[3] = (float)(a[23] * face);
        const float widen = a[18] >= 2.0 ? (float)((a[18] + 1.0) / (a[18] - 1.0)) : 0.0f;
        float span[3], lo[3], hi[3];
        for (int k = 0; k < 3; k++) {
            hi[k] = (float)a[24 + k];
            lo[k] = 1.0f - (float)a[27 + k];
            span[k] = hi[k] - lo[k];
            const float e = span[k] * widen;
            o->extent[k] = e < 0.0f ? 0.0f : e > 1.0f ? 1.0f : e;
        }
        /* LPV_IV_SLAB: across the axis the points' folded normals agree on, if they lie thin on it */
        const float fx = fabsf(o->fold[0]), fy = fabsf(o->fold[1]), fz = fabsf(o->fold[2]);
        const int axis = fx >= fy && fx >= fz ? 0 : fy >= fz ? 1 : 2;
        o->slab[0] = -1.0f;
        if (fabsf(o->fold[axis]) >= LPV_IV_FLAT && span[axis] <= LPV_IV_SLAB_MAX) {
            o->slab[0] = (float)axis;
            o->slab[1] = lo[axis];
            o->slab[2] = hi[axis];
        }
    }
    free(acc);
    if (taken)
        *taken = used;
    return 0;
}

