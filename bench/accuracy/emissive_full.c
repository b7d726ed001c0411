/* emissive_full.c - see emissive_full.h. */
#include "emissive_full.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "area_lights.h"
#include "image_io.h"
#include "metrics.h"
#include "pt.h"
#include "scene_load.h"
#include "tonemap.h"

#define MAX_TICKS 1000

/* The points: area lights off (before issue 10), then on with K samples at
 * the settings' area shadow step (0: the given settings', by default
 * the area_shadow_step row's), and at 4, 8 and 16 samples also at the
 * steps 1 and 4 (docs/area-lights.md, "The area shadow step"). */
static const struct {
    int samples; /* 0 = area lights off */
    int step;    /* area_shadow_step; 0 = the settings' */
} POINTS[] = {{0, 0},  {1, 0},  {4, 0}, {4, 1},  {4, 4},  {8, 0},  {8, 1},
              {8, 4},  {16, 0}, {16, 1}, {16, 4}, {32, 0}, {64, 0}};
#define NPOINTS ((int)(sizeof POINTS / sizeof POINTS[0]))

/* 1 when p lies on one of the emitters' triangles (within tol of its plane). */
static int on_emitter(const lpv_emitter_list *l, const float p[3], float tol)
{
    for (size_t t = 0; t < l->count; ++t) {
        const lpv_emitter_tri *tr = &l->tris[t];
        double d[3], e1[3], e2[3];
        for (int i = 0; i < 3; ++i) {
            d[i] = (double)p[i] - tr->p[0][i];
            e1[i] = (double)tr->p[1][i] - tr->p[0][i];
            e2[i] = (double)tr->p[2][i] - tr->p[0][i];
        }
        double h = d[0] * tr->normal[0] + d[1] * tr->normal[1] + d[2] * tr->normal[2];
        if (fabs(h) > tol)
            continue;
        double a = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2], b = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
        double c = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
        double p1 = d[0] * e1[0] + d[1] * e1[1] + d[2] * e1[2], p2 = d[0] * e2[0] + d[1] * e2[1] + d[2] * e2[2];
        double det = a * c - b * b;
        if (!(det > 0.0))
            continue;
        double u = (c * p1 - b * p2) / det, v = (a * p2 - b * p1) / det;
        if (u >= -1e-4 && v >= -1e-4 && u + v <= 1.0 + 1e-4)
            return 1;
    }
    return 0;
}

/* Alpha 0 in both images where the pixel's first surface is an emitter. */
static size_t mask_emitters(const lpv_ref *ref, const lpv_scene *scene, const lpv_view *v, float *a, float *b)
{
    lpv_emitter_list l;
    if (lpv_emitters_collect(scene, &l) != 0)
        return 0;
    float ext = 0.0f;
    for (int i = 0; i < 3; ++i)
        ext = fmaxf(ext, scene->bounds_max[i] - scene->bounds_min[i]);
    size_t masked = 0;
    for (int y = 0; y < v->height; ++y)
        for (int x = 0; x < v->width; ++x) {
            float org[3], dir[3], tmin, tmax, p[3];
            lpv_ref_pixel_ray(v, x, y, org, dir, &tmin, &tmax);
            if (lpv_ref_first_hit(ref, org, dir, tmin, tmax, NULL, p) && on_emitter(&l, p, 1e-4f * ext)) {
                size_t i = ((size_t)y * (size_t)v->width + (size_t)x) * 4 + 3;
                a[i] = b[i] = 0.0f;
                masked++;
            }
        }
    lpv_emitters_free(&l);
    return masked;
}

static int write_png(const char *path, const float *rgba, int w, int h, float exposure)
{
    size_t n = (size_t)w * (size_t)h;
    uint8_t *px = malloc(n * 4);
    char err[512];
    int rc = -1;
    if (px) {
        lpv_tonemap_rgba8(rgba, n, exposure, px);
        rc = lpv_image_write_u8(path, w, h, 4, px, err, sizeof err);
        if (rc != 0)
            fprintf(stderr, "lpvd-accuracy: %s\n", err);
        free(px);
    }
    return rc;
}

typedef struct row {
    const char *scene;
    int samples; /* 0 = area lights off */
    int step;    /* the area shadow step it ran at */
    double ms_frame, ms_tick;
    lpv_acc_metrics m;        /* the full frame */
    lpv_acc_metrics m_direct; /* direct light + emission only, against the reference's bounces = 0 */
} row;

/* lpvd's full frame for one point: the median GPU ms of the frames (tick +
 * render stages) and of the ticks alone; the last frame in rgba. */
static int lpvd_point(lpv_engine *e, const lpv_scene *scene, const lpv_view *view, lpv_settings st, int ticks,
                      int warmup, float *rgba, float *direct, double *ms_frame, double *ms_tick)
{
    char err[1024] = "";
    static double frames[MAX_TICKS], tick_ms[MAX_TICKS];
    const lpv_engine_item item = {.settings = &st, .scene = scene, .view = view};
    if (lpv_engine_run_item(e, &item, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd-accuracy: %s\n", err);
        return -1;
    }
    for (int t = 0; t < warmup + ticks; ++t) {
        lpv_engine_invalidate(e);
        if (lpv_engine_tick(e, err, sizeof err) != 0) {
            fprintf(stderr, "lpvd-accuracy: %s\n", err);
            return -1;
        }
        double tk = 0.0;
        const lpv_engine_stats *s = lpv_engine_last_stats(e);
        for (int j = 0; j < s->stage_count; ++j)
            tk += s->stages[j].gpu_ms;
        if (lpv_engine_render(e, LPV_TERMS_FULL, rgba, err, sizeof err) != 0) {
            fprintf(stderr, "lpvd-accuracy: %s\n", err);
            return -1;
        }
        double all = 0.0;
        for (int j = 0; j < s->stage_count; ++j)
            all += s->stages[j].gpu_ms;
        if (t >= warmup) {
            frames[t - warmup] = all;
            tick_ms[t - warmup] = tk;
        }
    }
    *ms_frame = lpv_acc_median(frames, (size_t)ticks);
    *ms_tick = lpv_acc_median(tick_ms, (size_t)ticks);
    if (lpv_engine_render(e, LPV_TERMS_DIRECT_ONLY, direct, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd-accuracy: %s\n", err);
        return -1;
    }
    return 0;
}

/* One scene: the reference, then every point. Appends to rows. */
static int run_scene(lpv_engine *e, const lpv_acc_emissive_desc *d, const char *name, lpv_scene *scene, row *rows,
                     int *nrows)
{
    char err[1024] = "", path[1400];
    lpv_view view;
    if (lpv_view_resolve(&d->opt->cam, scene, &view, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd-accuracy: %s: %s\n", name, err);
        return -1;
    }
    const size_t n = (size_t)view.width * (size_t)view.height * 4;
    float *ref = malloc(n * sizeof *ref), *se = malloc(n * sizeof *se), *img = malloc(n * sizeof *img);
    float *ref_m = malloc(n * sizeof *ref_m), *ref_d = malloc(n * sizeof *ref_d), *se_d = malloc(n * sizeof *se_d);
    float *img_d = malloc(n * sizeof *img_d);
    lpv_ref *pt = NULL;
    int rc = -1;
    if (!ref || !se || !img || !ref_m || !ref_d || !se_d || !img_d) {
        fprintf(stderr, "lpvd-accuracy: out of memory\n");
        goto done;
    }
    if (lpv_ref_create(scene, &(lpv_ref_desc){.emitters_are_lights = 1}, &pt, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd-accuracy: %s: reference: %s\n", name, err);
        goto done;
    }
    fprintf(stderr, "lpvd-accuracy: %s: the reference's full frame (1 bounce, %d spp)\n", name, d->spp);
    lpv_ref_render_full(pt, &view, 1, d->spp, ref, se);
    lpv_ref_render_full(pt, &view, 0, d->spp, ref_d, se_d);
    memcpy(ref_m, ref, n * sizeof *ref);
    double mean = 0.0;
    size_t lit = 0;
    for (size_t i = 0; i < n; i += 4) /* exposure from the lit pixels only (masked below) */
        if (ref[i + 3] > 0.5f) {
            mean += (ref[i] + ref[i + 1] + ref[i + 2]) / 3.0;
            lit++;
        }
    snprintf(path, sizeof path, "%s/emissive/%s-reference.exr", d->out_dir, name);
    if (lpv_image_write_f32(path, view.width, view.height, 4, ref, err, sizeof err) != 0)
        fprintf(stderr, "lpvd-accuracy: %s\n", err);
    for (int p = 0; p < NPOINTS; ++p) {
        lpv_settings st = d->opt->settings;
        if (st.technique == LPV_TECHNIQUE_ID_DEFAULT) /* the published table is the LPV's (not auto, the default) */
            st.technique = LPV_TECHNIQUE_ID_LPV;
        st.area_lights = POINTS[p].samples ? LPV_SWITCH_ON : LPV_SWITCH_OFF;
        st.area_light_samples = POINTS[p].samples;
        if (POINTS[p].step)
            st.area_shadow_step = POINTS[p].step;
        lpv_settings resolved = st;
        lpv_settings_resolve(&resolved);
        row *r = &rows[(*nrows)];
        r->scene = name;
        r->samples = POINTS[p].samples;
        r->step = resolved.area_shadow_step;
        if (lpvd_point(e, scene, &view, st, d->ticks, d->warmup, img, img_d, &r->ms_frame, &r->ms_tick) != 0)
            goto done;
        memcpy(ref_m, ref, n * sizeof *ref);
        size_t masked = mask_emitters(pt, scene, &view, img, ref_m);
        mask_emitters(pt, scene, &view, img_d, ref_d);
        if (lpv_acc_compare(img_d, ref_d, se_d, view.width, view.height, &r->m_direct) != 0)
            fprintf(stderr, "lpvd-accuracy: %s: warning: no pixel to compare\n", name);
        if (p == 0) { /* the tone-mapped reference, exposed for the lit surfaces */
            double lit_mean = 0.0;
            size_t k = 0;
            for (size_t i = 0; i < n; i += 4)
                if (ref_m[i + 3] > 0.5f) {
                    lit_mean += (ref_m[i] + ref_m[i + 1] + ref_m[i + 2]) / 3.0;
                    k++;
                }
            mean = k ? lit_mean / (double)k : (lit ? mean / (double)lit : 1.0);
            snprintf(path, sizeof path, "%s/emissive/%s-reference.png", d->out_dir, name);
            write_png(path, ref, view.width, view.height, (float)(0.25 / fmax(mean, 1e-30)));
            fprintf(stderr, "lpvd-accuracy: %s: %zu emitter pixels left out of the metrics\n", name, masked);
        }
        if (lpv_acc_compare(img, ref_m, se, view.width, view.height, &r->m) != 0)
            fprintf(stderr, "lpvd-accuracy: %s: warning: no pixel to compare\n", name);
        char label[48];
        if (!POINTS[p].samples)
            snprintf(label, sizeof label, "off");
        else if (POINTS[p].step)
            snprintf(label, sizeof label, "on-%d-step%d", POINTS[p].samples, POINTS[p].step);
        else
            snprintf(label, sizeof label, "on-%d", POINTS[p].samples);
        snprintf(path, sizeof path, "%s/emissive/%s-%s.png", d->out_dir, name, label);
        write_png(path, img, view.width, view.height, (float)(0.25 / fmax(mean, 1e-30)));
        snprintf(path, sizeof path, "%s/emissive/%s-%s-direct-error.png", d->out_dir, name, label);
        if (lpv_acc_write_error_png(path, img_d, ref_d, view.width, view.height, r->m_direct.mean_ref, err,
                                    sizeof err) != 0)
            fprintf(stderr, "lpvd-accuracy: %s\n", err);
        snprintf(path, sizeof path, "%s/emissive/%s-%s-error.png", d->out_dir, name, label);
        if (lpv_acc_write_error_png(path, img, ref_m, view.width, view.height, r->m.mean_ref, err, sizeof err) != 0)
            fprintf(stderr, "lpvd-accuracy: %s\n", err);
        fprintf(stderr,
                "lpvd-accuracy: %s, area lights %s: %.2f ms/frame (tick %.2f), full frame rel_rmse %.4f, rel_bias "
                "%+.4f, ref_noise %.4f; direct only rel_rmse %.4f, rel_bias %+.4f\n",
                name, label, r->ms_frame, r->ms_tick, r->m.rel_rmse, r->m.rel_bias, r->m.ref_noise,
                r->m_direct.rel_rmse, r->m_direct.rel_bias);
        (*nrows)++;
    }
    rc = 0;
done:
    lpv_ref_destroy(pt);
    free(ref);
    free(se);
    free(img);
    free(ref_m);
    free(ref_d);
    free(se_d);
    free(img_d);
    return rc;
}

int lpv_acc_emissive_run(lpv_engine *e, const lpv_acc_emissive_desc *d)
{
    char path[1400], err[1024] = "";
    snprintf(path, sizeof path, "%s/emissive", d->out_dir);
    if (mkdir(d->out_dir, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "lpvd-accuracy: cannot create %s: %s\n", d->out_dir, strerror(errno));
        return 1;
    }
    if (mkdir(path, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "lpvd-accuracy: cannot create %s: %s\n", path, strerror(errno));
        return 1;
    }
    static row rows[4 * NPOINTS];
    int nrows = 0, rc = 0;

    lpv_scene s;
    if (lpv_scene_builtin_cornell(&s) != 0) {
        fprintf(stderr, "lpvd-accuracy: out of memory\n");
        return 1;
    }
    s.light_count = 0; /* only the emissive ceiling quad */
    rc = run_scene(e, d, "cornell-emissive", &s, rows, &nrows) != 0;
    lpv_scene_free(&s);
    snprintf(path, sizeof path, "%s/emissive-room.glb", d->scenes_dir);
    FILE *probe = fopen(path, "rb");
    if (rc == 0 && probe) {
        fclose(probe);
        if (lpv_scene_load_user(path, NULL, &s, err, sizeof err) != 0) {
            fprintf(stderr, "lpvd-accuracy: %s\n", err);
            rc = 1;
        } else {
            rc = run_scene(e, d, "emissive-room", &s, rows, &nrows) != 0;
            lpv_scene_free(&s);
        }
    }

    snprintf(path, sizeof path, "%s/emissive.csv", d->out_dir);
    FILE *f = fopen(path, "w");
    if (!f)
        return 1;
    fprintf(f, "scene,area_lights,area_light_samples,area_shadow_step,ms_frame,ms_tick,pixels,mean_ref,mean_lpv,rel_rmse,rel_bias,"
               "ref_noise,rel_rmse_excess,rel_mae,direct_rel_rmse,direct_rel_bias,direct_ref_noise\n");
    for (int i = 0; i < nrows; ++i) {
        const row *r = &rows[i];
        fprintf(f, "%s,%s,%d,%d,%.3f,%.3f,%zu,%.6g,%.6g,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f\n", r->scene,
                r->samples ? "on" : "off", r->samples, r->step, r->ms_frame, r->ms_tick, r->m.pixels, r->m.mean_ref,
                r->m.mean_lpv, r->m.rel_rmse, r->m.rel_bias, r->m.ref_noise, r->m.rel_rmse_excess, r->m.rel_mae,
                r->m_direct.rel_rmse, r->m_direct.rel_bias, r->m_direct.ref_noise);
    }
    fclose(f);
    snprintf(path, sizeof path, "%s/emissive.md", d->out_dir);
    f = fopen(path, "w");
    if (!f)
        return 1;
    fprintf(f, "Full frame (emission + direct + LPV) vs the path tracer's full frame (1 bounce, %d spp), "
               "emitter pixels left out; GPU ms per frame = tick + render, median of %d.\n\n",
            d->spp, d->ticks);
    fprintf(f, "| scene | area lights | samples | area shadow step | ms/frame | ms/tick | rel. RMSE | rel. bias | "
               "ref. noise | direct only: rel. RMSE | rel. bias |\n");
    fprintf(f, "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int i = 0; i < nrows; ++i) {
        const row *r = &rows[i];
        char k[16] = "–", st[16] = "–";
        if (r->samples) {
            snprintf(k, sizeof k, "%d", r->samples);
            snprintf(st, sizeof st, "%d", r->step);
        }
        fprintf(f, "| %s | %s | %s | %s | %.1f | %.1f | %.3f | %+.3f | %.3f | %.3f | %+.3f |\n", r->scene,
                r->samples ? "on" : "off", k, st, r->ms_frame, r->ms_tick, r->m.rel_rmse, r->m.rel_bias, r->m.ref_noise,
                r->m_direct.rel_rmse, r->m_direct.rel_bias);
    }
    fclose(f);
    fprintf(stderr, "lpvd-accuracy: %d point(s) written to %s/emissive.csv, emissive.md\n", nrows, d->out_dir);
    return rc;
}
