/*
 * pt.c - the reference's public estimates (see pt.h and docs/reference.md):
 * irradiance at points and the indirect and full images, handed out to
 * worker threads in chunks; each pixel shades its first surface and
 * composites BLEND layers front to back. The other jobs live beside it:
 * pt_build.c (the scene and BVH), pt_rays.c, pt_material.c, pt_lights.c,
 * pt_paths.c (the estimator), sharing pt_internal.h.
 */
#include "pt_internal.h"

#include "material_sample.h"

#include <pthread.h>
#include <string.h>

#define PT_CHUNK 16 /* pixels or points a worker takes at a time */

/* ---- threading ------------------------------------------------------------- */

typedef struct job {
    const lpv_ref *ref;
    size_t count;
    size_t next;
    pthread_mutex_t lock;
    void (*item)(struct job *j, size_t i);
    /* points mode */
    const float *points, *normals;
    float *out, *out_se;
    /* image mode */
    const lpv_view *view;
    float *rgba, *rgba_se;
    int bounces, samples;
    int full;  /* image mode: the full frame */
} job;

static void *worker(void *arg)
{
    job *j = arg;
    for (;;) {
        pthread_mutex_lock(&j->lock);
        size_t begin = j->next;
        j->next = begin + PT_CHUNK < j->count ? begin + PT_CHUNK : j->count;
        size_t end = j->next;
        pthread_mutex_unlock(&j->lock);
        if (begin >= end)
            return NULL;
        for (size_t i = begin; i < end; ++i)
            j->item(j, i);
    }
}

static void run_job(job *j)
{
    int n = j->ref->threads;
    if ((size_t)n > (j->count + PT_CHUNK - 1) / PT_CHUNK)
        n = (int)((j->count + PT_CHUNK - 1) / PT_CHUNK);
    pthread_mutex_init(&j->lock, NULL);
    j->next = 0;
    pthread_t tid[256];
    int started = 0;
    for (int t = 1; t < n; ++t) {
        if (pthread_create(&tid[started], NULL, worker, j) != 0)
            break; /* the calling thread finishes the work alone */
        started++;
    }
    worker(j);
    for (int t = 0; t < started; ++t)
        pthread_join(tid[t], NULL);
    pthread_mutex_destroy(&j->lock);
}

static void point_item(job *j, size_t i)
{
    float e[3] = {0, 0, 0}, se[3] = {0, 0, 0}, nu[3];
    const float *p = &j->points[3 * i];
    if (finite3(p) && unit3(&j->normals[3 * i], nu))
        lpv_pt_estimate(j->ref, (uint64_t)i, p, nu, nu, j->bounces, j->samples, e, se);
    if (j->out)
        memcpy(&j->out[3 * i], e, sizeof e);
    if (j->out_se)
        memcpy(&j->out_se[3 * i], se, sizeof se);
}

int lpv_ref_irradiance(const lpv_ref *r, const float *points, const float *normals, size_t n, int bounces,
                       int samples, float *out_rgb, float *out_stderr_rgb)
{
    if (!r || (n && (!points || !normals)) || (bounces < 1 && bounces != LPV_REF_BOUNCES_CONVERGED) || samples < 1)
        return -1;
    if (!n)
        return 0;
    job j = {.ref = r, .count = n, .item = point_item, .points = points, .normals = normals, .out = out_rgb,
             .out_se = out_stderr_rgb, .bounces = bounces, .samples = samples};
    run_job(&j);
    return 0;
}

/* The pixel's light from surface h, out (W/(m^2 sr)) and its standard
 * error se, as lpvd's frame shows it (j->full) or its indirect term. */
static void shade_hit(job *j, size_t i, const hit *hp, float out[3], float out_se[3])
{
    const hit h = *hp;
    float alb[3], e[3] = {0, 0, 0}, se[3] = {0, 0, 0}, ed[3] = {0, 0, 0};
    lpv_pt_hit_albedo(j->ref, &h, alb);
    const float occ = lpv_pt_hit_occlusion(j->ref, &h);
    if (alb[0] > 0.0f || alb[1] > 0.0f || alb[2] > 0.0f) {
        if (j->full && occ < 1.0f) {
            /* the bounces alone take the occlusion: the emitters' direct
             * light apart (its own streams), then the bounces */
            lpv_pt_estimate_mode(j->ref, (uint64_t)i, h.p, h.ns, h.ng, j->bounces, j->samples, 1, 0, e, se);
            double em[3] = {0, 0, 0};
            for (int s = 0; s < j->samples; ++s) {
                pcg32 rng;
                pcg32_seed(&rng, j->ref->seed ^ 0x9e3779b97f4a7c15ull, (uint64_t)i, (uint64_t)s);
                double em_s[3];
                lpv_pt_emitter_direct(j->ref, &rng, h.p, h.ns, h.ng, em_s);
                for (int c = 0; c < 3; ++c)
                    em[c] += em_s[c] / j->samples;
            }
            for (int c = 0; c < 3; ++c) {
                e[c] = occ * e[c] + (float)em[c];
                se[c] *= occ;
            }
            lpv_pt_direct(j->ref, h.p, h.ns, h.ng, ed);
        } else if (j->full) { /* direct light (punctual exactly, emitters sampled) and the bounces */
            lpv_pt_estimate_mode(j->ref, (uint64_t)i, h.p, h.ns, h.ng, j->bounces, j->samples, 1, 1, e, se);
            lpv_pt_direct(j->ref, h.p, h.ns, h.ng, ed);
        } else {
            lpv_pt_estimate(j->ref, (uint64_t)i, h.p, h.ns, h.ng, j->bounces, j->samples, e, se);
            for (int c = 0; c < 3; ++c) {
                e[c] *= occ;
                se[c] *= occ;
            }
        }
    }
    float le[3] = {0.0f, 0.0f, 0.0f};
    if (j->full && !lpv_pt_hit_unlit(j->ref, &h, le))
        lpv_pt_hit_emission(j->ref, &h, le);
    for (int c = 0; c < 3; ++c) {
        out[c] = (float)(alb[c] / PT_PI) * (e[c] + ed[c]) + le[c];
        out_se[c] = (float)(alb[c] / PT_PI) * se[c];
    }
}

/* The share of the pixel a hit surface covers: its alpha for a BLEND
 * material (coverage), else 1. */
static float hit_coverage(const lpv_ref *r, const hit *h)
{
    const ref_tri *tr = &r->tris[h->tri];
    if (tr->material < 0 || r->look.materials[tr->material].alpha_mode != LPV_ALPHA_BLEND)
        return 1.0f;
    float uv0[2], uv1[2], color[4];
    tri_uv(tr, h->u, h->v, uv0, uv1, color);
    const float a = lpv_material_alpha_at(&r->look, &r->look.materials[tr->material], uv0, uv1, color[3]);
    return a > 0.0f ? (a < 1.0f ? a : 1.0f) : 0.0f;
}

/* Translucent layers a pixel composites before it takes the rest as hidden. */
#define REF_MAX_LAYERS 16

static void pixel_item(job *j, size_t i)
{
    const lpv_view *v = j->view;
    int x = (int)(i % (size_t)v->width), y = (int)(i / (size_t)v->width);
    float org[3], dir[3], tmin, tmax;
    float *px = &j->rgba[4 * i], *pse = j->rgba_se ? &j->rgba_se[4 * i] : NULL;
    px[0] = px[1] = px[2] = px[3] = 0.0f;
    if (pse)
        pse[0] = pse[1] = pse[2] = pse[3] = 0.0f;
    lpv_ref_pixel_ray(v, x, y, org, dir, &tmin, &tmax);
    if (!finite3(org) || !finite3(dir))
        return;
    /* Front to back through the BLEND surfaces, each weighing its alpha of
     * what is left ("over", as lpvd's frame lays its translucent layer over
     * the opaque one), to the first opaque surface. */
    float left = 1.0f;
    for (int layer = 0; layer < REF_MAX_LAYERS && left > 1e-6f; ++layer) {
        hit h;
        if (!lpv_pt_intersect(j->ref, org, dir, tmin, tmax, REF_BLEND_HIT, 0u, &h))
            break;
        const float a = hit_coverage(j->ref, &h);
        float c[3], cse[3];
        shade_hit(j, i, &h, c, cse);
        for (int k = 0; k < 3; ++k) {
            px[k] += left * a * c[k];
            if (pse)
                pse[k] += left * a * cse[k];
        }
        left *= 1.0f - a;
        tmin = h.t + j->ref->eps;
    }
    px[3] = 1.0f - left;
    if (pse)
        pse[3] = px[3];
}

int lpv_ref_render_indirect(const lpv_ref *r, const lpv_view *view, int bounces, int spp, float *rgba, float *rgba_se)
{
    if (!r || !view || !rgba || view->width < 1 || view->height < 1 ||
        (bounces < 1 && bounces != LPV_REF_BOUNCES_CONVERGED) || spp < 1)
        return -1;
    job j = {.ref = r, .count = (size_t)view->width * (size_t)view->height, .item = pixel_item, .view = view,
             .rgba = rgba, .rgba_se = rgba_se, .bounces = bounces, .samples = spp};
    run_job(&j);
    return 0;
}

int lpv_ref_render_full(const lpv_ref *r, const lpv_view *view, int bounces, int spp, float *rgba, float *rgba_se)
{
    if (!r || !view || !rgba || view->width < 1 || view->height < 1 ||
        (bounces < 0 && bounces != LPV_REF_BOUNCES_CONVERGED) || spp < 1)
        return -1;
    job j = {.ref = r, .count = (size_t)view->width * (size_t)view->height, .item = pixel_item, .view = view,
             .rgba = rgba, .rgba_se = rgba_se, .bounces = bounces, .samples = spp, .full = 1};
    run_job(&j);
    return 0;
}

double lpv_ref_mean_relative_stderr(const float *rgba, const float *rgba_se, int width, int height)
{
    double sum = 0.0;
    size_t n = 0;
    if (!rgba || !rgba_se || width < 1 || height < 1)
        return 0.0;
    for (size_t i = 0; i < (size_t)width * (size_t)height; ++i) {
        if (!(rgba[4 * i + 3] > 0.0f))
            continue;
        for (int c = 0; c < 3; ++c) {
            float v = rgba[4 * i + (size_t)c];
            if (v > 0.0f && isfinite(v)) {
                sum += (double)rgba_se[4 * i + (size_t)c] / (double)v;
                n++;
            }
        }
    }
    return n ? sum / (double)n : 0.0;
}

