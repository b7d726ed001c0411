/*
 * pt_paths.c - the path estimator: cosine-weighted sampling, one path's
 * sample of E_ind (emission seen by chance, or the emitters as lights with
 * next-event estimation; Russian roulette for converged light) and the mean
 * and standard error over a point's samples. The Monte Carlo itself, apart
 * from how points and pixels are handed out (pt.c).
 */
#include "pt_internal.h"

#include <string.h>

/* ---- sampling ------------------------------------------------------------ */

/* Orthonormal basis around unit n (Duff et al. 2017). */
static void basis(const float n[3], float t[3], float b[3])
{
    float sign = copysignf(1.0f, n[2]);
    float a = -1.0f / (sign + n[2]);
    float c = n[0] * n[1] * a;
    t[0] = 1.0f + sign * n[0] * n[0] * a;
    t[1] = sign * c;
    t[2] = -sign * n[0];
    b[0] = c;
    b[1] = sign + n[1] * n[1] * a;
    b[2] = -n[1];
}

/* Cosine-weighted direction around unit n (pdf cos / pi). */
static void sample_cosine(pcg32 *r, const float n[3], float out[3])
{
    float u1 = pcg32_float(r), u2 = pcg32_float(r);
    float rad = sqrtf(u1), phi = (float)(2.0 * PT_PI) * u2;
    float x = rad * cosf(phi), y = rad * sinf(phi), z = sqrtf(fmaxf(0.0f, 1.0f - u1));
    float t[3], b[3];
    basis(n, t, b);
    for (int i = 0; i < 3; ++i)
        out[i] = x * t[i] + y * b[i] + z * n[i];
}

/* ---- the estimator --------------------------------------------------------- */

/* One sample of E_ind(p, ns, bounces) / pi, i.e. the radiance L arriving along
 * one cosine-distributed direction, with next-event estimation at every hit. */
static void sample_path(const lpv_ref *r, pcg32 *rng, const float p_in[3], const float ns_in[3], const float ng_in[3],
                        int bounces, double out[3])
{
    float p[3], ns[3], ng[3], thr[3] = {1.0f, 1.0f, 1.0f};
    memcpy(p, p_in, sizeof p);
    memcpy(ns, ns_in, sizeof ns);
    memcpy(ng, ng_in, sizeof ng);
    out[0] = out[1] = out[2] = 0.0;
    const int converged = bounces == LPV_REF_BOUNCES_CONVERGED;
    if (converged)
        bounces = r->max_bounces;
    for (int depth = 1; depth <= bounces; ++depth) {
        float dir[3], org[3];
        if (converged && depth > LPV_REF_RR_START) {
            float q = fminf(0.95f, fmaxf(thr[0], fmaxf(thr[1], thr[2])));
            if (!(pcg32_float(rng) < q))
                break;
            for (int i = 0; i < 3; ++i)
                thr[i] /= q;
        }
        sample_cosine(rng, ns, dir);
        if (!(dot3(dir, ng) > 0.0f))
            break; /* below the surface itself (shading normal != geometric) */
        for (int i = 0; i < 3; ++i)
            org[i] = p[i] + r->eps * ng[i];
        hit h;
        if (!lpv_pt_intersect(r, org, dir, 0.0f, INFINITY, REF_BLEND_DRAW, r->has_blend ? pcg32_next(rng) : 0u, &h))
            break;
        float alb[3], ed[3] = {0.0f, 0.0f, 0.0f};
        lpv_pt_hit_albedo(r, &h, alb);
        float le[3] = {0.0f, 0.0f, 0.0f};
        lpv_pt_hit_emission(r, &h, le);
        if (alb[0] > 0.0f || alb[1] > 0.0f || alb[2] > 0.0f)
            lpv_pt_direct(r, h.p, h.ns, h.ng, ed);
        for (int i = 0; i < 3; ++i)
            out[i] += (double)thr[i] * ((double)le[i] + (double)alb[i] / PT_PI * (double)ed[i]);
        if (depth == bounces)
            break;
        for (int i = 0; i < 3; ++i)
            thr[i] *= alb[i];
        if (!(thr[0] > 0.0f || thr[1] > 0.0f || thr[2] > 0.0f))
            break;
        memcpy(p, h.p, sizeof p);
        memcpy(ns, h.ns, sizeof ns);
        memcpy(ng, h.ng, sizeof ng);
    }
}

/* With the emissive surfaces as lights (next-event estimation, never hit
 * by chance): one sample of (with_direct: the emitters' direct irradiance at
 * p, plus) pi x the radiance arriving along one cosine-distributed direction
 * after 1..bounces diffuse reflections of direct light (punctual and
 * emitted) - already an irradiance, unlike sample_path's radiance. */
static void sample_path_lights(const lpv_ref *r, pcg32 *rng, const float p_in[3], const float ns_in[3],
                               const float ng_in[3], int bounces, int with_direct, double out[3])
{
    float p[3], ns[3], ng[3];
    double thr[3] = {1.0, 1.0, 1.0};
    memcpy(p, p_in, sizeof p);
    memcpy(ns, ns_in, sizeof ns);
    memcpy(ng, ng_in, sizeof ng);
    out[0] = out[1] = out[2] = 0.0;
    if (with_direct)
        lpv_pt_emitter_direct(r, rng, p, ns, ng, out);
    const int converged = bounces == LPV_REF_BOUNCES_CONVERGED;
    if (converged)
        bounces = r->max_bounces;
    for (int depth = 1; depth <= bounces; ++depth) {
        float dir[3], org[3];
        if (converged && depth > LPV_REF_RR_START) {
            double q = fmin(0.95, fmax(thr[0], fmax(thr[1], thr[2])));
            if (!((double)pcg32_float(rng) < q))
                break;
            for (int i = 0; i < 3; ++i)
                thr[i] /= q;
        }
        sample_cosine(rng, ns, dir);
        if (!(dot3(dir, ng) > 0.0f))
            break;
        for (int i = 0; i < 3; ++i)
            org[i] = p[i] + r->eps * ng[i];
        hit h;
        if (!lpv_pt_intersect(r, org, dir, 0.0f, INFINITY, REF_BLEND_DRAW, r->has_blend ? pcg32_next(rng) : 0u, &h))
            break;
        float alb[3], ed[3] = {0.0f, 0.0f, 0.0f};
        double ee[3] = {0.0, 0.0, 0.0};
        lpv_pt_hit_albedo(r, &h, alb);
        if (!(alb[0] > 0.0f || alb[1] > 0.0f || alb[2] > 0.0f))
            break;
        lpv_pt_direct(r, h.p, h.ns, h.ng, ed);
        lpv_pt_emitter_direct(r, rng, h.p, h.ns, h.ng, ee);
        /* E = pi L, L = albedo / pi * E_direct(q): pi cancels */
        for (int i = 0; i < 3; ++i) {
            thr[i] *= alb[i];
            out[i] += thr[i] * ((double)ed[i] + ee[i]);
        }
        memcpy(p, h.p, sizeof p);
        memcpy(ns, h.ns, sizeof ns);
        memcpy(ng, h.ng, sizeof ng);
    }
}

/* E_ind and its standard error at one point, from `samples` samples of the
 * streams (index, 0..samples-1). with_direct (emitters as lights only): add
 * the emitters' direct irradiance (the full image's lpv_pt_estimate). */
void lpv_pt_estimate_mode(const lpv_ref *r, uint64_t index, const float p[3], const float ns[3], const float ng[3],
                          int bounces, int samples, int lights_mode, int with_direct, float e[3], float se[3])
{
    double sum[3] = {0, 0, 0}, sq[3] = {0, 0, 0};
    for (int s = 0; s < samples; ++s) {
        pcg32 rng;
        pcg32_seed(&rng, r->seed, index, (uint64_t)s);
        double l[3];
        if (lights_mode)
            sample_path_lights(r, &rng, p, ns, ng, bounces, with_direct, l);
        else
            sample_path(r, &rng, p, ns, ng, bounces, l);
        for (int i = 0; i < 3; ++i) {
            double v = lights_mode ? l[i] : PT_PI * l[i];
            sum[i] += v;
            sq[i] += v * v;
        }
    }
    double n = (double)samples;
    for (int i = 0; i < 3; ++i) {
        double mean = sum[i] / n;
        double var = samples > 1 ? fmax(0.0, (sq[i] - sum[i] * mean) / (n - 1.0)) : 0.0;
        e[i] = (float)mean;
        se[i] = (float)sqrt(var / n);
    }
}

void lpv_pt_estimate(const lpv_ref *r, uint64_t index, const float p[3], const float ns[3], const float ng[3],
                     int bounces, int samples, float e[3], float se[3])
{
    lpv_pt_estimate_mode(r, index, p, ns, ng, bounces, samples, r->emitters_are_lights, 0, e, se);
}

