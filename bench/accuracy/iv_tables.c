/* iv_tables.c - see iv_tables.h. */
#include "iv_tables.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "grid.h"
#include "iv_points.h"
#include "metrics.h"
#include "scene_load.h"
#include "settings.h"

#define IV_MAX_TICKS 1000
#define IV_NS 4
static const int POINTS_N[IV_NS] = {3, 7, 12, 19}; /* the paper's T_3 .. T_19 */

/* The stages the tables read, medians over the timed ticks. */
enum { S_POINTS, S_REPROJECT, S_RESOLVE, S_GATHER, S_AO, S_SHADE, S_COUNT };
static const char *const STAGE[S_COUNT] = {"iv_points", "iv_reproject", "iv_resolve", "iv_gather", "iv_ao", "shade"};

typedef struct measured {
    double stage[S_COUNT];
    double total; /* all stages */
} measured;

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}

/* Ticks the engine under st (warm-up first, every tick a full one) and
 * fills the stages' medians. Returns 0 or -1 (printed). */
static int run_ticks(lpv_engine *e, const lpv_settings *st, const lpv_scene *scene, const lpv_view *view, int ticks,
                     int warmup, measured *out)
{
    char err[1024];
    static double v[S_COUNT + 1][IV_MAX_TICKS];
    const lpv_engine_item item = {.settings = st, .scene = scene, .view = view};
    if (lpv_engine_run_item(e, &item, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd-accuracy: --iv-tables: %s\n", err);
        return -1;
    }
    float *rgba = malloc((size_t)view->width * (size_t)view->height * 4 * sizeof *rgba);
    if (!rgba)
        return -1;
    int rc = 0;
    for (int t = 0; t < warmup + ticks && rc == 0; ++t) {
        lpv_engine_invalidate(e);
        if (lpv_engine_tick(e, err, sizeof err) != 0 ||
            lpv_engine_render(e, LPV_TERMS_INDIRECT_ONLY, rgba, err, sizeof err) != 0) {
            fprintf(stderr, "lpvd-accuracy: --iv-tables: %s\n", err);
            rc = -1;
            break;
        }
        if (t < warmup)
            continue;
        const lpv_engine_stats *es = lpv_engine_last_stats(e);
        for (int k = 0; k <= S_COUNT; ++k)
            v[k][t - warmup] = 0.0;
        for (int j = 0; j < es->stage_count; ++j) {
            v[S_COUNT][t - warmup] += es->stages[j].gpu_ms;
            for (int k = 0; k < S_COUNT; ++k)
                if (strcmp(es->stages[j].name, STAGE[k]) == 0)
                    v[k][t - warmup] += es->stages[j].gpu_ms;
        }
    }
    free(rgba);
    for (int k = 0; k < S_COUNT; ++k)
        out->stage[k] = lpv_acc_median(v[k], (size_t)ticks);
    out->total = lpv_acc_median(v[S_COUNT], (size_t)ticks);
    return rc;
}

/* The point cloud as the engine makes it (gpu/engine_scene.c,
 * sample_iv_points), made `runs` times: the median CPU ms and its stats. */
static double cloud_cpu_ms(const lpv_scene *scene, const lpv_settings *resolved, int runs, lpv_iv_point_stats *stats)
{
    const int given = lpv_settings_bounds_given(resolved);
    lpv_grid g;
    if (lpv_grid_place_cubic(resolved->iv.resolution, given ? resolved->bounds_min : scene->bounds_min,
                             given ? resolved->bounds_max : scene->bounds_max, &g) != 0)
        return NAN;
    const lpv_iv_point_params p = lpv_iv_point_params_of(resolved, &g);
    double ms[IV_MAX_TICKS];
    int n = 0;
    for (int r = 0; r < runs && r < IV_MAX_TICKS; ++r) {
        struct IvPoint *pts = NULL;
        size_t count = 0;
        double t0 = now_ms();
        int rc = lpv_iv_points_make(scene, &p, &pts, &count, stats);
        ms[n++] = now_ms() - t0;
        free(pts);
        if (rc != 0)
            return NAN;
    }
    return lpv_acc_median(ms, (size_t)n);
}

typedef struct scene_row {
    const char *name;
    size_t triangles;
    double cpu[IV_NS], gpu[IV_NS], reproject[IV_NS];
    lpv_iv_point_stats cloud[IV_NS];
    measured t2;
    int bounces, ok1, ok2;
} scene_row;

static void print_tables(FILE *f, const lpv_acc_iv_tables_desc *d, const lpv_settings *base, const lpv_view *view0,
                         const scene_row *rows, int n)
{
    const lpv_iv_settings *iv = &base->iv;
    fprintf(f, "# Imperfect volumes: the paper's tables on lpvd's scenes\n\n");
    fprintf(f, "Machine: %s. Command: `%s`.\n\n", d->machine, d->command);
    fprintf(f, "Settings: %d voxels along the longest side, %d rays per voxel, %d bounces, neighbours %d, split %g "
               "voxel(s), point budget %d, RSM %d², view %dx%d (reprojection: %d points); median of %d tick(s) after "
               "%d warm-up, every tick a full one (lpv_engine_invalidate). GPU ms from timer queries (on llvmpipe: "
               "CPU ms of the emulation). Paper: 64³ voxels, 100 rays, GeForce GTX 460.\n\n",
            iv->resolution, iv->rays, iv->bounces, iv->neighbours, (double)iv->split, iv->max_points, base->rsm_size,
            view0->width, view0->height, view0->width * view0->height, d->ticks, d->warmup);
    fprintf(f, "## Table 1: volume creation (ms)\n\n");
    fprintf(f, "T_N = making the point cloud with N points per triangle on the CPU (lpv_iv_points_make, done when the "
               "geometry or a sampling knob changes) + lighting and splatting it on the GPU (stage iv_points, every "
               "tick); T_rp = reprojecting the view's %d² pixels (stage iv_reproject, median over the four runs).\n\n",
            view0->width);
    fprintf(f, "| scene | G (triangles) |");
    for (int j = 0; j < IV_NS; ++j)
        fprintf(f, " T_%d (CPU + GPU) |", POINTS_N[j]);
    fprintf(f, " T_rp |\n|:---|---:|");
    for (int j = 0; j < IV_NS; ++j)
        fprintf(f, "---:|");
    fprintf(f, "---:|\n");
    for (int i = 0; i < n; ++i) {
        const scene_row *r = &rows[i];
        fprintf(f, "| %s | %zu |", r->name, r->triangles);
        if (!r->ok1) {
            for (int j = 0; j <= IV_NS; ++j)
                fprintf(f, " failed |");
            fputc('\n', f);
            continue;
        }
        for (int j = 0; j < IV_NS; ++j)
            fprintf(f, " %.1f (%.1f + %.1f) |", r->cpu[j] + r->gpu[j], r->cpu[j], r->gpu[j]);
        double rp[IV_NS];
        memcpy(rp, r->reproject, sizeof rp);
        fprintf(f, " %.1f |\n", lpv_acc_median(rp, IV_NS));
    }
    fprintf(f, "\nThe clouds (points made; pieces after splitting triangles longer than the split; * = the budget "
               "(--iv-max-points) lowered the points per piece to the number given, so T_N measured fewer):\n\n"
               "| scene |");
    for (int j = 0; j < IV_NS; ++j)
        fprintf(f, " N = %d |", POINTS_N[j]);
    fprintf(f, "\n|:---|");
    for (int j = 0; j < IV_NS; ++j)
        fprintf(f, "---:|");
    fputc('\n', f);
    for (int i = 0; i < n; ++i) {
        fprintf(f, "| %s |", rows[i].name);
        for (int j = 0; j < IV_NS; ++j)
            if (rows[i].cloud[j].budget_cut)
                fprintf(f, " %zu points, %zu pieces * (%d per piece) |", rows[i].cloud[j].points,
                        rows[i].cloud[j].pieces, rows[i].cloud[j].points_per_piece);
            else
                fprintf(f, " %zu points, %zu pieces |", rows[i].cloud[j].points, rows[i].cloud[j].pieces);
        fputc('\n', f);
    }
    fprintf(f, "\n## Table 2: marching and reconstruction (ms), iv_ao on, %d points per triangle\n\n", iv->points);
    char reach[64];
    if (iv->ao_distance > 0.0f)
        snprintf(reach, sizeof reach, "%g m", (double)iv->ao_distance);
    else
        snprintf(reach, sizeof reach, "%g-voxel", (double)LPV_IV_AO_VOXELS);
    fprintf(f, "R_AO = the AO march (stage iv_ao, %d rays per voxel over a %s reach); R_GI = the GI march per bounce "
               "(stage iv_gather / bounces; each bounce's emission pass included); I = the reconstruction (stage "
               "shade: the lookup and shading of %dx%d pixels); the tick's total beside them.\n\n",
            iv->rays, reach, view0->width, view0->height);
    fprintf(f, "| scene | G (triangles) | R_AO | R_GI (per bounce) | bounces | I | total ms/tick |\n");
    fprintf(f, "|:---|---:|---:|---:|---:|---:|---:|\n");
    for (int i = 0; i < n; ++i) {
        const scene_row *r = &rows[i];
        if (!r->ok2) {
            fprintf(f, "| %s | %zu | failed | | | | |\n", r->name, r->triangles);
            continue;
        }
        fprintf(f, "| %s | %zu | %.1f | %.1f | %d | %.1f | %.1f |\n", r->name, r->triangles, r->t2.stage[S_AO],
                r->bounces ? r->t2.stage[S_GATHER] / r->bounces : 0.0, r->bounces, r->t2.stage[S_SHADE],
                r->t2.total);
    }
    fprintf(f, "\nPaper (GTX 460, 64³, 100 rays): T_3..T_19 = 22..125 ms (sponza, 262 267 triangles) and 4..10 ms "
               "(room, 8 760), T_rp 0.7 ms; R_AO 12-16, R_GI 52-70, I 5-7 ms.\n");
}

int lpv_acc_iv_tables_run(lpv_engine *engine, const lpv_acc_iv_tables_desc *d)
{
    if (d->ticks < 1 || d->ticks > IV_MAX_TICKS || d->nscenes < 1)
        return 2;
    if (mkdir(d->out_dir, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "lpvd-accuracy: cannot create %s: %s\n", d->out_dir, strerror(errno));
        return 1;
    }
    lpv_settings base = d->opt->settings;
    base.technique = LPV_TECHNIQUE_ID_IV;
    lpv_settings resolved_base = base;
    lpv_settings_resolve(&resolved_base);
    scene_row *rows = calloc((size_t)d->nscenes, sizeof *rows);
    if (!rows)
        return 1;
    lpv_view view0 = {0};
    int rc = 0;
    for (int s = 0; s < d->nscenes; ++s) {
        scene_row *r = &rows[s];
        r->name = d->scenes[s].name;
        char err[1024];
        lpv_scene scene;
        if (lpv_scene_load_user(d->scenes[s].path, NULL, &scene, err, sizeof err) != 0) {
            fprintf(stderr, "lpvd-accuracy: --iv-tables: %s\n", err);
            rc = 1;
            continue;
        }
        r->triangles = scene.index_count / 3;
        lpv_view_choice cam = d->opt->cam;
        if (d->scenes[s].has_cam) {
            cam.has_eye = cam.has_target = cam.has_fov = 1;
            memcpy(cam.eye, d->scenes[s].eye, sizeof cam.eye);
            memcpy(cam.target, d->scenes[s].target, sizeof cam.target);
            cam.fov_deg = d->scenes[s].fov;
        }
        lpv_view view;
        if (lpv_view_resolve(&cam, &scene, &view, err, sizeof err) != 0) {
            fprintf(stderr, "lpvd-accuracy: --iv-tables: %s: %s\n", r->name, err);
            lpv_scene_free(&scene);
            rc = 1;
            continue;
        }
        view0 = view;
        r->ok1 = 1;
        for (int j = 0; j < IV_NS; ++j) { /* table 1 */
            lpv_settings st = base;
            st.iv.points = POINTS_N[j];
            lpv_settings rs = st;
            lpv_settings_resolve(&rs);
            measured m;
            if (run_ticks(engine, &st, &scene, &view, d->ticks, d->warmup, &m) != 0) {
                r->ok1 = 0;
                rc = 1;
                break;
            }
            r->gpu[j] = m.stage[S_POINTS];
            r->reproject[j] = m.stage[S_REPROJECT];
            r->cpu[j] = cloud_cpu_ms(&scene, &rs, d->ticks, &r->cloud[j]);
            fprintf(stderr, "lpvd-accuracy: --iv-tables: %s, N = %d: cloud %zu points, CPU %.1f ms, iv_points %.1f ms, "
                            "iv_reproject %.1f ms\n", r->name, POINTS_N[j], r->cloud[j].points, r->cpu[j], r->gpu[j],
                    r->reproject[j]);
        }
        lpv_settings st = base; /* table 2 */
        st.iv.ao = LPV_SWITCH_ON;
        lpv_settings rs = st;
        lpv_settings_resolve(&rs);
        r->bounces = rs.iv.bounces;
        r->ok2 = run_ticks(engine, &st, &scene, &view, d->ticks, d->warmup, &r->t2) == 0;
        if (!r->ok2)
            rc = 1;
        else
            fprintf(stderr, "lpvd-accuracy: --iv-tables: %s: iv_ao %.1f ms, iv_gather %.1f ms (%d bounces), shade "
                            "%.1f ms\n", r->name, r->t2.stage[S_AO], r->t2.stage[S_GATHER], r->bounces,
                    r->t2.stage[S_SHADE]);
        lpv_scene_free(&scene);
    }
    char path[1200];
    snprintf(path, sizeof path, "%s/iv-tables.md", d->out_dir);
    FILE *f = fopen(path, "w");
    if (f) {
        print_tables(f, d, &resolved_base, &view0, rows, d->nscenes);
        fclose(f);
    } else {
        fprintf(stderr, "lpvd-accuracy: cannot write %s\n", path);
        rc = 1;
    }
    print_tables(stdout, d, &resolved_base, &view0, rows, d->nscenes);
    free(rows);
    return rc;
}
