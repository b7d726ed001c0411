/*
 * lpvd_accuracy.c - `lpvd-accuracy`: what accuracy costs in time. For each
 * scene and each point of a sweep over the engine's quality knobs (grid,
 * iterations, RSM size, occlusion), renders lpvd's indirect-only frame in
 * process, times it (median GPU ms per tick after warm-up, timer queries),
 * compares it with a path-traced reference (metrics.h) and writes
 *
 *   OUT/results.csv   one row per (scene, point), with the Pareto flag and
 *                     the named preset (settings.h) the point equals, if any
 *   OUT/results.md    one Markdown table per scene, Pareto points marked
 *   OUT/plot.gp, OUT/plot.png   error vs ms per tick (log x), fronts connected,
 *                     preset points labelled
 *   OUT/err/SCENE/g<grid>-i<iter>-r<rsm>-occ<on|off>.png   per-point error images
 *   OUT/ref/SCENE-<key>.exr (+ .stderr.exr, .png)        the cached references
 *
 * The reference comes from the `lpvd-reference` command (reference/), run
 * once per scene, camera, size and spp and cached under OUT/ref. See
 * docs/accuracy.md. Nothing here asserts a time.
 *
 * This file holds main, the steps in order: the command line (acc_cli.c),
 * the --emissive and --iv-tables modes, the point set (acc_point_set.c), the
 * scenes (acc_scenes.c), the run (acc_run_scene.c, acc_run_point.c), the
 * Pareto fronts and the outputs (acc_csv.c, acc_markdown.c, acc_plot.c,
 * acc_overall_front.c). accuracy_internal.h lists every file's job.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "accuracy_internal.h"
#include "context.h"
#include "emissive_full.h"
#include "engine.h"
#include "iv_tables.h"

/* The CPU's model name (/proc/cpuinfo) and core count, for the tables' header. */
static void cpu_name(char *out, size_t n)
{
    FILE *f = fopen("/proc/cpuinfo", "r");
    char line[512];
    snprintf(out, n, "unknown CPU");
    while (f && fgets(line, sizeof line, f)) {
        char *colon = strchr(line, ':');
        if (strncmp(line, "model name", 10) == 0 && colon) {
            line[strcspn(line, "\n")] = '\0';
            snprintf(out, n, "%s", colon + 2);
            break;
        }
    }
    if (f)
        fclose(f);
    size_t len = strlen(out);
    snprintf(out + len, n - len, ", %ld cores", sysconf(_SC_NPROCESSORS_ONLN));
}

/* --iv-tables (iv_tables.h): the paper's tables 1 and 2 on the scenes. */
/* A GL context and an engine on it, or 1 with the reason on stderr. */
static int open_gl(lpv_backend backend, lpv_gl_context **ctx, lpv_engine **engine)
{
    char err[1024];
    *ctx = lpv_gl_context_create(&(lpv_gl_context_desc){.backend = backend}, err, sizeof err);
    if (!*ctx) {
        fprintf(stderr, "lpvd-accuracy: no OpenGL 4.5 context: %s\n", err);
        return 1;
    }
    *engine = lpv_engine_create(err, sizeof err);
    if (!*engine) {
        fprintf(stderr, "lpvd-accuracy: %s\n", err);
        lpv_gl_context_destroy(*ctx);
        *ctx = NULL;
        return 1;
    }
    return 0;
}

static int run_iv_tables(const lpvd_options *opt, const char *out_dir, const char *scene_list, int ticks, int warmup,
                         int has_points, int argc, char **argv)
{
    if (has_points) {
        fprintf(stderr, "lpvd-accuracy: --iv-tables measures fixed settings: no --knobs, --points, --quick, "
                        "--presets or --features with it (set knobs with --iv-*)\n");
        return 2;
    }
    static scene_entry scenes[MAX_SCENES];
    static char paths[MAX_SCENES][1024];
    int n = acc_parse_scenes(scene_list, scenes, paths);
    if (n <= 0)
        return 2;
    lpv_acc_iv_scene is[MAX_SCENES];
    for (int i = 0; i < n; ++i) {
        is[i] = (lpv_acc_iv_scene){.name = scenes[i].name, .path = scenes[i].path, .has_cam = scenes[i].has_cam,
                                   .fov = scenes[i].fov};
        memcpy(is[i].eye, scenes[i].eye, sizeof is[i].eye);
        memcpy(is[i].target, scenes[i].target, sizeof is[i].target);
    }
    lpv_gl_context *ctx = NULL;
    lpv_engine *engine = NULL;
    if (open_gl(opt->backend, &ctx, &engine) != 0)
        return 1;
    int rc = 1;
    {
        char machine[1024], cpu[256], command[4096];
        cpu_name(cpu, sizeof cpu);
        snprintf(machine, sizeof machine, "backend %s, GL_RENDERER %s; CPU %s",
                 lpv_backend_name(lpv_gl_context_backend(ctx)), lpv_gl_context_renderer(ctx), cpu);
        size_t len = 0;
        command[0] = '\0';
        for (int i = 0; i < argc && len < sizeof command; ++i)
            len += (size_t)snprintf(command + len, sizeof command - len, "%s%s", i ? " " : "", argv[i]);
        fprintf(stderr, "lpvd-accuracy: --iv-tables: %s\n", machine);
        lpv_acc_iv_tables_desc d = {.out_dir = out_dir, .opt = opt, .scenes = is, .nscenes = n, .ticks = ticks,
                                    .warmup = warmup, .machine = machine, .command = command};
        rc = lpv_acc_iv_tables_run(engine, &d);
    }
    lpv_engine_destroy(engine);
    lpv_gl_context_destroy(ctx);
    return rc;
}

int main(int argc, char **argv)
{
    acc_args a;
    const int parsed = acc_parse_args(&a, argc, argv);
    if (parsed >= 0)
        return parsed;
    lpv_settings resolved = a.opt.settings;
    lpv_settings_resolve(&resolved);
    const int area_lights = resolved.area_lights == LPV_SWITCH_ON;
    if (a.emissive) {
        lpv_gl_context *ctx = NULL;
        lpv_engine *engine = NULL;
        if (open_gl(a.opt.backend, &ctx, &engine) != 0)
            return 1;
        int rc = 1;
        {
            fprintf(stderr, "lpvd-accuracy: backend %s, GL_RENDERER %s\n",
                    lpv_backend_name(lpv_gl_context_backend(ctx)), lpv_gl_context_renderer(ctx));
            lpv_acc_emissive_desc d = {.out_dir = a.out_dir, .scenes_dir = LPVD_ACCURACY_SCENES_DIR, .opt = &a.opt,
                                       .spp = a.spp, .ticks = a.ticks, .warmup = a.warmup};
            rc = lpv_acc_emissive_run(engine, &d);
        }
        lpv_engine_destroy(engine);
        lpv_gl_context_destroy(ctx);
        return rc;
    }

    if (a.iv_tables)
        return run_iv_tables(&a.opt, a.out_dir, a.scenes_given ? a.scene_list : "cornell,courtyard,blinds,engine", a.ticks,
                             a.warmup, a.knobs || a.points_arg || a.quick || a.presets || a.features, argc, argv);

    /* The point set. */
    static point pts[MAX_POINTS];
    const int npts = acc_point_set(&a, &resolved, pts);
    if (npts < 0)
        return 2;

    /* The scenes. */
    static scene_entry scenes[MAX_SCENES];
    static char scene_paths[MAX_SCENES][1024];
    int nscenes = acc_parse_scenes(a.scene_list, scenes, scene_paths);
    if (nscenes < 0)
        return 2;
    if (nscenes == 0) {
        fprintf(stderr, "lpvd-accuracy: --scenes is empty\n");
        return 2;
    }

    char ref_cmd[1200];
    int ref_is_cmd = acc_find_reference(a.ref_given, ref_cmd, sizeof ref_cmd);
    char sub[1200];
    snprintf(sub, sizeof sub, "%s/ref", a.out_dir);
    if (acc_mkdir_p(sub) != 0) {
        fprintf(stderr, "lpvd-accuracy: cannot create %s: %s\n", sub, strerror(errno));
        return 1;
    }

    lpv_gl_context *ctx = NULL;
    lpv_engine *engine = NULL;
    if (open_gl(a.opt.backend, &ctx, &engine) != 0)
        return 1;
    char header[2048];
    snprintf(header, sizeof header,
             "backend %s, GL_RENDERER %s; image %dx%d; reference `%s`: converged light (every bounce, Russian "
             "roulette) with 2 seeds at %d spp each, the own-bounce references at %d spp; median of %d ticks after "
             "%d warm-up; %d point(s) per scene.\n",
             lpv_backend_name(lpv_gl_context_backend(ctx)), lpv_gl_context_renderer(ctx), a.opt.cam.width,
             a.opt.cam.height, ref_cmd, a.conv_spp > 0 ? a.conv_spp : (a.spp / 2 > 0 ? a.spp / 2 : 1), a.spp, a.ticks, a.warmup,
             npts);
    fprintf(stderr, "lpvd-accuracy: %s", header);

    acc_run c = {.a = &a, .engine = engine, .pts = pts, .npts = npts, .scenes = scenes, .nscenes = nscenes,
                 .ref_cmd = ref_cmd, .ref_is_cmd = ref_is_cmd, .area_lights = area_lights};
    c.results = calloc((size_t)nscenes * (size_t)npts, sizeof *c.results);
    int rc = acc_run_scenes(&c);
    result *results = c.results;
    const int nres = c.nres;
    lpv_engine_destroy(engine);
    lpv_gl_context_destroy(ctx);

    /* The Pareto front per scene (ms per tick vs relative RMSE). */
    for (int s = 0; s < nscenes; ++s) {
        double cost[MAX_POINTS], error[MAX_POINTS];
        int idx[MAX_POINTS], front[MAX_POINTS], k = 0;
        for (int i = 0; i < nres; ++i)
            if (results[i].scene == s && !results[i].p.feat) {
                cost[k] = results[i].ms_total;
                error[k] = results[i].m.rel_rmse;
                idx[k++] = i;
            }
        lpv_acc_pareto(cost, error, (size_t)k, front);
        for (int j = 0; j < k; ++j)
            results[idx[j]].pareto = front[j];
        k = 0; /* the features block: its own front */
        for (int i = 0; i < nres; ++i)
            if (results[i].scene == s && results[i].p.feat) {
                cost[k] = results[i].ms_total;
                error[k] = results[i].m.rel_rmse;
                idx[k++] = i;
            }
        lpv_acc_pareto(cost, error, (size_t)k, front);
        for (int j = 0; j < k; ++j)
            results[idx[j]].pareto = front[j];
    }

    char path[1200];
    snprintf(path, sizeof path, "%s/results.csv", a.out_dir);
    FILE *f = fopen(path, "w");
    if (f) {
        acc_write_csv(f, results, nres, scenes);
        fclose(f);
    } else {
        rc = 1;
    }
    snprintf(path, sizeof path, "%s/results.md", a.out_dir);
    f = fopen(path, "w");
    if (f) {
        acc_write_md(f, results, nres, scenes, nscenes, header);
        fclose(f);
    } else {
        rc = 1;
    }
    int nclassic = 0;
    for (int i = 0; i < nres; ++i)
        nclassic += !results[i].p.feat;
    if (nclassic > 0 && acc_write_plot(a.out_dir, results, nres, scenes, nscenes, a.no_plot) != 0 && !a.no_plot)
        fprintf(stderr, "lpvd-accuracy: no plot.png\n");
    if (nres > 0 && acc_write_features_plot(a.out_dir, results, nres, scenes, nscenes, a.no_plot) != 0 && !a.no_plot)
        fprintf(stderr, "lpvd-accuracy: no features.png\n");
    if (nres > 0 && acc_write_overall(a.out_dir, results, nres, scenes, nscenes, a.no_plot) != 0)
        fprintf(stderr, "lpvd-accuracy: no overall front (overall.csv, overall.png)\n");
    free(results);
    fprintf(stderr, "lpvd-accuracy: %d point(s) written to %s/results.csv, results.md%s\n", nres, a.out_dir,
            a.no_plot ? "" : ", plot.png");
    return rc;
}
