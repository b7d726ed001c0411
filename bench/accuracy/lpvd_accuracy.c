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
 */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "context.h"
#include "emissive_full.h"
#include "engine.h"
#include "hash.h"
#include "image_io.h"
#include "iv_knobs.h"
#include "iv_tables.h"
#include "metrics.h"
#include "oracle_octree.h"
#include "overall.h"
#include "options.h"
#include "scene_load.h"
#include "tonemap.h"
#include "pt.h"

#ifndef LPVD_ACCURACY_SCENES_DIR
#define LPVD_ACCURACY_SCENES_DIR "scenes"
#endif

#include "settings.h"

/* glTF 2.0 models of Debian's assimp-testmodels (scripts/install-deps.sh) */
#define ASSIMP_GLTF2_DIR "/usr/share/assimp/models/glTF2"
#define MAX_POINTS 512
#define MAX_SCENES 16
#define MAX_TICKS 1000
#define MAX_PASS 16

/* The stages lpv_engine_stats reports, in CSV column order: the first
 * NSTAGES_LPV in their old place, the imperfect volume's at the row's end. */
static const char *const STAGES[] = {"rsm",   "vpl_extract", "inject", "gbuffer",    "gv",   "propagate",
                                     "shade", "emissive",    "pack",   "downsample", "merge",
                                     "iv_points", "iv_reproject", "iv_resolve", "iv_gather", "iv_ao"};
#define NSTAGES ((int)(sizeof STAGES / sizeof STAGES[0]))
#define NSTAGES_LPV 11
enum { ST_GV = 4, ST_PROPAGATE = 5, ST_SHADE = 6, ST_IV_POINTS = 11, ST_IV_REPROJECT, ST_IV_RESOLVE, ST_IV_GATHER };

/* The full factorial's default values (--knobs replaces any list). RSM and
 * occlusion stay at 128^2 / on by default: the first sweep (docs/accuracy.md,
 * "History") found larger RSMs buy nothing and occlusion always helps. */
static const int GRIDS[] = {6, 8, 12, 16, 32};
static const int ITERS[] = {2, 4, 8, 16};
static const int RSMS[] = {128};
static const int OCCS[] = {1};
static const int MODS[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15};

/* The departures from the paper a point switches on (docs/propagation.md),
 * as bits of point.mods, in the order of their letters "cbfs"
 * (lpv_settings_departures). */
enum { MOD_CENTRAL = 1, MOD_BINS = 2, MOD_FAR = 4, MOD_SURFELS = 8, MOD_ALL = 15 };

typedef struct point {
    int grid, iterations, rsm, occlusion;
    int mods;           /* MOD_* bits */
    /* --features (one factor at a time around balanced); all 0 for the classic sweep */
    int feat;           /* 1: a point of the features block */
    int cascades;       /* settings.lpv.cascades (0 = auto) */
    float cascade_size; /* m; 0 = default */
    int bounces;        /* 1 = on */
    float damping;      /* 0 = off */
    char label[32];     /* the features block's name of the point */
    lpv_technique_id technique; /* 0 (DEFAULT): the cascaded LPV (lpv_of: not the engine's default, auto) */
    /* technique iv: its knobs (0 = --iv-* or the engine's default); of the
     * LPV's knobs only rsm applies (the lights' shadow maps) */
    lpv_acc_iv_knobs iv;
    /* the down-sampling of the camera's surfels and the RSMs' VPLs
     * (settings.camera_surfel_step, rsm_vpl_step): 0 = not swept (the
     * flags' value, else auto), -1 = auto, N = every N texels */
    int cstep, rstep;
    /* the frame's lookup step (settings.lookup_step): 0 = not swept (the
     * flag's value), N = once per N x N pixels */
    int lstep;
} point;

/* The setting a swept step stands for (0 = auto), or the base's. */
static int step_setting(int swept, int base) { return swept == 0 ? base : swept < 0 ? 0 : swept; }

/* The swept steps of a point, "" when it sweeps none: for a label
 * (file = 0) " cam 4, vpl auto lookup 2", for an image's file name (file =
 * 1) "-cam4-vplauto-lookup2", so points that differ only in their steps do
 * not overwrite each other's images. */
static const char *steps_text(const point *p, int file, char buf[48])
{
    buf[0] = '\0';
    size_t at = 0;
    if (p->cstep || p->rstep) {
        char c[12], r[12];
        snprintf(c, sizeof c, p->cstep > 0 ? "%d" : "auto", p->cstep);
        snprintf(r, sizeof r, p->rstep > 0 ? "%d" : "auto", p->rstep);
        at = (size_t)snprintf(buf, 48, file ? "-cam%s-vpl%s" : " cam %s, vpl %s", p->cstep ? c : "-",
                              p->rstep ? r : "-");
    }
    if (p->lstep && at < 48)
        snprintf(buf + at, 48 - at, file ? "-lookup%d" : " lookup %d", p->lstep);
    return buf;
}



static int is_iv(const point *p) { return p->technique == LPV_TECHNIQUE_ID_IV; }

/* --features: the knob varied, around the balanced preset with one grid over
 * the scene (cascades 1), bounces off, damping 0. "cascades 3" uses the
 * scene's cascade size (scene_entry.lpv.cascade_size). */
typedef struct feature_def {
    const char *label;
    int cascades, bounces;
    float damping;
} feature_def;
static const feature_def FEATURES[] = {
    {"base", 1, 0, 0.0f},      {"cascades-3", 3, 0, 0.0f}, {"bounces-on", 1, 1, 0.0f},
    {"damping-0.5", 1, 0, 0.5f}, {"damping-1", 1, 0, 1.0f},
};
#define NFEATURES ((int)(sizeof FEATURES / sizeof FEATURES[0]))

/* --quick: a handful of points spanning cheap to expensive. */
static const point QUICK[] = {
    {16, 4, 128, 1, 0}, {32, 4, 128, 1, 0}, {8, 8, 128, 1, MOD_CENTRAL | MOD_FAR},
    {12, 8, 128, 1, MOD_ALL}, {16, 8, 128, 1, MOD_ALL}, {32, 8, 256, 1, MOD_ALL},
};

static lpv_switch on_off(int on)
{
    return on ? LPV_SWITCH_ON : LPV_SWITCH_OFF;
}

/* A point's technique: 0 (the presets' and the features' points) is the
 * cascaded LPV, whatever the engine's default (auto since issue 30). */
static lpv_technique_id lpv_of(lpv_technique_id t) { return t == LPV_TECHNIQUE_ID_DEFAULT ? LPV_TECHNIQUE_ID_LPV : t; }

/* The engine settings of a point: exactly its knobs, nothing from a preset. */
static lpv_settings point_settings(const point *p)
{
    return (lpv_settings){.grid_dims = {p->grid, p->grid, p->grid},
                          .lpv.iterations = p->iterations,
                          .rsm_size = p->rsm,
                          .lpv.occlusion = on_off(p->occlusion),
                          .lpv.central_transport = on_off(p->mods & MOD_CENTRAL),
                          .lpv.normal_bins = on_off(p->mods & MOD_BINS),
                          .lpv.far_field = on_off(p->mods & MOD_FAR),
                          .scene_surfels = on_off(p->mods & MOD_SURFELS),
                          .technique = lpv_of(p->technique)};
}

/* The point's technique by name: "lpv", "octree". */
static const char *tech_name(int technique) { return lpv_technique_name(lpv_of((lpv_technique_id)technique)); }

/* Whether the technique can run the point: the octree halves a cubic
 * power-of-two grid, and its levels are single grids (no normal bins, no far
 * field), so it has no points that differ only in those two switches. */
static int technique_runs(const point *p)
{
    if (p->technique != LPV_TECHNIQUE_ID_OCTREE)
        return 1;
    return (p->grid & (p->grid - 1)) == 0 && !(p->mods & (MOD_BINS | MOD_FAR));
}

/* "cbfs" with '-' for the switches that are off: the point's departures. */
static const char *mods_name(int mods, char buf[5])
{
    lpv_settings s = point_settings(&(point){.mods = mods});
    return lpv_settings_departures(&s, buf);
}

/* The four letters, in the order of the MOD_* bits. */
static const char *mod_letters(void)
{
    static char all[5];
    return mods_name(MOD_ALL, all);
}

static int mods_of_settings(const lpv_settings *s)
{
    return (s->lpv.central_transport == LPV_SWITCH_ON ? MOD_CENTRAL : 0) |
           (s->lpv.normal_bins == LPV_SWITCH_ON ? MOD_BINS : 0) | (s->lpv.far_field == LPV_SWITCH_ON ? MOD_FAR : 0) |
           (s->scene_surfels == LPV_SWITCH_ON ? MOD_SURFELS : 0);
}

/* The named preset the point equals (settings.h), or "" when none: the sweep
 * labels the presets so one can see where they sit on the front. */
static const char *point_preset(const point *p)
{
    lpv_settings s = point_settings(p);
    if (p->technique != LPV_TECHNIQUE_ID_DEFAULT && p->technique != LPV_TECHNIQUE_ID_LPV)
        return ""; /* the presets are the cascaded LPV's */
    if (p->cstep > 0 || p->rstep > 0 || p->lstep > 1)
        return ""; /* a preset down-samples automatically and looks every pixel up */
    lpv_preset m = lpv_preset_match(&s);
    return m == LPV_PRESET_DEFAULT ? "" : lpv_preset_name(m);
}

/* --presets: exactly the named presets, in the table's order. */
static int preset_points(point *pts)
{
    const lpv_preset order[] = {LPV_PRESET_FAST, LPV_PRESET_BALANCED, LPV_PRESET_ACCURATE};
    int n = 0;
    for (size_t i = 0; i < sizeof order / sizeof order[0]; ++i) {
        lpv_settings s;
        if (lpv_preset_settings(order[i], &s) != 0)
            continue;
        pts[n++] = (point){s.grid_dims[0], s.lpv.iterations, s.rsm_size, s.lpv.occlusion == LPV_SWITCH_ON,
                           mods_of_settings(&s)};
    }
    return n;
}

typedef struct result {
    int scene;
    point p;
    double ms_total;
    double stage_ms[NSTAGES];
    lpv_acc_metrics m;
    int pareto;
    int cascades_used;          /* lpv_engine_cascade_count after the point's ticks */
    int ref_bounces;            /* bounces of the point's own reference (own) */
    lpv_acc_metrics own;        /* vs that own-bounce reference (m: vs converged light) */
    int at_noise;               /* m.rel_rmse < 2 x the scene's ref_noise2: at the reference's noise */
    double rel_rmse_1b;         /* vs the 1-bounce reference */
    double rel_rmse_multi;      /* vs the multi-bounce reference; NAN when not rendered */
    double black, constant;     /* the baselines' rel_rmse (lpv_acc_baselines) */
    double region_share[LPV_ACC_REGIONS], region_rmse[LPV_ACC_REGIONS], region_ratio[LPV_ACC_REGIONS];
    lpv_octree_error octree;    /* the octree technique's own metric (thesis 6.2); elements 0 otherwise */
    lpv_acc_iv_knobs iv;        /* technique iv: the knobs it ran with (resolved) */
} result;

/* The thesis' correctness metric (section 6.2) on the octree the GPU
 * computed: every level's accumulation read back into the oracle's octree,
 * each level above 0 against the mean of its children (techniques/octree/core/oracle_octree.h). */
static void octree_metric(lpv_engine *engine, lpv_octree_error *out)
{
    memset(out, 0, sizeof *out);
    char err[256];
    lpv_octree o = {0};
    if (lpv_octree_create(lpv_engine_grid(engine), 0, &o, err, sizeof err) != 0)
        return;
    size_t all = 0;
    for (int i = 0; i < o.levels; ++i)
        all += lpv_grid_cell_count(&o.level[i].grid);
    lpv_cell *levels = malloc(all * sizeof *levels);
    if (levels && lpv_engine_read_volumes(engine, LPV_GRID_ACCUMULATED, levels, all) == all) {
        size_t at = 0;
        for (int i = 0; i < o.levels; at += lpv_grid_cell_count(&o.level[i].grid), ++i)
            memcpy(o.level[i].acc, levels + at, lpv_grid_cell_count(&o.level[i].grid) * sizeof *levels);
        lpv_octree_measure(&o, out);
    }
    free(levels);
    lpv_octree_free(&o);
}

/* Each pixel's region (metrics.h) from the reference's primary rays. */
static uint8_t *region_map(const lpv_scene *scene, const lpv_view *view)
{
    char err[512];
    lpv_ref *ref = NULL;
    size_t n = (size_t)view->width * (size_t)view->height;
    uint8_t *m = malloc(n);
    if (!m || lpv_ref_create(scene, NULL, &ref, err, sizeof err) != 0) {
        free(m);
        return NULL;
    }
    for (int y = 0; y < view->height; ++y)
        for (int x = 0; x < view->width; ++x) {
            float o[3], d[3], t0, t1, nn[3];
            lpv_ref_pixel_ray(view, x, y, o, d, &t0, &t1);
            size_t i = (size_t)y * (size_t)view->width + (size_t)x; /* row 0 at the top, as the images */
            m[i] = lpv_ref_first_surface(ref, o, d, t0, t1, NULL, NULL, nn) ? (uint8_t)lpv_acc_region_of(nn)
                                                                             : (uint8_t)LPV_ACC_REGION_NONE;
        }
    lpv_ref_destroy(ref);
    return m;
}

typedef struct scene_entry {
    char name[64];
    const char *path; /* NULL = the built-in Cornell box */
    char ref_exr[1024], ref_se[1024];
    int have_se;
    char mref_exr[1024], mref_se[1024]; /* the multi-bounce reference (bounces on) */
    int have_mref, have_mse;
    int has_cam; /* a camera of its own (cornell-inside) */
    float eye[3], target[3], fov;
    float cascade_size; /* m, for --features' "cascades-3" (0: auto) */
    int scale_free;     /* a real scene in its own units (engine: millimetres) */
    /* converged light (LPV_REF_BOUNCES_CONVERGED), rendered with two seeds:
     * their mean is what every point is scored against */
    char cref_exr[2][1024], cref_se[2][1024];
    int have_cse[2];
    int conv_spp;     /* samples per pixel of each seed */
    double ref_noise2; /* sqrt(mean((R1 - R2)^2)) / 2 / mean(R): the noise of their mean */
    int nxref;          /* the iv points' B-bounce references (B > 1), for results.md */
    int xref_bounces[LPV_IV_MAX_BOUNCES];
    char xref_exr[LPV_IV_MAX_BOUNCES][1024];
} scene_entry;

enum {
    A_OUT, A_REF_SPP, A_CONV_SPP, A_SCENES, A_QUICK, A_PRESETS, A_FEATURES, A_MULTI_BOUNCES, A_KNOBS, A_POINTS,
    A_TICKS, A_WARMUP, A_REFERENCE, A_NO_PLOT, A_EMISSIVE, A_IV_TABLES, A_HELP, A_COUNT
};

static const lpv_flag FLAGS[A_COUNT] = {
    [A_OUT] = {"out", 0, "DIR", "output folder (default accuracy-out)"},
    [A_REF_SPP] = {"ref-spp", 0, "N", "reference samples per pixel (default 256)"},
    [A_CONV_SPP] = {"conv-spp", 0, "N", "samples per pixel of each of the two seeds of the converged\n"
                                        "reference every point is scored against (default ref-spp / 2:\n"
                                        "their mean has ref-spp)"},
    [A_SCENES] = {"scenes", 0, "LIST",
                  "comma list: cornell (built-in), courtyard, blinds (scenes/*.glb),\n"
                  "engine, clearcoat (Debian's assimp-testmodels: 2CylinderEngine.glb,\n"
                  "a CAD model in mm under the default light; ClearCoatTest.gltf, spheres\n"
                  "lit by emissive labels), or paths to .glb/.gltf files\n"
                  "(default cornell,courtyard,blinds)"},
    [A_QUICK] = {"quick", 0, NULL, "the quick points (count below) instead of the 320-point factorial\n"
                                   "(grid 6/8/12/16/32 x iterations 2/4/8/16 x the 16 combinations of the\n"
                                   "mods below; RSM 128, occlusion on)"},
    [A_PRESETS] = {"presets", 0, NULL, "exactly the named presets (fast, balanced, accurate) as the points"},
    [A_FEATURES] = {"features", 0, NULL, "one knob at a time around balanced: cascades 3, bounces on, damping\n"
                                         "0.5 and 1 vs one grid (alone: scenes cornell-inside,courtyard,blinds;\n"
                                         "with another point set: added to it); features.png"},
    [A_MULTI_BOUNCES] = {"multi-bounces", 0, "N", "bounces of the reference for bounces on (--features; 2..64,\n"
                                                  "default 3)"},
    [A_KNOBS] = {"knobs", 0, "SPEC", "the factorial's values per knob (any given list replaces the default), e.g.\n"
                                     "grid=16/32,iterations=8,rsm=256,occlusion=on,central=on,bins=off/on,\n"
                                     "far=on,surfels=on (mods: central transport, normal bins, far field,\n"
                                     "scene surfels), technique=lpv/octree/iv; the imperfect volume's\n"
                                     "iv_resolution=16/32,iv_points=1/8,iv_rays=32/64,iv_bounces=1/3,\n"
                                     "iv_reprojection=on/off,iv_neighbours=6/8 make a factorial of iv points\n"
                                     "(unnamed iv knobs: --iv-* or the engine's default; rsm applies to every\n"
                                     "technique, the other LPV knobs only to lpv/octree points); iv knobs\n"
                                     "alone imply technique=iv; camera_step=auto/1/4, rsm_step=auto/1/4\n"
                                     "sweep the down-sampling of the camera's surfels and the RSMs' VPLs\n"
                                     "(--camera-surfel-step, --rsm-vpl-step; auto = the engine's default);\n"
                                     "lookup_step=1/2 runs every point at each lookup step (--lookup-step)"},
    [A_POINTS] = {"points", 0, "LIST", "explicit points GRID:ITER:RSM:on|off[:MODS[:TECHNIQUE]] (MODS letters\n"
                                       "of cbfs) or iv[:RES:POINTS:RAYS:BOUNCES:REPROJ:NEIGHBOURS], e.g.\n"
                                       "iv:32:8:64:3:on:8 or iv:16:-:100 (a field left out or '-': --iv-* or\n"
                                       "the default; RSM 128); @CAM/VPL after a point sets its steps (a\n"
                                       "number or auto), e.g. 8:8:128:on:cbfs@1/1"},
    [A_TICKS] = {"ticks", 0, "N", "timed ticks per point, median reported (default 5)"},
    [A_WARMUP] = {"warmup", 0, "N", "untimed ticks first (default 2)"},
    [A_REFERENCE] = {"reference", 0, "PATH", "run this reference command (lpvd-reference's CLI) instead of the\n"
                                             "linked lpv_reference library (default: $LPVD_REFERENCE, else the\n"
                                             "library when linked, else reference/lpvd-reference in this build tree)"},
    [A_NO_PLOT] = {"no-plot", 0, NULL, "do not run gnuplot (plot.gp is still written)"},
    [A_EMISSIVE] = {"emissive", 0, NULL, "only the emissive-lit scenes: lpvd's FULL frame vs the reference's\n"
                                         "full frame, area lights off and on with 1..64 samples, at 4, 8\n"
                                         "and 16 samples also at area shadow steps 1 and 4\n"
                                         "(emissive.csv, emissive.md; docs/area-lights.md)"},
    [A_IV_TABLES] = {"iv-tables", 0, NULL, "the imperfect volumes paper's tables 1 and 2 instead of a sweep:\n"
                                          "creation ms (CPU point cloud + GPU iv_points) for 3/7/12/19 points\n"
                                          "per triangle, reprojection ms, AO and GI march ms, shade ms (scenes\n"
                                          "default cornell,courtyard,blinds,engine; --size default 512x512;\n"
                                          "--iv-* set the other knobs); iv-tables.md"},
    [A_HELP] = {"help", 'h', NULL, "this text"},
};

/* The shared flags this program refuses: the sweep sets them per point. */
static const char *const SWEPT[] = {"grid", "iterations", "rsm-size", "occlusion", "preset", "technique", "central-transport",
                                    "normal-bins", "far-field", "scene-surfels", NULL};

static int is_swept(const char *name)
{
    for (int i = 0; SWEPT[i]; ++i)
        if (strcmp(name, SWEPT[i]) == 0)
            return 1;
    return 0;
}

static void usage(FILE *f)
{
    static char help[8192];
    size_t len = 0;
    lpv_flags_help(help, sizeof help, &len, FLAGS, A_COUNT);
    fprintf(f,
            "usage: lpvd-accuracy [--out DIR] [--size WxH] [--ref-spp N] [--conv-spp N] [--scenes LIST] [--quick] [--presets]\n"
            "                     [--knobs SPEC] [--points LIST] [--ticks N] [--warmup N]\n"
            "                     [--reference PATH] [--no-plot] [--iv-tables] [lpvd flags: --backend, --camera, ...]\n"
            "Sweeps lpvd's quality knobs against a path-traced reference (docs/accuracy.md).\n"
            "%s(--quick: %d points; --size: default 128x128 here)\n"
            "lpvd flags (all but the swept knobs: --preset, --grid, --iterations, --rsm-size, --occlusion,\n"
            "--central-transport, --normal-bins, --far-field, --scene-surfels; an --iv-* knob only while\n"
            "--knobs or --points does not sweep it):\n%s",
            help, (int)(sizeof QUICK / sizeof QUICK[0]), LPVD_OPTIONS_HELP);
}

static int mkdir_p(const char *path)
{
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", path);
    for (char *p = buf + 1; *p; ++p) {
        if (*p == '/') {
            *p = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                return -1;
            *p = '/';
        }
    }
    return (mkdir(buf, 0777) != 0 && errno != EEXIST) ? -1 : 0;
}

static int file_exists(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISREG(st.st_mode);
}

static uint64_t hash_file(uint64_t h, const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return lpv_hash_bytes(h, path, strlen(path));
    unsigned char buf[65536];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0)
        h = lpv_hash_bytes(h, buf, n);
    fclose(f);
    return h;
}

/* Parses "16/32" style value lists into out; returns the count or -1. */
static int parse_values(const char *s, int *out, int max, int is_switch)
{
    int n = 0;
    char buf[256];
    snprintf(buf, sizeof buf, "%s", s);
    for (char *save = NULL, *tok = strtok_r(buf, "/", &save); tok; tok = strtok_r(NULL, "/", &save)) {
        if (n >= max)
            return -1;
        if (is_switch) {
            if (strcmp(tok, "on") == 0 || strcmp(tok, "1") == 0)
                out[n++] = 1;
            else if (strcmp(tok, "off") == 0 || strcmp(tok, "0") == 0)
                out[n++] = 0;
            else
                return -1;
        } else {
            char *end = NULL;
            long v = strtol(tok, &end, 10);
            if (!end || *end || v < 1 || v > 4096)
                return -1;
            out[n++] = (int)v;
        }
    }
    return n > 0 ? n : -1;
}

static int in_list(int v, const int *list, int n)
{
    if (n == 0)
        return 1;
    for (int i = 0; i < n; ++i)
        if (list[i] == v)
            return 1;
    return 0;
}

/* --knobs SPEC: filters (value lists, empty = any) applied to the point set. */
typedef struct knob_filter {
    int grid[16], ngrid, iter[16], niter, rsm[16], nrsm, occ[2], nocc;
    int sw[4][2], nsw[4]; /* central, bins, far, surfels: off/on */
    int tech[LPV_TECHNIQUE_ID_COUNT_], ntech; /* lpv_technique_id */
    int iv[LPV_ACC_IV_KNOBS][16], niv[LPV_ACC_IV_KNOBS]; /* technique iv's knobs (iv_knobs.h) */
    int cs[16], ncs, rs[16], nrs; /* camera_step, rsm_step: -1 = auto (point.cstep, rstep) */
    int ls[16], nls;              /* lookup_step: every point at each (point.lstep) */
} knob_filter;

/* "auto/1/4": the steps' list, auto as -1. */
static int parse_steps(const char *v, int *out, int max)
{
    char buf[128];
    snprintf(buf, sizeof buf, "%s", v);
    int n = 0;
    for (char *save = NULL, *t = strtok_r(buf, "/", &save); t; t = strtok_r(NULL, "/", &save)) {
        char *end;
        long x = strcmp(t, "auto") == 0 ? -1 : strtol(t, &end, 10);
        if (n >= max || (x != -1 && (*end || x < 1 || x > LPV_MAX_CAMERA_SURFEL_STEP)))
            return -1;
        out[n++] = (int)x;
    }
    return n > 0 ? n : -1;
}

/* Whether the filter names one of the LPV's own knobs (not rsm: the imperfect
 * volume's shadow maps are RSMs too), or one of the imperfect volume's. */
static int names_lpv_knob(const knob_filter *kf)
{
    return kf->ngrid || kf->niter || kf->nocc || kf->nsw[0] || kf->nsw[1] || kf->nsw[2] || kf->nsw[3];
}

static int names_iv_knob(const knob_filter *kf)
{
    for (int k = 0; k < LPV_ACC_IV_KNOBS; ++k)
        if (kf->niv[k])
            return 1;
    return 0;
}

static const char *const MOD_KNOBS[4] = {"central", "bins", "far", "surfels"};

static int parse_knobs(const char *spec, knob_filter *kf)
{
    char buf[512];
    snprintf(buf, sizeof buf, "%s", spec);
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(tok, '=');
        if (!eq)
            return -1;
        *eq = '\0';
        const char *v = eq + 1;
        int r;
        if (strcmp(tok, "grid") == 0)
            r = kf->ngrid = parse_values(v, kf->grid, 16, 0);
        else if (strcmp(tok, "iterations") == 0)
            r = kf->niter = parse_values(v, kf->iter, 16, 0);
        else if (strcmp(tok, "rsm") == 0)
            r = kf->nrsm = parse_values(v, kf->rsm, 16, 0);
        else if (strcmp(tok, "occlusion") == 0)
            r = kf->nocc = parse_values(v, kf->occ, 2, 1);
        else if (strcmp(tok, "camera_step") == 0)
            r = kf->ncs = parse_steps(v, kf->cs, 16);
        else if (strcmp(tok, "rsm_step") == 0)
            r = kf->nrs = parse_steps(v, kf->rs, 16);
        else if (strcmp(tok, "lookup_step") == 0) {
            r = kf->nls = parse_values(v, kf->ls, 16, 0);
            for (int i = 0; i < kf->nls; ++i)
                if (kf->ls[i] < 1 || kf->ls[i] > LPV_MAX_LOOKUP_STEP)
                    r = -1;
        }
        else if (strcmp(tok, "technique") == 0) {
            char names[128];
            snprintf(names, sizeof names, "%s", v);
            r = kf->ntech = 0;
            for (char *s2 = NULL, *t = strtok_r(names, "/", &s2); t; t = strtok_r(NULL, "/", &s2)) {
                lpv_technique_id id;
                if (kf->ntech >= LPV_TECHNIQUE_ID_COUNT_ || lpv_technique_from_name(t, &id) != 0)
                    return -1;
                kf->tech[kf->ntech++] = (int)id;
            }
            r = kf->ntech > 0 ? kf->ntech : -1;
        } else if (lpv_acc_iv_knob_from_name(tok) >= 0) {
            const int ik = lpv_acc_iv_knob_from_name(tok);
            r = kf->niv[ik] = lpv_acc_iv_parse_list(ik, v, kf->iv[ik], 16);
        } else {
            r = -1;
            for (int m = 0; m < 4; ++m)
                if (strcmp(tok, MOD_KNOBS[m]) == 0)
                    r = kf->nsw[m] = parse_values(v, kf->sw[m], 2, 1);
            if (r < 0)
                return -1;
        }
        if (r < 0)
            return -1;
    }
    return 0;
}

/* --points: "GRID:ITER:RSM:on|off[:MODS[:TECHNIQUE]][@CAM/VPL]" (the steps,
 * a number or auto) or the imperfect
 * volume's "iv[:RES:POINTS:RAYS:BOUNCES:REPROJ:NEIGHBOURS]" (iv_knobs.h),
 * comma-separated. Returns the count, or -1 with err set. */
static int parse_points(const char *list, point *pts, int max, char *err, size_t err_size)
{
    int n = 0;
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", list);
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        char occ[8] = "", mods[8] = "", tech[16] = "";
        point p = {0};
        char *steps = strchr(tok, '@'); /* the steps */
        if (steps) {
            int st[2];
            *steps = '\0';
            if (parse_steps(steps + 1, st, 2) != 2) {
                snprintf(err, err_size, "%s: @CAM/VPL expects two steps, each a number or auto", steps + 1);
                return -1;
            }
            p.cstep = st[0];
            p.rstep = st[1];
        }
        if (n >= max) {
            snprintf(err, err_size, "at most %d points", max);
            return -1;
        }
        int iv = lpv_acc_iv_parse_point(tok, &p.iv, err, err_size);
        if (iv < 0)
            return -1;
        if (iv > 0) { /* RSM as the sweep's default (RSMS) */
            p.technique = LPV_TECHNIQUE_ID_IV;
            p.rsm = RSMS[0];
            pts[n++] = p;
            continue;
        }
        snprintf(err, err_size, "%s: expected GRID:ITER:RSM:on|off[:MODS[:TECHNIQUE]] or "
                                "iv[:RES:POINTS:RAYS:BOUNCES:REPROJ:NEIGHBOURS]", tok);
        int got = sscanf(tok, "%d:%d:%d:%7[a-z]:%7[-a-z]:%15s", &p.grid, &p.iterations, &p.rsm, occ, mods, tech);
        if (got < 4)
            return -1;
        lpv_technique_id id = LPV_TECHNIQUE_ID_LPV;
        if (got == 6 && lpv_technique_from_name(tech, &id) != 0)
            return -1;
        p.technique = id;
        if (strcmp(occ, "on") == 0)
            p.occlusion = 1;
        else if (strcmp(occ, "off") == 0)
            p.occlusion = 0;
        else
            return -1;
        for (const char *c = got >= 5 ? mods : ""; *c; ++c) { /* letters of cbfs, '-' for off */
            const char *at = strchr(mod_letters(), *c);
            if (*c != '-' && !at)
                return -1;
            if (*c != '-')
                p.mods |= 1 << (at - mod_letters());
        }
        if (p.grid < 1 || p.grid > 256 || p.iterations < 0 || p.iterations > 4096 || p.rsm < 16 || p.rsm > 8192 ||
            !technique_runs(&p))
            return -1;
        if (is_iv(&p)) /* the old form with technique iv: its RSM, the iv knobs' defaults */
            p = (point){.rsm = p.rsm, .technique = LPV_TECHNIQUE_ID_IV, .cstep = p.cstep, .rstep = p.rstep};
        pts[n++] = p;
    }
    if (n == 0)
        snprintf(err, err_size, "--points is empty");
    return n > 0 ? n : -1;
}

/* The reference command: --reference, $LPVD_REFERENCE, else (returning 0)
 * the linked lpv_reference library when built with it, else the build tree's
 * reference/lpvd-reference (this binary is <build>/bench/accuracy/), PATH.
 * Returns 1 when out names a command. */
static int find_reference(const char *given, char *out, size_t n)
{
    if (given) {
        snprintf(out, n, "%s", given);
        return 1;
    }
    const char *env = getenv("LPVD_REFERENCE");
    if (env && *env) {
        snprintf(out, n, "%s", env);
        return 1;
    }
    snprintf(out, n, "lpv_reference (linked, in process)");
    return 0;
    char self[1024];
    ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
    if (len > 0) {
        self[len] = '\0';
        char *slash = strrchr(self, '/');
        if (slash) {
            *slash = '\0';
            char cand[1200];
            snprintf(cand, sizeof cand, "%s/../../reference/lpvd-reference", self);
            if (access(cand, X_OK) == 0) {
                snprintf(out, n, "%s", cand);
                return 1;
            }
        }
    }
    snprintf(out, n, "lpvd-reference");
    return 1;
}

/* Runs argv (execvp), waits; returns the exit status or -1. */
static int run_command(char *const argv[])
{
    fflush(stdout);
    fflush(stderr);
    pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        execvp(argv[0], argv);
        fprintf(stderr, "lpvd-accuracy: cannot run %s: %s\n", argv[0], strerror(errno));
        _exit(127);
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0) {
        if (errno != EINTR)
            return -1;
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* The reference in process (lpv_reference): `bounces` bounces
 * (LPV_REF_BOUNCES_CONVERGED: converged light), spp samples per pixel. */
static int render_reference_lib(const lpv_scene *scene, const lpv_view *view, int bounces, int spp, uint64_t seed,
                                int area_lights, const char *exr, const char *se_exr)
{
    char err[1024] = "";
    lpv_ref *ref = NULL;
    size_t n = (size_t)view->width * (size_t)view->height * 4;
    float *rgba = malloc(n * sizeof(float)), *se = malloc(n * sizeof(float));
    int rc = -1;
    if (!rgba || !se) {
        fprintf(stderr, "lpvd-accuracy: out of memory for the reference\n");
    } else if (lpv_ref_create(scene, &(lpv_ref_desc){.emitters_are_lights = area_lights, .seed = seed}, &ref, err,
                              sizeof err) != 0) {
        fprintf(stderr, "lpvd-accuracy: reference: %s\n", err);
    } else if (lpv_ref_render_indirect(ref, view, bounces, spp, rgba, se) != 0) {
        fprintf(stderr, "lpvd-accuracy: reference: lpv_ref_render_indirect failed\n");
    } else if (lpv_image_write_f32(exr, view->width, view->height, 4, rgba, err, sizeof err) != 0 ||
               lpv_image_write_f32(se_exr, view->width, view->height, 4, se, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd-accuracy: %s\n", err);
    } else {
        rc = 0;
    }
    lpv_ref_destroy(ref);
    free(rgba);
    free(se);
    return rc;
}

/* Makes sure a reference of the scene is cached under OUT/ref; fills
 * ref_exr / ref_se (1024 bytes each) and *have_se. bounces > 1 or
 * LPV_REF_BOUNCES_CONVERGED with a seed (0 = the default stream): their own
 * keys; the 1-bounce key and file names stay as they were, so old caches
 * still hit. ref_cmd NULL: the linked library (lpv_reference, in process). */
static int ensure_reference_as(scene_entry *e, const lpv_scene *scene, const lpv_view *view, const char *out_dir,
                               int spp, const char *ref_cmd, char *const *cam_args, int ncam, int bounces,
                               uint64_t seed, int area_lights, char *ref_exr, char *ref_se, int *have_se)
{
    char bsuffix[64] = "";
    if (bounces == LPV_REF_BOUNCES_CONVERGED)
        snprintf(bsuffix, sizeof bsuffix, "-conv-s%llu", (unsigned long long)seed);
    else if (bounces > 1)
        snprintf(bsuffix, sizeof bsuffix, "-b%d", bounces);
    /* lpvd with area lights on keeps the emitters' direct light out of its
     * indirect term, and so does the reference it is compared with */
    if (area_lights)
        strcat(bsuffix, "-al");
    uint64_t h = LPV_HASH_INIT;
    h = e->path ? hash_file(h, e->path) : lpv_hash_bytes(h, "built-in:cornell-box", 20);
    h = lpv_hash_bytes(h, view, sizeof *view);
    h = lpv_hash_bytes(h, &spp, sizeof spp);
    h = ref_cmd ? lpv_hash_bytes(h, ref_cmd, strlen(ref_cmd)) : lpv_hash_bytes(h, "lib:lpv_reference", 17);
    if (bounces > 1 || bounces == LPV_REF_BOUNCES_CONVERGED)
        h = lpv_hash_bytes(h, &bounces, sizeof bounces);
    if (seed)
        h = lpv_hash_bytes(h, &seed, sizeof seed);
    char key[256];
    if (snprintf(key, sizeof key, "%s-%dx%d-spp%d%s-%016llx", e->name, view->width, view->height, spp, bsuffix,
                 (unsigned long long)h) >= (int)sizeof key ||
        snprintf(ref_exr, sizeof e->ref_exr, "%s/ref/%s.exr", out_dir, key) >= (int)sizeof e->ref_exr ||
        snprintf(ref_se, sizeof e->ref_se, "%s/ref/%s.stderr.exr", out_dir, key) >= (int)sizeof e->ref_se) {
        fprintf(stderr, "lpvd-accuracy: output path too long\n");
        return -1;
    }
    if (file_exists(ref_exr)) {
        *have_se = file_exists(ref_se);
        fprintf(stderr, "lpvd-accuracy: %s: cached reference %s\n", e->name, ref_exr);
        return 0;
    }
    char tmp_exr[1100], tmp_se[1100], spp_s[32], size_s[64];
    snprintf(tmp_exr, sizeof tmp_exr, "%s/ref/%s.tmp%d.exr", out_dir, key, (int)getpid());
    snprintf(tmp_se, sizeof tmp_se, "%s/ref/%s.stderr.tmp%d.exr", out_dir, key, (int)getpid());
    if (!ref_cmd) {
        if (bounces == LPV_REF_BOUNCES_CONVERGED)
            fprintf(stderr, "lpvd-accuracy: %s: rendering the reference in process (lpv_reference, converged, "
                            "seed %llu, %d spp)\n", e->name, (unsigned long long)seed, spp);
        else
            fprintf(stderr, "lpvd-accuracy: %s: rendering the reference in process (lpv_reference, %d bounce(s), "
                            "%d spp)\n", e->name, bounces, spp);
        if (render_reference_lib(scene, view, bounces, spp, seed, area_lights, tmp_exr, tmp_se) != 0 ||
            rename(tmp_exr, ref_exr) != 0 ||
            rename(tmp_se, ref_se) != 0) {
            unlink(tmp_exr);
            unlink(tmp_se);
            return -1;
        }
        *have_se = 1;
        return 0;
    }
    snprintf(spp_s, sizeof spp_s, "%d", spp);
    snprintf(size_s, sizeof size_s, "%dx%d", view->width, view->height);
    char bounces_s[16], seed_s[32];
    if (bounces == LPV_REF_BOUNCES_CONVERGED)
        snprintf(bounces_s, sizeof bounces_s, "%s", "converged");
    else
        snprintf(bounces_s, sizeof bounces_s, "%d", bounces);
    snprintf(seed_s, sizeof seed_s, "%llu", (unsigned long long)seed);
    char *argv[32 + MAX_PASS];
    int a = 0;
    argv[a++] = (char *)ref_cmd;
    if (e->path)
        argv[a++] = (char *)e->path;
    argv[a++] = "-o";
    argv[a++] = tmp_exr;
    argv[a++] = "--stderr";
    argv[a++] = tmp_se;
    argv[a++] = "--spp";
    argv[a++] = spp_s;
    argv[a++] = "--size";
    argv[a++] = size_s;
    for (int i = 0; i < ncam; ++i)
        argv[a++] = cam_args[i];
    char cam_s[3][64];
    if (e->has_cam) { /* the scene's own camera (cornell-inside) */
        snprintf(cam_s[0], sizeof cam_s[0], "%g,%g,%g", (double)e->eye[0], (double)e->eye[1], (double)e->eye[2]);
        snprintf(cam_s[1], sizeof cam_s[1], "%g,%g,%g", (double)e->target[0], (double)e->target[1],
                 (double)e->target[2]);
        snprintf(cam_s[2], sizeof cam_s[2], "%g", (double)e->fov);
        argv[a++] = "--eye";
        argv[a++] = cam_s[0];
        argv[a++] = "--target";
        argv[a++] = cam_s[1];
        argv[a++] = "--fov";
        argv[a++] = cam_s[2];
    }
    if (bounces > 1 || bounces == LPV_REF_BOUNCES_CONVERGED) {
        argv[a++] = "--bounces";
        argv[a++] = bounces_s;
    }
    if (seed) {
        argv[a++] = "--seed";
        argv[a++] = seed_s;
    }
    argv[a++] = "--area-lights";
    argv[a++] = area_lights ? "on" : "off";
    argv[a] = NULL;
    fprintf(stderr, "lpvd-accuracy: %s: rendering the reference:", e->name);
    for (int i = 0; i < a; ++i)
        fprintf(stderr, " %s", argv[i]);
    fputc('\n', stderr);
    int rc = run_command(argv);
    if (rc != 0 || !file_exists(tmp_exr)) {
        fprintf(stderr, "lpvd-accuracy: %s: the reference command failed (status %d): %s\n", e->name, rc, ref_cmd);
        unlink(tmp_exr);
        unlink(tmp_se);
        return -1;
    }
    if (rename(tmp_exr, ref_exr) != 0)
        return -1;
    *have_se = file_exists(tmp_se) && rename(tmp_se, ref_se) == 0;
    if (!*have_se)
        fprintf(stderr, "lpvd-accuracy: %s: warning: no stderr image; ref_noise will be 0\n", e->name);
    return 0;
}

/* The 1-bounce reference (into e->ref_*) or, bounces > 1, the multi-bounce
 * one (e->mref_*), seed 0. */
static int ensure_reference(scene_entry *e, const lpv_scene *scene, const lpv_view *view, const char *out_dir,
                            int spp, const char *ref_cmd, char *const *cam_args, int ncam, int bounces,
                            int area_lights)
{
    if (bounces > 1)
        return ensure_reference_as(e, scene, view, out_dir, spp, ref_cmd, cam_args, ncam, bounces, 0, area_lights,
                                   e->mref_exr, e->mref_se, &e->have_mse);
    return ensure_reference_as(e, scene, view, out_dir, spp, ref_cmd, cam_args, ncam, bounces, 0, area_lights,
                               e->ref_exr, e->ref_se, &e->have_se);
}

static const char *occ_name(int on)
{
    return on ? "on" : "off";
}

/* A tone-mapped preview next to a reference EXR (PATH.exr -> PATH.png). */
static void write_preview(const char *exr, const float *img, int w, int h)
{
    size_t np = (size_t)w * (size_t)h;
    uint8_t *px = malloc(np * 4);
    char prev[1100], err[512];
    snprintf(prev, sizeof prev, "%.*s.png", (int)strlen(exr) - 4, exr);
    if (px) {
        lpv_tonemap_rgba8(img, np, 1.0f, px);
        if (lpv_image_write_u8(prev, w, h, 4, px, err, sizeof err) != 0)
            fprintf(stderr, "lpvd-accuracy: %s\n", err);
        free(px);
    }
}

/* What a reference is rendered with, beside the scene and the view. */
typedef struct ref_source {
    const char *out_dir, *cmd; /* cmd NULL: the linked library */
    int spp, area_lights, ncam;
    char *const *cam_args;
} ref_source;

/* The B-bounce reference (B > 1) an imperfect-volume point with B bounces is
 * compared with: rendered once per scene and bounce count and cached under
 * OUT/ref like the multi-bounce one (ensure_reference), read into *img and
 * *se_img (NULL when it has none) on first use. Returns *img, NULL when it
 * cannot be had. */
static const float *bounce_reference(scene_entry *e, const lpv_scene *scene, const lpv_view *view,
                                     const ref_source *src, int bounces, float **img, float **se_img)
{
    if (*img)
        return *img;
    char err[1024];
    int w = 0, h = 0;
    if (ensure_reference(e, scene, view, src->out_dir, src->spp, src->cmd, src->cam_args, src->ncam, bounces,
                         src->area_lights) != 0 ||
        lpv_image_read_f32(e->mref_exr, 4, &w, &h, img, err, sizeof err) != 0 || w != view->width ||
        h != view->height) {
        fprintf(stderr, "lpvd-accuracy: %s: no %d-bounce reference\n", e->name, bounces);
        free(*img);
        *img = NULL;
        return NULL;
    }
    if (e->have_mse &&
        (lpv_image_read_f32(e->mref_se, 4, &w, &h, se_img, err, sizeof err) != 0 || w != view->width ||
         h != view->height)) {
        free(*se_img);
        *se_img = NULL;
    }
    write_preview(e->mref_exr, *img, w, h);
    if (e->nxref < LPV_IV_MAX_BOUNCES) {
        e->xref_bounces[e->nxref] = bounces;
        snprintf(e->xref_exr[e->nxref++], sizeof e->xref_exr[0], "%s", e->mref_exr);
    }
    return *img;
}

/* The seeds of the two converged references. */
static const uint64_t CONV_SEEDS[2] = {1, 2};

/* Converged light, what a user sees: the reference with every bounce
 * (LPV_REF_BOUNCES_CONVERGED), rendered with two seeds at e->conv_spp each
 * and cached under OUT/ref like the others. *img gets their mean R, *se_img
 * its standard error sqrt(S1^2 + S2^2) / 2 (NULL without stderr images), and
 * e->ref_noise2 = sqrt(mean((R1 - R2)^2)) / 2 / mean(R) over the pixels both
 * cover: the noise of the mean of two, measured rather than estimated.
 * Returns 0 or -1. */
static int converged_reference(scene_entry *e, const lpv_scene *scene, const lpv_view *view, const ref_source *src,
                               float **img, float **se_img)
{
    char err[1024];
    float *r[2] = {NULL, NULL}, *sd[2] = {NULL, NULL};
    int rc = -1;
    *img = *se_img = NULL;
    e->ref_noise2 = NAN;
    for (int k = 0; k < 2; ++k) {
        int w = 0, h = 0;
        if (ensure_reference_as(e, scene, view, src->out_dir, e->conv_spp, src->cmd, src->cam_args, src->ncam,
                                LPV_REF_BOUNCES_CONVERGED, CONV_SEEDS[k], src->area_lights, e->cref_exr[k],
                                e->cref_se[k], &e->have_cse[k]) != 0 ||
            lpv_image_read_f32(e->cref_exr[k], 4, &w, &h, &r[k], err, sizeof err) != 0 || w != view->width ||
            h != view->height) {
            fprintf(stderr, "lpvd-accuracy: %s: no converged reference (seed %llu)\n", e->name,
                    (unsigned long long)CONV_SEEDS[k]);
            goto done;
        }
        if (e->have_cse[k] && (lpv_image_read_f32(e->cref_se[k], 4, &w, &h, &sd[k], err, sizeof err) != 0 ||
                               w != view->width || h != view->height)) {
            free(sd[k]);
            sd[k] = NULL;
        }
    }
    size_t np = (size_t)view->width * (size_t)view->height;
    float *m = malloc(np * 4 * sizeof *m), *ms = sd[0] && sd[1] ? malloc(np * 4 * sizeof *ms) : NULL;
    if (!m) {
        free(ms);
        goto done;
    }
    double sum = 0.0, d2 = 0.0;
    size_t cnt = 0;
    for (size_t i = 0; i < np; ++i) {
        const int both = r[0][4 * i + 3] > 0.5f && r[1][4 * i + 3] > 0.5f;
        for (int c = 0; c < 4; ++c) {
            m[4 * i + (size_t)c] = c == 3 ? (both ? 1.0f : 0.0f) : 0.5f * (r[0][4 * i + (size_t)c] + r[1][4 * i + (size_t)c]);
            if (ms) {
                double a = sd[0][4 * i + (size_t)c], b = sd[1][4 * i + (size_t)c];
                ms[4 * i + (size_t)c] = c == 3 ? 1.0f : (float)(0.5 * sqrt(a * a + b * b));
            }
            if (both && c < 3) {
                double d = (double)r[0][4 * i + (size_t)c] - r[1][4 * i + (size_t)c];
                sum += m[4 * i + (size_t)c];
                d2 += d * d;
                cnt++;
            }
        }
    }
    if (cnt && sum > 0.0)
        e->ref_noise2 = sqrt(d2 / (double)cnt) / 2.0 / (sum / (double)cnt);
    *img = m;
    *se_img = ms;
    write_preview(e->cref_exr[0], r[0], view->width, view->height);
    rc = 0;
done:
    for (int k = 0; k < 2; ++k) {
        free(r[k]);
        free(sd[k]);
    }
    return rc;
}

/* "at the reference's noise": a rel. RMSE below twice the converged
 * reference's measured noise tells nothing about the technique. */
static int at_ref_noise(double rel_rmse, double ref_noise2)
{
    return isfinite(rel_rmse) && isfinite(ref_noise2) && rel_rmse < 2.0 * ref_noise2;
}

/* A Markdown rel. RMSE cell's text: the figure, or "at the reference's noise". */
static const char *md_rmse(double rel_rmse, int at_noise, char *buf, size_t size)
{
    if (at_noise)
        snprintf(buf, size, "%s", "at the reference's noise");
    else
        snprintf(buf, size, "%.3f", rel_rmse);
    return buf;
}

/* "on"/"off" of an lpv_switch value (iv_reprojection). */
/* The own reference of a point with ref_bounces b: "converged" (0: an
 * imperfect volume whose tail models every bounce) or "B bounce(s)"; and as
 * a table cell, "all" or B. */
static const char *own_text(int b, char buf[32])
{
    if (b == 0)
        return "converged";
    snprintf(buf, 32, "%d bounce(s)", b);
    return buf;
}

static const char *bounces_cell(int b, char buf[16])
{
    if (b == 0)
        return "all";
    snprintf(buf, 16, "%d", b);
    return buf;
}

static const char *switch_name(int v)
{
    return v == LPV_SWITCH_ON ? "on" : v == LPV_SWITCH_OFF ? "off" : "default";
}

/* The CSV: the LPV's columns in their old order (an iv point leaves the
 * LPV's own knobs, grid to mods and bounces, empty), then the imperfect
 * volume's knobs and stages (empty and 0 for LPV points). */
static void write_csv(FILE *f, const result *r, int n, const scene_entry *scenes)
{
    fprintf(f, "scene,grid,iterations,rsm,occlusion,mods,technique,ms_per_tick");
    for (int k = 0; k < NSTAGES_LPV; ++k)
        fprintf(f, ",ms_%s", STAGES[k]);
    fprintf(f, ",rel_rmse,rel_bias,ref_noise,rel_rmse_excess,rel_mae,pixels,pareto,preset");
    fprintf(f, ",block,label,cascades,cascade_size,bounces,damping,ref_bounces,rel_rmse_1b,rel_rmse_multi");
    fprintf(f, ",black_rmse,constant_rmse,share_floor,share_ceiling,share_walls,rmse_floor,rmse_ceiling,rmse_walls,"
               "ratio_floor,ratio_ceiling,ratio_walls,octree_e_abs,octree_e_rel,octree_mean_rel");
    for (int k = 0; k < LPV_ACC_IV_KNOBS; ++k)
        fprintf(f, ",%s", lpv_acc_iv_knob_name(k));
    for (int k = NSTAGES_LPV; k < NSTAGES; ++k)
        fprintf(f, ",ms_%s", STAGES[k]);
    fprintf(f, ",camera_surfel_step,rsm_vpl_step,lookup_step"); /* the settings, 0 = auto; empty: not swept */
    /* rel_rmse .. rel_mae above: against converged light; these: against the
     * reference with the point's own bounces (ref_bounces) */
    fprintf(f, ",rel_rmse_own,rel_bias_own,rel_mae_own,ref_noise_own,ref_noise2,at_ref_noise");
    fputc('\n', f);
    for (int i = 0; i < n; ++i) {
        char mb[5];
        const int iv = is_iv(&r[i].p);
        if (iv)
            fprintf(f, "%s,,,%d,,,%s,%.3f", scenes[r[i].scene].name, r[i].p.rsm, tech_name(r[i].p.technique),
                    r[i].ms_total);
        else
            fprintf(f, "%s,%d,%d,%d,%s,%s,%s,%.3f", scenes[r[i].scene].name, r[i].p.grid, r[i].p.iterations,
                    r[i].p.rsm, occ_name(r[i].p.occlusion), mods_name(r[i].p.mods, mb), tech_name(r[i].p.technique),
                    r[i].ms_total);
        for (int k = 0; k < NSTAGES_LPV; ++k)
            fprintf(f, ",%.3f", r[i].stage_ms[k]);
        fprintf(f, ",%.5f,%.5f,%.5f,%.5f,%.5f,%zu,%d,%s", r[i].m.rel_rmse, r[i].m.rel_bias, r[i].m.ref_noise,
                r[i].m.rel_rmse_excess, r[i].m.rel_mae, r[i].m.pixels, r[i].pareto,
                r[i].p.feat ? "" : point_preset(&r[i].p));
        fprintf(f, ",%s,%s,%d,%g,%s,%g,%d,%.5f,", r[i].p.feat ? "features" : "sweep", r[i].p.label,
                r[i].cascades_used, (double)r[i].p.cascade_size, iv ? "" : occ_name(r[i].p.bounces),
                (double)r[i].p.damping, r[i].ref_bounces, r[i].rel_rmse_1b);
        if (isfinite(r[i].rel_rmse_multi))
            fprintf(f, "%.5f", r[i].rel_rmse_multi);
        fprintf(f, ",%.5f,%.5f", r[i].black, r[i].constant);
        for (int g = 0; g < LPV_ACC_REGIONS; ++g)
            fprintf(f, ",%.5f", r[i].region_share[g]);
        for (int g = 0; g < LPV_ACC_REGIONS; ++g)
            fprintf(f, ",%.5f", r[i].region_rmse[g]);
        for (int g = 0; g < LPV_ACC_REGIONS; ++g)
            fprintf(f, ",%.5f", r[i].region_ratio[g]);
        if (r[i].octree.elements) /* the octree's own metric; empty for the cascaded LPV */
            fprintf(f, ",%.6g,%.6g,%.6g", r[i].octree.e_abs, r[i].octree.e_rel, r[i].octree.mean_rel);
        else
            fprintf(f, ",,,");
        for (int k = 0; k < LPV_ACC_IV_KNOBS; ++k) {
            if (!iv)
                fputc(',', f);
            else if (k == LPV_ACC_IV_REPROJECTION)
                fprintf(f, ",%s", switch_name(r[i].iv.v[k]));
            else
                fprintf(f, ",%d", r[i].iv.v[k]);
        }
        for (int k = NSTAGES_LPV; k < NSTAGES; ++k)
            fprintf(f, ",%.3f", r[i].stage_ms[k]);
        if (r[i].p.cstep)
            fprintf(f, ",%d", step_setting(r[i].p.cstep, 0));
        else
            fputc(',', f);
        if (r[i].p.rstep)
            fprintf(f, ",%d", step_setting(r[i].p.rstep, 0));
        else
            fputc(',', f);
        if (r[i].p.lstep)
            fprintf(f, ",%d", r[i].p.lstep);
        else
            fputc(',', f);
        fprintf(f, ",%.5f,%.5f,%.5f,%.5f,%.5f,%d", r[i].own.rel_rmse, r[i].own.rel_bias, r[i].own.rel_mae,
                r[i].own.ref_noise, scenes[r[i].scene].ref_noise2, r[i].at_noise);
        fputc('\n', f);
    }
}

static int cmp_ms(const void *a, const void *b)
{
    const result *x = *(const result *const *)a, *y = *(const result *const *)b;
    return (x->ms_total > y->ms_total) - (x->ms_total < y->ms_total);
}

/* The results of one scene sorted by ms; returns the count. */
static int scene_rows(const result *r, int n, int scene, const result **rows)
{
    int k = 0;
    for (int i = 0; i < n; ++i)
        if (r[i].scene == scene && !r[i].p.feat)
            rows[k++] = &r[i];
    qsort(rows, (size_t)k, sizeof *rows, cmp_ms);
    return k;
}

/* A "-" for a knob or stage the row's technique does not have. */
static void md_cell_int(FILE *f, int have, int v, const char *b)
{
    if (have)
        fprintf(f, " %s%d%s |", b, v, b);
    else
        fprintf(f, " - |");
}

static void md_cell_ms(FILE *f, int have, double v)
{
    if (have)
        fprintf(f, " %.2f |", v);
    else
        fprintf(f, " - |");
}

/* One scene's table when it has imperfect-volume rows: the LPV's columns
 * ("-" on iv rows) only when LPV rows are there too, then the iv knobs and
 * stages ("-" on LPV rows), the error against converged light, the own
 * reference's bounces and the error against it and against the 1-bounce
 * reference. */
static void write_md_iv_table(FILE *f, const result *const *rows, int k)
{
    int has_lpv = 0;
    for (int i = 0; i < k; ++i)
        has_lpv |= !is_iv(&rows[i]->p);
    fprintf(f, "| technique |%s RSM |%s iv res. | points | rays | bounces | reproj. | nbrs | ms/tick |%s points ms "
               "| reproject ms | resolve ms | gather ms | shade ms | rel. RMSE | rel. bias | rel. MAE | ref. noise "
               "| ref. bounces | rel. RMSE vs own | rel. bias vs own | vs 1-bounce ref | Pareto |\n",
            has_lpv ? " grid | iterations |" : "", has_lpv ? " occlusion | mods | preset |" : "",
            has_lpv ? " propagate ms | gv ms |" : "");
    fprintf(f, "|:---:|%s---:|%s---:|---:|---:|---:|:---:|---:|---:|%s---:|---:|---:|---:|---:|---:|---:|---:|---:|"
               "---:|---:|---:|---:|:---:|\n",
            has_lpv ? "---:|---:|" : "", has_lpv ? ":---:|:---:|:---:|" : "", has_lpv ? "---:|---:|" : "");
    for (int i = 0; i < k; ++i) {
        const result *x = rows[i];
        const int iv = is_iv(&x->p);
        const char *b = x->pareto ? "**" : "";
        fprintf(f, "| %s |", tech_name(x->p.technique));
        if (has_lpv) {
            if (iv)
                fprintf(f, " - | - |");
            else
                fprintf(f, " %s%d³%s | %d |", b, x->p.grid, b, x->p.iterations);
        }
        fprintf(f, " %d² |", x->p.rsm);
        if (has_lpv) {
            if (iv)
                fprintf(f, " - | - | |");
            else
                fprintf(f, " %s | `%s` | %s |", occ_name(x->p.occlusion), mods_name(x->p.mods, (char[5]){0}),
                        point_preset(&x->p));
        }
        if (iv)
            fprintf(f, " %s%d³%s |", b, x->iv.v[LPV_ACC_IV_RESOLUTION], b);
        else
            fprintf(f, " - |");
        md_cell_int(f, iv, x->iv.v[LPV_ACC_IV_POINTS], "");
        md_cell_int(f, iv, x->iv.v[LPV_ACC_IV_RAYS], "");
        md_cell_int(f, iv, x->iv.v[LPV_ACC_IV_BOUNCES], "");
        fprintf(f, " %s |", iv ? switch_name(x->iv.v[LPV_ACC_IV_REPROJECTION]) : "-");
        md_cell_int(f, iv, x->iv.v[LPV_ACC_IV_NEIGHBOURS], "");
        fprintf(f, " %s%.2f%s |", b, x->ms_total, b);
        if (has_lpv) {
            md_cell_ms(f, !iv, x->stage_ms[ST_PROPAGATE]);
            md_cell_ms(f, !iv, x->stage_ms[ST_GV]);
        }
        for (int st = ST_IV_POINTS; st <= ST_IV_GATHER; ++st)
            md_cell_ms(f, iv, x->stage_ms[st]);
        char rm[40];
        fprintf(f, " %.2f | %s%s%s | %+.3f | %.3f | %.3f | %s | %.3f | %+.3f | %.3f | %s |\n", x->stage_ms[ST_SHADE],
                b, md_rmse(x->m.rel_rmse, x->at_noise, rm, sizeof rm), b, x->m.rel_bias, x->m.rel_mae,
                x->m.ref_noise, bounces_cell(x->ref_bounces, (char[16]){0}),
                x->own.rel_rmse, x->own.rel_bias, x->rel_rmse_1b,
                x->pareto ? "**◆**" : "");
    }
    fputc('\n', f);
}

static void write_md(FILE *f, const result *r, int n, const scene_entry *scenes, int nscenes, const char *header)
{
    fprintf(f, "# lpvd accuracy sweep\n\n%s\n", header);
    fprintf(f, "Error metrics: docs/accuracy.md. ms/tick: median GPU ms of one tick + the indirect-only render "
               "(sum of the stages). Pareto: no other point of the scene is both faster and more accurate "
               "(rel. RMSE). Rows sorted by ms/tick; Pareto rows marked **◆**; preset: the named preset "
               "(`--preset`) the point equals. rel. RMSE, rel. bias, rel. MAE, ref. noise, the Pareto front, "
               "plots and error images: against converged light (`lpvd-reference --bounces converged`, the mean of "
               "two seeds), the light a user sees; \"at the reference's noise\" where rel. RMSE is below twice "
               "the converged reference's measured noise (ref_noise2 below). rel. RMSE / bias vs own: against the "
               "reference with as many bounces as the point computes (ref. bounces: 1 for the LPV and the octree, "
               "its iv_bounces for an imperfect volume, the multi-bounce count for bounces on). Imperfect-volume "
               "(iv) stage ms are the medians of iv_points, iv_reproject, iv_resolve, iv_gather (all bounces) and "
               "shade.\n\n");
    const result **rows = malloc((size_t)n * sizeof *rows);
    if (!rows)
        return;
    for (int s = 0; s < nscenes; ++s) {
        const result *base = NULL;
        int nf = 0;
        for (int i = 0; i < n; ++i)
            if (r[i].scene == s && r[i].p.feat) {
                if (!base)
                    base = &r[i];
                ++nf;
            }
        if (nf == 0)
            continue;
        fprintf(f, "## %s: one factor at a time (--features)\n\n", scenes[s].name);
        fprintf(f, "Each row changes one knob of `base` (balanced: 32³, 4 iterations, RSM 128², occlusion on; "
                   "cascades 1 = one grid over the scene, bounces off, damping 0). rel. RMSE and bias: against "
                   "converged light; the two columns after it compare every point with the 1-bounce and the "
                   "%d-bounce references.%s\n\n",
                base->ref_bounces > 1 ? base->ref_bounces : 3,
                scenes[s].has_cam ? " This scene uses its own camera inside the box (see docs), so that 1 m "
                                    "cascades nest in the 2 m box." : "");
        fprintf(f, "| point | cascades (size) | bounces | damping | ms/tick | Δ ms vs base | propagate ms | rel. RMSE "
                   "| vs 1-bounce ref | vs multi-bounce ref | rel. bias | rel. MAE |\n");
        fprintf(f, "|---|---:|:---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
        for (int i = 0; i < n; ++i) {
            const result *x = &r[i];
            if (x->scene != s || !x->p.feat)
                continue;
            char csz[32] = "";
            if (x->cascades_used > 1)
                snprintf(csz, sizeof csz, " (%g m)", (double)x->p.cascade_size);
            char rm[40];
            fprintf(f, "| %s | %d%s | %s | %g | %.2f | %+.2f | %.2f | %s | %.3f | ", x->p.label, x->cascades_used,
                    csz, occ_name(x->p.bounces), (double)x->p.damping, x->ms_total, x->ms_total - base->ms_total,
                    x->stage_ms[5], md_rmse(x->m.rel_rmse, x->at_noise, rm, sizeof rm), x->rel_rmse_1b);
            if (isfinite(x->rel_rmse_multi))
                fprintf(f, "%.3f", x->rel_rmse_multi);
            else
                fprintf(f, "–");
            fprintf(f, " | %+.3f | %.3f |\n", x->m.rel_bias, x->m.rel_mae);
        }
        fputc('\n', f);
    }
    for (int s = 0; s < nscenes; ++s) {
        int k = scene_rows(r, n, s, rows);
        if (k == 0)
            continue;
        fprintf(f, "## %s\n\n", scenes[s].name);
        fprintf(f, "converged reference (scored against): the mean of `%s` and `%s` (%d spp each); its noise "
                   "ref_noise2 = sqrt(mean((R1 - R2)^2)) / 2 / mean(R) = %.4f.\n\n",
                scenes[s].cref_exr[0], scenes[s].cref_exr[1], scenes[s].conv_spp, scenes[s].ref_noise2);
        fprintf(f, "1-bounce reference: `%s`%s", scenes[s].ref_exr, scenes[s].have_se ? "" : " (no stderr image)");
        for (int j = 0; j < scenes[s].nxref; ++j)
            fprintf(f, "; %d bounces (iv points with %d bounces): `%s`", scenes[s].xref_bounces[j],
                    scenes[s].xref_bounces[j], scenes[s].xref_exr[j]);
        fprintf(f, "\n\n");
        int has_iv = 0;
        for (int i = 0; i < k; ++i)
            has_iv |= is_iv(&rows[i]->p);
        if (has_iv) {
            write_md_iv_table(f, rows, k);
            continue;
        }
        fprintf(f, "| technique | grid | iterations | RSM | occlusion | mods | preset | ms/tick | propagate ms | gv ms "
                   "| rel. RMSE | rel. bias | rel. MAE | ref. noise | ref. bounces | rel. RMSE vs own | rel. bias vs own "
                   "| Pareto |\n");
        fprintf(f, "|:---:|---:|---:|---:|:---:|:---:|:---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|:---:|\n");
        for (int i = 0; i < k; ++i) {
            const result *x = rows[i];
            const char *b = x->pareto ? "**" : "";
            char rm[40];
            fprintf(f,
                    "| %s | %s%d³%s | %d | %d² | %s | `%s`%s | %s | %s%.2f%s | %.2f | %.2f | %s%s%s | %+.3f | %.3f | %.3f "
                    "| %d | %.3f | %+.3f | %s |\n",
                    tech_name(x->p.technique), b, x->p.grid, b, x->p.iterations, x->p.rsm, occ_name(x->p.occlusion),
                    mods_name(x->p.mods, (char[5]){0}), steps_text(&x->p, 0, (char[48]){0}), point_preset(&x->p), b,
                    x->ms_total, b,
                    x->stage_ms[5], x->stage_ms[4], b, md_rmse(x->m.rel_rmse, x->at_noise, rm, sizeof rm), b,
                    x->m.rel_bias, x->m.rel_mae, x->m.ref_noise, x->ref_bounces, x->own.rel_rmse, x->own.rel_bias,
                    x->pareto ? "**◆**" : "");
        }
        fputc('\n', f);
    }
    free(rows);
}

static int have_pngcairo(void)
{
    FILE *p = popen("gnuplot -e 'set terminal' 2>&1", "r");
    if (!p)
        return 0;
    char line[512];
    int found = 0;
    while (fgets(line, sizeof line, p))
        if (strstr(line, "pngcairo"))
            found = 1;
    pclose(p);
    return found;
}

/* plot/SCENE-presets.dat: "ms rel_rmse name" of the scene's points that equal
 * a named preset, for gnuplot's labels. Returns how many, or -1. */
static int write_preset_labels(const char *out_dir, const char *scene, const result *const *rows, int k)
{
    char path[1200];
    if (snprintf(path, sizeof path, "%s/plot/%s-presets.dat", out_dir, scene) >= (int)sizeof path)
        return -1; /* too long a path: no labels rather than a wrong file */
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    int count = 0;
    fprintf(f, "# ms_per_tick rel_rmse preset\n");
    for (int i = 0; i < k; ++i) {
        const char *name = point_preset(&rows[i]->p);
        if (*name) {
            fprintf(f, "%.4f %.5f %s\n", rows[i]->ms_total, rows[i]->m.rel_rmse, name);
            ++count;
        }
    }
    fclose(f);
    return count;
}

/* OUT/NAME.gp opened for writing, with the terminal (pngcairo when there,
 * else png) and the output OUT/NAME.png set; the caller adds the plot. */
static FILE *open_gnuplot_script(const char *out_dir, const char *name, const char *what, int no_plot)
{
    char path[1200];
    if (snprintf(path, sizeof path, "%s/%s.gp", out_dir, name) >= (int)sizeof path)
        return NULL;
    FILE *f = fopen(path, "w");
    if (!f)
        return NULL;
    int cairo = no_plot ? 1 : have_pngcairo();
    fprintf(f, "# lpvd-accuracy: %s; run from %s: gnuplot %s.gp\n", what, out_dir, name);
    fprintf(f, "set terminal %s size 960,640%s\n", cairo ? "pngcairo" : "png", cairo ? " font 'sans,11'" : "");
    fprintf(f, "set output '%s.png'\n", name);
    return f;
}

/* Runs gnuplot on OUT/NAME.gp in OUT. Returns 0, or -1 (and says so). */
static int run_gnuplot(const char *out_dir, const char *name)
{
    char cmd[1400];
    if (snprintf(cmd, sizeof cmd, "cd '%s' && gnuplot %s.gp", out_dir, name) >= (int)sizeof cmd)
        return -1;
    int rc = system(cmd);
    if (rc != 0) {
        fprintf(stderr, "lpvd-accuracy: gnuplot failed (status %d); %s.gp and plot/*.dat are written\n", rc, name);
        return -1;
    }
    return 0;
}

/* plot.gp + data files; runs gnuplot unless no_plot. */
static int write_plot(const char *out_dir, const result *r, int n, const scene_entry *scenes, int nscenes,
                      int no_plot)
{
    char path[1200];
    int labels[MAX_SCENES] = {0};
    const result **rows = malloc((size_t)n * sizeof *rows);
    if (!rows)
        return -1;
    snprintf(path, sizeof path, "%s/plot", out_dir);
    mkdir_p(path);
    for (int s = 0; s < nscenes; ++s) {
        int k = scene_rows(r, n, s, rows);
        labels[s] = write_preset_labels(out_dir, scenes[s].name, rows, k);
        for (int front = 0; front < 2; ++front) {
            int len = snprintf(path, sizeof path, "%s/plot/%s%s.dat", out_dir, scenes[s].name,
                               front ? "-pareto" : "");
            FILE *f = len < (int)sizeof path ? fopen(path, "w") : NULL;
            if (!f) {
                free(rows);
                return -1;
            }
            fprintf(f, "# ms_per_tick rel_rmse grid iterations rsm occlusion\n");
            for (int i = 0; i < k; ++i)
                if (!front || rows[i]->pareto)
                    fprintf(f, "%.4f %.5f %d %d %d %d\n", rows[i]->ms_total, rows[i]->m.rel_rmse, rows[i]->p.grid,
                            rows[i]->p.iterations, rows[i]->p.rsm, rows[i]->p.occlusion);
            fclose(f);
        }
    }
    free(rows);
    FILE *f = open_gnuplot_script(out_dir, "plot", "error vs milliseconds per tick", no_plot);
    if (!f)
        return -1;
    fprintf(f, "set title 'lpvd indirect light vs path-traced reference: what accuracy costs in time'\n");
    fprintf(f, "set xlabel 'GPU ms per tick (median; tick + indirect-only render)'\n");
    fprintf(f, "set ylabel 'relative RMSE vs converged light'\n");
    fprintf(f, "set logscale x\nset grid xtics ytics mxtics\nset key outside right top\nset yrange [0:*]\n");
    fprintf(f, "plot \\\n");
    for (int s = 0; s < nscenes; ++s) {
        fprintf(f,
                "  'plot/%s.dat' using 1:2 with points pt 7 ps 0.8 lc %d title '%s', \\\n"
                "  'plot/%s-pareto.dat' using 1:2 with linespoints pt 6 ps 1.6 lw 2 lc %d title '%s Pareto front'",
                scenes[s].name, s + 1, scenes[s].name, scenes[s].name, s + 1, scenes[s].name);
        if (labels[s] > 0) /* the named presets, labelled next to their points */
            fprintf(f, ", \\\n  'plot/%s-presets.dat' using 1:2:3 with labels left offset 0.8,0.6 tc lt %d notitle",
                    scenes[s].name, s + 1);
        fprintf(f, "%s\n", s + 1 < nscenes ? ", \\" : "");
    }
    fclose(f);
    if (no_plot)
        return 0;
    return run_gnuplot(out_dir, "plot");
}

/* features.gp + plot/features.dat: per knob of the features block, the ms per
 * tick (top) and the rel. RMSE against the point's own reference (bottom),
 * one bar per scene. Returns 0 (nothing to do without feature points). */
static int write_features_plot(const char *out_dir, const result *r, int n, const scene_entry *scenes, int nscenes,
                               int no_plot)
{
    int any = 0;
    for (int i = 0; i < n; ++i)
        any |= r[i].p.feat;
    if (!any)
        return 0;
    char path[1200];
    snprintf(path, sizeof path, "%s/plot", out_dir);
    mkdir_p(path);
    snprintf(path, sizeof path, "%s/plot/features.dat", out_dir);
    FILE *d = fopen(path, "w");
    if (!d)
        return -1;
    fprintf(d, "# knob, then per scene: ms_per_tick rel_rmse (NaN = not measured)\n# knob");
    for (int s = 0; s < nscenes; ++s)
        fprintf(d, " ms_%s rmse_%s", scenes[s].name, scenes[s].name);
    fputc('\n', d);
    for (int k = 0; k < NFEATURES; ++k) {
        fprintf(d, "%s", FEATURES[k].label);
        for (int s = 0; s < nscenes; ++s) {
            const result *x = NULL;
            for (int i = 0; i < n; ++i)
                if (r[i].scene == s && r[i].p.feat && strcmp(r[i].p.label, FEATURES[k].label) == 0)
                    x = &r[i];
            if (x)
                fprintf(d, " %.4f %.5f", x->ms_total, x->m.rel_rmse);
            else
                fprintf(d, " NaN NaN");
        }
        fputc('\n', d);
    }
    fclose(d);
    FILE *f = open_gnuplot_script(out_dir, "features", "what each new knob costs and buys", no_plot);
    if (!f)
        return -1;
    fprintf(f, "set terminal pngcairo size 960,900 font 'sans,11'\nset output 'features.png'\n");
    fprintf(f, "set multiplot layout 2,1 title 'one knob at a time around balanced (32^3, 4 it., RSM 128^2, "
               "occlusion on, 1 cascade)'\n");
    fprintf(f, "set style data histograms\nset style histogram clustered gap 1\nset style fill solid 0.8 border -1\n"
               "set boxwidth 0.9\nset grid ytics\nset key top left\nset yrange [0:*]\nset datafile missing 'NaN'\n");
    for (int panel = 0; panel < 2; ++panel) {
        fprintf(f, "set ylabel '%s'\n", panel == 0 ? "GPU ms per tick (median)"
                                                     : "relative RMSE vs converged light");
        fprintf(f, "plot ");
        for (int s = 0; s < nscenes; ++s)
            fprintf(f, "%s'plot/features.dat' using %d%s title '%s'", s ? ", " : "", 2 + 2 * s + panel,
                    s == 0 ? ":xtic(1)" : "", scenes[s].name);
        fputc('\n', f);
    }
    fprintf(f, "unset multiplot\n");
    fclose(f);
    if (no_plot)
        return 0;
    return run_gnuplot(out_dir, "features");
}

/* ---- The overall front (overall.h), written when there are 2+ scenes ---- */

static const char *key_preset(const int key[LPV_ACC_KEY])
{
    point p = {key[0], key[1], key[2], key[3], key[4]};
    p.technique = (lpv_technique_id)key[5];
    p.cstep = key[LPV_ACC_KEY_STEPS];
    p.rstep = key[LPV_ACC_KEY_STEPS + 1];
    p.lstep = key[LPV_ACC_KEY_STEPS + 2];
    return point_preset(&p);
}

/* Appends the overall table to results.md, writes overall.csv, and
 * overall.gp / plot/overall*.dat; runs gnuplot for overall.png unless
 * no_plot. Returns 0, or -1 when a file cannot be written. */
static int write_overall(const char *out_dir, const result *r, int n, const scene_entry *scenes, int nscenes,
                         int no_plot)
{
    if (nscenes < 2 || nscenes > LPV_ACC_MAX_SCENES)
        return 0;
    lpv_acc_row *rows = malloc((size_t)n * sizeof *rows);
    lpv_acc_overall *o = malloc((size_t)n * sizeof *o);
    if (!rows || !o) {
        free(rows);
        free(o);
        return -1;
    }
    size_t nrows = 0;
    int has_iv = 0, has_lpv = 0;
    for (int i = 0; i < n; ++i) { /* the classic sweep's points only: features share their four knobs */
        if (r[i].p.feat)
            continue;
        lpv_acc_row row = {r[i].scene, {0}, r[i].ms_total, r[i].m.rel_rmse};
        row.key[2] = r[i].p.rsm;
        row.key[LPV_ACC_KEY_TECHNIQUE] = (int)r[i].p.technique;
        row.key[LPV_ACC_KEY_STEPS] = r[i].p.cstep;
        row.key[LPV_ACC_KEY_STEPS + 1] = r[i].p.rstep;
        row.key[LPV_ACC_KEY_STEPS + 2] = r[i].p.lstep;
        if (is_iv(&r[i].p)) {
            memcpy(row.key + LPV_ACC_KEY_IV, r[i].iv.v, sizeof r[i].iv.v);
            has_iv = 1;
        } else {
            row.key[0] = r[i].p.grid;
            row.key[1] = r[i].p.iterations;
            row.key[3] = r[i].p.occlusion;
            row.key[4] = r[i].p.mods;
            has_lpv = 1;
        }
        rows[nrows++] = row;
    }
    if (nrows == 0) {
        free(rows);
        free(o);
        return 0;
    }
    size_t k = lpv_acc_overall_front(rows, nrows, nscenes, o, (size_t)n);
    free(rows);
    char path[1200];
    snprintf(path, sizeof path, "%s/results.md", out_dir);
    FILE *md = fopen(path, "a");
    snprintf(path, sizeof path, "%s/overall.csv", out_dir);
    FILE *csv = fopen(path, "w");
    snprintf(path, sizeof path, "%s/plot/overall.dat", out_dir);
    FILE *dat = fopen(path, "w");
    int rc = md && csv && dat ? 0 : -1;
    if (rc == 0) {
        fprintf(md, "## all scenes: the overall front\n\nPoints measured on every scene, by mean ms/tick over the "
                    "scenes and normalised RMSE = mean over the scenes of rel. RMSE / the scene's best rel. RMSE "
                    "(1 = the best of this sweep on every scene; docs/accuracy.md), every rel. RMSE against "
                    "converged light. The presets are chosen from this front. mods: the departures from the paper switched on, c = central transport, b = "
                    "normal bins, f = far field, s = scene surfels (docs/propagation.md).%s\n\n| technique |",
                has_iv ? " iv: the imperfect volume (resolution, points per triangle, rays per voxel, bounces, "
                         "reprojection, neighbours)." : "");
        if (has_lpv)
            fprintf(md, " grid | iterations | RSM | occlusion | mods | preset |");
        else
            fprintf(md, " RSM |");
        if (has_iv)
            fprintf(md, " iv res. | points | rays | bounces | reproj. | nbrs |");
        fprintf(md, " mean ms/tick | normalised RMSE |");
        fprintf(csv, "grid,iterations,rsm,occlusion,mods,technique,mean_ms_per_tick,norm_rmse");
        for (int s = 0; s < nscenes; ++s) {
            fprintf(md, " %s rel. RMSE |", scenes[s].name);
            fprintf(csv, ",rel_rmse_%s", scenes[s].name);
        }
        fprintf(md, " Pareto |\n|:---:|%s%s---:|---:|", has_lpv ? "---:|---:|---:|:---:|:---:|:---:|" : "---:|",
                has_iv ? "---:|---:|---:|---:|:---:|---:|" : "");
        fprintf(csv, ",pareto,preset");
        for (int j = 0; j < LPV_ACC_IV_KNOBS; ++j)
            fprintf(csv, ",%s", lpv_acc_iv_knob_name(j));
        fputc('\n', csv);
        for (int s = 0; s < nscenes; ++s)
            fprintf(md, "---:|");
        fprintf(md, ":---:|\n");
        fprintf(dat, "# mean_ms norm_rmse pareto preset technique\n");
        for (size_t j = 0; j < k; ++j) {
            const lpv_acc_overall *x = &o[j];
            const char *b = x->pareto ? "**" : "", *pre = key_preset(x->key);
            const int iv = x->key[LPV_ACC_KEY_TECHNIQUE] == LPV_TECHNIQUE_ID_IV;
            const int *ivk = x->key + LPV_ACC_KEY_IV;
            char mb[5] = "";
            if (!iv)
                mods_name(x->key[4], mb);
            fprintf(md, "| %s |", tech_name(x->key[LPV_ACC_KEY_TECHNIQUE]));
            if (has_lpv && iv)
                fprintf(md, " - | - | %d² | - | - | |", x->key[2]);
            else if (has_lpv)
                fprintf(md, " %s%d³%s | %d | %d² | %s | `%s`%s | %s |", b, x->key[0], b, x->key[1], x->key[2],
                        occ_name(x->key[3]), mb,
                        steps_text(&(point){.cstep = x->key[LPV_ACC_KEY_STEPS],
                                            .rstep = x->key[LPV_ACC_KEY_STEPS + 1],
                                            .lstep = x->key[LPV_ACC_KEY_STEPS + 2]},
                                   0, (char[48]){0}),
                        pre);
            else
                fprintf(md, " %d² |", x->key[2]);
            if (has_iv && iv)
                fprintf(md, " %s%d³%s | %d | %d | %d | %s | %d |", b, ivk[LPV_ACC_IV_RESOLUTION], b,
                        ivk[LPV_ACC_IV_POINTS], ivk[LPV_ACC_IV_RAYS], ivk[LPV_ACC_IV_BOUNCES],
                        switch_name(ivk[LPV_ACC_IV_REPROJECTION]), ivk[LPV_ACC_IV_NEIGHBOURS]);
            else if (has_iv)
                fprintf(md, " - | - | - | - | - | - |");
            fprintf(md, " %s%.2f%s | %s%.3f%s |", b, x->ms, b, b, x->norm_rmse, b);
            if (iv)
                fprintf(csv, ",,%d,,,%s,%.4f,%.5f", x->key[2], tech_name(x->key[LPV_ACC_KEY_TECHNIQUE]), x->ms,
                        x->norm_rmse);
            else
                fprintf(csv, "%d,%d,%d,%s,%s,%s,%.4f,%.5f", x->key[0], x->key[1], x->key[2], occ_name(x->key[3]), mb,
                        tech_name(x->key[LPV_ACC_KEY_TECHNIQUE]), x->ms, x->norm_rmse);
            for (int s = 0; s < nscenes; ++s) {
                char rm[40];
                fprintf(md, " %s |", md_rmse(x->rel_rmse[s], at_ref_noise(x->rel_rmse[s], scenes[s].ref_noise2), rm,
                                             sizeof rm));
                fprintf(csv, ",%.5f", x->rel_rmse[s]);
            }
            fprintf(md, " %s |\n", x->pareto ? "**◆**" : "");
            fprintf(csv, ",%d,%s", x->pareto, pre);
            for (int q = 0; q < LPV_ACC_IV_KNOBS; ++q) {
                if (!iv)
                    fputc(',', csv);
                else if (q == LPV_ACC_IV_REPROJECTION)
                    fprintf(csv, ",%s", switch_name(ivk[q]));
                else
                    fprintf(csv, ",%d", ivk[q]);
            }
            fputc('\n', csv);
            fprintf(dat, "%.4f %.5f %d %s %s\n", x->ms, x->norm_rmse, x->pareto, *pre ? pre : "-",
                    tech_name(x->key[LPV_ACC_KEY_TECHNIQUE]));
        }
        fputc('\n', md);
    }
    if (md)
        fclose(md);
    if (csv)
        fclose(csv);
    if (dat)
        fclose(dat);
    /* The front as its own file sorted by ms, so gnuplot draws one line. */
    snprintf(path, sizeof path, "%s/plot/overall-pareto.dat", out_dir);
    FILE *pf = rc == 0 ? fopen(path, "w") : NULL;
    if (pf) {
        fprintf(pf, "# mean_ms norm_rmse (the overall front, by ms)\n");
        for (double last = -INFINITY;;) {
            const lpv_acc_overall *next = NULL;
            for (size_t j = 0; j < k; ++j)
                if (o[j].pareto && o[j].ms > last && (!next || o[j].ms < next->ms))
                    next = &o[j];
            if (!next)
                break;
            fprintf(pf, "%.4f %.5f\n", next->ms, next->norm_rmse);
            last = next->ms;
        }
        fclose(pf);
    } else {
        rc = -1;
    }
    free(o);
    if (rc != 0)
        return -1;
    FILE *f = open_gnuplot_script(out_dir, "overall", "the overall front", no_plot);
    if (!f)
        return -1;
    fprintf(f, "set title 'lpvd over all scenes: normalised error vs time (1 = best of the sweep on every scene)'\n");
    fprintf(f, "set xlabel 'GPU ms per tick, mean over the scenes'\nset ylabel 'normalised relative RMSE'\n");
    fprintf(f, "set logscale x\nset grid xtics ytics mxtics\nset key top right\n");
    fprintf(f, "plot 'plot/overall.dat' using 1:(stringcolumn(5) eq 'lpv' ? $2 : 1/0) with points pt 7 ps 0.8 lc 1 "
               "title 'lpv (cascaded LPV)', \\\n"
               "  'plot/overall.dat' using 1:(stringcolumn(5) eq 'octree' ? $2 : 1/0) with points pt 9 ps 1.1 lc 4 "
               "title 'octree LPV', \\\n"
               "  'plot/overall.dat' using 1:(stringcolumn(5) eq 'iv' ? $2 : 1/0) with points pt 5 ps 0.9 lc 7 "
               "title 'imperfect volumes (iv)', \\\n"
               "  'plot/overall-pareto.dat' using 1:2 with linespoints pt 6 ps 1.6 lw 2 lc 2 "
               "title 'Pareto front', \\\n"
               "  'plot/overall.dat' using 1:2:(stringcolumn(4) eq '-' ? '' : stringcolumn(4)) with labels left "
               "offset 0.8,0.6 notitle\n");
    fclose(f);
    if (no_plot)
        return 0;
    return run_gnuplot(out_dir, "overall");
}

/* The scenes of a --scenes list (names or paths) into scenes[] (paths[]
 * holds their files). Returns the count, or -1 after saying why. */
static int parse_scenes(const char *list, scene_entry *scenes, char (*paths)[1024])
{
    int nscenes = 0;
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", list);
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        if (nscenes >= MAX_SCENES) {
            fprintf(stderr, "lpvd-accuracy: at most %d scenes\n", MAX_SCENES);
            return -1;
        }
        scene_entry *e = &scenes[nscenes];
        const char *base = strrchr(tok, '/') ? strrchr(tok, '/') + 1 : tok;
        snprintf(e->name, sizeof e->name, "%s", base);
        char *dot = strrchr(e->name, '.');
        int is_file = strchr(tok, '/') || (dot && (strcmp(dot, ".glb") == 0 || strcmp(dot, ".gltf") == 0));
        if (dot)
            *dot = '\0';
        for (char *c = e->name; *c; ++c)
            if (!((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') ||
                  *c == '-' || *c == '_'))
                *c = '_';
        if (is_file) {
            snprintf(paths[nscenes], sizeof paths[nscenes], "%s", tok);
            e->path = paths[nscenes];
        } else if (strcmp(tok, "cornell") == 0) {
            e->path = NULL;
        } else if (strcmp(tok, "engine") == 0 || strcmp(tok, "clearcoat") == 0) {
            /* real scenes the project did not write (scripts/install-deps.sh installs them) */
            snprintf(paths[nscenes], sizeof paths[nscenes], "%s/%s", ASSIMP_GLTF2_DIR,
                     strcmp(tok, "engine") == 0 ? "2CylinderEngine-glTF-Binary/2CylinderEngine.glb"
                                                : "ClearCoat-glTF/ClearCoatTest.gltf");
            e->path = paths[nscenes];
            e->scale_free = 1;
        } else if (strcmp(tok, "cornell-inside") == 0) {
            /* the built-in box seen from inside its opening: the box's own
             * camera stands 2.9 m in front of it, and camera-following
             * cascades of 1 m would then hold no geometry */
            e->path = NULL;
            e->has_cam = 1;
            e->eye[0] = 0.0f, e->eye[1] = 1.0f, e->eye[2] = 0.9f;
            e->target[0] = 0.0f, e->target[1] = 1.0f, e->target[2] = -1.0f;
            e->fov = 70.0f;
        } else {
            snprintf(paths[nscenes], sizeof paths[nscenes], "%s/%s.glb", LPVD_ACCURACY_SCENES_DIR,
                     tok);
            e->path = paths[nscenes];
        }
        /* "cascades-3" of --features: a finest cascade well inside the scene */
        e->cascade_size = e->scale_free ? 0.0f /* auto: a quarter of the scene */
                          : e->path == NULL ? 1.0f : strcmp(e->name, "blinds") == 0 ? 4.0f : 8.0f;
        ++nscenes;
    }
    return nscenes;
}

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
    int n = parse_scenes(scene_list, scenes, paths);
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
    const char *out_dir = "accuracy-out", *scene_list = "cornell,courtyard,blinds", *ref_given = NULL;
    const char *knobs = NULL, *points_arg = NULL;
    int spp = 256, conv_spp = 0, quick = 0, presets = 0, ticks = 5, warmup = 2, no_plot = 0, size_given = 0;
    int features = 0, multi_bounces = 3, scenes_given = 0, emissive = 0, iv_tables = 0;
    int iv_flag_given[LPV_ACC_IV_KNOBS] = {0}; /* --iv-resolution, ...: refused when the knob is swept */
    lpvd_options opt = {0};
    char *cam_args[MAX_PASS];
    char cam_flags[MAX_PASS / 2][16];
    int ncam = 0;
    char err[1024] = "";

    /* The shared groups come back unparsed: the swept knobs are refused and
     * the camera choice is also handed on to a reference command. */
    lpv_flag_group groups[4] = {{FLAGS, A_COUNT, NULL, NULL}};
    int ngroups = 1 + lpvd_options_groups(&opt, LPVD_GROUP_ALL, 0, groups + 1);
    lpv_flags cli;
    if (lpv_flags_begin(&cli, argc, argv, groups, ngroups, 0) != 0) {
        fprintf(stderr, "lpvd-accuracy: %s\n", cli.err);
        return 2;
    }
    int cg;
    const lpv_flag *fl;
    const char *v;
    for (lpv_flags_item it; (it = lpv_flags_next(&cli, &cg, &fl, &v)) != LPV_FLAGS_END;) {
        if (lpv_flags_refuse(&cli, it, v, "lpvd-accuracy", 0))
            return 2;
        if (cg > 0) { /* a shared flag */
            if (is_swept(fl->name)) {
                fprintf(stderr, "lpvd-accuracy: --%s is a swept knob; use --knobs, --points or --presets\n",
                        fl->name);
                return 2;
            }
            if (lpvd_option_parse(&opt, fl->name, v, err, sizeof err) < 0) {
                fprintf(stderr, "lpvd-accuracy: %s\n", err);
                return 2;
            }
            for (int k = 0; k < LPV_ACC_IV_KNOBS; ++k) { /* "iv-rays" is the flag of "iv_rays" */
                const char *kn = lpv_acc_iv_knob_name(k);
                if (strncmp(fl->name, "iv-", 3) == 0 && strcmp(fl->name + 3, kn + 3) == 0)
                    iv_flag_given[k] = 1;
            }
            if (strcmp(fl->name, "size") == 0)
                size_given = 1;
            /* the camera choice goes to the reference command too */
            if ((strcmp(fl->name, "camera") == 0 || strcmp(fl->name, "eye") == 0 || strcmp(fl->name, "target") == 0 ||
                 strcmp(fl->name, "fov") == 0) &&
                ncam + 2 <= MAX_PASS) {
                snprintf(cam_flags[ncam / 2], sizeof cam_flags[0], "--%s", fl->name);
                cam_args[ncam] = cam_flags[ncam / 2];
                cam_args[ncam + 1] = (char *)v;
                ncam += 2;
            }
            continue;
        }
        const int id = (int)(fl - FLAGS);
        switch (id) {
        case A_HELP: usage(stdout); return 0;
        case A_QUICK: quick = 1; break;
        case A_PRESETS: presets = 1; break;
        case A_FEATURES: features = 1; break;
        case A_EMISSIVE: emissive = 1; break;
        case A_IV_TABLES: iv_tables = 1; break;
        case A_NO_PLOT: no_plot = 1; break;
        case A_OUT: out_dir = v; break;
        case A_SCENES:
            scene_list = v;
            scenes_given = 1;
            break;
        case A_REFERENCE: ref_given = v; break;
        case A_KNOBS: knobs = v; break;
        case A_POINTS: points_arg = v; break;
        case A_MULTI_BOUNCES: {
            char *end = NULL;
            long x = strtol(v, &end, 10);
            if (!end || *end || x < 2 || x > 64) {
                fprintf(stderr, "lpvd-accuracy: --multi-bounces expects 2..64\n");
                return 2;
            }
            multi_bounces = (int)x;
            break;
        }
        case A_REF_SPP:
        case A_CONV_SPP:
        case A_TICKS:
        case A_WARMUP: {
            char *end = NULL;
            long x = strtol(v, &end, 10);
            if (!end || *end || x < (id == A_WARMUP ? 0 : 1) ||
                x > (id == A_REF_SPP || id == A_CONV_SPP ? 1000000 : MAX_TICKS)) {
                fprintf(stderr, "lpvd-accuracy: bad value for --%s: %s\n", fl->name, v);
                return 2;
            }
            if (id == A_REF_SPP)
                spp = (int)x;
            else if (id == A_CONV_SPP)
                conv_spp = (int)x;
            else if (id == A_TICKS)
                ticks = (int)x;
            else
                warmup = (int)x;
            break;
        }
        }
    }
    if (!size_given) /* the paper's table 1 reprojects 512^2 points */
        opt.cam.width = opt.cam.height = iv_tables ? 512 : 128;
    if (opt.cam.height == 0) {
        fprintf(stderr, "lpvd-accuracy: --size needs WxH\n");
        return 2;
    }
    lpv_settings resolved = opt.settings;
    lpv_settings_resolve(&resolved);
    const int area_lights = resolved.area_lights == LPV_SWITCH_ON;
    if (emissive) {
        lpv_gl_context *ctx = NULL;
        lpv_engine *engine = NULL;
        if (open_gl(opt.backend, &ctx, &engine) != 0)
            return 1;
        int rc = 1;
        {
            fprintf(stderr, "lpvd-accuracy: backend %s, GL_RENDERER %s\n",
                    lpv_backend_name(lpv_gl_context_backend(ctx)), lpv_gl_context_renderer(ctx));
            lpv_acc_emissive_desc d = {.out_dir = out_dir, .scenes_dir = LPVD_ACCURACY_SCENES_DIR, .opt = &opt,
                                       .spp = spp, .ticks = ticks, .warmup = warmup};
            rc = lpv_acc_emissive_run(engine, &d);
        }
        lpv_engine_destroy(engine);
        lpv_gl_context_destroy(ctx);
        return rc;
    }

    if (iv_tables)
        return run_iv_tables(&opt, out_dir, scenes_given ? scene_list : "cornell,courtyard,blinds,engine", ticks,
                             warmup, knobs || points_arg || quick || presets || features, argc, argv);

    /* The point set. */
    static point pts[MAX_POINTS];
    int npts = 0;
    if (features && !points_arg && !presets && !quick && !knobs) {
        /* --features alone: only the features block (its scenes by default
         * cornell-inside, courtyard, blinds); otherwise the block is added to
         * the chosen sweep points. */
        if (!scenes_given)
            scene_list = "cornell-inside,courtyard,blinds";
        goto add_features;
    }
    if (points_arg && presets) {
        fprintf(stderr, "lpvd-accuracy: --points and --presets both name the points; give one\n");
        return 2;
    }
    if (points_arg) {
        npts = parse_points(points_arg, pts, MAX_POINTS, err, sizeof err);
        if (npts < 0) {
            fprintf(stderr, "lpvd-accuracy: --points: %s\n", err);
            return 2;
        }
    } else if (presets) {
        npts = preset_points(pts);
    } else if (quick) {
        npts = (int)(sizeof QUICK / sizeof QUICK[0]);
        memcpy(pts, QUICK, sizeof QUICK);
    }
    knob_filter kf = {0};
    if (knobs && parse_knobs(knobs, &kf) != 0) {
        fprintf(stderr, "lpvd-accuracy: --knobs expects e.g. grid=16/32,iterations=8,rsm=256,occlusion=on,"
                        "central=on,bins=off/on,far=on,surfels=on,technique=lpv/iv,iv_resolution=16/32,iv_points=8,"
                        "iv_rays=32/64,iv_bounces=1/3,iv_reprojection=on/off,iv_neighbours=6/8,camera_step=auto/1,"
                        "rsm_step=auto/1,lookup_step=1/2 (see --help)\n");
        return 2;
    }
    if (!points_arg && !presets && !quick) {
        /* the factorial: each knob's --knobs list, else its default values */
        const int *gl = kf.ngrid ? kf.grid : GRIDS, *il = kf.niter ? kf.iter : ITERS, *rl = kf.nrsm ? kf.rsm : RSMS,
                  *ol = kf.nocc ? kf.occ : OCCS;
        int ng = kf.ngrid ? kf.ngrid : (int)(sizeof GRIDS / sizeof *GRIDS),
            ni = kf.niter ? kf.niter : (int)(sizeof ITERS / sizeof *ITERS),
            nr = kf.nrsm ? kf.nrsm : (int)(sizeof RSMS / sizeof *RSMS),
            no = kf.nocc ? kf.nocc : (int)(sizeof OCCS / sizeof *OCCS);
        /* the techniques: --knobs technique=..., else lpv, or iv when only iv knobs are named */
        const int lpv_only[] = {LPV_TECHNIQUE_ID_LPV}, iv_only[] = {LPV_TECHNIQUE_ID_IV};
        const int implied_iv = !kf.ntech && names_iv_knob(&kf);
        const int *tl = kf.ntech ? kf.tech : implied_iv ? iv_only : lpv_only, nt = kf.ntech ? kf.ntech : 1;
        int tech_lpv = 0, tech_iv = 0;
        for (int t = 0; t < nt; ++t)
            *(tl[t] == LPV_TECHNIQUE_ID_IV ? &tech_iv : &tech_lpv) = 1;
        if (implied_iv && names_lpv_knob(&kf)) {
            fprintf(stderr, "lpvd-accuracy: --knobs names LPV and iv knobs: say which techniques (technique=lpv/iv)\n");
            return 2;
        }
        if (names_iv_knob(&kf) && !tech_iv) {
            fprintf(stderr, "lpvd-accuracy: --knobs names iv knobs but technique= has no iv\n");
            return 2;
        }
        if (names_lpv_knob(&kf) && !tech_lpv) {
            fprintf(stderr, "lpvd-accuracy: --knobs names LPV knobs (grid, iterations, occlusion, central, bins, "
                            "far, surfels) but technique= has neither lpv nor octree\n");
            return 2;
        }
        for (int t = 0; t < nt; ++t) {
            if (tl[t] == LPV_TECHNIQUE_ID_IV) { /* the iv knobs' factorial (unnamed: not set) x rsm */
                int idx[LPV_ACC_IV_KNOBS] = {0};
                for (int r = 0; r < nr; ++r)
                    for (int done = 0; !done && npts < MAX_POINTS;) {
                        point q = {.rsm = rl[r], .technique = LPV_TECHNIQUE_ID_IV};
                        for (int k = 0; k < LPV_ACC_IV_KNOBS; ++k)
                            q.iv.v[k] = kf.niv[k] ? kf.iv[k][idx[k]] : 0;
                        pts[npts++] = q;
                        int k = LPV_ACC_IV_KNOBS - 1; /* the next combination, the last knob fastest */
                        while (k >= 0 && ++idx[k] >= (kf.niv[k] ? kf.niv[k] : 1))
                            idx[k--] = 0;
                        done = k < 0;
                    }
                continue;
            }
            for (int g = 0; g < ng; ++g)
                for (int it = 0; it < ni; ++it)
                    for (int r = 0; r < nr; ++r)
                        for (int o = 0; o < no; ++o)
                            for (size_t m = 0; m < sizeof MODS / sizeof *MODS && npts < MAX_POINTS; ++m) {
                                point q = {gl[g], il[it], rl[r], ol[o], MODS[m]};
                                q.technique = (lpv_technique_id)tl[t];
                                if (!technique_runs(&q))
                                    continue;
                                for (int c = 0; c < (kf.ncs ? kf.ncs : 1); ++c) /* the steps, when swept */
                                    for (int e = 0; e < (kf.nrs ? kf.nrs : 1) && npts < MAX_POINTS; ++e) {
                                        q.cstep = kf.ncs ? kf.cs[c] : 0;
                                        q.rstep = kf.nrs ? kf.rs[e] : 0;
                                        pts[npts++] = q;
                                    }
                            }
        }
    }
    if (knobs) {
        int k = 0;
        for (int i = 0; i < npts; ++i) {
            int keep = in_list(pts[i].rsm, kf.rsm, kf.nrsm) &&
                       in_list(pts[i].technique ? (int)pts[i].technique : LPV_TECHNIQUE_ID_LPV, kf.tech, kf.ntech);
            if (is_iv(&pts[i])) { /* its iv knobs as it will run them; the LPV's do not apply */
                for (int q = 0; q < LPV_ACC_IV_KNOBS; ++q)
                    keep = keep && in_list(pts[i].iv.v[q] ? pts[i].iv.v[q] : lpv_acc_iv_get(&resolved.iv, q),
                                           kf.iv[q], kf.niv[q]);
                if (keep)
                    pts[k++] = pts[i];
                continue;
            }
            keep = keep && in_list(pts[i].grid, kf.grid, kf.ngrid) && in_list(pts[i].iterations, kf.iter, kf.niter) &&
                   in_list(pts[i].occlusion, kf.occ, kf.nocc) && in_list(pts[i].cstep, kf.cs, kf.ncs) &&
                   in_list(pts[i].rstep, kf.rs, kf.nrs);
            for (int m = 0; m < 4; ++m)
                keep = keep && in_list((pts[i].mods >> m) & 1, kf.sw[m], kf.nsw[m]);
            if (keep)
                pts[k++] = pts[i];
        }
        npts = k;
        if (npts == 0) {
            fprintf(stderr, "lpvd-accuracy: --knobs %s leaves no point\n", knobs);
            return 2;
        }
    }
    if (kf.nls) { /* the lookup step: every point (of any point set) at each swept step */
        static point base[MAX_POINTS];
        memcpy(base, pts, (size_t)npts * sizeof *pts);
        const int nbase = npts;
        npts = 0;
        for (int i = 0; i < nbase; ++i)
            for (int l = 0; l < kf.nls && npts < MAX_POINTS; ++l) {
                pts[npts] = base[i];
                pts[npts++].lstep = kf.ls[l];
            }
    }
    for (int k = 0; k < LPV_ACC_IV_KNOBS; ++k) { /* a swept iv knob is not also a flag */
        int swept = kf.niv[k] > 0;
        for (int i = 0; i < npts; ++i)
            swept |= is_iv(&pts[i]) && pts[i].iv.v[k];
        if (swept && iv_flag_given[k]) {
            fprintf(stderr, "lpvd-accuracy: %s is swept by --knobs/--points; drop --iv-%s\n", lpv_acc_iv_knob_name(k),
                    lpv_acc_iv_knob_name(k) + 3);
            return 2;
        }
    }
add_features:
    if (features) {
        lpv_settings b;
        lpv_preset_settings(LPV_PRESET_BALANCED, &b);
        for (int k = 0; k < NFEATURES && npts < MAX_POINTS; ++k) {
            point fp = {b.grid_dims[0], b.lpv.iterations, b.rsm_size, b.lpv.occlusion == LPV_SWITCH_ON};
            fp.feat = 1;
            fp.cascades = FEATURES[k].cascades;
            fp.bounces = FEATURES[k].bounces;
            fp.damping = FEATURES[k].damping;
            snprintf(fp.label, sizeof fp.label, "%s", FEATURES[k].label);
            pts[npts++] = fp;
        }
    }

    /* The scenes. */
    static scene_entry scenes[MAX_SCENES];
    static char scene_paths[MAX_SCENES][1024];
    int nscenes = parse_scenes(scene_list, scenes, scene_paths);
    if (nscenes < 0)
        return 2;
    if (nscenes == 0) {
        fprintf(stderr, "lpvd-accuracy: --scenes is empty\n");
        return 2;
    }

    char ref_cmd[1200];
    int ref_is_cmd = find_reference(ref_given, ref_cmd, sizeof ref_cmd);
    char sub[1200];
    snprintf(sub, sizeof sub, "%s/ref", out_dir);
    if (mkdir_p(sub) != 0) {
        fprintf(stderr, "lpvd-accuracy: cannot create %s: %s\n", sub, strerror(errno));
        return 1;
    }

    lpv_gl_context *ctx = NULL;
    lpv_engine *engine = NULL;
    if (open_gl(opt.backend, &ctx, &engine) != 0)
        return 1;
    char header[2048];
    snprintf(header, sizeof header,
             "backend %s, GL_RENDERER %s; image %dx%d; reference `%s`: converged light (every bounce, Russian "
             "roulette) with 2 seeds at %d spp each, the own-bounce references at %d spp; median of %d ticks after "
             "%d warm-up; %d point(s) per scene.\n",
             lpv_backend_name(lpv_gl_context_backend(ctx)), lpv_gl_context_renderer(ctx), opt.cam.width,
             opt.cam.height, ref_cmd, conv_spp > 0 ? conv_spp : (spp / 2 > 0 ? spp / 2 : 1), spp, ticks, warmup,
             npts);
    fprintf(stderr, "lpvd-accuracy: %s", header);

    result *results = calloc((size_t)nscenes * (size_t)npts, sizeof *results);
    int nres = 0, rc = 0;
    for (int s = 0; s < nscenes && rc == 0; ++s) {
        scene_entry *se = &scenes[s];
        lpv_scene scene;
        if (lpv_scene_load_user(se->path, NULL, &scene, err, sizeof err) != 0) {
            fprintf(stderr, "lpvd-accuracy: %s\n", err);
            rc = 1;
            break;
        }
        lpv_view view;
        float *ref = NULL, *ref_se = NULL, *rgba = NULL;
        /* the iv points' B-bounce references (B > 1), by B, read on first use */
        float *bref[LPV_IV_MAX_BOUNCES + 1] = {0}, *bref_se[LPV_IV_MAX_BOUNCES + 1] = {0};
        const ref_source rsrc = {out_dir, ref_is_cmd ? ref_cmd : NULL, spp, area_lights, se->has_cam ? 0 : ncam,
                                 cam_args};
        uint8_t *regions = NULL;
        int rw = 0, rh = 0;
        lpv_view_choice cam = opt.cam;
        if (se->has_cam) {
            cam.has_eye = cam.has_target = cam.has_fov = 1;
            memcpy(cam.eye, se->eye, sizeof cam.eye);
            memcpy(cam.target, se->target, sizeof cam.target);
            cam.fov_deg = se->fov;
        }
        if (lpv_view_resolve(&cam, &scene, &view, err, sizeof err) != 0) {
            fprintf(stderr, "lpvd-accuracy: %s\n", err);
            rc = 2;
            goto next_scene;
        }
        if (ensure_reference(se, &scene, &view, out_dir, spp, ref_is_cmd ? ref_cmd : NULL, cam_args,
                             se->has_cam ? 0 : ncam, 1, area_lights) != 0) {
            rc = 1;
            goto next_scene;
        }
        float *mref = NULL, *mref_se = NULL, *cref = NULL, *cref_se = NULL;
        if (features) { /* the multi-bounce reference: for bounces on, and to compare every point with */
            int mw = 0, mh = 0;
            if (ensure_reference(se, &scene, &view, out_dir, spp, ref_is_cmd ? ref_cmd : NULL, cam_args,
                                 se->has_cam ? 0 : ncam, multi_bounces, area_lights) != 0 ||
                lpv_image_read_f32(se->mref_exr, 4, &mw, &mh, &mref, err, sizeof err) != 0 || mw != view.width ||
                mh != view.height) {
                fprintf(stderr, "lpvd-accuracy: %s: no multi-bounce reference\n", se->name);
                rc = 1;
                goto next_scene;
            }
            se->have_mref = 1;
            if (se->have_mse && (lpv_image_read_f32(se->mref_se, 4, &mw, &mh, &mref_se, err, sizeof err) != 0 ||
                                 mw != view.width || mh != view.height)) {
                free(mref_se);
                mref_se = NULL;
            }
        }
        if (lpv_image_read_f32(se->ref_exr, 4, &rw, &rh, &ref, err, sizeof err) != 0) {
            fprintf(stderr, "lpvd-accuracy: %s\n", err);
            rc = 1;
            goto next_scene;
        }
        if (rw != view.width || rh != view.height) {
            fprintf(stderr, "lpvd-accuracy: %s is %dx%d, expected %dx%d\n", se->ref_exr, rw, rh, view.width,
                    view.height);
            rc = 1;
            goto next_scene;
        }
        if (se->have_se) {
            int sw = 0, sh = 0;
            if (lpv_image_read_f32(se->ref_se, 4, &sw, &sh, &ref_se, err, sizeof err) != 0 || sw != rw ||
                sh != rh) {
                fprintf(stderr, "lpvd-accuracy: %s: unreadable or wrong size; ignoring it\n", se->ref_se);
                free(ref_se);
                ref_se = NULL;
                se->have_se = 0;
            }
        }
        write_preview(se->ref_exr, ref, rw, rh); /* a tone-mapped preview of the reference next to it */
        se->conv_spp = conv_spp > 0 ? conv_spp : (spp / 2 > 0 ? spp / 2 : 1);
        if (converged_reference(se, &scene, &view, &rsrc, &cref, &cref_se) != 0) {
            rc = 1;
            goto next_scene;
        }
        fprintf(stderr, "lpvd-accuracy: %s: converged reference, 2 seeds x %d spp, ref_noise2 %.4f\n", se->name,
                se->conv_spp, se->ref_noise2);
        if (snprintf(sub, sizeof sub, "%s/err/%s", out_dir, se->name) >= (int)sizeof sub || mkdir_p(sub) != 0) {
            fprintf(stderr, "lpvd-accuracy: cannot create %s/err/%s\n", out_dir, se->name);
            rc = 1;
            goto next_scene;
        }
        rgba = malloc((size_t)view.width * (size_t)view.height * 4 * sizeof(float));
        regions = region_map(&scene, &view);
        for (int p = 0; p < npts && rc == 0 && rgba; ++p) {
            result *res = &results[nres];
            res->scene = s;
            res->p = pts[p];
            lpv_settings st = opt.settings;
            if (is_iv(&pts[p])) { /* its knobs over --iv-* and the defaults; the LPV's knobs do not apply */
                st.technique = LPV_TECHNIQUE_ID_IV;
                st.rsm_size = pts[p].rsm;
                lpv_acc_iv_apply(&pts[p].iv, &st.iv);
                goto settings_made;
            }
            st.grid_dims[0] = st.grid_dims[1] = st.grid_dims[2] = pts[p].grid;
            st.lpv.iterations = pts[p].iterations;
            st.rsm_size = pts[p].rsm;
            st.lpv.occlusion = pts[p].occlusion ? LPV_SWITCH_ON : LPV_SWITCH_OFF;
            st.lpv.central_transport = on_off(pts[p].mods & MOD_CENTRAL);
            st.lpv.normal_bins = on_off(pts[p].mods & MOD_BINS);
            st.lpv.far_field = on_off(pts[p].mods & MOD_FAR);
            st.scene_surfels = on_off(pts[p].mods & MOD_SURFELS);
            st.technique = lpv_of(pts[p].technique);
            st.camera_surfel_step = step_setting(pts[p].cstep, st.camera_surfel_step);
            st.rsm_vpl_step = step_setting(pts[p].rstep, st.rsm_vpl_step);
            if (pts[p].lstep)
                st.lookup_step = pts[p].lstep;
            if (pts[p].feat) {
                st.lpv.cascades = pts[p].cascades;
                if (pts[p].cascades > 1) {
                    st.lpv.cascade_size = se->cascade_size;
                    res->p.cascade_size = se->cascade_size;
                }
                st.lpv.bounces = pts[p].bounces ? LPV_SWITCH_ON : LPV_SWITCH_OFF;
                st.lpv.damping = pts[p].damping;
            }
        settings_made:
            if (lpv_engine_set_settings(engine, &st, err, sizeof err) != 0 ||
                lpv_engine_set_scene(engine, &scene, err, sizeof err) != 0 ||
                lpv_engine_set_view(engine, &view, err, sizeof err) != 0) {
                fprintf(stderr, "lpvd-accuracy: %s\n", err);
                rc = 1;
                break;
            }
            {
                lpv_settings rs = st;
                lpv_settings_resolve(&rs);
                res->iv = lpv_acc_iv_of_settings(&rs.iv);
            }
            static double totals[MAX_TICKS], stage[NSTAGES][MAX_TICKS];
            for (int t = 0; t < warmup + ticks; ++t) {
                /* With the planner on, a tick on an unchanged scene serves the
                 * cached volume and runs no stage: every timed tick is a full one. */
                lpv_engine_invalidate(engine);
                if (lpv_engine_tick(engine, err, sizeof err) != 0 ||
                    lpv_engine_render(engine, LPV_TERMS_INDIRECT_ONLY, rgba, err, sizeof err) != 0) {
                    fprintf(stderr, "lpvd-accuracy: %s\n", err);
                    rc = 1;
                    break;
                }
                if (t < warmup)
                    continue;
                const lpv_engine_stats *es = lpv_engine_last_stats(engine);
                double total = 0.0;
                for (int k = 0; k < NSTAGES; ++k)
                    stage[k][t - warmup] = 0.0;
                for (int j = 0; j < es->stage_count; ++j) {
                    total += es->stages[j].gpu_ms;
                    for (int k = 0; k < NSTAGES; ++k)
                        if (strcmp(es->stages[j].name, STAGES[k]) == 0)
                            stage[k][t - warmup] = es->stages[j].gpu_ms;
                }
                totals[t - warmup] = total;
            }
            if (rc)
                break;
            res->ms_total = lpv_acc_median(totals, (size_t)ticks);
            for (int k = 0; k < NSTAGES; ++k)
                res->stage_ms[k] = lpv_acc_median(stage[k], (size_t)ticks);
            res->cascades_used = lpv_engine_cascade_count(engine);
            if (pts[p].technique == LPV_TECHNIQUE_ID_OCTREE)
                octree_metric(engine, &res->octree);
            if (lpv_acc_compare(rgba, ref, ref_se, view.width, view.height, &res->m) != 0)
                fprintf(stderr, "lpvd-accuracy: %s: warning: no pixel seen by both, or a black reference\n",
                        se->name);
            res->rel_rmse_1b = res->m.rel_rmse;
            res->ref_bounces = 1;
            res->rel_rmse_multi = NAN;
            const float *cmp_ref = ref;
            if (mref) {
                lpv_acc_metrics mm;
                if (lpv_acc_compare(rgba, mref, mref_se, view.width, view.height, &mm) == 0) {
                    res->rel_rmse_multi = mm.rel_rmse;
                    if (pts[p].bounces) { /* bounces on models more than one bounce: its own reference */
                        res->m = mm;
                        res->ref_bounces = multi_bounces;
                        cmp_ref = mref;
                    }
                }
            }
            const int ivb = res->iv.v[LPV_ACC_IV_BOUNCES];
            /* an imperfect volume whose tail adds the bounces after its last (iv_tail, 3 or more bounces) models
             * every bounce: its own reference is converged light (ref_bounces 0) */
            const int iv_all = is_iv(&pts[p]) && ivb >= 3 && lpv_engine_settings(engine)->iv.tail == LPV_SWITCH_ON;
            if (is_iv(&pts[p]) && !iv_all && ivb > 1 && ivb <= LPV_IV_MAX_BOUNCES) { /* its own bounces' reference */
                const float *bimg = bounce_reference(se, &scene, &view, &rsrc, ivb, &bref[ivb], &bref_se[ivb]);
                lpv_acc_metrics mb;
                if (!bimg) {
                    rc = 1;
                    break;
                }
                if (lpv_acc_compare(rgba, bimg, bref_se[ivb], view.width, view.height, &mb) != 0)
                    fprintf(stderr, "lpvd-accuracy: %s: warning: no pixel seen by both the %d-bounce reference and "
                                    "lpvd\n", se->name, ivb);
                res->m = mb;
                res->ref_bounces = ivb;
                cmp_ref = bimg;
            }
            /* The score: against converged light (what a user sees), the
             * own-bounce figures beside it; the baselines, regions and
             * error image against converged light too. */
            res->own = res->m;
            if (lpv_acc_compare(rgba, cref, cref_se, view.width, view.height, &res->m) != 0)
                fprintf(stderr, "lpvd-accuracy: %s: warning: no pixel seen by both the converged reference and "
                                "lpvd\n", se->name);
            if (iv_all) {
                res->own = res->m;
                res->ref_bounces = 0;
            }
            res->at_noise = at_ref_noise(res->m.rel_rmse, se->ref_noise2);
            cmp_ref = cref;
            const float *base_ref = cref;
            lpv_acc_baselines(rgba, base_ref, view.width, view.height, &res->black, &res->constant);
            for (int g = 0; g < LPV_ACC_REGIONS; ++g)
                res->region_share[g] = res->region_rmse[g] = res->region_ratio[g] = NAN;
            if (regions)
                lpv_acc_region_errors(rgba, base_ref, regions, view.width, view.height, res->region_share,
                                      res->region_rmse, res->region_ratio);
            char ep[1400];
            if (pts[p].feat)
                snprintf(ep, sizeof ep, "%s/features-%s.png", sub, pts[p].label);
            else if (is_iv(&pts[p]))
                snprintf(ep, sizeof ep, "%s/iv-%s-r%d.png", sub, lpv_acc_iv_label(&res->iv, (char[96]){0}, 96),
                         pts[p].rsm);
            else
                snprintf(ep, sizeof ep, "%s/g%d-i%d-r%d-occ%s-%s%s%s%s.png", sub, pts[p].grid, pts[p].iterations,
                         pts[p].rsm, occ_name(pts[p].occlusion), mods_name(pts[p].mods, (char[5]){0}),
                         pts[p].technique == LPV_TECHNIQUE_ID_OCTREE ? "-" : "",
                         pts[p].technique == LPV_TECHNIQUE_ID_OCTREE ? tech_name(pts[p].technique) : "",
                         steps_text(&pts[p], 1, (char[48]){0}));
            if (lpv_acc_write_error_png(ep, rgba, cmp_ref, view.width, view.height, res->m.mean_ref, err,
                                        sizeof err) != 0)
                fprintf(stderr, "lpvd-accuracy: %s\n", err);
            { /* lpvd's own frame beside it, tone-mapped like the reference's preview */
                size_t np = (size_t)view.width * (size_t)view.height;
                uint8_t *px = malloc(np * 4);
                char lp[1500];
                snprintf(lp, sizeof lp, "%.*s.lpvd.png", (int)strlen(ep) - 4, ep);
                if (px) {
                    lpv_tonemap_rgba8(rgba, np, 1.0f, px);
                    if (lpv_image_write_u8(lp, view.width, view.height, 4, px, err, sizeof err) != 0)
                        fprintf(stderr, "lpvd-accuracy: %s\n", err);
                    free(px);
                }
            }
            if (is_iv(&pts[p]))
                fprintf(stderr,
                        "lpvd-accuracy: %s %d/%d: iv, resolution %d, points %d, rays %d, bounces %d, reprojection %s, "
                        "neighbours %d, rsm %d: %.2f ms/tick (iv_points %.2f, iv_reproject %.2f, iv_resolve %.2f, "
                        "iv_gather %.2f, shade %.2f), rel_rmse %.4f rel_bias %+.4f vs converged%s; %.4f %+.4f vs %s "
                        "(%.4f vs 1)\n",
                        se->name, p + 1, npts, res->iv.v[0], res->iv.v[1], res->iv.v[2], res->iv.v[3],
                        switch_name(res->iv.v[4]), res->iv.v[5], pts[p].rsm, res->ms_total,
                        res->stage_ms[ST_IV_POINTS], res->stage_ms[ST_IV_REPROJECT], res->stage_ms[ST_IV_RESOLVE],
                        res->stage_ms[ST_IV_GATHER], res->stage_ms[ST_SHADE], res->m.rel_rmse, res->m.rel_bias,
                        res->at_noise ? " (at the reference's noise)" : "", res->own.rel_rmse, res->own.rel_bias,
                        own_text(res->ref_bounces, (char[32]){0}), res->rel_rmse_1b);
            else
                fprintf(stderr,
                        "lpvd-accuracy: %s %d/%d: %s, grid %d, iterations %d, rsm %d, occlusion %s, mods %s%s: "
                        "%.2f ms/tick, rel_rmse %.4f, rel_bias %+.4f vs converged%s (ref_noise2 %.4f); %.4f %+.4f vs "
                        "%d bounce(s)%s%s\n",
                        se->name, p + 1, npts, tech_name(pts[p].technique), pts[p].grid, pts[p].iterations, pts[p].rsm,
                        occ_name(pts[p].occlusion), mods_name(pts[p].mods, (char[5]){0}),
                        steps_text(&pts[p], 0, (char[48]){0}),
                        res->ms_total, res->m.rel_rmse, res->m.rel_bias,
                        res->at_noise ? " (at the reference's noise)" : "", se->ref_noise2, res->own.rel_rmse,
                        res->own.rel_bias, res->ref_bounces, pts[p].feat ? "; " : "",
                        pts[p].label);
            ++nres;
        }
        free(mref);
        free(mref_se);
        free(cref);
        free(cref_se);
    next_scene:
        for (int b = 0; b <= LPV_IV_MAX_BOUNCES; ++b) {
            free(bref[b]);
            free(bref_se[b]);
        }
        free(regions);
        free(rgba);
        free(ref);
        free(ref_se);
        lpv_scene_free(&scene);
    }
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
    snprintf(path, sizeof path, "%s/results.csv", out_dir);
    FILE *f = fopen(path, "w");
    if (f) {
        write_csv(f, results, nres, scenes);
        fclose(f);
    } else {
        rc = 1;
    }
    snprintf(path, sizeof path, "%s/results.md", out_dir);
    f = fopen(path, "w");
    if (f) {
        write_md(f, results, nres, scenes, nscenes, header);
        fclose(f);
    } else {
        rc = 1;
    }
    int nclassic = 0;
    for (int i = 0; i < nres; ++i)
        nclassic += !results[i].p.feat;
    if (nclassic > 0 && write_plot(out_dir, results, nres, scenes, nscenes, no_plot) != 0 && !no_plot)
        fprintf(stderr, "lpvd-accuracy: no plot.png\n");
    if (nres > 0 && write_features_plot(out_dir, results, nres, scenes, nscenes, no_plot) != 0 && !no_plot)
        fprintf(stderr, "lpvd-accuracy: no features.png\n");
    if (nres > 0 && write_overall(out_dir, results, nres, scenes, nscenes, no_plot) != 0)
        fprintf(stderr, "lpvd-accuracy: no overall front (overall.csv, overall.png)\n");
    free(results);
    fprintf(stderr, "lpvd-accuracy: %d point(s) written to %s/results.csv, results.md%s\n", nres, out_dir,
            no_plot ? "" : ", plot.png");
    return rc;
}
