/*
 * oracle_iv_filter.c - the imperfect-volumes oracle's filter after the last
 * bounce (LPV_IV_FILTER, oracle_iv.h lpv_iv_filter), as iv_filter.comp
 * computes it: a surface voxel's gather becomes the binomial 3 x 3 mean of
 * the surface voxels around it on the same plane.
 */
#include <stdlib.h>

#include "oracle_iv_internal.h"

void lpv_iv_filter(const lpv_grid *g, const lpv_iv_voxel *voxels, const lpv_cell *raw, lpv_cell *out)
{
    for (int z = 0; z < g->dims[2]; z++)
        for (int y = 0; y < g->dims[1]; y++)
            for (int x = 0; x < g->dims[0]; x++) {
                const int c[3] = {x, y, z};
                const size_t i = lpv_grid_index(g, x, y, z);
                int own[3], k;
                float side[3], plane;
                if (!surface_plane(g, voxels, c, own, side, &k, &plane)) {
                    out[i] = raw[i];
                    continue;
                }
                const int u = (k + 1) % 3, v = (k + 2) % 3;
                double acc[12] = {0.0}, sum = 0.0;
                for (int dv = -1; dv <= 1; dv++)
                    for (int du = -1; du <= 1; du++) {
                        int n[3] = {x, y, z};
                        n[u] += du;
                        n[v] += dv;
                        if (du != 0 || dv != 0) {
                            int own_n[3], k_n;
                            float side_n[3], plane_n;
                            if (n[u] < 0 || n[v] < 0 || n[u] >= g->dims[u] || n[v] >= g->dims[v] ||
                                !surface_plane(g, voxels, n, own_n, side_n, &k_n, &plane_n) ||
                                memcmp(side_n, side, sizeof side) != 0 || fabsf(plane_n - plane) > LPV_IV_FILTER_PLANE)
                                continue;
                        }
                        const double w = (double)((2 - abs(du)) * (2 - abs(dv)));
                        const float *f = (const float *)&raw[lpv_grid_index(g, n[0], n[1], n[2])];
                        for (int j = 0; j < 12; j++)
                            acc[j] += w * (double)f[j];
                        sum += w;
                    }
                float *o = (float *)&out[i];
                for (int j = 0; j < 12; j++)
                    o[j] = (float)(acc[j] / sum);
            }
}
