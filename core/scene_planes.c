/*
 * scene_planes.c - see scene_planes.h.
 */
#include "scene_planes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct plane_area {
    float n[3];
    double area;
} plane_area;

/* By the normal's bits: equal normals end up next to each other. */
static int by_normal(const void *a, const void *b)
{
    return memcmp(((const plane_area *)a)->n, ((const plane_area *)b)->n, sizeof(float[3]));
}

/* Largest area first; equal areas by the normal's bits (a stable order). */
static int by_area(const void *a, const void *b)
{
    const plane_area *x = a, *y = b;
    if (x->area != y->area)
        return x->area > y->area ? -1 : 1;
    return by_normal(a, b);
}

static int on_axis(const float n[3])
{
    int zeros = (n[0] == 0.0f) + (n[1] == 0.0f) + (n[2] == 0.0f);
    return zeros >= 2;
}

static int within_tolerance(const float a[3], const float b[3])
{
    return fabsf(a[0] - b[0]) <= LPV_LOOKUP_PLANE_TOLERANCE && fabsf(a[1] - b[1]) <= LPV_LOOKUP_PLANE_TOLERANCE &&
           fabsf(a[2] - b[2]) <= LPV_LOOKUP_PLANE_TOLERANCE;
}

/* Whether t is, for the lookup (within LPV_LOOKUP_PLANE_TOLERANCE per
 * component), an axis or one of the first count normals: the opposite sides
 * of a block are one plane normal and its negation. So no pixel's normal
 * matches an axis and a plane, which lookup.glsl's search relies on. */
static int listed(const float (*out)[3], int count, const float t[3])
{
    for (int a = 0; a < 6; ++a) {
        float axis[3] = {0.0f, 0.0f, 0.0f};
        axis[a >> 1] = (a & 1) ? -1.0f : 1.0f;
        if (within_tolerance(axis, t))
            return 1;
    }
    for (int i = 0; i < count; ++i)
        if (within_tolerance(out[i], t))
            return 1;
    return 0;
}

int lpv_scene_plane_normals(const lpv_scene *scene, float (*out)[3], int max)
{
    const uint32_t triangles = scene->index_count / 3;
    if (max < 2 || triangles == 0)
        return 0;
    plane_area *p = malloc((size_t)triangles * sizeof *p);
    if (!p)
        return -1;
    size_t n = 0;
    for (uint32_t d = 0; d < scene->draw_count; ++d) {
        const lpv_draw *dr = &scene->draws[d];
        for (uint32_t t = 0; t + 2 < dr->index_count; t += 3) {
            const lpv_vertex *v[3];
            float front[3];
            double area;
            if (!lpv_scene_triangle(scene, dr->first_index + t, v, front, &area))
                continue;
            if (memcmp(v[0]->normal, v[1]->normal, sizeof v[0]->normal) != 0 ||
                memcmp(v[0]->normal, v[2]->normal, sizeof v[0]->normal) != 0 || on_axis(v[0]->normal))
                continue;
            memcpy(p[n].n, v[0]->normal, sizeof p[n].n);
            p[n].n[0] += 0.0f, p[n].n[1] += 0.0f, p[n].n[2] += 0.0f; /* -0 as +0, one key per normal */
            p[n++].area = area;
        }
    }
    qsort(p, n, sizeof *p, by_normal);
    size_t m = 0;
    for (size_t i = 0; i < n; ++i) {
        if (m > 0 && by_normal(&p[m - 1], &p[i]) == 0)
            p[m - 1].area += p[i].area;
        else
            p[m++] = p[i];
    }
    qsort(p, m, sizeof *p, by_area);
    int count = 0;
    for (size_t i = 0; i < m && count + 2 <= max; ++i) {
        /* as the G-buffer normalises it (a file's normal may be off unit length) */
        const double len = sqrt((double)p[i].n[0] * p[i].n[0] + (double)p[i].n[1] * p[i].n[1] +
                                (double)p[i].n[2] * p[i].n[2]);
        if (!(len > 1e-8))
            continue;
        for (int side = 0; side < 2; ++side) {
            float t[3];
            for (int k = 0; k < 3; ++k)
                t[k] = (float)((side ? -p[i].n[k] : p[i].n[k]) / len) + 0.0f;
            if (!listed(out, count, t))
                memcpy(out[count++], t, sizeof t);
        }
    }
    free(p);
    return count;
}
