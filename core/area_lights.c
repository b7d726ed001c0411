/* area_lights.c - see area_lights.h. */
#include "area_lights.h"
#include "material_sample.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int emits(const lpv_scene *s, int m)
{
    if (m < 0 || (uint32_t)m >= s->material_count)
        return 0;
    const float *e = s->materials[m].emission;
    return isfinite(e[0] + e[1] + e[2]) && e[0] >= 0.0f && e[1] >= 0.0f && e[2] >= 0.0f &&
           (e[0] > 0.0f || e[1] > 0.0f || e[2] > 0.0f);
}

int lpv_emitters_collect(const lpv_scene *s, lpv_emitter_list *list)
{
    memset(list, 0, sizeof *list);
    size_t cap = 0;
    for (uint32_t d = 0; d < s->draw_count; ++d)
        if (emits(s, s->draws[d].material))
            cap += s->draws[d].index_count / 3 * (size_t)lpv_material_emitting_sides(&s->materials[s->draws[d].material]);
    if (!cap)
        return 0;
    list->tris = malloc(cap * sizeof *list->tris);
    if (!list->tris)
        return -1;
    for (uint32_t d = 0; d < s->draw_count; ++d) {
        const lpv_draw *dr = &s->draws[d];
        if (!emits(s, dr->material))
            continue;
        size_t before = list->count;
        for (uint32_t t = 0; t + 3 <= dr->index_count && list->count < cap; t += 3) {
            const lpv_vertex *v[3];
            lpv_emitter_tri *o = &list->tris[list->count];
            if ((uint64_t)dr->first_index + t + 3 > s->index_count ||
                !lpv_scene_triangle(s, dr->first_index + t, v, o->normal, &o->area))
                continue;
            for (int k = 0; k < 3; ++k)
                memcpy(o->p[k], v[k]->position, sizeof o->p[k]);
            lpv_triangle_emission(s, &s->materials[dr->material], v, o->emission); /* its emissiveTexture's mean */
            list->count++;
        }
        /* A double-sided emitter (glTF doubleSided, as Blender, three.js and
         * the Khronos viewer light it) emits the same radiance from its back:
         * the draw's triangles again, facing the other way, after its front
         * ones so that the samples of one side stay one patch. */
        if (lpv_material_emitting_sides(&s->materials[dr->material]) == 2)
            for (size_t t = before, front_end = list->count; t < front_end && list->count < cap; ++t) {
                lpv_emitter_tri *o = &list->tris[list->count++];
                *o = list->tris[t];
                for (int i = 0; i < 3; ++i)
                    o->normal[i] = -o->normal[i];
            }
        if (list->count > before)
            list->surfaces++;
    }
    return 0;
}

void lpv_emitters_free(lpv_emitter_list *list)
{
    free(list->tris);
    memset(list, 0, sizeof *list);
}

/* The weight a triangle's length on the power line has: (L_r + L_g + L_b) A. */
static double weight(const lpv_emitter_tri *t)
{
    return ((double)t->emission[0] + t->emission[1] + t->emission[2]) * t->area;
}

/* Cell `index` of the triangle's midpoint subdivision at depth `depth`
 * (4^depth cells of equal area): its centroid. The index's base-4 digits,
 * most significant first, pick one of the four children level by level
 * (corner a, the middle, corner b, corner c, each next to the one before),
 * so a run of indices is a compact patch of the triangle. */
#define PATCH_DEPTH 5 /* 1024 cells */
static void cell_centroid(unsigned index, int depth, const float p[3][3], double out[3])
{
    double a[3], b[3], c[3];
    for (int i = 0; i < 3; ++i)
        a[i] = p[0][i], b[i] = p[1][i], c[i] = p[2][i];
    for (int level = depth - 1; level >= 0; --level) {
        unsigned k = (index >> (2 * level)) & 3u;
        double ab[3], bc[3], ca[3];
        for (int i = 0; i < 3; ++i) {
            ab[i] = 0.5 * (a[i] + b[i]);
            bc[i] = 0.5 * (b[i] + c[i]);
            ca[i] = 0.5 * (c[i] + a[i]);
        }
        for (int i = 0; i < 3; ++i) {
            double na, nb, nc;
            switch (k) {
            case 0: na = a[i], nb = ab[i], nc = ca[i]; break;
            case 1: na = bc[i], nb = ca[i], nc = ab[i]; break;
            case 2: na = ab[i], nb = b[i], nc = bc[i]; break;
            default: na = ca[i], nb = bc[i], nc = c[i]; break;
            }
            a[i] = na, b[i] = nb, c[i] = nc;
        }
    }
    for (int i = 0; i < 3; ++i)
        out[i] = (a[i] + b[i] + c[i]) / 3.0;
}

/* The centroid of the patch [u0, u1) (fractions of the triangle's area along
 * the subdivision order): exact for the whole triangle, else the
 * area-weighted mean of the depth-5 cells it covers. */
static void patch_centroid(const lpv_emitter_tri *t, double u0, double u1, double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    if (u0 <= 0.0 && u1 >= 1.0) {
        for (int v = 0; v < 3; ++v)
            for (int i = 0; i < 3; ++i)
                out[i] += t->p[v][i] / 3.0;
        return;
    }
    const unsigned cells = 1u << (2 * PATCH_DEPTH);
    double x0 = fmax(0.0, u0) * cells, x1 = fmin(1.0, u1) * cells, wsum = 0.0;
    unsigned first = (unsigned)floor(x0), last = (unsigned)ceil(x1);
    if (last > cells)
        last = cells;
    for (unsigned i = first; i < last; ++i) {
        double w = fmin(x1, (double)i + 1.0) - fmax(x0, (double)i);
        if (!(w > 0.0))
            continue;
        double q[3];
        cell_centroid(i, PATCH_DEPTH, t->p, q);
        for (int k = 0; k < 3; ++k)
            out[k] += w * q[k];
        wsum += w;
    }
    if (wsum > 0.0)
        for (int k = 0; k < 3; ++k)
            out[k] /= wsum;
    else
        cell_centroid(first < cells ? first : cells - 1, PATCH_DEPTH, t->p, out);
}

size_t lpv_area_lights_sample(const lpv_emitter_list *list, size_t k, lpv_area_sample *out)
{
    if (!list || !list->count || !k)
        return 0;
    const size_t n = list->count;
    double *start = malloc((n + 1) * sizeof *start); /* start[t]: where triangle t begins on the line */
    if (!start)
        return 0;
    start[0] = 0.0;
    for (size_t t = 0; t < n; ++t)
        start[t + 1] = start[t] + weight(&list->tris[t]);
    const double total = start[n];
    if (!(total > 0.0) || !isfinite(total)) {
        free(start);
        return 0;
    }
    size_t first = 0; /* first triangle overlapping the current part */
    for (size_t s = 0; s < k; ++s) {
        const double lo = total * (double)s / (double)k, hi = s + 1 == k ? total : total * (double)(s + 1) / (double)k;
        const double mid = 0.5 * (lo + hi);
        while (first + 1 < n && start[first + 1] <= lo)
            ++first;
        /* the intensity and area are exact sums over the part's pieces; the
         * position is their power-weighted centroid when they all lie in the
         * plane of the piece holding the midpoint, else that piece's centroid */
        double inten[3] = {0.0, 0.0, 0.0}, area = 0.0, sum_w = 0.0, centroid[3] = {0.0, 0.0, 0.0}, at_c[3] = {0, 0, 0};
        size_t at = first;
        int coplanar = 1;
        for (size_t t = first; t < n && start[t] < hi; ++t) {
            const double w = start[t + 1] - start[t];
            const double a0 = fmax(lo, start[t]), a1 = fmin(hi, start[t + 1]);
            if (!(w > 0.0) || !(a1 > a0))
                continue;
            const lpv_emitter_tri *tr = &list->tris[t];
            const double frac = (a1 - a0) / w;
            for (int c = 0; c < 3; ++c)
                inten[c] += (double)tr->emission[c] * tr->area * frac;
            area += tr->area * frac;
            double pc[3];
            patch_centroid(tr, (a0 - start[t]) / w, (a1 - start[t]) / w, pc);
            for (int i = 0; i < 3; ++i)
                centroid[i] += pc[i] * (a1 - a0);
            sum_w += a1 - a0;
            if (start[t] <= mid && mid < start[t + 1]) {
                at = t;
                memcpy(at_c, pc, sizeof at_c);
            }
        }
        const lpv_emitter_tri *ta = &list->tris[at];
        for (size_t t = first; t < n && start[t] < hi && coplanar; ++t) {
            const lpv_emitter_tri *tr = &list->tris[t];
            double cosn = 0.0, dist = 0.0, scale = sqrt(ta->area) + sqrt(tr->area);
            for (int i = 0; i < 3; ++i) {
                cosn += (double)tr->normal[i] * ta->normal[i];
                for (int v = 0; v < 3; ++v)
                    dist = fmax(dist, fabs(((double)tr->p[v][0] - ta->p[0][0]) * ta->normal[0] +
                                           ((double)tr->p[v][1] - ta->p[0][1]) * ta->normal[1] +
                                           ((double)tr->p[v][2] - ta->p[0][2]) * ta->normal[2]));
            }
            coplanar = cosn > 0.9999 && dist <= 1e-4 * scale;
        }
        lpv_area_sample *o = &out[s];
        for (int i = 0; i < 3; ++i) {
            o->position[i] = (float)(coplanar && sum_w > 0.0 ? centroid[i] / sum_w : at_c[i]);
            o->normal[i] = ta->normal[i];
            o->intensity[i] = (float)inten[i];
        }
        o->area = (float)area;
    }
    free(start);
    return k;
}
