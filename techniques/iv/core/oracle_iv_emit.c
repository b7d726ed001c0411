/*
 * oracle_iv_emit.c - emission per bounce of the imperfect-volumes oracle
 * (oracle_iv.h lpv_iv_emit): what each occupied voxel sends out, its direct
 * SH plus both sides' bounce light, spread by how much of each side its
 * surface covers (iv_emit.comp's rules).
 */
#include <string.h>

#include "oracle_iv_internal.h"

/* ---- Emission per bounce --------------------------------------------------- */

/* The voxel's axis a and the share *front of its points facing it (the
 * rest face -a, if every normal is +-a): the mean normal m where the points
 * mostly agree (one surface, a corner), else the folded mean f (LPV_IV_FOLD:
 * a wall's two faces); *front = (1 + m.a) / 2. 0 where neither gives an
 * axis. As iv_emit.comp's iv_axis. */
static int axis_of(const lpv_iv_voxel *h, float a[3], float *front)
{
    const float *m = h->normal, *f = h->fold;
    const float lm = sqrtf(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    const float lf = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    const float *src = m;
    float len = lm;
    if (!(lm >= LPV_IV_ONE_SIDED * lf && lm > 1e-3f)) {
        if (!(lf > 1e-3f))
            return 0;
        src = f;
        len = lf;
    }
    for (int k = 0; k < 3; k++)
        a[k] = src[k] / len;
    const float c = 0.5f * (1.0f + (m[0] * a[0] + m[1] * a[1] + m[2] * a[2]));
    *front = c < 0.0f ? 0.0f : c > 1.0f ? 1.0f : c;
    return 1;
}

static float clampf(float x, float lo, float hi) { return x < lo ? lo : x > hi ? hi : x; }

/* How much of its mean radiance each side shows, *kf and *kb
 * (LPV_IV_COVER): where the points all lie along one axis and the cloud
 * gave their area, the part of the voxel face the side covers (its area
 * over LPV_IV_COVER_AREA of the face's, at most the points' extent across
 * the axis over LPV_IV_COVER_ACROSS), between its share and 1; elsewhere
 * c + t (1 - c), t = 1 - |m| / |f|. As iv_emit.comp's iv_cover. */
static void cover(const lpv_iv_voxel *h, const float a[3], float front, float *kf, float *kb)
{
    const float back = 1.0f - front;
    const float *m = h->normal, *f = h->fold;
    const float lm = sqrtf(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    const float lf = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    if (lf >= LPV_IV_FLAT && h->albedo[3] > 0.0f) {
        const float plus = 0.5f * (h->albedo[3] + h->fold[3]), minus = 0.5f * (h->albedo[3] - h->fold[3]);
        const int front_plus = a[0] * f[0] + a[1] * f[1] + a[2] * f[2] >= 0.0f;
        const float ax = fabsf(a[0]), ay = fabsf(a[1]), az = fabsf(a[2]);
        const float *e = h->extent;
        const float across = ax >= ay && ax >= az ? e[1] * e[2] : ay >= az ? e[0] * e[2] : e[0] * e[1];
        const float af = (front_plus ? plus : minus) / LPV_IV_COVER_AREA, ab = (front_plus ? minus : plus) / LPV_IV_COVER_AREA;
        const float x = across / LPV_IV_COVER_ACROSS;
        *kf = clampf(af < x ? af : x, front, 1.0f);
        *kb = clampf(ab < x ? ab : x, back, 1.0f);
        return;
    }
    const float t = lf > 1e-3f ? clampf(1.0f - lm / lf, 0.0f, 1.0f) : 0.0f;
    *kf = front + t * (1.0f - front);
    *kb = back + t * (1.0f - back);
}

/* One channel's SH e read along the axis as two hemispheres, B_f and B_b,
 * each shown at the part kf, kb of its mean radiance B / share (cover);
 * iv_emit.comp's iv_sides says why. */
static void sides(float e[4], const float a[3], float front, float back, float kf, float kb, const float hf[4],
                  const float hb[4])
{
    const float sum = e[0] / LPV_IV_HEMI0;
    if (!(sum > 0.0f))
        return;
    float diff = (e[3] * a[0] + e[1] * a[1] + e[2] * a[2]) / LPV_IV_HEMI1;
    diff = diff < -sum ? -sum : diff > sum ? sum : diff;
    const float bf = 0.5f * (sum + diff), bb = 0.5f * (sum - diff);
    float xf = kf / (front > LPV_IV_SIDE_MIN ? front : LPV_IV_SIDE_MIN) - 1.0f;
    float xb = kb / (back > LPV_IV_SIDE_MIN ? back : LPV_IV_SIDE_MIN) - 1.0f;
    xf = xf > 0.0f ? xf : 0.0f;
    xb = xb > 0.0f ? xb : 0.0f;
    for (int k = 0; k < 4; k++)
        e[k] += bf * xf * hf[k] + bb * xb * hb[k];
}

void lpv_iv_emit(const lpv_grid *g, const lpv_iv_voxel *voxels, const lpv_cell *incoming, int bounce, int neighbours,
                 lpv_cell *emit)
{
    for (int z = 0; z < g->dims[2]; z++) {
        for (int y = 0; y < g->dims[1]; y++) {
            for (int x = 0; x < g->dims[0]; x++) {
                size_t i = lpv_grid_index(g, x, y, z);
                const lpv_iv_voxel *h = &voxels[i];
                lpv_cell *e = &emit[i];
                memset(e, 0, sizeof *e);
                if (!lpv_iv_occupied(h))
                    continue;
                memcpy(e->r, h->r, sizeof e->r);
                memcpy(e->g, h->g, sizeof e->g);
                memcpy(e->b, h->b, sizeof e->b);
                float nh[3], front;
                if (!axis_of(h, nh, &front))
                    continue;
                const float back = 1.0f - front, nb[3] = {-nh[0], -nh[1], -nh[2]};
                float hf[4], hb[4];
                hemi(nh, hf);
                hemi(nb, hb);
                if (bounce > 1 && incoming) {
                    const float p[3] = {centre_of(g, 0, x), centre_of(g, 1, y), centre_of(g, 2, z)};
                    float Ef[3], Eb[3] = {0.0f, 0.0f, 0.0f};
                    lpv_iv_irradiance(g, voxels, incoming, p, nh, neighbours, Ef);
                    if (back > 0.0f)
                        lpv_iv_irradiance(g, voxels, incoming, p, nb, neighbours, Eb);
                    for (int ch = 0; ch < 3; ch++) {
                        float af = h->albedo[ch] * Ef[ch] * front, ab = h->albedo[ch] * Eb[ch] * back;
                        float *c = channel(e, ch);
                        for (int k = 0; k < 4; k++)
                            c[k] += af * hf[k] + ab * hb[k];
                    }
                }
                float kf, kb;
                cover(h, nh, front, &kf, &kb);
                for (int ch = 0; ch < 3; ch++)
                    sides(channel(e, ch), nh, front, back, kf, kb, hf, hb);
            }
        }
    }
}

