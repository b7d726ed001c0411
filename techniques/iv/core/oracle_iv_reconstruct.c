/*
 * oracle_iv_reconstruct.c - reconstruction of the imperfect-volumes oracle
 * (3.4): the radiance, irradiance and AO at a surface point blended from
 * the voxels around it (oracle_iv.h lpv_iv_reconstruct, lpv_iv_irradiance,
 * their _held forms, lpv_iv_ao). The final lookup, and what emission
 * reads each bounce's light with.
 */
#include <string.h>

#include "oracle_iv_internal.h"
#include "sh.h"

static float dot4(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]; }

/* ---- Reconstruction (3.4) -------------------------------------------------- */

/* Which voxels hold a surface: the created voxels (lpv_iv_occupied) or one
 * flag per voxel (non-zero: holds one, as a volume's index on the wire, SPEC
 * R5.14); neither: none does. */
typedef struct held_by {
    const lpv_iv_voxel *voxels;
    const uint32_t *flags;
} held_by;

static int holds(const held_by *h, size_t i)
{
    return h->voxels ? lpv_iv_occupied(&h->voxels[i]) : h->flags ? h->flags[i] != 0 : 0;
}

/* The corners reconstruction blends at p for n, and their weights w_c (not
 * yet divided by the sum). Returns how many were written to index[] and
 * weight[] (at most 8); 0 when nothing contributes. */
static int corners(const lpv_grid *g, const held_by *held, const float p[3], const float n[3], int neighbours,
                   size_t index[8], double weight[8])
{
    float nh[3];
    if (!finite3(p) || !lpv_unit_direction(n, nh))
        return 0;
    const float s = g->cell_size;
    float f[3];
    int base[3];
    for (int a = 0; a < 3; a++) {
        float q = p[a] + 0.5f * s * nh[a];
        float u = (q - g->origin[a]) / s - 0.5f;
        /* base and base + 1 both outside the grid (or u not finite): nothing */
        if (!(u >= -1.0f && u < (float)g->dims[a]))
            return 0;
        float b = floorf(u);
        base[a] = (int)b;
        f[a] = u - b;
    }
    /* the corners by distance to q, then index (insertion sort, stable) */
    int order[8];
    float d2[8];
    for (int c = 0; c < 8; c++) {
        d2[c] = 0.0f;
        for (int a = 0; a < 3; a++) {
            float e = f[a] - (float)((c >> a) & 1);
            d2[c] += e * e;
        }
        int k = c;
        while (k > 0 && d2[order[k - 1]] > d2[c]) {
            order[k] = order[k - 1];
            k--;
        }
        order[k] = c;
    }
    if (neighbours < 1)
        neighbours = 1;
    if (neighbours > 8)
        neighbours = 8;
    int m = 0;
    for (int r = 0; r < neighbours; r++) {
        const int c = order[r];
        int v[3], inside = 1;
        for (int a = 0; a < 3; a++) {
            v[a] = base[a] + ((c >> a) & 1);
            inside &= v[a] >= 0 && v[a] < g->dims[a];
        }
        if (!inside)
            continue;
        float t = 1.0f;
        for (int a = 0; a < 3; a++)
            t *= (c >> a) & 1 ? f[a] : 1.0f - f[a];
        float d[3];
        for (int a = 0; a < 3; a++)
            d[a] = centre_of(g, a, v[a]) - p[a];
        float len = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        float cosine = 0.0f;
        if (len > 0.0f)
            cosine = nh[0] * (d[0] / len) + nh[1] * (d[1] / len) + nh[2] * (d[2] / len);
        float w = t * (cosine > 0.0f ? cosine : 0.0f);
        const size_t vi = lpv_grid_index(g, v[0], v[1], v[2]);
        if (holds(held, vi))
            w *= LPV_IV_HELD_WEIGHT;
        if (!(w > 0.0f))
            continue;
        index[m] = vi;
        weight[m] = w;
        m++;
    }
    return m;
}

static void reconstruct(const lpv_grid *g, const held_by *held, const lpv_cell *vol, const float p[3], const float n[3],
                        int neighbours, lpv_cell *out)
{
    memset(out, 0, sizeof *out);
    size_t index[8];
    double weight[8], sum = 0.0, acc[3][4] = {{0.0}};
    int m = corners(g, held, p, n, neighbours, index, weight);
    for (int i = 0; i < m; i++) {
        sum += weight[i];
        for (int ch = 0; ch < 3; ch++)
            for (int k = 0; k < 4; k++)
                acc[ch][k] += weight[i] * cchannel(&vol[index[i]], ch)[k];
    }
    if (!(sum > 0.0))
        return;
    for (int ch = 0; ch < 3; ch++)
        for (int k = 0; k < 4; k++)
            channel(out, ch)[k] = (float)(acc[ch][k] / sum);
}

/* lobe(-n^) for a unit-able n; 0 and a zero lobe otherwise. */
static int lobe_minus(const float n[3], float lobe[4])
{
    float nh[3], m[3];
    if (!lpv_unit_direction(n, nh)) {
        memset(lobe, 0, 4 * sizeof *lobe);
        return 0;
    }
    m[0] = -nh[0];
    m[1] = -nh[1];
    m[2] = -nh[2];
    lpv_sh_cosine_lobe(m, lobe);
    return 1;
}

/* The 2-band irradiance e (any sign per channel) as light, one rule for the
 * whole colour, as iv_lookup.glsl's iv_physical: none where its luminance
 * y <= 0; else y kept and the chroma scaled by y / (y - 2 m), m the most
 * negative channel (1 where none is negative), so no channel is clipped to
 * exactly 0 while another stays lit. */
static void physical(const float e[3], float rgb[3])
{
    const float y = e[0] * LPV_IV_LUMA_R + e[1] * LPV_IV_LUMA_G + e[2] * LPV_IV_LUMA_B;
    if (!(y > 0.0f)) {
        rgb[0] = rgb[1] = rgb[2] = 0.0f;
        return;
    }
    float m = e[0] < e[1] ? e[0] : e[1];
    m = m < e[2] ? m : e[2];
    const float s = m >= 0.0f ? 1.0f : y / (y - 2.0f * m);
    for (int ch = 0; ch < 3; ch++)
        rgb[ch] = m >= 0.0f ? e[ch] : y + (e[ch] - y) * s;
}

static void irradiance(const lpv_grid *g, const held_by *held, const lpv_cell *vol, const float p[3], const float n[3],
                       int neighbours, float rgb[3])
{
    lpv_cell L;
    float lobe[4];
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    if (!lobe_minus(n, lobe))
        return;
    reconstruct(g, held, vol, p, n, neighbours, &L);
    float e[3];
    for (int ch = 0; ch < 3; ch++)
        e[ch] = dot4(cchannel(&L, ch), lobe);
    physical(e, rgb);
}

void lpv_iv_reconstruct(const lpv_grid *g, const lpv_iv_voxel *voxels, const lpv_cell *vol, const float p[3],
                        const float n[3], int neighbours, lpv_cell *out)
{
    const held_by held = {.voxels = voxels};
    reconstruct(g, &held, vol, p, n, neighbours, out);
}

void lpv_iv_reconstruct_held(const lpv_grid *g, const uint32_t *held, const lpv_cell *vol, const float p[3],
                             const float n[3], int neighbours, lpv_cell *out)
{
    const held_by by = {.flags = held};
    reconstruct(g, &by, vol, p, n, neighbours, out);
}

void lpv_iv_irradiance(const lpv_grid *g, const lpv_iv_voxel *voxels, const lpv_cell *vol, const float p[3],
                       const float n[3], int neighbours, float rgb[3])
{
    const held_by held = {.voxels = voxels};
    irradiance(g, &held, vol, p, n, neighbours, rgb);
}

void lpv_iv_irradiance_held(const lpv_grid *g, const uint32_t *held, const lpv_cell *vol, const float p[3],
                            const float n[3], int neighbours, float rgb[3])
{
    const held_by by = {.flags = held};
    irradiance(g, &by, vol, p, n, neighbours, rgb);
}

float lpv_iv_ao(const lpv_grid *g, const lpv_iv_voxel *voxels, const vec4 *ao, const float p[3], const float n[3],
                int neighbours)
{
    float lobe[4];
    if (!lobe_minus(n, lobe))
        return 1.0f;
    size_t index[8];
    double weight[8], sum = 0.0, acc[4] = {0.0};
    const held_by held = {.voxels = voxels};
    int m = corners(g, &held, p, n, neighbours, index, weight);
    for (int i = 0; i < m; i++) {
        sum += weight[i];
        for (int k = 0; k < 4; k++)
            acc[k] += weight[i] * ao[index[i]][k];
    }
    if (!(sum > 0.0))
        return 1.0f; /* nothing to blend: open, as the GPU lookup answers */
    float L[4];
    for (int k = 0; k < 4; k++)
        L[k] = (float)(acc[k] / sum);
    float a = dot4(L, lobe) / LPV_PI;
    return a > 1.0f ? 1.0f : a > 0.0f ? a : 0.0f;
}

