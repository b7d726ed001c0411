/*
 * pt_lights.c - direct light: the punctual lights' shadowed irradiance,
 * exactly (shaders/lights.glsl's falloffs), and the emissive surfaces' by
 * next-event estimation (pt.h lpv_ref_direct_irradiance,
 * lpv_ref_emitter_irradiance). Every path vertex and every pixel of the
 * full image takes its direct light from here.
 */
#include "pt_internal.h"

#include "material_sample.h"

/* ---- punctual lights (shaders/lights.glsl) -------------------------------- */

static float spot_factor(const lpv_light *li, const float travel[3])
{
    if (li->type != LPV_LIGHT_SPOT)
        return 1.0f;
    float cos_inner = cosf(li->inner_cone), cos_outer = cosf(li->outer_cone);
    float cd = dot3(travel, li->direction);
    float scale = 1.0f / fmaxf(1e-3f, cos_inner - cos_outer);
    float t = fminf(fmaxf((cd - cos_outer) * scale, 0.0f), 1.0f);
    return t * t;
}

static float range_window(const lpv_light *li, float dist)
{
    if (!(li->range > 0.0f))
        return 1.0f;
    float q = dist / li->range;
    float w = fminf(fmaxf(1.0f - q * q * q * q, 0.0f), 1.0f);
    return w * w;
}

/* Direct irradiance at p: ns is the cosine's normal, ng the side's geometric
 * normal (light behind it is cut off; shadow rays start eps along it). */
void lpv_pt_direct(const lpv_ref *r, const float p[3], const float ns[3], const float ng[3], float out[3])
{
    out[0] = out[1] = out[2] = 0.0f;
    float org[3];
    for (int i = 0; i < 3; ++i)
        org[i] = p[i] + r->eps * ng[i];
    for (uint32_t l = 0; l < r->light_count; ++l) {
        const lpv_light *li = &r->lights[l];
        float to_light[3], e, dist = INFINITY;
        if (li->type == LPV_LIGHT_DIRECTIONAL) {
            float neg[3] = {-li->direction[0], -li->direction[1], -li->direction[2]};
            if (!unit3(neg, to_light))
                continue;
            e = li->intensity;
        } else {
            float d[3] = {li->position[0] - p[0], li->position[1] - p[1], li->position[2] - p[2]};
            float dist2 = fmaxf(dot3(d, d), 1e-12f);
            dist = sqrtf(dist2);
            for (int i = 0; i < 3; ++i)
                to_light[i] = d[i] / dist;
            float travel[3] = {-to_light[0], -to_light[1], -to_light[2]};
            e = li->intensity * spot_factor(li, travel) * range_window(li, dist) / dist2;
        }
        float c = dot3(ns, to_light);
        if (!(e > 0.0f) || !isfinite(e) || !(c > 0.0f) || !(dot3(ng, to_light) > 0.0f))
            continue;
        float tmax = isfinite(dist) ? dist - 2.0f * r->eps : INFINITY;
        if (!(tmax > 0.0f))
            continue;
        const float pass = lpv_pt_transmitted(r, org, to_light, tmax);
        if (!(pass > 0.0f))
            continue;
        for (int i = 0; i < 3; ++i)
            out[i] += li->color[i] * e * c * pass;
    }
}

/* One sample of the irradiance at p from the emissive surfaces (their front
 * sides, and the backs of double-sided ones), by next-event estimation: a
 * triangle by emitted power, a uniform point on it, a shadow ray. Unbiased;
 * ns the cosine's normal, ng the side's. */
void lpv_pt_emitter_direct(const lpv_ref *r, pcg32 *rng, const float p[3], const float ns[3], const float ng[3],
                           double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    if (!r->emitter_count)
        return;
    const double total = r->emitter_cdf[r->emitter_count];
    double u = (double)pcg32_float(rng) * total;
    uint32_t lo = 0, hi = r->emitter_count - 1; /* first k with cdf[k + 1] > u */
    while (lo < hi) {
        uint32_t mid = (lo + hi) / 2;
        if (r->emitter_cdf[mid + 1] > u)
            hi = mid;
        else
            lo = mid + 1;
    }
    const ref_tri *tr = &r->tris[r->emitters[lo]];
    const ref_material *m = &r->materials[tr->material];
    float s1 = sqrtf(pcg32_float(rng)), s2 = pcg32_float(rng);
    float b1 = s1 * (1.0f - s2), b2 = s1 * s2, q[3], d[3], le[3], uv0[2], uv1[2];
    tri_uv(tr, b1, b2, uv0, uv1, NULL);
    lpv_material_emission_at(&r->look, &r->look.materials[tr->material], uv0, uv1, le); /* at q: its texture */
    for (int i = 0; i < 3; ++i) {
        q[i] = tr->p0[i] + b1 * tr->e1[i] + b2 * tr->e2[i];
        d[i] = q[i] - p[i];
    }
    float dist2 = dot3(d, d), dist = sqrtf(dist2), w[3];
    if (!(dist > 2.0f * r->eps) || !isfinite(dist))
        return;
    for (int i = 0; i < 3; ++i)
        w[i] = d[i] / dist;
    float cos_r = dot3(ns, w), cos_e = -dot3(tr->front, w);
    if (m->sides == 2) /* p sees the side it faces, which emits either way */
        cos_e = fabsf(cos_e);
    if (!(cos_r > 0.0f) || !(cos_e > 0.0f) || !(dot3(ng, w) > 0.0f))
        return;
    /* The shadow ray leaves eps off the surface and is aimed at q from
     * there: along w from the offset origin it would meet the emitter's
     * plane eps (ng . n_e) / cos_e short of q, inside the 2 eps margin only
     * when cos_e > 1/2, and so shadow itself at grazing angles (14 % of a
     * large emitter's light lost 1 m under it). */
    float org[3], to_q[3];
    for (int i = 0; i < 3; ++i) {
        org[i] = p[i] + r->eps * ng[i];
        to_q[i] = q[i] - org[i];
    }
    float len = sqrtf(dot3(to_q, to_q));
    if (!(len > 2.0f * r->eps))
        return;
    for (int i = 0; i < 3; ++i)
        to_q[i] /= len;
    const float pass = lpv_pt_transmitted(r, org, to_q, len - 2.0f * r->eps);
    if (!(pass > 0.0f))
        return;
    /* pdf per unit area of q: the triangle's share of the CDF (its mean
     * emission x area x sides) over its area, / total */
    const double pdf_area = (r->emitter_cdf[lo + 1] - r->emitter_cdf[lo]) / (total * tri_area(tr));
    if (!(pdf_area > 0.0))
        return;
    double g = (double)pass * cos_r * cos_e / dist2 / pdf_area;
    for (int i = 0; i < 3; ++i)
        out[i] = (isfinite(le[i]) && le[i] > 0.0f ? le[i] : 0.0f) * g;
}

void lpv_ref_direct_irradiance(const lpv_ref *r, const float p[3], const float n[3], float out_rgb[3])
{
    float nu[3];
    out_rgb[0] = out_rgb[1] = out_rgb[2] = 0.0f;
    if (!r || !finite3(p) || !unit3(n, nu))
        return;
    lpv_pt_direct(r, p, nu, nu, out_rgb);
}

int lpv_ref_emitter_irradiance(const lpv_ref *r, const float *points, const float *normals, size_t n, int samples,
                               float *out_rgb, float *out_stderr_rgb)
{
    if (!r || (n && (!points || !normals)) || samples < 1)
        return -1;
    for (size_t i = 0; i < n; ++i) {
        float nu[3];
        double sum[3] = {0, 0, 0}, sq[3] = {0, 0, 0};
        const float *p = &points[3 * i];
        if (finite3(p) && unit3(&normals[3 * i], nu))
            for (int s = 0; s < samples; ++s) {
                pcg32 rng;
                pcg32_seed(&rng, r->seed, (uint64_t)i, (uint64_t)s);
                double v[3];
                lpv_pt_emitter_direct(r, &rng, p, nu, nu, v);
                for (int c = 0; c < 3; ++c) {
                    sum[c] += v[c];
                    sq[c] += v[c] * v[c];
                }
            }
        for (int c = 0; c < 3; ++c) {
            double mean = sum[c] / samples;
            double var = samples > 1 ? fmax(0.0, (sq[c] - sum[c] * mean) / (samples - 1.0)) : 0.0;
            if (out_rgb)
                out_rgb[3 * i + (size_t)c] = (float)mean;
            if (out_stderr_rgb)
                out_stderr_rgb[3 * i + (size_t)c] = (float)sqrt(var / samples);
        }
    }
    return 0;
}

