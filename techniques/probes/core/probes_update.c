/* probes_update.c - see probes_update.h. */
#include "probes_update.h"

#include <math.h>
#include <string.h>

#include "probes_math.h"

void lpv_probes_texel_dir(int x, int y, int oct_size, float d[3])
{
    const float uv[2] = {((float)x + 0.5f) / (float)oct_size * 2.0f - 1.0f,
                         ((float)y + 0.5f) / (float)oct_size * 2.0f - 1.0f};
    lpv_probes_oct_decode(uv, d);
}

/* 1 when the ray along d meets triangle tri's back: the normal its winding
 * gives, (v1 - v0) x (v2 - v0), faces along the ray. */
static int back_face(const lpv_probes_bvh *b, uint32_t tri, const float d[3])
{
    const float *v = b->vertices + 12 * (size_t)tri;
    const float e1[3] = {v[4] - v[0], v[5] - v[1], v[6] - v[2]}, e2[3] = {v[8] - v[0], v[9] - v[1], v[10] - v[2]};
    const float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    return n[0] * d[0] + n[1] * d[1] + n[2] * d[2] > 0.0f;
}

int lpv_probes_update_cpu(const lpv_probes_update_desc *d, lpv_probe_result *out)
{
    if (!d || !d->bvh || (!d->positions && d->probe_count) || !out || d->rays < 1 || d->oct_size < 1 ||
        d->oct_size > LPV_PROBES_OCT_MAX || !(d->max_distance > 0.0f))
        return -1;
    const int s = d->oct_size;
    const size_t texels = (size_t)s * (size_t)s;
    float m[9];
    lpv_probes_rotation(d->tick, d->seed, m);
    for (size_t p = 0; p < d->probe_count; ++p) {
        lpv_probe_result *r = &out[p];
        const float *o = d->positions + 3 * p;
        memset(r->sh, 0, sizeof r->sh);
        /* the moments' weighted sums, then their weights, in the caller's array and a pass over it */
        for (size_t k = 0; k < 2 * texels; ++k)
            r->moments[k] = 0.0f;
        float wsum[LPV_PROBES_OCT_MAX * LPV_PROBES_OCT_MAX];
        memset(wsum, 0, texels * sizeof *wsum);
        uint32_t back = 0;
        for (uint32_t i = 0; i < d->rays; ++i) {
            float dir[3], l[3] = {0.0f, 0.0f, 0.0f}, t = d->max_distance;
            uint32_t tri = 0;
            lpv_probes_ray(i, d->rays, m, dir);
            if (lpv_probes_bvh_intersect(d->bvh, o, dir, d->max_distance, &t, &tri)) {
                if (back_face(d->bvh, tri, dir))
                    ++back;
                if (d->shade) {
                    const float hit[3] = {o[0] + t * dir[0], o[1] + t * dir[1], o[2] + t * dir[2]};
                    d->shade(d->ctx, tri, hit, dir, t, l);
                }
            } else if (d->sky) {
                memcpy(l, d->sky, sizeof l);
            }
            lpv_probes_sh_add(r->sh, dir, l, d->rays);
            for (int y = 0; y < s; ++y)
                for (int x = 0; x < s; ++x) {
                    float td[3];
                    lpv_probes_texel_dir(x, y, s, td);
                    const float c = td[0] * dir[0] + td[1] * dir[1] + td[2] * dir[2];
                    if (!(c > 0.0f))
                        continue;
                    const float w = powf(c, d->sharpness);
                    const size_t k = (size_t)y * (size_t)s + (size_t)x;
                    r->moments[2 * k] += w * t;
                    r->moments[2 * k + 1] += w * t * t;
                    wsum[k] += w;
                }
        }
        for (size_t k = 0; k < texels; ++k) {
            const float w = wsum[k];
            r->moments[2 * k] = w > 0.0f ? r->moments[2 * k] / w : d->max_distance;
            r->moments[2 * k + 1] = w > 0.0f ? r->moments[2 * k + 1] / w : d->max_distance * d->max_distance;
        }
        r->backface_share = (float)back / (float)d->rays;
    }
    return 0;
}
