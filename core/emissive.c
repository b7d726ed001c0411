/* emissive.c - see emissive.h. */
#include "emissive.h"
#include "material_sample.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int material_emits(const lpv_scene *s, int m)
{
    if (m < 0 || (uint32_t)m >= s->material_count)
        return 0;
    const float *e = s->materials[m].emission;
    return (e[0] > 0.0f || e[1] > 0.0f || e[2] > 0.0f) && isfinite(e[0] + e[1] + e[2]);
}

/* The triangles' mean emitted radiance (their emissiveTexture's mean,
 * core/material_sample.h: up to thousands of texture samples each), kept
 * from a walk for the next one over the same scene. */
typedef struct emission_memo {
    float (*e)[3];
    size_t n, cap, next;
    int ready; /* filled: the next walk reads it */
    int oom;
} emission_memo;

/* Triangle i's mean emitted radiance into e: from the memo once it is
 * ready, else computed (and kept when there is a memo). */
static void emission_of(const lpv_scene *s, const lpv_material *m, const lpv_vertex *const v[3],
                        emission_memo *memo, float e[3])
{
    if (memo && memo->ready && memo->next < memo->n) {
        memcpy(e, memo->e[memo->next++], 3 * sizeof(float));
        return;
    }
    lpv_triangle_emission(s, m, v, e);
    if (!memo || memo->ready || memo->oom)
        return;
    if (memo->n == memo->cap) {
        size_t cap = memo->cap ? 2 * memo->cap : 256;
        float(*grown)[3] = realloc(memo->e, cap * sizeof *grown);
        if (!grown) {
            memo->oom = 1; /* the next walk computes again */
            return;
        }
        memo->e = grown;
        memo->cap = cap;
    }
    memcpy(memo->e[memo->n++], e, 3 * sizeof(float));
}

static double emission_weight(const float e[3])
{
    return (double)e[0] + e[1] + e[2];
}

/* Calls fn for every emitting side of every non-degenerate triangle of every
 * emissive draw, in draw order: its front, then (double-sided material, as
 * glTF's doubleSided means) its back with the normal turned. Returns 0, or
 * the first non-zero value fn returned (stop). */
typedef int (*triangle_fn)(void *ud, const float *p[3], const float n[3], double area, const float e[3]);

static int for_each_emissive_triangle(const lpv_scene *s, triangle_fn fn, void *ud, emission_memo *memo)
{
    if (memo && !memo->oom && memo->n) {
        memo->ready = 1;
        memo->next = 0;
    }
    for (uint32_t d = 0; d < s->draw_count; ++d) {
        const lpv_draw *dr = &s->draws[d];
        if (!material_emits(s, dr->material))
            continue;
        const lpv_material *m = &s->materials[dr->material];
        const int sides = lpv_material_emitting_sides(m);
        for (uint32_t t = 0; t + 3 <= dr->index_count; t += 3) {
            const lpv_vertex *v[3];
            const float *p[3];
            float n[3], e[3];
            double area;
            if (dr->first_index + t + 3 > s->index_count || !lpv_scene_triangle(s, dr->first_index + t, v, n, &area))
                continue;
            for (int k = 0; k < 3; ++k)
                p[k] = v[k]->position;
            emission_of(s, m, v, memo, e);
            for (int side = 0; side < sides; ++side) {
                if (side)
                    for (int i = 0; i < 3; ++i)
                        n[i] = -n[i];
                int rc = fn(ud, p, n, area, e);
                if (rc)
                    return rc;
            }
        }
    }
    return 0;
}

static int add_flux(void *ud, const float *p[3], const float n[3], double area, const float e[3])
{
    (void)p;
    (void)n;
    double *flux = ud;
    for (int c = 0; c < 3; ++c)
        flux[c] += M_PI * e[c] * area;
    return 0;
}

void lpv_emissive_total_flux(const lpv_scene *s, double flux[3])
{
    flux[0] = flux[1] = flux[2] = 0.0;
    for_each_emissive_triangle(s, add_flux, flux, NULL);
}

static int add_weight(void *ud, const float *p[3], const float n[3], double area, const float e[3])
{
    (void)p;
    (void)n;
    *(double *)ud += emission_weight(e) * area;
    return 0;
}

typedef struct sampler {
    double total_weight;
    size_t target, count, max;
    lpv_vpl *out;
} sampler;

/* Places this triangle's share of the samples on the R2 low-discrepancy
 * sequence (generalised golden ratio), warped uniformly onto the triangle. */
static int sample_triangle(void *ud, const float *p[3], const float n[3], double area, const float e[3])
{
    sampler *sm = ud;
    const double a1 = 0.7548776662466927, a2 = 0.5698402909980532;
    size_t k_count = (size_t)floor((double)sm->target * emission_weight(e) * area / sm->total_weight + 0.5);
    if (k_count == 0)
        k_count = 1;
    if (sm->count + k_count > sm->max)
        k_count = sm->max - sm->count;
    if (k_count == 0)
        return 1; /* out of room */
    for (size_t k = 0; k < k_count; ++k) {
        double u = fmod(0.5 + a1 * (double)(k + 1), 1.0);
        double v = fmod(0.5 + a2 * (double)(k + 1), 1.0);
        double r = sqrt(u);
        double b0 = 1.0 - r, b1 = r * (1.0 - v), b2 = r * v;
        lpv_vpl *o = &sm->out[sm->count++];
        memset(o, 0, sizeof *o);
        for (int i = 0; i < 3; ++i) {
            o->position[i] = (float)(b0 * p[0][i] + b1 * p[1][i] + b2 * p[2][i]);
            o->normal[i] = n[i];
            o->flux[i] = (float)(M_PI * e[i] * area / (double)k_count);
        }
        o->position[3] = 1.0f;
    }
    return 0;
}

size_t lpv_emissive_sample(const lpv_scene *s, size_t target, lpv_vpl *out, size_t max)
{
    sampler sm = {.target = target, .max = max, .out = out};
    emission_memo memo = {0}; /* the weights' walk computes each triangle's emission, the samples' reads it */
    for_each_emissive_triangle(s, add_weight, &sm.total_weight, &memo);
    if (!(sm.total_weight > 0.0) || target == 0) {
        free(memo.e);
        return 0;
    }
    for_each_emissive_triangle(s, sample_triangle, &sm, &memo);
    free(memo.e);
    return sm.count;
}
