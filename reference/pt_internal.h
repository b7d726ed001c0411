/*
 * pt_internal.h - the reference's state and the helpers its files share
 * (pt_build.c: the scene copy and the Embree BVH; pt_rays.c: rays against
 * it; pt_material.c: the surface at a hit; pt_lights.c: punctual lights and
 * the emitters' next-event estimation; pt_paths.c: the path estimator;
 * pt.c: the public estimates, points and images, over worker threads).
 * Not seen outside reference/: pt.h is the interface. The small helpers are
 * static inline so that every file computes with the same code.
 */
#ifndef LPV_REFERENCE_PT_INTERNAL_H
#define LPV_REFERENCE_PT_INTERNAL_H

#include "pt.h"

#include <embree3/rtcore.h>
#include <math.h>
#include <stdint.h>

#define PT_PI 3.14159265358979323846

typedef struct ref_tri {
    float p0[3], e1[3], e2[3]; /* corners p0, p0 + e1, p0 + e2 */
    float vn[3][3];            /* vertex normals (unit; the front normal where the file's was bad) */
    float uv[3][2], uv1[3][2]; /* TEXCOORD_0, TEXCOORD_1 */
    float color[3][4];         /* COLOR_0 (rgba) at the corners; 1 where the draw has none */
    float front[3]; /* unit geometric normal of the front side (the emitting one, or the first of two) */
    int material;   /* -1 = none: black, not emissive */
} ref_tri;

typedef struct ref_material {
    int emits;
    int sides;   /* emitting sides: 2 double-sided (glTF doubleSided: the back emits L_e too), else 1 */
} ref_material;

struct lpv_ref {
    RTCDevice device;
    RTCScene scene; /* NULL when there are no triangles */
    ref_tri *tris;
    uint32_t tri_count;
    ref_material *materials;
    uint32_t material_count;
    /* copies of the scene's materials and textures (nothing else): a hit's
     * albedo and emission follow core/material_sample.h, the rules lpvd's
     * shaders and CPU samplers follow */
    lpv_scene look;
    lpv_light *lights;
    uint32_t light_count;
    /* emissive triangles for next-event estimation, by emitted power */
    uint32_t *emitters;  /* triangle indices */
    double *emitter_cdf; /* emitter_count + 1 running sums of (L_r + L_g + L_b) A x sides */
    uint32_t emitter_count;
    int emitters_are_lights;
    int max_bounces; /* converged paths' cap */
    int threads;
    uint64_t seed;
    float eps;
    int has_blend; /* some material is alphaMode BLEND (its rays draw whether they pass) */
};

/* ---- small vector helpers ---------------------------------------------- */

static inline float dot3(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void cross3(const float a[3], const float b[3], float out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Normalises v into out; returns 0 if v is not unit-able (out untouched). */
static inline int unit3(const float v[3], float out[3])
{
    float l = sqrtf(dot3(v, v));
    if (!(l > 1e-12f) || !isfinite(l))
        return 0;
    for (int i = 0; i < 3; ++i)
        out[i] = v[i] / l;
    return 1;
}

static inline int finite3(const float v[3])
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

/* ---- RNG: PCG32 (O'Neill), one stream per (index, sample) ---------------- */

typedef struct pcg32 {
    uint64_t state, inc;
} pcg32;

static inline uint32_t pcg32_next(pcg32 *r)
{
    uint64_t old = r->state;
    r->state = old * 6364136223846793005ULL + r->inc;
    uint32_t xs = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = (uint32_t)(old >> 59u);
    return (xs >> rot) | (xs << ((-rot) & 31u));
}

static inline uint64_t splitmix64(uint64_t x)
{
    x += 0x9E3779B97F4A7C15ULL;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
    return x ^ (x >> 31);
}

static inline void pcg32_seed(pcg32 *r, uint64_t seed, uint64_t index, uint64_t sample)
{
    uint64_t initstate = splitmix64(index ^ splitmix64(seed));
    uint64_t initseq = splitmix64(sample + 0x632BE59BD9B4E019ULL * seed);
    r->state = 0;
    r->inc = (initseq << 1u) | 1u;
    pcg32_next(r);
    r->state += initstate;
    pcg32_next(r);
}

static inline float pcg32_float(pcg32 *r)
{
    return (float)(pcg32_next(r) >> 8) * (1.0f / 16777216.0f);
}

/* The uv sets (and, color not NULL, COLOR_0's rgba) at barycentrics
 * (1 - b1 - b2, b1, b2). */
static inline void tri_uv(const ref_tri *t, float b1, float b2, float uv0[2], float uv1[2], float *color)
{
    const float w = 1.0f - b1 - b2;
    for (int i = 0; i < 2; ++i) {
        uv0[i] = w * t->uv[0][i] + b1 * t->uv[1][i] + b2 * t->uv[2][i];
        uv1[i] = w * t->uv1[0][i] + b1 * t->uv1[1][i] + b2 * t->uv1[2][i];
    }
    for (int i = 0; color && i < 4; ++i)
        color[i] = w * t->color[0][i] + b1 * t->color[1][i] + b2 * t->color[2][i];
}

static inline double tri_area(const ref_tri *t)
{
    float c[3];
    cross3(t->e1, t->e2, c);
    return 0.5 * sqrt((double)dot3(c, c));
}

/* How a ray treats BLEND surfaces (alpha is coverage: a fraction alpha of
 * the surface is there, 1 - alpha of the light passes; docs/scenes.md
 * "Alpha"). MASK cut-outs are cut in every mode. */
typedef enum ref_blend {
    REF_BLEND_DRAW = 0, /* a path's ray: it stops at the surface with probability alpha (its draw) */
    REF_BLEND_HIT,      /* a camera ray that composites the layers itself: every BLEND texel of alpha > 0 is hit */
    REF_BLEND_SKIP,     /* a query for the opaque surface behind (the points lpvd's G-buffer holds) */
    REF_BLEND_TRANSMIT, /* a shadow ray: passes, taking the product of 1 - alpha along it */
} ref_blend;

typedef struct hit {
    float p[3];
    float ng[3];    /* unit geometric normal on the side the ray came from */
    float ns[3];    /* unit shading normal on that side */
    int front;      /* 1 if the ray arrived on the front side */
    uint32_t tri;
    float u, v;
    float t;
} hit;

/* ---- shared between the files ---------------------------------------------- */

/* pt_rays.c: Embree's filter for both ray kinds (installed by pt_build.c),
 * the first surface along a ray, and the light passing along a shadow ray. */
void lpv_pt_alpha_filter(const struct RTCFilterFunctionNArguments *args);
int lpv_pt_intersect(const lpv_ref *r, const float org[3], const float dir[3], float tmin, float tmax,
                     ref_blend blend, uint32_t salt, hit *h);
float lpv_pt_transmitted(const lpv_ref *r, const float org[3], const float dir[3], float tmax);

/* pt_material.c: the material at a hit. */
void lpv_pt_hit_albedo(const lpv_ref *r, const hit *h, float out[3]);
int lpv_pt_hit_unlit(const lpv_ref *r, const hit *h, float out[3]);
float lpv_pt_hit_occlusion(const lpv_ref *r, const hit *h);
int lpv_pt_hit_emission(const lpv_ref *r, const hit *h, float out[3]);

/* pt_lights.c: direct irradiance from the punctual lights, and one sample
 * of the emitters' (next-event estimation). */
void lpv_pt_direct(const lpv_ref *r, const float p[3], const float ns[3], const float ng[3], float out[3]);
void lpv_pt_emitter_direct(const lpv_ref *r, pcg32 *rng, const float p[3], const float ns[3], const float ng[3],
                           double out[3]);

/* pt_paths.c: E_ind and its standard error at one point. */
void lpv_pt_estimate_mode(const lpv_ref *r, uint64_t index, const float p[3], const float ns[3], const float ng[3],
                          int bounces, int samples, int lights_mode, int with_direct, float e[3], float se[3]);
void lpv_pt_estimate(const lpv_ref *r, uint64_t index, const float p[3], const float ns[3], const float ng[3],
                     int bounces, int samples, float e[3], float se[3]);

#endif /* LPV_REFERENCE_PT_INTERNAL_H */
