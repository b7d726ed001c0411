/* probes_table.c - see probes_table.h. */
#include "probes_table.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lpv_shared.h"
#include "probes_math.h"
#include "probes_update.h"

void lpv_probes_table_free(lpv_probes_table *t)
{
    free(t->dirs);
    free(t->taps);
    memset(t, 0, sizeof *t);
}

int lpv_probes_table_make(lpv_probes_table *t, uint32_t tick, uint32_t seed, uint32_t rays, int oct,
                          float sharpness, int irr_oct)
{
    lpv_probes_table_free(t);
    if (rays < 1 || oct < 1 || irr_oct < 1)
        return -1;
    const size_t texels = (size_t)oct * (size_t)oct + (size_t)irr_oct * (size_t)irr_oct;
    t->dirs = malloc((size_t)rays * 4 * sizeof *t->dirs);
    /* at most every ray in every texel */
    t->taps = malloc((texels + texels * rays) * 2 * sizeof *t->taps);
    float *w = malloc((size_t)rays * sizeof *w);
    if (!t->dirs || !t->taps || !w) {
        free(w);
        lpv_probes_table_free(t);
        return -1;
    }
    float m[9];
    lpv_probes_rotation(tick, seed, m);
    for (uint32_t i = 0; i < rays; ++i) {
        lpv_probes_ray(i, rays, m, t->dirs + 4 * i);
        t->dirs[4 * i + 3] = 0.0f;
    }
    size_t at = 2 * texels;
    for (int map = 0; map < 2; ++map) {
        const int side = map == 0 ? oct : irr_oct;
        const size_t base = map == 0 ? 0 : (size_t)oct * (size_t)oct;
        for (int y = 0; y < side; ++y)
            for (int x = 0; x < side; ++x) {
                float td[3], top = 0.0f, sum = 0.0f;
                lpv_probes_texel_dir(x, y, side, td);
                for (uint32_t i = 0; i < rays; ++i) {
                    const float *d = t->dirs + 4 * i;
                    const float c = td[0] * d[0] + td[1] * d[1] + td[2] * d[2];
                    w[i] = c > 0.0f ? (map == 0 ? powf(c, sharpness) : c) : 0.0f;
                    top = w[i] > top ? w[i] : top;
                }
                const float floor = map == 0 ? LPV_PROBES_TAP_FLOOR * top : 0.0f;
                for (uint32_t i = 0; i < rays; ++i)
                    sum += w[i] >= floor && w[i] > 0.0f ? w[i] : 0.0f;
                /* the distance map's weights sum to 1; the irradiance map's to pi */
                const float scale = map == 0 ? 1.0f : (float)LPV_PI;
                const size_t k = base + (size_t)y * (size_t)side + (size_t)x, first = at;
                for (uint32_t i = 0; i < rays && sum > 0.0f; ++i)
                    if (w[i] >= floor && w[i] > 0.0f) {
                        const float n = scale * w[i] / sum;
                        t->taps[at++] = i;
                        memcpy(&t->taps[at++], &n, sizeof n);
                    }
                t->taps[2 * k] = (uint32_t)(first / 2);
                t->taps[2 * k + 1] = (uint32_t)((at - first) / 2);
            }
    }
    t->tap_words = at;
    free(w);
    return 0;
}
