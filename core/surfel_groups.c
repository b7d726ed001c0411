/*
 * surfel_groups.c - see surfel_groups.h.
 */
#include "surfel_groups.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "oracle.h"
#include "sh.h"

typedef struct keyed {
    int32_t point[LPV_MAX_CASCADES][3];
    int32_t bin; /* the normal's dominant axis and sign: opposite faces of a thin wall never share a group */
    float size;
    uint32_t index; /* in the input: ties keep the input's order, so a group's first surfel comes first */
} keyed;

static int cmp_keyed(const void *pa, const void *pb)
{
    const keyed *a = pa, *b = pb;
    int c = memcmp(a->point, b->point, sizeof a->point);
    if (c)
        return c;
    if (a->bin != b->bin)
        return a->bin < b->bin ? -1 : 1;
    if (a->size != b->size)
        return a->size < b->size ? -1 : 1;
    return (a->index > b->index) - (a->index < b->index);
}

static int same_group(const keyed *a, const keyed *b)
{
    return memcmp(a->point, b->point, sizeof a->point) == 0 && a->bin == b->bin && a->size == b->size;
}

size_t lpv_surfels_group(const lpv_surfel *in, size_t n, const lpv_group_grid *grids, int levels, lpv_surfel *out)
{
    if (levels < 0)
        levels = 0;
    if (levels > LPV_MAX_CASCADES)
        levels = LPV_MAX_CASCADES;
    keyed *k = n ? calloc(n, sizeof *k) : NULL;
    if (!k)
        return 0;
    size_t m = 0;
    for (size_t i = 0; i < n && i <= UINT32_MAX; ++i) {
        const lpv_surfel *s = &in[i];
        float dir[3];
        float area = s->position[3];
        if (!(area > 0.0f) || !isfinite(area) || !isfinite(s->position[0]) || !isfinite(s->position[1]) ||
            !isfinite(s->position[2]) || !lpv_mean_direction(s->normal, dir))
            continue;
        keyed *e = &k[m++];
        for (int c = 0; c < levels; ++c)
            for (int a = 0; a < 3; ++a) {
                /* as grid.glsl's gv_point_at, in float */
                float x = s->position[a] + LPV_TIE_CELLS * grids[c].cell_size * dir[a];
                float q = floorf(x / grids[c].cell_size - grids[c].origin_cells[a] + 0.5f);
                e->point[c][a] = q > 1e9f ? 1000000000 : q < -1e9f ? -1000000000 : (int32_t)q;
            }
        e->bin = lpv_oracle_normal_bin(dir);
        e->size = s->normal[3];
        e->index = (uint32_t)i;
    }
    qsort(k, m, sizeof *k, cmp_keyed);
    size_t groups = 0;
    for (size_t i = 0; i < m;) {
        const lpv_surfel *first = &in[k[i].index];
        double area = 0.0, d[3] = {0, 0, 0}, nrm[3] = {0, 0, 0}, alb[3] = {0, 0, 0};
        size_t j = i;
        for (; j < m && same_group(&k[i], &k[j]); ++j) {
            const lpv_surfel *s = &in[k[j].index];
            float dir[3];
            lpv_mean_direction(s->normal, dir);
            double w = s->position[3];
            area += w;
            for (int a = 0; a < 3; ++a) {
                /* differences from the first: a group on one plane keeps
                 * that plane's coordinate to the bit */
                d[a] += w * ((double)s->position[a] - (double)first->position[a]);
                nrm[a] += w * dir[a];
                alb[a] += w * s->albedo[a];
            }
        }
        lpv_surfel *o = &out[groups++];
        memset(o, 0, sizeof *o);
        for (int a = 0; a < 3; ++a) {
            o->position[a] = (float)((double)first->position[a] + d[a] / area);
            o->normal[a] = (float)(nrm[a] / area);
            o->albedo[a] = (float)(alb[a] / area);
        }
        if (j == i + 1) /* one surfel: itself, to the bit */
            memcpy(o->normal, first->normal, sizeof o->normal);
        o->position[3] = (float)area;
        o->normal[3] = k[i].size;
        i = j;
    }
    free(k);
    return groups;
}
