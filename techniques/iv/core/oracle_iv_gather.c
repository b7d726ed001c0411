/*
 * oracle_iv_gather.c - the march of the imperfect-volumes oracle (3.3, 3.5):
 * rays from every voxel near a surface through the grid (Amanatides & Woo),
 * the radiance they bring back (oracle_iv.h lpv_iv_gather) or whether they
 * escape (lpv_iv_gather_ao), as iv_gather.comp walks them.
 */
#include <string.h>

#include "oracle_iv_internal.h"

#define IV_PI 3.14159265358979323846

static void basis(const float d[3], float y[4])
{
    y[0] = LPV_SH_C0;
    y[1] = LPV_SH_C1 * d[1];
    y[2] = LPV_SH_C1 * d[2];
    y[3] = LPV_SH_C1 * d[0];
}

/* 1 when any voxel of the 3x3x3 block around (x, y, z), itself included and
 * clipped to the grid, is occupied. */
static int near_occupied(const lpv_grid *g, const lpv_iv_voxel *voxels, int x, int y, int z)
{
    for (int dz = -1; dz <= 1; dz++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++)
                if (occupied_at(g, voxels, x + dx, y + dy, z + dz))
                    return 1;
    return 0;
}

/* ---- The march (3.3, 3.5) -------------------------------------------------- */

float lpv_iv_emitted(const float e[4], const float t[3])
{
    const float sum = e[0] / LPV_IV_HEMI0;
    const float v[3] = {e[3] / LPV_IV_HEMI1, e[1] / LPV_IV_HEMI1, e[2] / LPV_IV_HEMI1};
    float diff = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (diff > sum)
        diff = sum;
    const float side = v[0] * t[0] + v[1] * t[1] + v[2] * t[2] > 0.0f ? sum + diff : sum - diff;
    return side > 0.0f ? side * (float)(0.5 / IV_PI) : 0.0f;
}

/* Y(-w) of ray j of voxel (x, y, z); w to dir. */
static void ray(const lpv_grid *g, uint32_t seed, int x, int y, int z, int j, int rays, float dir[3], float y4[4])
{
    lpv_iv_ray(seed, (uint32_t)lpv_grid_index(g, x, y, z), (uint32_t)j, (uint32_t)rays, dir);
    const float back[3] = {-dir[0], -dir[1], -dir[2]};
    basis(back, y4);
}

/* Whether a ray's stretch through occupied voxel h at q, from
 * o + t_in w to o + t_out w (in voxels), meets its surface: passes through
 * its slab (LPV_IV_SLAB, widened by LPV_IV_SLAB_PAD), anywhere in it where
 * it has none. As iv_gather.comp's meets. */
static int meets(const lpv_iv_voxel *h, const int q[3], const float o[3], const float w[3], float t_in, float t_out)
{
    if (h->slab[0] < 0.0f)
        return 1;
    const int k = (int)h->slab[0];
    const float x_in = o[k] - (float)q[k] + t_in * w[k], x_out = o[k] - (float)q[k] + t_out * w[k];
    const float top = x_in > x_out ? x_in : x_out, bottom = x_in < x_out ? x_in : x_out;
    return top >= h->slab[1] - LPV_IV_SLAB_PAD && bottom <= h->slab[2] + LPV_IV_SLAB_PAD;
}

/* The march from o (in voxels) along w (Amanatides & Woo, as iv_gather.comp
 * walks it): every voxel the ray crosses but c and own, until an occupied
 * one (with slabs, one whose slab it meets: LPV_IV_SLAB_MARCH), the grid's
 * edge (LPV_IV_ESCAPED) or, entering a voxel more than reach voxels from the
 * start (start + the distance from o), LPV_IV_BEYOND. With slabs, *corner
 * gets the axis of the face through which the ray entered the voxel it hit
 * when it came straight from an occupied voxel it passed (LPV_IV_CORNER_READ),
 * else -1; q_hit the voxel's coordinates. */
static long march_from(const lpv_grid *g, const lpv_iv_voxel *voxels, const int c[3], const int own[3],
                       const float o[3], const float w[3], int slabs, float start, float reach, int q_hit[3],
                       int *corner)
{
    float inv[3], cross[3];
    int q[3], st[3];
    for (int a = 0; a < 3; a++) {
        q[a] = (int)floorf(o[a]);
        st[a] = w[a] > 0.0f ? 1 : w[a] < 0.0f ? -1 : 0;
        inv[a] = fabsf(w[a]) > 1e-12f ? 1.0f / fabsf(w[a]) : 1e30f;
        cross[a] = (w[a] > 0.0f ? (float)q[a] + 1.0f - o[a] : o[a] - (float)q[a]) * inv[a];
    }
    float t = 0.0f;
    int entered = -1, passed = 0; /* the face q was entered through; the voxel before it was occupied */
    *corner = -1;
    const long max_steps = (long)g->dims[0] + g->dims[1] + g->dims[2] + 3;
    for (long i = 0; i < max_steps; i++) {
        if (start + t > reach)
            return LPV_IV_BEYOND;
        if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= g->dims[0] || q[1] >= g->dims[1] || q[2] >= g->dims[2])
            return LPV_IV_ESCAPED;
        const size_t h = lpv_grid_index(g, q[0], q[1], q[2]);
        const int a = cross[0] < cross[1] ? (cross[0] < cross[2] ? 0 : 2) : (cross[1] < cross[2] ? 1 : 2);
        const int skip = (q[0] == c[0] && q[1] == c[1] && q[2] == c[2]) ||
                         (q[0] == own[0] && q[1] == own[1] && q[2] == own[2]);
        const int held = !skip && lpv_iv_occupied(&voxels[h]);
        if (held && (!slabs || meets(&voxels[h], q, o, w, t, cross[a]))) {
            memcpy(q_hit, q, sizeof q);
            *corner = slabs && passed ? entered : -1;
            return (long)h;
        }
        passed = held;
        entered = a;
        t = cross[a];
        q[a] += st[a];
        cross[a] += inv[a];
    }
    return LPV_IV_ESCAPED;
}

/* LPV_IV_CORNER_READ: what a ray that reached voxel q through the face
 * across `axis`, straight from a surface it passed, sees there. A voxel
 * without a slab (a corner: a floor's and a wall's ends, a thin wall's two
 * faces and the floor under it) shows its points' mean as two hemispheres
 * along one axis, which reads a wall's lit face behind its dark back and
 * hidden faces; the ray is looking at the surfaces that continue into it, so
 * it reads the mean of its face neighbours that hold a slab across `axis`
 * (the wall above a floor's corner, for a ray that skimmed the floor
 * towards the wall), or q itself where none does. Returns the voxels read
 * (their indices in out[0..]). */
static int corner_read(const lpv_grid *g, const lpv_iv_voxel *voxels, const int q[3], long h, int axis, long out[4])
{
    int n = 0;
    if (axis >= 0 && voxels[h].slab[0] < 0.0f)
        for (int b = 0; b < 3; b++) {
            if (b == axis)
                continue;
            for (int sg = -1; sg <= 1; sg += 2) {
                int p[3] = {q[0], q[1], q[2]};
                p[b] += sg;
                if (!occupied_at(g, voxels, p[0], p[1], p[2]))
                    continue;
                const size_t k = lpv_grid_index(g, p[0], p[1], p[2]);
                if (voxels[k].slab[0] == (float)axis)
                    out[n++] = (long)k;
            }
        }
    if (n == 0)
        out[n++] = h;
    return n;
}

long lpv_iv_march(const lpv_grid *g, const lpv_iv_voxel *voxels, int x, int y, int z, const float w[3], float reach)
{
    /* occupied voxels start LPV_IV_START out (their own surface), empty
     * ones at the centre */
    const int c[3] = {x, y, z};
    const float start = lpv_iv_occupied(&voxels[lpv_grid_index(g, x, y, z)]) ? LPV_IV_START : 0.0f;
    float o[3];
    for (int a = 0; a < 3; a++)
        o[a] = (float)c[a] + 0.5f + start * w[a];
    int q_hit[3], corner;
    return march_from(g, voxels, c, c, o, w, 0, start, reach / g->cell_size, q_hit, &corner);
}

void lpv_iv_gather(const lpv_grid *g, const lpv_iv_voxel *voxels, const lpv_cell *emit, uint32_t seed, int rays,
                   lpv_cell *incoming)
{
    const double scale = 4.0 * IV_PI / (double)rays;
    for (int z = 0; z < g->dims[2]; z++) {
        for (int y = 0; y < g->dims[1]; y++) {
            for (int x = 0; x < g->dims[0]; x++) {
                lpv_cell *out = &incoming[lpv_grid_index(g, x, y, z)];
                memset(out, 0, sizeof *out);
                if (!near_occupied(g, voxels, x, y, z))
                    continue;
                const int c[3] = {x, y, z};
                const float start = lpv_iv_occupied(&voxels[lpv_grid_index(g, x, y, z)]) ? LPV_IV_START : 0.0f;
                float axis[3] = {0.0f, 0.0f, 0.0f}, side[3], origin[3], plane;
                int own[3], k_plane;
                for (int k = 0; k < 3; k++)
                    origin[k] = (float)c[k] + 0.5f;
                /* LPV_IV_SURFACE_GATHER: on the slab of the one surface beside it */
                const int surf = surface_plane(g, voxels, c, own, side, &k_plane, &plane);
                if (surf) {
                    origin[k_plane] = plane + LPV_IV_SLAB_PAD * side[k_plane];
                    memcpy(axis, side, sizeof axis); /* LPV_IV_AXIS_L0 */
                }
                double acc[3][4] = {{0.0}}, e_plus[3] = {0.0}, e_minus[3] = {0.0};
                for (int j = 0; j < rays; j++) {
                    float w[3], yb[4];
                    ray(g, seed, x, y, z, j, rays, w, yb);
                    long h, read[4];
                    int n_read = 1;
                    if (surf && w[0] * side[0] + w[1] * side[1] + w[2] * side[2] <= 0.0f) {
                        h = (long)lpv_grid_index(g, own[0], own[1], own[2]); /* into the surface */
                        read[0] = h;
                    } else {
                        float o[3];
                        int q_hit[3], corner;
                        for (int k = 0; k < 3; k++)
                            o[k] = surf ? origin[k] : (float)c[k] + 0.5f + start * w[k];
                        h = march_from(g, voxels, c, own, o, w, 1, start, INFINITY, q_hit, &corner);
                        if (h >= 0)
                            n_read = corner_read(g, voxels, q_hit, h, corner, read);
                    }
                    if (h < 0)
                        continue; /* escaped: no light */
                    const float back[3] = {-w[0], -w[1], -w[2]};
                    const float up = axis[0] * w[0] + axis[1] * w[1] + axis[2] * w[2];
                    for (int ch = 0; ch < 3; ch++) {
                        float L = 0.0f;
                        for (int r = 0; r < n_read; r++)
                            L += lpv_iv_emitted(cchannel(&emit[read[r]], ch), back);
                        L /= (float)n_read;
                        if (!(L > 0.0f))
                            continue;
                        for (int k = 0; k < 4; k++)
                            acc[ch][k] += (double)(L * yb[k]);
                        e_plus[ch] += (double)(L * (up > 0.0f ? up : 0.0f));
                        e_minus[ch] += (double)(L * (up < 0.0f ? -up : 0.0f));
                    }
                }
                if (axis[0] != 0.0f || axis[1] != 0.0f || axis[2] != 0.0f) /* LPV_IV_AXIS_L0 */
                    for (int ch = 0; ch < 3; ch++)
                        acc[ch][0] = (e_plus[ch] + e_minus[ch]) / (2.0 * LPV_SH_LOBE0);
                for (int ch = 0; ch < 3; ch++)
                    for (int k = 0; k < 4; k++)
                        channel(out, ch)[k] = (float)(acc[ch][k] * scale);
            }
        }
    }
}

void lpv_iv_gather_ao(const lpv_grid *g, const lpv_iv_voxel *voxels, uint32_t seed, int rays, float reach, vec4 *ao)
{
    const double scale = 4.0 * IV_PI / (double)rays;
    for (int z = 0; z < g->dims[2]; z++) {
        for (int y = 0; y < g->dims[1]; y++) {
            for (int x = 0; x < g->dims[0]; x++) {
                float *out = ao[lpv_grid_index(g, x, y, z)];
                if (!near_occupied(g, voxels, x, y, z)) {
                    /* all visible: the projection of the constant 1 */
                    out[0] = 4.0f * LPV_PI * LPV_SH_C0;
                    out[1] = out[2] = out[3] = 0.0f;
                    continue;
                }
                double acc[4] = {0.0};
                for (int j = 0; j < rays; j++) {
                    float w[3], yb[4];
                    ray(g, seed, x, y, z, j, rays, w, yb);
                    if (lpv_iv_march(g, voxels, x, y, z, w, reach) >= 0)
                        continue; /* hit: V = 0 */
                    for (int k = 0; k < 4; k++)
                        acc[k] += yb[k];
                }
                for (int k = 0; k < 4; k++)
                    out[k] = (float)(acc[k] * scale);
            }
        }
    }
}

