/*
 * lpvd_bench_features.c - what the engine's newer features cost per stage:
 * cascades (1 vs 3) x multiple bounces (off / on), glossy reflections and
 * homogeneous fog, on the built-in Cornell box and scenes/courtyard.glb (and
 * scenes/glossy.glb for glossy), plus what the tick planner saves on a
 * scene where nothing changed and where only the camera moved within a cell.
 *
 *   lpvd-bench-features [--repeat N] [--warmup N] [--scenes-dir DIR] [lpvd flags: --size WxH, --backend NAME, ...]
 *
 * Every configuration starts from the settings given on the command line
 * (default: the balanced preset; the header line says which). With the planner on, a tick on an unchanged scene
 * serves the cached volume and runs no stage, so to time the stages every
 * timed tick first calls lpv_engine_invalidate (a full recompute). The
 * planner table instead measures exactly the ticks the
 * planner skips. Per stage: median GPU ms (timer queries) over --repeat
 * ticks after --warmup ticks; stage "shade" is the render of the frame.
 * Not a test: nothing here asserts a time.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "context.h"
#include "engine.h"
#include "gl.h"
#include "options.h"
#include "scene_load.h"

#ifndef LPVD_BENCH_SCENES_DIR
#define LPVD_BENCH_SCENES_DIR "scenes"
#endif

#define MAX_REPEAT 200
#define MAX_COLS 24

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(const double *v, int n)
{
    double t[MAX_REPEAT];
    memcpy(t, v, (size_t)n * sizeof *t);
    qsort(t, (size_t)n, sizeof *t, cmp_double);
    return n % 2 ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]);
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* One scene of the benchmark: the file (NULL = built-in Cornell box) and an
 * optional camera override. */
typedef struct bench_scene {
    const char *name;
    char path[1024];
    int builtin;
    int has_cam;
    float eye[3], target[3], fov;
    float cascade_size; /* for the 3-cascade configurations */
} bench_scene;

typedef struct bench_config {
    const char *label;
    int cascades; /* 0 = auto */
    int bounces;  /* 0 off, 1 on */
    int glossy;   /* -1 default, 0 off, 1 on */
    float fog_sigma_s;
} bench_config;

/* Stage columns: the union of the names seen, in first-seen order. */
static char g_cols[MAX_COLS][32];
static int g_ncols;

static int col_index(const char *name)
{
    for (int i = 0; i < g_ncols; ++i)
        if (strcmp(g_cols[i], name) == 0)
            return i;
    if (g_ncols == MAX_COLS)
        return -1;
    snprintf(g_cols[g_ncols], sizeof g_cols[g_ncols], "%s", name);
    return g_ncols++;
}

typedef struct row {
    char scene[64], label[96];
    int cascades;
    double ms[MAX_COLS]; /* median per stage; NAN = stage not recorded */
    double total;
    char passes[256]; /* glossy / media / bounce: run or skipped */
} row;

static row g_rows[64];
static int g_nrows;

static int load_view(const bench_scene *bs, const lpvd_options *opt, lpv_scene *scene, lpv_view *view, char *err,
                     size_t n)
{
    if (lpv_scene_load_user(bs->builtin ? NULL : bs->path, NULL, scene, err, n) != 0)
        return -1;
    lpv_view_choice cam = opt->cam;
    if (bs->has_cam) {
        cam.has_eye = cam.has_target = cam.has_fov = 1;
        memcpy(cam.eye, bs->eye, sizeof cam.eye);
        memcpy(cam.target, bs->target, sizeof cam.target);
        cam.fov_deg = bs->fov;
    }
    if (lpv_view_resolve(&cam, scene, view, err, n) != 0) {
        lpv_scene_free(scene);
        return -1;
    }
    return 0;
}

/* Times one configuration; appends a row. */
static int run_config(lpv_engine *e, const lpv_scene *scene, const lpv_view *view, const bench_scene *bs,
                      const bench_config *c, const lpvd_options *opt, int warmup, int repeat, float *rgba)
{
    char err[1024];
    lpv_settings s = opt->settings;
    s.lpv.cascades = c->cascades;
    if (c->cascades > 1)
        s.lpv.cascade_size = bs->cascade_size;
    s.lpv.bounces = c->bounces ? LPV_SWITCH_ON : LPV_SWITCH_OFF;
    if (c->glossy >= 0)
        s.glossy = c->glossy ? LPV_SWITCH_ON : LPV_SWITCH_OFF;
    s.fog_sigma_s = c->fog_sigma_s;
    if (lpv_engine_set_scene(e, scene, err, sizeof err) != 0 || lpv_engine_set_view(e, view, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd-bench-features: %s\n", err);
        return -1;
    }
    static double samples[MAX_COLS][MAX_REPEAT], totals[MAX_REPEAT];
    int seen[MAX_COLS] = {0};
    for (int r = 0; r < warmup + repeat; ++r) {
        lpv_engine_invalidate(e); /* a full tick, not the cached volume */
        if (lpv_engine_set_settings(e, &s, err, sizeof err) != 0 || lpv_engine_tick(e, err, sizeof err) != 0 ||
            lpv_engine_render(e, LPV_TERMS_FULL, rgba, err, sizeof err) != 0) {
            /* a feature that fails (e.g. one still being implemented) is a row that says so */
            fprintf(stderr, "lpvd-bench-features: %s / %s: %s\n", bs->name, c->label, err);
            row *w = &g_rows[g_nrows++];
            snprintf(w->scene, sizeof w->scene, "%s", bs->name);
            snprintf(w->label, sizeof w->label, "%s", c->label);
            w->cascades = lpv_engine_cascade_count(e);
            for (int k = 0; k < MAX_COLS; ++k)
                w->ms[k] = NAN;
            w->total = NAN;
            snprintf(w->passes, sizeof w->passes, "FAILED: %.200s", err);
            return 0;
        }
        if (!lpv_engine_last_plan(e)->recompute) {
            fprintf(stderr, "lpvd-bench-features: tick %d was not recomputed (%s)\n", r,
                    lpv_engine_last_plan(e)->recompute_reason);
            return -1;
        }
        if (r < warmup)
            continue;
        const lpv_engine_stats *st = lpv_engine_last_stats(e);
        double total = 0.0;
        for (int k = 0; k < MAX_COLS; ++k)
            samples[k][r - warmup] = 0.0;
        for (int k = 0; k < st->stage_count; ++k) {
            int ci = col_index(st->stages[k].name);
            if (ci < 0)
                continue;
            samples[ci][r - warmup] += st->stages[k].gpu_ms;
            seen[ci] = 1;
            total += st->stages[k].gpu_ms;
        }
        totals[r - warmup] = total;
    }
    row *w = &g_rows[g_nrows++];
    snprintf(w->scene, sizeof w->scene, "%s", bs->name);
    snprintf(w->label, sizeof w->label, "%s", c->label);
    w->cascades = lpv_engine_cascade_count(e);
    for (int k = 0; k < MAX_COLS; ++k)
        w->ms[k] = seen[k] ? median(samples[k], repeat) : NAN;
    w->total = median(totals, repeat);
    const lpv_plan *p = lpv_engine_last_plan(e);
    snprintf(w->passes, sizeof w->passes, "bounce %s, glossy %s, media %s", p->pass[LPV_PASS_BOUNCE].run ? "run" : "-",
             p->pass[LPV_PASS_GLOSSY].run ? "run" : "-", p->pass[LPV_PASS_MEDIA].run ? "run" : "-");
    fprintf(stderr, "lpvd-bench-features: %s / %s: %d cascade(s), %.2f ms; %s\n", bs->name, c->label, w->cascades,
            w->total, w->passes);
    return 0;
}

static void print_stage_tables(void)
{
    const char *last = "";
    for (int i = 0; i < g_nrows; ++i) {
        const row *w = &g_rows[i];
        if (strcmp(w->scene, last) != 0) {
            /* the columns any row of this scene recorded */
            printf("\n#### %s\n\n| configuration | cascades |", w->scene);
            for (int k = 0; k < g_ncols; ++k)
                printf(" %s |", g_cols[k]);
            printf(" **total** | planner: extra passes |\n|---|---:|");
            for (int k = 0; k <= g_ncols; ++k)
                printf("---:|");
            printf("---|\n");
            last = w->scene;
        }
        printf("| %s | %d |", w->label, w->cascades);
        for (int k = 0; k < g_ncols; ++k) {
            if (isnan(w->ms[k]))
                printf(" – |");
            else
                printf(" %.2f |", w->ms[k]);
        }
        if (isnan(w->total))
            printf(" – | %s |\n", w->passes);
        else
            printf(" **%.2f** | %s |\n", w->total, w->passes);
    }
    printf("\n");
}

/* The planner's saving on one scene (balanced settings): tick wall ms (tick
 * + glFinish) and tick GPU ms (sum of the tick's stages, render excluded). */
static int run_planner(lpv_engine *e, const lpv_scene *scene, const lpv_view *view, const bench_scene *bs,
                       const lpvd_options *opt, int warmup, int repeat, float *rgba)
{
    char err[1024];
    const char *modes[] = {"planner off: every tick recomputes", "planner on: settings change every tick (full)",
                           "planner on: nothing changed", "planner on: camera moved 0.1 cell (every other tick)"};
    double wall_med[4], gpu_med[4], frame_med[4];
    int recomputed[4];
    char reason[4][LPV_PLAN_REASON_MAX];
    /* the count auto picks with the planner on: planner off would force the
     * default 3 when auto, so it gets this count explicitly */
    lpv_settings on = opt->settings;
    const lpv_engine_item first = {.settings = &on, .scene = scene, .view = view, .tick = 1};
    if (lpv_engine_run_item(e, &first, err, sizeof err) != 0)
        goto fail;
    const int cascades = lpv_engine_cascade_count(e);
    int failed[4] = {0};
    for (int m = 0; m < 4; ++m) {
        lpv_settings s = opt->settings;
        s.planner = m == 0 ? LPV_SWITCH_OFF : LPV_SWITCH_ON;
        if (m == 0)
            s.lpv.cascades = cascades;
        const lpv_engine_item item = {.settings = &s, .scene = scene, .view = view};
        if (lpv_engine_run_item(e, &item, err, sizeof err) != 0)
            goto mode_fail;
        double wall[MAX_REPEAT], gpu[MAX_REPEAT], frame[MAX_REPEAT];
        recomputed[m] = 0;
        const float cell = lpv_engine_grid(e)->cell_size;
        for (int r = 0; r < warmup + repeat; ++r) {
            if (m == 1)
                lpv_engine_invalidate(e);
            if (m == 3 && r >= warmup) { /* alternate between the view and the view moved by 0.1 cell along x */
                lpv_view v = *view;
                float dx = (r & 1) ? 0.1f * cell : 0.0f;
                v.eye[0] += dx;
                if (lpv_engine_set_view(e, &v, err, sizeof err) != 0)
                    goto mode_fail;
            }
            glFinish();
            double t0 = now_ms();
            if (lpv_engine_tick(e, err, sizeof err) != 0)
                goto mode_fail;
            glFinish();
            double t1 = now_ms();
            const lpv_engine_stats *st = lpv_engine_last_stats(e);
            const lpv_plan *p = lpv_engine_last_plan(e);
            double g = 0.0;
            for (int k = 0; k < st->stage_count; ++k)
                g += st->stages[k].gpu_ms;
            if (r >= warmup) {
                wall[r - warmup] = t1 - t0;
                gpu[r - warmup] = p->recompute ? g : 0.0;
                recomputed[m] += p->recompute;
                if (m != 3 || (r & 1)) /* mode 3: the reason of a tick that moved the camera */
                    snprintf(reason[m], sizeof reason[m], "%s", p->recompute_reason);
            }
            if (lpv_engine_render(e, LPV_TERMS_FULL, rgba, err, sizeof err) != 0)
                goto mode_fail;
            if (r >= warmup)
                frame[r - warmup] = now_ms() - t0; /* the render reads the frame back: synchronous */
        }
        wall_med[m] = median(wall, repeat);
        gpu_med[m] = median(gpu, repeat);
        frame_med[m] = median(frame, repeat);
        continue;
    mode_fail: /* e.g. planner off forces the media pass, which may still be in the works */
        fprintf(stderr, "lpvd-bench-features: %s / %s: %s\n", bs->name, modes[m], err);
        snprintf(reason[m], sizeof reason[m], "FAILED: %.100s", err);
        failed[m] = 1;
        wall_med[m] = gpu_med[m] = frame_med[m] = NAN;
    }
    printf("\n#### %s (balanced, %d cascade(s))\n\n", bs->name, cascades);
    printf("| tick | recomputed | tick wall ms (median) | tick GPU ms (median) | full / this (wall; full = planner "
           "on, settings changed) | tick + render wall ms | planner's reason (last tick) |\n|---|---:|---:|---:|---:|---:|---|\n");
    for (int m = 0; m < 4; ++m) {
        if (failed[m]) {
            printf("| %s | – | – | – | – | – | %s |\n", modes[m], reason[m]);
            continue;
        }
        printf("| %s | %d/%d | %.2f | %.2f | %.0f× | %.2f | %s |\n", modes[m], recomputed[m], repeat, wall_med[m],
               gpu_med[m], wall_med[m] > 0.0 && !failed[1] ? wall_med[1] / wall_med[m] : NAN, frame_med[m],
               reason[m]);
    }
    fflush(stdout);
    return 0;
fail:
    fprintf(stderr, "lpvd-bench-features: %s\n", err);
    return -1;
}

enum { B_REPEAT, B_WARMUP, B_SCENES_DIR, B_PLANNER_ONLY, B_STAGES_ONLY, B_HELP, B_COUNT };

static const lpv_flag FLAGS[B_COUNT] = {
    [B_REPEAT] = {"repeat", 0, "N", "timed ticks per configuration, 1..200 (default 7)"},
    [B_WARMUP] = {"warmup", 0, "N", "untimed ticks first (default 2)"},
    [B_SCENES_DIR] = {"scenes-dir", 0, "DIR", "where courtyard.glb and glossy.glb are (default: scenes/ of the\n"
                                              "source tree)"},
    [B_PLANNER_ONLY] = {"planner-only", 0, NULL, "only the planner's table (default: both tables)"},
    [B_STAGES_ONLY] = {"stages-only", 0, NULL, "only the per-stage table"},
    [B_HELP] = {"help", 'h', NULL, "this text"},
};

static void usage(FILE *f)
{
    char help[2048];
    size_t len = 0;
    lpv_flags_help(help, sizeof help, &len, FLAGS, B_COUNT);
    fprintf(f, "usage: lpvd-bench-features [--repeat N] [--warmup N] [--scenes-dir DIR] [--planner-only | "
               "--stages-only] [lpvd flags]\n%s%s",
            help, LPVD_OPTIONS_HELP);
}

int main(int argc, char **argv)
{
    int repeat = 7, warmup = 2, skip_stages = 0, skip_planner = 0;
    const char *scenes_dir = LPVD_BENCH_SCENES_DIR;
    /* the features are the cascaded LPV's: the LPV unless --technique names
     * another (the engine's default is auto since issue 30) */
    lpvd_options opt = {.settings = {.technique = LPV_TECHNIQUE_ID_LPV}};
    char err[1024];
    lpv_flag_group groups[4] = {{FLAGS, B_COUNT, NULL, NULL}};
    int ngroups = 1 + lpvd_options_groups(&opt, LPVD_GROUP_ALL, 1, groups + 1);
    lpv_flags p;
    if (lpv_flags_begin(&p, argc, argv, groups, ngroups, 0) != 0) {
        fprintf(stderr, "lpvd-bench-features: %s\n", p.err);
        return 2;
    }
    int g;
    const lpv_flag *fl;
    const char *v;
    for (lpv_flags_item it; (it = lpv_flags_next(&p, &g, &fl, &v)) != LPV_FLAGS_END;) {
        if (lpv_flags_refuse(&p, it, v, "lpvd-bench-features", 0)) {
            return 2;
        } else if (fl == &FLAGS[B_HELP]) {
            usage(stdout);
            return 0;
        } else if (fl == &FLAGS[B_REPEAT]) {
            repeat = atoi(v);
        } else if (fl == &FLAGS[B_WARMUP]) {
            warmup = atoi(v);
        } else if (fl == &FLAGS[B_SCENES_DIR]) {
            scenes_dir = v;
        } else if (fl == &FLAGS[B_PLANNER_ONLY]) {
            skip_stages = 1;
        } else if (fl == &FLAGS[B_STAGES_ONLY]) {
            skip_planner = 1;
        }
    }
    if (repeat < 1 || repeat > MAX_REPEAT || warmup < 0) {
        fprintf(stderr, "lpvd-bench-features: --repeat 1..%d, --warmup >= 0\n", MAX_REPEAT);
        return 2;
    }
    /* The Cornell box's own camera stands 2.9 m in front of the open box; the
     * cascades follow the camera, so with it the finest cascades would hold
     * no geometry. Inside the opening, looking in, 1 m cascades (1, 2, 4 m)
     * nest in the 2 m box. */
    bench_scene scenes[3] = {
        {.name = "cornell (camera inside)", .builtin = 1, .has_cam = 1, .eye = {0.0f, 1.0f, 0.9f},
         .target = {0.0f, 1.0f, -1.0f}, .fov = 70.0f, .cascade_size = 1.0f},
        {.name = "courtyard", .cascade_size = 8.0f},
        {.name = "glossy", .cascade_size = 1.0f},
    };
    snprintf(scenes[1].path, sizeof scenes[1].path, "%s/courtyard.glb", scenes_dir);
    snprintf(scenes[2].path, sizeof scenes[2].path, "%s/glossy.glb", scenes_dir);

    lpv_gl_context *ctx = lpv_gl_context_create(&(lpv_gl_context_desc){.backend = opt.backend}, err, sizeof err);
    if (!ctx) {
        fprintf(stderr, "lpvd-bench-features: %s\n", err);
        return 1;
    }
    lpv_engine *e = lpv_engine_create(err, sizeof err);
    if (!e) {
        fprintf(stderr, "lpvd-bench-features: %s\n", err);
        return 1;
    }
    const bench_config grid_configs[] = {
        {"1 cascade, bounces off", 1, 0, -1, 0.0f},
        {"1 cascade, bounces on", 1, 1, -1, 0.0f},
        {"3 cascades, bounces off", 3, 0, -1, 0.0f},
        {"3 cascades, bounces on", 3, 1, -1, 0.0f},
        {"1 cascade, fog σs 0.05/m", 1, 0, -1, 0.05f},
        {"3 cascades, fog σs 0.05/m", 3, 0, -1, 0.05f},
    };
    const bench_config glossy_configs[] = {
        {"1 cascade, glossy off", 1, 0, 0, 0.0f},
        {"1 cascade, glossy on (floor roughness 0.1 < 0.3)", 1, 0, 1, 0.0f},
    };
    int rc = 0;
    lpv_view first_view = {0};
    int printed_header = 0;
    for (int si = 0; si < 3 && rc == 0 && !skip_stages; ++si) {
        lpv_scene scene;
        lpv_view view;
        if (load_view(&scenes[si], &opt, &scene, &view, err, sizeof err) != 0) {
            fprintf(stderr, "lpvd-bench-features: %s: %s (skipped)\n", scenes[si].name, err);
            continue;
        }
        if (!printed_header) {
            first_view = view;
            lpv_settings base = opt.settings;
            lpv_settings_resolve(&base);
            char departures[5];
            printf("# lpvd-bench-features: backend %s, GL_RENDERER %s, image %dx%d, median of %d ticks after %d "
                   "warm-up; %d^3, %d iterations, RSM %d^2, occlusion %s, departures %s unless stated\n",
                   lpv_backend_name(lpv_gl_context_backend(ctx)), lpv_gl_context_renderer(ctx), view.width,
                   view.height, repeat, warmup, base.grid_dims[0], base.lpv.iterations, base.rsm_size,
                   base.lpv.occlusion == LPV_SWITCH_ON ? "on" : "off", lpv_settings_departures(&base, departures));
            printed_header = 1;
        }
        float *rgba = malloc((size_t)view.width * view.height * 4 * sizeof(float));
        const bench_config *cfg = si == 2 ? glossy_configs : grid_configs;
        size_t ncfg = si == 2 ? sizeof glossy_configs / sizeof *glossy_configs
                              : sizeof grid_configs / sizeof *grid_configs;
        for (size_t c = 0; c < ncfg && rc == 0; ++c)
            rc = run_config(e, &scene, &view, &scenes[si], &cfg[c], &opt, warmup, repeat, rgba);
        free(rgba);
        lpv_scene_free(&scene);
    }
    (void)first_view;
    if (rc == 0 && !skip_stages) {
        printf("\n### GPU ms per stage (median)\n");
        printf("\n'–': the stage did not run. cornell: cascade_size 1 m for 3 cascades (1, 2, 4 m); courtyard: "
               "cascade_size 8 m (8, 16, 32 m; what auto picks); 1 cascade = one grid over the scene.\n");
        print_stage_tables();
    }
    if (rc == 0 && !skip_planner) {
        printf("\n### Tick planner: cost of a tick (render excluded)\n");
        for (int si = 0; si < 2 && rc == 0; ++si) {
            lpv_scene scene;
            lpv_view view;
            if (load_view(&scenes[si], &opt, &scene, &view, err, sizeof err) != 0) {
                fprintf(stderr, "lpvd-bench-features: %s\n", err);
                rc = 1;
                break;
            }
            float *rgba = malloc((size_t)view.width * view.height * 4 * sizeof(float));
            rc = run_planner(e, &scene, &view, &scenes[si], &opt, warmup, repeat, rgba);
            free(rgba);
            lpv_scene_free(&scene);
        }
    }
    lpv_engine_destroy(e);
    lpv_gl_context_destroy(ctx);
    return rc ? 1 : 0;
}
