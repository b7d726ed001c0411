/*
 * lpvd_bench.c - per-stage GPU milliseconds of the engine (median over
 * repeated ticks, after warm-up ticks that absorb shader compilation) and
 * the propagation throughput in cell-steps per second.
 *
 *   lpvd-bench [--repeat N] [--warmup N] [--config NAME] [--frame-out DIR] [lpvd flags: --size WxH, --backend NAME, ...] [SCENE]
 *
 * Configurations: the default preset (balanced), and the paper's pipeline
 * (the four departures of docs/propagation.md off) at 32^3 / 8 iterations /
 * RSM 256^2, the same at 64^3 (the configurations the propagation
 * throughput has been measured on since issue 3) and with 3 cascades of 32^3.
 * Prints a Markdown table per configuration: each stage's GPU ms, their sum,
 * and "wall": the whole tick and frame as the process sees it (CPU clock,
 * lpv_engine_tick + lpv_engine_render with its read-back). bench/README.md records
 * it with the machine; bench/compare_builds.py runs two builds' benches
 * alternately and prints the ratios. Each configuration's last frame is
 * summarised (mean radiance of the covered pixels, non-finite values) so a
 * run on another GPU or driver can be checked against llvmpipe's figures;
 * --frame-out writes it as raw RGBA8 (display-encoded as `lpvd render` does)
 * for a look where the machine has no image library.
 * Not a test: nothing here asserts a time.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "context.h"
#include "engine.h"
#include "options.h"
#include "scene_load.h"
#include "tonemap.h"

typedef struct config {
    const char *name;          /* --config */
    int grid, iterations, rsm; /* 0: the preset's */
    int paper;                 /* 1: the departures off */
    int cascades;              /* 0: the settings' (auto) */
} config;

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* The frame's check figures: mean RGB radiance (W/(sr m^2)) of the pixels
 * that see geometry (alpha > 0.5) and the count of non-finite values; with
 * dir, the frame display-encoded (automatic exposure) as raw RGBA8. */
static int frame_report(const char *dir, const char *name, const float *rgba, int w, int h)
{
    size_t n = (size_t)w * h, covered = 0, bad = 0;
    double sum[3] = {0, 0, 0};
    for (size_t i = 0; i < n; ++i) {
        const float *p = rgba + 4 * i;
        for (int c = 0; c < 4; ++c)
            bad += !isfinite(p[c]);
        if (p[3] > 0.5f && isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2])) {
            ++covered;
            for (int c = 0; c < 3; ++c)
                sum[c] += p[c];
        }
    }
    double k = covered ? 1.0 / (double)covered : 0.0;
    printf("frame: %zu of %zu pixels covered, mean radiance %.6g %.6g %.6g W/(sr m^2), %zu non-finite values\n", covered,
           n, sum[0] * k, sum[1] * k, sum[2] * k, bad);
    if (!dir)
        return 0;
    uint8_t *px = malloc(n * 4);
    char path[1024];
    snprintf(path, sizeof path, "%s/%s-%dx%d.rgba", dir, name, w, h);
    FILE *f = px ? fopen(path, "wb") : NULL;
    int ok = f != NULL;
    if (ok) {
        lpv_display d;
        lpv_display_default(&d);
        lpv_display_rgba8(rgba, n, &d, px);
        ok = fwrite(px, 4, n, f) == n;
    }
    if (f)
        ok &= fclose(f) == 0;
    free(px);
    if (!ok)
        fprintf(stderr, "lpvd-bench: --frame-out: cannot write %s\n", path);
    return ok ? 0 : -1;
}

enum { B_REPEAT, B_WARMUP, B_CONFIG, B_FRAME_OUT, B_HELP, B_COUNT };

static const lpv_flag FLAGS[B_COUNT] = {
    [B_REPEAT] = {"repeat", 0, "N", "timed ticks per configuration, 1..1000 (default 15)"},
    [B_WARMUP] = {"warmup", 0, "N", "untimed ticks first (default 3)"},
    [B_CONFIG] = {"config", 0, "NAME", "only this configuration: balanced, paper32, paper64 or cascades3 (default all)"},
    [B_FRAME_OUT] = {"frame-out", 0, "DIR", "write each configuration's last frame to DIR/CONFIG-WxH.rgba (raw RGBA8, sRGB)"},
    [B_HELP] = {"help", 'h', NULL, "this text"},
};

static void usage(FILE *f)
{
    char help[2048];
    size_t len = 0;
    lpv_flags_help(help, sizeof help, &len, FLAGS, B_COUNT);
    fprintf(f, "usage: lpvd-bench [--repeat N] [--warmup N] [--config NAME] [--frame-out DIR] [lpvd flags] [SCENE]\n%s%s", help, LPVD_OPTIONS_HELP);
}

int main(int argc, char **argv)
{
    int repeat = 15, warmup = 3;
    const char *only = NULL, *frame_dir = NULL;
    const char *scene_path = NULL;
    /* its configurations are the cascaded LPV's (grid, iterations,
     * departures): the LPV unless --technique names another (the engine's
     * default is auto since issue 30) */
    lpvd_options opt = {.settings = {.technique = LPV_TECHNIQUE_ID_LPV}};
    char err[1024];
    lpv_flag_group groups[4] = {{FLAGS, B_COUNT, NULL, NULL}};
    int ngroups = 1 + lpvd_options_groups(&opt, LPVD_GROUP_ALL, 1, groups + 1);
    lpv_flags p;
    if (lpv_flags_begin(&p, argc, argv, groups, ngroups, 0) != 0) {
        fprintf(stderr, "lpvd-bench: %s\n", p.err);
        return 2;
    }
    int g;
    const lpv_flag *fl;
    const char *v;
    for (lpv_flags_item it; (it = lpv_flags_next(&p, &g, &fl, &v)) != LPV_FLAGS_END;) {
        if (lpv_flags_refuse(&p, it, v, "lpvd-bench", 1)) {
            return 2;
        } else if (it == LPV_FLAGS_POSITIONAL) {
            scene_path = v; /* the last one given */
        } else if (fl == &FLAGS[B_HELP]) {
            usage(stdout);
            return 0;
        } else if (fl == &FLAGS[B_REPEAT]) {
            repeat = atoi(v);
        } else if (fl == &FLAGS[B_WARMUP]) {
            warmup = atoi(v);
        } else if (fl == &FLAGS[B_CONFIG]) {
            only = v;
        } else if (fl == &FLAGS[B_FRAME_OUT]) {
            frame_dir = v;
        }
    }
    if (repeat < 1 || repeat > 1000 || warmup < 0) {
        fprintf(stderr, "lpvd-bench: --repeat 1..1000, --warmup >= 0\n");
        return 2;
    }
    const config configs[] = {{"balanced", 0, 0, 0, 0, 0},
                              {"paper32", 32, 8, 256, 1, 0},
                              {"paper64", 64, 8, 256, 1, 0},
                              {"cascades3", 32, 8, 256, 1, 3}};
    int known = !only;
    for (size_t c = 0; c < sizeof configs / sizeof configs[0]; ++c)
        known |= only && strcmp(only, configs[c].name) == 0;
    if (!known) {
        fprintf(stderr, "lpvd-bench: --config %s: expected balanced, paper32, paper64 or cascades3\n", only);
        return 2;
    }

    lpv_scene scene;
    if (lpv_scene_load_user(scene_path, NULL, &scene, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd-bench: %s\n", err);
        return 1;
    }
    lpv_view view;
    if (lpv_view_resolve(&opt.cam, &scene, &view, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd-bench: %s\n", err);
        return 2;
    }
    lpv_gl_context *ctx = lpv_gl_context_create(&(lpv_gl_context_desc){.backend = opt.backend}, err, sizeof err);
    if (!ctx) {
        fprintf(stderr, "lpvd-bench: %s\n", err);
        return 1;
    }
    lpv_engine *e = lpv_engine_create(err, sizeof err);
    if (!e) {
        fprintf(stderr, "lpvd-bench: %s\n", err);
        return 1;
    }
    float *rgba = malloc((size_t)view.width * view.height * 4 * sizeof(float));

    printf("# lpvd-bench: %s, backend %s, GL_RENDERER %s, image %dx%d, median of %d ticks after %d warm-up\n\n",
           scene.source, lpv_backend_name(lpv_gl_context_backend(ctx)), lpv_gl_context_renderer(ctx), view.width,
           view.height, repeat, warmup);
    int rc = 0;
    for (size_t c = 0; c < sizeof configs / sizeof configs[0] && rc == 0; ++c) {
        if (only && strcmp(only, configs[c].name) != 0)
            continue;
        lpv_settings s = opt.settings;
        if (configs[c].grid) {
            s.grid_dims[0] = s.grid_dims[1] = s.grid_dims[2] = configs[c].grid;
            s.lpv.iterations = configs[c].iterations;
            s.rsm_size = configs[c].rsm;
        }
        if (configs[c].cascades)
            s.lpv.cascades = configs[c].cascades;
        if (configs[c].paper)
            s.lpv.central_transport = s.lpv.normal_bins = s.lpv.far_field = s.scene_surfels = LPV_SWITCH_OFF;
        lpv_settings_resolve(&s);
        const lpv_engine_item item = {.settings = &s, .scene = &scene, .view = &view};
        if (lpv_engine_run_item(e, &item, err, sizeof err) != 0) {
            fprintf(stderr, "lpvd-bench: %s\n", err);
            rc = 1;
            break;
        }
        double samples[LPV_STAGE_MAX][1000];
        double totals[1000], walls[1000];
        char names[LPV_STAGE_MAX][32];
        int stage_count = 0;
        for (int r = 0; r < warmup + repeat; ++r) {
            /* The planner serves an unchanged scene's cached volume without
             * running a stage: every timed tick is made a full one. */
            lpv_engine_invalidate(e);
            if (lpv_engine_set_settings(e, &s, err, sizeof err) != 0) {
                fprintf(stderr, "lpvd-bench: %s\n", err);
                rc = 1;
                break;
            }
            double t0 = now_ms();
            if (lpv_engine_tick(e, err, sizeof err) != 0 || lpv_engine_render(e, LPV_TERMS_FULL, rgba, err, sizeof err)) {
                fprintf(stderr, "lpvd-bench: %s\n", err);
                rc = 1;
                break;
            }
            double wall = now_ms() - t0;
            if (r < warmup)
                continue;
            walls[r - warmup] = wall;
            const lpv_engine_stats *st = lpv_engine_last_stats(e);
            stage_count = st->stage_count;
            double total = 0.0;
            for (int k = 0; k < st->stage_count; ++k) {
                snprintf(names[k], sizeof names[k], "%s", st->stages[k].name);
                samples[k][r - warmup] = st->stages[k].gpu_ms;
                total += st->stages[k].gpu_ms;
            }
            totals[r - warmup] = total;
        }
        if (rc)
            break;
        const lpv_engine_stats *st = lpv_engine_last_stats(e);
        char letters[5];
        printf("## %s: %d^3 cells, %d iterations, RSM %d^2, occlusion %s, departures %s (%d cascades)\n\n",
               configs[c].cascades ? "cascaded, the paper's pipeline"
               : configs[c].grid   ? "the paper's pipeline"
                                   : lpv_preset_name(s.preset),
               s.grid_dims[0], s.lpv.iterations,
               s.rsm_size, st->occlusion ? "on" : "off", lpv_settings_departures(&s, letters), st->cascades);
        printf("| stage | GPU ms (median) |\n|---|---:|\n");
        double prop_ms = 0.0;
        for (int k = 0; k < stage_count; ++k) {
            double m = median(samples[k], repeat);
            if (strcmp(names[k], "propagate") == 0)
                prop_ms = m;
            printf("| %s | %.2f |\n", names[k], m);
        }
        printf("| **total** | **%.2f** |\n", median(totals, repeat));
        printf("| **wall** | **%.2f** |\n\n", median(walls, repeat));
        if (frame_report(frame_dir, configs[c].name, rgba, view.width, view.height) != 0) {
            rc = 1;
            break;
        }
        /* The shading's parts (the frame's own stages, shade and
         * area_shadow): the same frame with only direct light, then only
         * the LPV term (a tick that finds nothing changed runs no pass,
         * so each render's stages are the last stats'). */
        double split[2][1000];
        const lpv_frame_terms split_terms[2] = {LPV_TERMS_DIRECT_ONLY, LPV_TERMS_INDIRECT_ONLY};
        for (int t = 0; t < 2 && rc == 0; ++t)
            for (int r = 0; r < repeat; ++r) {
                if (lpv_engine_tick(e, err, sizeof err) != 0 ||
                    lpv_engine_render(e, split_terms[t], rgba, err, sizeof err) != 0) {
                    fprintf(stderr, "lpvd-bench: %s\n", err);
                    rc = 1;
                    break;
                }
                const lpv_engine_stats *ss = lpv_engine_last_stats(e);
                split[t][r] = 0.0;
                for (int k = 0; k < ss->stage_count; ++k)
                    if (strcmp(ss->stages[k].name, "shade") == 0 || strcmp(ss->stages[k].name, "area_shadow") == 0)
                        split[t][r] += ss->stages[k].gpu_ms;
            }
        if (rc)
            break;
        printf("shade + area_shadow: direct light only %.2f ms, indirect (the lookup) only %.2f ms\n\n", median(split[0], repeat),
               median(split[1], repeat));
        /* every volume's cells (cascades x normal bins) times the steps */
        double cell_steps = st->cell_steps;
        printf("propagation: %.0f cell-steps in %.2f ms = **%.1f M cell-steps/s**\n\n", cell_steps, prop_ms,
               prop_ms > 0.0 ? cell_steps / prop_ms / 1e3 : 0.0);
        fflush(stdout);
    }
    free(rgba);
    lpv_engine_destroy(e);
    lpv_gl_context_destroy(ctx);
    lpv_scene_free(&scene);
    return rc;
}
