/*
 * lpvd_hard_cases.c - `lpvd-hard-cases`: the engine's hard cases
 * (hard_cases.h) against the path-traced reference. For each case it renders
 * lpvd's indirect-only frame and the reference's (1 bounce), computes the
 * error metrics (metrics.h), and checks what must hold however large the
 * error is: every pixel and LPV coefficient finite, the last propagation
 * step carrying no more flux than was injected (nor than the first step
 * carried), and the relative RMSE finite and below REL_RMSE_BOUND. Writes
 *
 *   OUT/hard-cases.csv, OUT/hard-cases.md, OUT/err/CASE.png (error images),
 *   OUT/img/CASE-lpvd.png, CASE-ref.png (both at one exposure: mean(R) -> 0.5)
 *
 * prints one line per case and exits 1 when any case fails (docs/hard-cases.md).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "context.h"
#include "engine.h"
#include "hard_cases.h"
#include "image_io.h"
#include "metrics.h"
#include "options.h"
#include "pt.h"
#include "tonemap.h"

/* "Unbounded": LPV errors on these scenes are O(1) (docs/accuracy.md), so a
 * relative RMSE a hundred times the reference's mean means something blew
 * up, not that the approximation is coarse. */
#define REL_RMSE_BOUND 100.0
#define BOUND_TEXT "100" /* REL_RMSE_BOUND as text, for the verdicts */
/* Flux may not grow; float sums over the grid get this relative slack. */
#define ENERGY_SLACK 1e-5

typedef struct case_result {
    const lpv_hard_case_info *info;
    char settings[96];
    lpv_acc_metrics m;
    int has_dark;
    lpv_acc_metrics dark; /* the pixels on the case's dark side only */
    int finite;           /* every lpvd pixel and LPV coefficient (injected, last step, accumulated) */
    double max_pixel;
    double flux_injected, flux_first, flux_last; /* W, summed over r, g, b */
    double energy_ratio;                         /* flux_last / flux_injected */
    double step_ratio;                           /* flux_last / flux_first */
    double ms_lpvd, ms_ref;                      /* wall clock */
    int ok;
    char verdict[192];
} case_result;

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static int make_dir(const char *path)
{
    return (mkdir(path, 0777) != 0 && errno != EEXIST) ? -1 : 0;
}

static double grid_flux(const lpv_grid *g, const lpv_cell *cells)
{
    double f[3];
    lpv_oracle_total_flux(g, cells, f);
    return f[0] + f[1] + f[2];
}

static int all_finite(const float *v, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* a / b for the energy checks: 0 / 0 is 0 (nothing in, nothing out). */
static double ratio(double a, double b)
{
    if (b > 0.0)
        return a / b;
    return a == 0.0 ? 0.0 : INFINITY;
}

/* Reads one grid; 0 on success. */
static int read_grid(lpv_engine *e, lpv_grid_which w, lpv_cell *cells, size_t n)
{
    return lpv_engine_read_grid(e, w, cells, n) == n ? 0 : -1;
}

/* Ticks with settings s; returns 0 or -1 (err). */
static int tick(lpv_engine *e, const lpv_hard_scene *h, const lpv_settings *s, const lpv_view *v, char *err,
                size_t n)
{
    const lpv_engine_item item = {.settings = s, .scene = &h->scene, .view = v, .tick = 1};
    return lpv_engine_run_item(e, &item, err, n);
}

static void describe_settings(const lpv_settings *s, float cell_size, char *out, size_t n)
{
    char grid[32];
    if (s->grid_dims[0] == s->grid_dims[1] && s->grid_dims[1] == s->grid_dims[2])
        snprintf(grid, sizeof grid, "%d³", s->grid_dims[0]);
    else
        snprintf(grid, sizeof grid, "%dx%dx%d", s->grid_dims[0], s->grid_dims[1], s->grid_dims[2]);
    snprintf(out, n, "grid %s (cell %.3g m), %d it, RSM %d, occ %s", grid, cell_size, s->lpv.iterations, s->rsm_size,
             s->lpv.occlusion == LPV_SWITCH_OFF ? "off" : "on");
}

/* lpvd's side: the first step's flux (a tick with 1 iteration), then the
 * case's own tick, its indirect-only frame and the grids' checks. */
static int run_lpvd(lpv_engine *e, const lpv_hard_scene *h, const lpv_view *v, float *rgba, case_result *r,
                    char *err, size_t n)
{
    lpv_settings one = h->settings;
    one.lpv.iterations = 1;
    if (tick(e, h, &one, v, err, n) != 0)
        return -1;
    const lpv_grid *g = lpv_engine_grid(e);
    size_t cells = lpv_grid_cell_count(g);
    lpv_cell *buf = calloc(cells, sizeof *buf);
    if (!buf) {
        snprintf(err, n, "out of memory");
        return -1;
    }
    int rc = -1;
    if (read_grid(e, LPV_GRID_LAST_STEP, buf, cells) != 0)
        goto done;
    r->flux_first = grid_flux(g, buf);
    r->finite = all_finite((const float *)buf, cells * sizeof *buf / sizeof(float));

    double t0 = now_ms();
    if (tick(e, h, &h->settings, v, err, n) != 0 || lpv_engine_render(e, LPV_TERMS_INDIRECT_ONLY, rgba, err, n) != 0)
        goto done;
    r->ms_lpvd = now_ms() - t0;
    g = lpv_engine_grid(e);
    describe_settings(lpv_engine_settings(e), g->cell_size, r->settings, sizeof r->settings);
    static const lpv_grid_which WHICH[3] = {LPV_GRID_INJECTED, LPV_GRID_LAST_STEP, LPV_GRID_ACCUMULATED};
    double *flux[3] = {&r->flux_injected, &r->flux_last, NULL};
    for (int k = 0; k < 3; ++k) {
        if (read_grid(e, WHICH[k], buf, cells) != 0)
            goto done;
        r->finite &= all_finite((const float *)buf, cells * sizeof *buf / sizeof(float));
        if (flux[k])
            *flux[k] = grid_flux(g, buf);
    }
    size_t px = (size_t)v->width * (size_t)v->height;
    r->finite &= all_finite(rgba, px * 4);
    r->max_pixel = 0.0;
    for (size_t i = 0; i < px; ++i)
        for (int c = 0; c < 3; ++c)
            if (!(rgba[4 * i + (size_t)c] <= r->max_pixel)) /* NaN sticks */
                r->max_pixel = rgba[4 * i + (size_t)c];
    r->energy_ratio = ratio(r->flux_last, r->flux_injected);
    r->step_ratio = ratio(r->flux_last, r->flux_first);
    rc = 0;
done:
    if (rc != 0 && !err[0])
        snprintf(err, n, "grid read-back failed");
    free(buf);
    return rc;
}

/* Copies lpv and ref with alpha 0 wherever the reference's first hit lies
 * outside the dark-side box, so lpv_acc_compare sees only the dark side. */
static void mask_dark_side(const lpv_ref *ref, const lpv_hard_scene *h, const lpv_view *v, const float *lpv,
                           const float *refimg, float *lpv_out, float *ref_out)
{
    size_t np = (size_t)v->width * (size_t)v->height;
    memcpy(lpv_out, lpv, np * 4 * sizeof(float));
    memcpy(ref_out, refimg, np * 4 * sizeof(float));
    for (int y = 0; y < v->height; ++y)
        for (int x = 0; x < v->width; ++x) {
            float org[3], dir[3], tmin, tmax, p[3];
            lpv_ref_pixel_ray(v, x, y, org, dir, &tmin, &tmax);
            int in = lpv_ref_first_hit(ref, org, dir, tmin, tmax, NULL, p);
            for (int k = 0; k < 3 && in; ++k)
                in = p[k] >= h->dark_lo[k] && p[k] <= h->dark_hi[k];
            if (!in)
                lpv_out[4 * ((size_t)y * (size_t)v->width + (size_t)x) + 3] =
                    ref_out[4 * ((size_t)y * (size_t)v->width + (size_t)x) + 3] = 0.0f;
        }
}

/* A tone-mapped preview; exposure 1/mean(R) puts the reference's mean at
 * 0.5 after Reinhard, whatever the case's light level (1e-3 to 1e30). */
static void write_preview(const char *out_dir, const char *name, const char *what, const float *rgba, int w,
                          int hgt, double mean_ref)
{
    size_t np = (size_t)w * (size_t)hgt;
    uint8_t *px = malloc(np * 4);
    char path[1200], err[512];
    if (!px)
        return;
    lpv_tonemap_rgba8(rgba, np, mean_ref > 0.0 ? (float)(1.0 / mean_ref) : 1.0f, px);
    snprintf(path, sizeof path, "%s/img/%s-%s.png", out_dir, name, what);
    if (lpv_image_write_u8(path, w, hgt, 4, px, err, sizeof err) != 0)
        fprintf(stderr, "lpvd-hard-cases: %s\n", err);
    free(px);
}

static int metrics_ok(const lpv_acc_metrics *m)
{
    return isfinite(m->rel_rmse) && isfinite(m->rel_bias) && isfinite(m->rel_mae) && isfinite(m->ref_noise) &&
           m->rel_rmse <= REL_RMSE_BOUND;
}

/* Appends one failure reason to the verdict ("FAIL: a; b"). */
static void fail(case_result *r, const char *fmt, double value)
{
    size_t used = strlen(r->verdict);
    if (used + 1 >= sizeof r->verdict)
        return;
    char reason[128];
    snprintf(reason, sizeof reason, fmt, value);
    snprintf(r->verdict + used, sizeof r->verdict - used, "%s %s", r->ok ? "FAIL:" : ";", reason);
    r->ok = 0;
}

static void judge(case_result *r)
{
    r->ok = 1;
    r->verdict[0] = '\0';
    if (!r->finite || !isfinite(r->max_pixel))
        fail(r, "non-finite lpvd value (max pixel %.3g)", r->max_pixel);
    if (!metrics_ok(&r->m))
        fail(r, "rel_rmse %.3g not finite or > " BOUND_TEXT, r->m.rel_rmse);
    if (r->has_dark && !metrics_ok(&r->dark))
        fail(r, "dark-side rel_rmse %.3g not finite or > " BOUND_TEXT, r->dark.rel_rmse);
    if (!(r->energy_ratio <= 1.0 + ENERGY_SLACK))
        fail(r, "energy ratio %.6g > 1", r->energy_ratio);
    if (!(r->step_ratio <= 1.0 + ENERGY_SLACK))
        fail(r, "last/first step flux %.6g > 1", r->step_ratio);
    if (r->ok)
        snprintf(r->verdict, sizeof r->verdict, "ok");
}

static int run_case(lpv_engine *e, const char *name, int w, int hgt, int spp, const char *out_dir, case_result *r)
{
    char err[1024] = "";
    lpv_hard_scene h;
    lpv_view v;
    lpv_ref *ref = NULL;
    size_t np = (size_t)w * (size_t)hgt;
    float *img = calloc(np * 4 * 4, sizeof(float)); /* lpvd, reference, its stderr, scratch */
    float *mask = calloc(np * 4 * 2, sizeof(float));
    int rc = -1;
    r->info = lpv_hard_case_get((size_t)lpv_hard_case_find(name));
    if (!img || !mask || lpv_hard_case_build(name, &h) != 0) {
        fprintf(stderr, "lpvd-hard-cases: %s: cannot build the case\n", name);
        free(img);
        free(mask);
        return -1;
    }
    float *lpv = img, *refimg = img + np * 4, *se = img + np * 8;
    if (lpv_hard_case_view(&h, w, hgt, &v) != 0 || run_lpvd(e, &h, &v, lpv, r, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd-hard-cases: %s: lpvd: %s\n", name, err);
        goto done;
    }
    double t0 = now_ms();
    if (lpv_ref_create(&h.scene, NULL, &ref, err, sizeof err) != 0 ||
        lpv_ref_render_indirect(ref, &v, 1, spp, refimg, se) != 0) {
        fprintf(stderr, "lpvd-hard-cases: %s: reference: %s\n", name, err[0] ? err : "render failed");
        goto done;
    }
    r->ms_ref = now_ms() - t0;
    /* a failed comparison leaves NaN metrics, which judge() reports */
    lpv_acc_compare(lpv, refimg, se, w, hgt, &r->m);
    r->has_dark = h.has_dark_side;
    if (r->has_dark) {
        mask_dark_side(ref, &h, &v, lpv, refimg, mask, mask + np * 4);
        lpv_acc_compare(mask, mask + np * 4, se, w, hgt, &r->dark);
    }
    char path[1200];
    snprintf(path, sizeof path, "%s/err/%s.png", out_dir, name);
    if (lpv_acc_write_error_png(path, lpv, refimg, w, hgt, r->m.mean_ref, err, sizeof err) != 0)
        fprintf(stderr, "lpvd-hard-cases: %s: %s\n", name, err);
    write_preview(out_dir, name, "lpvd", lpv, w, hgt, r->m.mean_ref);
    write_preview(out_dir, name, "ref", refimg, w, hgt, r->m.mean_ref);
    judge(r);
    rc = 0;
done:
    lpv_ref_destroy(ref);
    lpv_hard_scene_free(&h);
    free(img);
    free(mask);
    return rc;
}

static void write_csv(FILE *f, const case_result *r, int n)
{
    fprintf(f, "case,settings,rel_rmse,rel_bias,rel_mae,ref_noise,dark_rel_rmse,dark_rel_bias,dark_rel_mae,"
               "finite,max_pixel,flux_injected,flux_first_step,flux_last_step,energy_ratio,last_over_first_step,"
               "ms_lpvd,ms_reference,verdict\n");
    for (int i = 0; i < n; ++i) {
        const case_result *x = &r[i];
        fprintf(f, "%s,\"%s\",%.6g,%.6g,%.6g,%.6g,", x->info->name, x->settings, x->m.rel_rmse, x->m.rel_bias,
                x->m.rel_mae, x->m.ref_noise);
        if (x->has_dark)
            fprintf(f, "%.6g,%.6g,%.6g,", x->dark.rel_rmse, x->dark.rel_bias, x->dark.rel_mae);
        else
            fprintf(f, ",,,");
        fprintf(f, "%s,%.6g,%.9g,%.9g,%.9g,%.9g,%.9g,%.1f,%.1f,\"%s\"\n", x->finite ? "yes" : "no", x->max_pixel,
                x->flux_injected, x->flux_first, x->flux_last, x->energy_ratio, x->step_ratio, x->ms_lpvd, x->ms_ref,
                x->verdict);
    }
}

static void write_md(FILE *f, const case_result *r, int n, const char *header)
{
    fprintf(f, "# lpvd hard cases against the reference\n\n%s\n", header);
    fprintf(f, "Metrics: docs/accuracy.md (indirect-only frame vs the 1-bounce reference). finite: every lpvd "
               "pixel and every injected, last-step and accumulated LPV coefficient. energy: last step's flux / "
               "injected flux; last/first: last step's flux / the first step's. Verdict fails on a non-finite "
               "value, an energy ratio above 1 + %g, or a rel. RMSE not finite or above %g.\n\n",
            ENERGY_SLACK, REL_RMSE_BOUND);
    fprintf(f, "| case | what it tests | settings | rel. RMSE | rel. bias | rel. MAE | ref. noise | finite | "
               "energy | last/first | max pixel | verdict |\n");
    fprintf(f, "|---|---|---|---:|---:|---:|---:|:---:|---:|---:|---:|---|\n");
    for (int i = 0; i < n; ++i) {
        const case_result *x = &r[i];
        fprintf(f, "| `%s` | %s | %s | %.3f | %+.3f | %.3f | %.3f | %s | %.4g | %.4g | %.3g | %s |\n", x->info->name,
                x->info->what, x->settings, x->m.rel_rmse, x->m.rel_bias, x->m.rel_mae, x->m.ref_noise,
                x->finite ? "yes" : "**no**", x->energy_ratio, x->step_ratio, x->max_pixel, x->verdict);
        if (x->has_dark)
            fprintf(f, "| `%s` dark side | pixels seeing the unlit side of the wall only | | %.3f | %+.3f | %.3f | "
                       "%.3f | | | | | |\n",
                    x->info->name, x->dark.rel_rmse, x->dark.rel_bias, x->dark.rel_mae, x->dark.ref_noise);
    }
}

enum { H_OUT, H_CASES, H_REF_SPP, H_HELP, H_COUNT };

static const lpv_flag FLAGS[H_COUNT] = {
    [H_OUT] = {"out", 0, "DIR", "output folder (default hard-cases-out)"},
    [H_CASES] = {"cases", 0, "LIST", "comma list of case names (default all, below)"},
    [H_REF_SPP] = {"ref-spp", 0, "N", "reference samples per pixel (default 256)"},
    [H_HELP] = {"help", 'h', NULL, "this text"},
};

static void usage(FILE *f, const lpv_flag *size_flag, const lpv_flag_group *backend)
{
    char help[4096];
    size_t len = 0;
    lpv_flags_help(help, sizeof help, &len, FLAGS, H_COUNT);
    lpv_flags_help(help, sizeof help, &len, size_flag, 1);
    lpv_flags_help(help, sizeof help, &len, backend->flags, backend->count);
    fprintf(f,
            "usage: lpvd-hard-cases [--out DIR] [--size WxH] [--ref-spp N] [--cases LIST] [--backend B]\n"
            "Renders each hard case (docs/hard-cases.md) with lpvd and the path-traced reference and checks\n"
            "it stays finite and energy-bounded. Exit status 1 when a case fails. --size defaults to 64x64\n"
            "here.\n%sThe cases:\n",
            help);
    for (size_t i = 0; i < lpv_hard_case_count(); ++i)
        fprintf(f, "  %-24s %s\n", lpv_hard_case_get(i)->name, lpv_hard_case_get(i)->what);
}

int main(int argc, char **argv)
{
    const char *out_dir = "hard-cases-out", *case_list = NULL;
    int spp = 256;
    lpvd_options opt = {0};
    opt.cam.width = opt.cam.height = 64;
    char err[1024] = "";
    /* Only --size and --backend of the shared flags: the cases fix settings and cameras. */
    lpv_flag_group groups[3] = {{FLAGS, H_COUNT, NULL, NULL}, lpv_view_flag_group(&opt.cam)};
    groups[1].flags = lpv_flag_find(groups[1].flags, groups[1].count, "size");
    groups[1].count = 1;
    lpvd_options_groups(&opt, LPVD_GROUP_BACKEND, 1, &groups[2]);
    lpv_flags p;
    if (lpv_flags_begin(&p, argc, argv, groups, 3, 0) != 0) {
        fprintf(stderr, "lpvd-hard-cases: %s\n", p.err);
        return 2;
    }
    int g;
    const lpv_flag *fl;
    const char *v;
    for (lpv_flags_item it; (it = lpv_flags_next(&p, &g, &fl, &v)) != LPV_FLAGS_END;) {
        if (lpv_flags_refuse(&p, it, v, "lpvd-hard-cases", 0)) {
            return 2;
        } else if (fl == &FLAGS[H_HELP]) {
            usage(stdout, groups[1].flags, &groups[2]);
            return 0;
        } else if (fl == &FLAGS[H_OUT]) {
            out_dir = v;
        } else if (fl == &FLAGS[H_CASES]) {
            case_list = v;
        } else if (fl == &FLAGS[H_REF_SPP]) {
            char *end = NULL;
            long x = strtol(v, &end, 10);
            if (!end || *end || x < 1 || x > 1000000) {
                fprintf(stderr, "lpvd-hard-cases: bad --ref-spp %s\n", v);
                return 2;
            }
            spp = (int)x;
        }
    }

    const char *names[64];
    int n = 0;
    char list[1024];
    if (case_list) {
        snprintf(list, sizeof list, "%s", case_list);
        for (char *save = NULL, *t = strtok_r(list, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
            if (lpv_hard_case_find(t) < 0 || n >= 64) {
                fprintf(stderr, "lpvd-hard-cases: unknown case %s (see --help)\n", t);
                return 2;
            }
            names[n++] = t;
        }
    } else {
        for (size_t i = 0; i < lpv_hard_case_count() && n < 64; ++i)
            names[n++] = lpv_hard_case_get(i)->name;
    }
    if (n == 0) {
        fprintf(stderr, "lpvd-hard-cases: no case to run\n");
        return 2;
    }
    char path[1200];
    snprintf(path, sizeof path, "%s/err", out_dir);
    char img_dir[1200];
    snprintf(img_dir, sizeof img_dir, "%s/img", out_dir);
    if (make_dir(out_dir) != 0 || make_dir(path) != 0 || make_dir(img_dir) != 0) {
        fprintf(stderr, "lpvd-hard-cases: cannot create %s/err, %s/img: %s\n", out_dir, out_dir, strerror(errno));
        return 1;
    }

    lpv_gl_context *ctx = lpv_gl_context_create(&(lpv_gl_context_desc){.backend = opt.backend}, err, sizeof err);
    if (!ctx) {
        fprintf(stderr, "lpvd-hard-cases: no OpenGL 4.5 context: %s\n", err);
        return 1;
    }
    lpv_engine *engine = lpv_engine_create(err, sizeof err);
    if (!engine) {
        fprintf(stderr, "lpvd-hard-cases: %s\n", err);
        lpv_gl_context_destroy(ctx);
        return 1;
    }
    char header[1024];
    snprintf(header, sizeof header, "backend %s, GL_RENDERER %s; image %dx%d; reference lpv_reference, 1 bounce, %d spp.\n",
             lpv_backend_name(lpv_gl_context_backend(ctx)), lpv_gl_context_renderer(ctx), opt.cam.width,
             opt.cam.height, spp);
    fprintf(stderr, "lpvd-hard-cases: %s", header);

    case_result res[64];
    memset(res, 0, sizeof res);
    int failed = 0;
    for (int i = 0; i < n; ++i) {
        case_result *r = &res[i];
        if (run_case(engine, names[i], opt.cam.width, opt.cam.height, spp, out_dir, r) != 0) {
            r->info = lpv_hard_case_get((size_t)lpv_hard_case_find(names[i]));
            r->m.rel_rmse = r->m.rel_bias = r->m.rel_mae = r->m.ref_noise = NAN;
            snprintf(r->verdict, sizeof r->verdict, "FAIL: did not run");
        }
        failed += !r->ok;
        printf("%-24s %-5s rel_rmse %8.4f  rel_bias %+8.4f  rel_mae %7.4f  ref_noise %6.4f  finite %-3s  "
               "energy %.4g  last/first %.4g  max %.3g",
               names[i], r->ok ? "ok" : "FAIL", r->m.rel_rmse, r->m.rel_bias, r->m.rel_mae, r->m.ref_noise,
               r->finite ? "yes" : "no", r->energy_ratio, r->step_ratio, r->max_pixel);
        if (r->has_dark)
            printf("  dark side: rel_rmse %.4f rel_bias %+.4f", r->dark.rel_rmse, r->dark.rel_bias);
        printf("%s%s\n", r->ok ? "" : "  ", r->ok ? "" : r->verdict);
        fflush(stdout);
    }
    lpv_engine_destroy(engine);
    lpv_gl_context_destroy(ctx);

    int rc = failed ? 1 : 0;
    snprintf(path, sizeof path, "%s/hard-cases.csv", out_dir);
    FILE *f = fopen(path, "w");
    if (f) {
        write_csv(f, res, n);
        fclose(f);
    } else {
        rc = 1;
    }
    snprintf(path, sizeof path, "%s/hard-cases.md", out_dir);
    f = fopen(path, "w");
    if (f) {
        write_md(f, res, n, header);
        fclose(f);
    } else {
        rc = 1;
    }
    fprintf(stderr, "lpvd-hard-cases: %d case(s), %d failed; wrote %s/hard-cases.csv, hard-cases.md, err/, img/\n", n,
            failed, out_dir);
    return rc;
}
