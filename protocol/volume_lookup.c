/*
 * volume_lookup.c - SPEC R5.7, R5.14 and R5.15 on a decoded volume (see
 * volume_lookup.h): the cascade choice and border blend here, the SH lookup,
 * the imperfect volume's reconstruction and the probes' weighted lookup
 * from core's oracles.
 */
#include "volume_lookup.h"

#include <math.h>
#include <stdalign.h>
#include <stdint.h>

#include "oracle.h"
#include "oracle_iv.h"
#include "probes_lookup.h"

/* The wire's 12 values per cell are core's lpv_cell, r g b vec4 each (R5.1). */
_Static_assert(sizeof(lpv_cell) == 12 * sizeof(float), "lpv_cell is the wire's 12 floats");

static int usable(const lpvp_lookup_cascade *cs)
{
    return cs && cs->cells && ((uintptr_t)cs->cells % alignof(lpv_cell)) == 0 && cs->dims[0] >= 1 &&
           cs->dims[1] >= 1 && cs->dims[2] >= 1 && cs->cell_size > 0.0f && isfinite(cs->cell_size);
}

int lpvp_cascade_irradiance(const lpvp_lookup_cascade *cs, const float p[3], const float n[3], float rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    if (!usable(cs))
        return -1;
    lpv_grid g = {.dims = {cs->dims[0], cs->dims[1], cs->dims[2]},
                  .origin = {cs->origin[0], cs->origin[1], cs->origin[2]},
                  .cell_size = cs->cell_size};
    lpv_oracle_irradiance(&g, (const lpv_cell *)(const void *)cs->cells, p, n, rgb);
    return 0;
}

/* Distance from p to the box of cs in its cells (the smallest over the six
 * faces; negative outside, NaN for a NaN p). */
static float border_cells(const lpvp_lookup_cascade *cs, const float p[3])
{
    float d = INFINITY;
    for (int a = 0; a < 3; a++) {
        float u = (p[a] - cs->origin[a]) / cs->cell_size;
        if (isnan(u))
            return NAN;
        d = fminf(d, fminf(u, (float)cs->dims[a] - u));
    }
    return d;
}

int lpvp_volume_irradiance(const lpvp_lookup_cascade *cs, int count, const float p[3], const float n[3],
                           float rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    if (!cs || count < 1 || count > LPV_MAX_CASCADES)
        return -1;
    for (int i = 0; i < count; i++)
        if (!usable(&cs[i]))
            return -1;
    int k = count - 1; /* the finest cascade containing p, the coarsest if none does */
    for (int i = 0; i < count; i++)
        if (border_cells(&cs[i], p) >= 0.0f) {
            k = i;
            break;
        }
    lpvp_cascade_irradiance(&cs[k], p, n, rgb);
    if (k + 1 >= count || !(border_cells(&cs[k + 1], p) >= 0.0f))
        return 0;
    float w = fminf(fmaxf((border_cells(&cs[k], p) - 1.0f) * 0.5f, 0.0f), 1.0f);
    if (w >= 1.0f)
        return 0;
    float coarse[3];
    lpvp_cascade_irradiance(&cs[k + 1], p, n, coarse);
    for (int ch = 0; ch < 3; ch++)
        rgb[ch] = w * rgb[ch] + (1.0f - w) * coarse[ch];
    return 0;
}

int lpvp_iv_irradiance(const lpvp_lookup_iv *v, const float p[3], const float n[3], float rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    if (!v || !v->held || v->neighbours < 1 || v->neighbours > 8)
        return -1;
    const lpvp_lookup_cascade cs = {.dims = {v->dims[0], v->dims[1], v->dims[2]},
                                    .origin = {v->origin[0], v->origin[1], v->origin[2]},
                                    .cell_size = v->cell_size,
                                    .cells = v->cells};
    if (!usable(&cs))
        return -1;
    lpv_grid g = {.dims = {v->dims[0], v->dims[1], v->dims[2]},
                  .origin = {v->origin[0], v->origin[1], v->origin[2]},
                  .cell_size = v->cell_size};
    lpv_iv_irradiance_held(&g, v->held, (const lpv_cell *)(const void *)v->cells, p, n, v->neighbours, rgb);
    return 0;
}

int lpvp_probes_irradiance(const lpvp_lookup_probes *v, const float p[3], const float n[3], float rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    if (!v || !v->records || v->count < 1 || v->count > 4)
        return -1;
    lpv_probes_field f = {.levels = v->count, .irradiance_side = v->irradiance_side,
                          .distance_side = v->distance_side, .bias_cells = v->bias_cells};
    const size_t per = lpv_probes_record_values(v->irradiance_side, v->distance_side);
    size_t first = 0;
    for (int k = 0; k < v->count; ++k) {
        const lpvp_lookup_cascade *c = &v->levels[k];
        lpv_probes_level *l = &f.level[k];
        for (int a = 0; a < 3; ++a) {
            if (c->dims[a] < 1)
                return -1;
            l->dims[a] = c->dims[a];
            l->origin[a] = c->origin[a];
        }
        l->cell_size = c->cell_size;
        l->records = v->records + first * per;
        first += (size_t)c->dims[0] * (size_t)c->dims[1] * (size_t)c->dims[2];
    }
    return lpv_probes_irradiance(&f, p, n, rgb);
}
