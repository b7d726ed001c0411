/*
 * pt_rays.c - rays against the reference's BVH: Embree's alpha filter (MASK
 * cut-outs, BLEND coverage as each ray kind treats it), the first surface
 * along a ray, the light a shadow ray lets through, and the camera's primary
 * rays (pt.h lpv_ref_first_hit, lpv_ref_first_surface, lpv_ref_pixel_ray).
 * The one place that talks to Embree after the build.
 */
#include "pt_internal.h"

#include "lpv_shared.h" /* lpv_hash_u32 */
#include "material_sample.h"

#include <string.h>

/* ---- rays ---------------------------------------------------------------- */

#define REF_SEEN_MAX 16

/* The context Embree hands the filter: its own first, then how the ray
 * treats BLEND surfaces. */
typedef struct ref_context {
    struct RTCIntersectContext base;
    ref_blend blend;
    uint32_t salt;   /* REF_BLEND_DRAW: the path's draw for this ray */
    float transmit;  /* REF_BLEND_TRANSMIT: the product of 1 - alpha of the BLEND texels passed */
    /* REF_BLEND_TRANSMIT: the triangles counted (Embree may report a hit
     * twice, e.g. a triangle split between nodes) */
    unsigned seen[REF_SEEN_MAX];
    int seen_count;
} ref_context;

/* Embree's filter for both ray kinds: a hit on a texel where the material
 * is not there is no hit, as lpvd's shaders cut it (core/material_sample.h
 * lpv_material_covers_at): alpha below a MASK cutoff; for BLEND as the
 * ray's context says. Installed only when some material cuts or blends. */
void lpv_pt_alpha_filter(const struct RTCFilterFunctionNArguments *args)
{
    /* RTCHitN's layout (rtcore_ray.h's RTCHitN_u/_v/_primID, C++ only): N
     * floats each of Ng x, y, z, u, v, then N primIDs */
    const float *hf = (const float *)args->hit;
    const unsigned *hu = (const unsigned *)args->hit;
    const lpv_ref *r = args->geometryUserPtr;
    ref_context *ctx = (ref_context *)args->context;
    const unsigned N = args->N;
    for (unsigned i = 0; i < N; ++i) {
        if (args->valid[i] != -1)
            continue;
        const unsigned prim = hu[5 * N + i];
        if (prim >= r->tri_count)
            continue;
        const ref_tri *tr = &r->tris[prim];
        if (tr->material < 0)
            continue;
        const lpv_material *m = &r->look.materials[tr->material];
        float uv0[2], uv1[2], color[4];
        tri_uv(tr, hf[3 * N + i], hf[4 * N + i], uv0, uv1, color);
        if (m->alpha_mode == LPV_ALPHA_BLEND && ctx->blend == REF_BLEND_TRANSMIT) {
            int seen = 0;
            for (int k = 0; k < ctx->seen_count; ++k)
                seen |= ctx->seen[k] == prim;
            if (!seen) {
                const float a = lpv_material_alpha_at(&r->look, m, uv0, uv1, color[3]);
                ctx->transmit *= a > 0.0f ? (a < 1.0f ? 1.0f - a : 0.0f) : 1.0f; /* NaN: passes */
                if (ctx->seen_count < REF_SEEN_MAX)
                    ctx->seen[ctx->seen_count++] = prim;
            }
            args->valid[i] = ctx->transmit > 0.0f ? 0 : -1; /* opaque where nothing passes any more */
            continue;
        }
        const float u = ctx->blend == REF_BLEND_HIT    ? 0.0f
                        : ctx->blend == REF_BLEND_SKIP ? INFINITY
                                                       : lpv_hash_unit(lpv_hash_u32(ctx->salt ^ lpv_hash_u32(prim)));
        if (!lpv_material_covers_at(&r->look, m, uv0, uv1, color[3], u))
            args->valid[i] = 0;
    }
}

/* The first surface along the ray in [tmin, tmax]; blend and salt: how it
 * treats BLEND surfaces (ref_blend). */
int lpv_pt_intersect(const lpv_ref *r, const float org[3], const float dir[3], float tmin, float tmax,
                     ref_blend blend, uint32_t salt, hit *h)
{
    if (!r->scene)
        return 0;
    ref_context ctx = {.blend = blend, .salt = salt, .transmit = 1.0f};
    rtcInitIntersectContext(&ctx.base);
    struct RTCRayHit rh;
    memset(&rh, 0, sizeof rh);
    rh.ray.org_x = org[0];
    rh.ray.org_y = org[1];
    rh.ray.org_z = org[2];
    rh.ray.dir_x = dir[0];
    rh.ray.dir_y = dir[1];
    rh.ray.dir_z = dir[2];
    rh.ray.tnear = tmin;
    rh.ray.tfar = tmax;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(r->scene, &ctx.base, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID || rh.hit.primID >= r->tri_count)
        return 0;
    const ref_tri *tr = &r->tris[rh.hit.primID];
    float u = rh.hit.u, v = rh.hit.v, w = 1.0f - u - v;
    h->tri = rh.hit.primID;
    h->u = u;
    h->v = v;
    h->t = rh.ray.tfar;
    for (int i = 0; i < 3; ++i)
        h->p[i] = tr->p0[i] + u * tr->e1[i] + v * tr->e2[i];
    float side = dot3(tr->front, dir) < 0.0f ? 1.0f : -1.0f;
    h->front = side > 0.0f;
    float ns[3];
    for (int i = 0; i < 3; ++i) {
        h->ng[i] = side * tr->front[i];
        ns[i] = side * (w * tr->vn[0][i] + u * tr->vn[1][i] + v * tr->vn[2][i]);
    }
    if (!unit3(ns, h->ns) || dot3(h->ns, h->ng) <= 0.0f)
        memcpy(h->ns, h->ng, sizeof h->ns);
    return 1;
}

/* The fraction of light that passes from org along dir to tmax: 0 behind
 * an opaque surface, else the product of 1 - alpha of the BLEND surfaces
 * between (1 with none). */
float lpv_pt_transmitted(const lpv_ref *r, const float org[3], const float dir[3], float tmax)
{
    if (!r->scene)
        return 1.0f;
    ref_context ctx = {.blend = REF_BLEND_TRANSMIT, .transmit = 1.0f};
    rtcInitIntersectContext(&ctx.base);
    struct RTCRay ray;
    memset(&ray, 0, sizeof ray);
    ray.org_x = org[0];
    ray.org_y = org[1];
    ray.org_z = org[2];
    ray.dir_x = dir[0];
    ray.dir_y = dir[1];
    ray.dir_z = dir[2];
    ray.tnear = 0.0f;
    ray.tfar = tmax;
    ray.mask = 0xFFFFFFFFu;
    rtcOccluded1(r->scene, &ctx.base, &ray);
    return ray.tfar < 0.0f ? 0.0f : ctx.transmit;
}

int lpv_ref_first_hit(const lpv_ref *r, const float org[3], const float dir[3], float tmin, float tmax, float *t,
                      float p[3])
{
    hit h;
    if (!r || !finite3(org) || !finite3(dir) || !lpv_pt_intersect(r, org, dir, tmin, tmax, REF_BLEND_SKIP, 0u, &h))
        return 0;
    if (t)
        *t = h.t;
    if (p)
        memcpy(p, h.p, sizeof h.p);
    return 1;
}

int lpv_ref_first_surface(const lpv_ref *r, const float org[3], const float dir[3], float tmin, float tmax, float *t,
                          float p[3], float n[3])
{
    hit h;
    if (!r || !finite3(org) || !finite3(dir) || !lpv_pt_intersect(r, org, dir, tmin, tmax, REF_BLEND_SKIP, 0u, &h))
        return 0;
    if (t)
        *t = h.t;
    if (p)
        memcpy(p, h.p, sizeof h.p);
    if (n)
        memcpy(n, h.ns, sizeof h.ns);
    return 1;
}

void lpv_ref_pixel_ray(const lpv_view *v, int x, int y, float org[3], float dir[3], float *tmin, float *tmax)
{
    /* The inverse of lpv_view_project (core/view.c): right = forward x up,
     * true up = right x forward, pixel (0, 0) at the top-left. */
    float f[3], r[3], u[3];
    if (!unit3(v->forward, f)) {
        f[0] = f[1] = 0.0f;
        f[2] = -1.0f;
    }
    cross3(f, v->up, r);
    if (!unit3(r, r)) {
        r[0] = 1.0f;
        r[1] = r[2] = 0.0f;
    }
    cross3(r, f, u);
    float aspect = (float)v->width / (float)v->height;
    float ndc_x = ((float)x + 0.5f) / (float)v->width * 2.0f - 1.0f;
    float ndc_y = 1.0f - ((float)y + 0.5f) / (float)v->height * 2.0f;
    float zn = v->znear > 0.0f ? v->znear : 0.0f, zf = v->zfar > 0.0f ? v->zfar : INFINITY;
    if (v->orthographic) {
        for (int i = 0; i < 3; ++i) {
            org[i] = v->eye[i] + ndc_x * v->ymag * aspect * r[i] + ndc_y * v->ymag * u[i];
            dir[i] = f[i];
        }
        *tmin = zn;
        *tmax = zf;
        return;
    }
    float th = tanf(0.5f * v->yfov), d[3];
    for (int i = 0; i < 3; ++i) {
        org[i] = v->eye[i];
        d[i] = f[i] + ndc_x * th * aspect * r[i] + ndc_y * th * u[i];
    }
    float len = sqrtf(dot3(d, d));
    for (int i = 0; i < 3; ++i)
        dir[i] = d[i] / len;
    float cz = dot3(dir, f); /* depth along forward per unit t */
    *tmin = zn / cz;
    *tmax = zf / cz;
}

