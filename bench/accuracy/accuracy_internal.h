/*
 * accuracy_internal.h - what the files of `lpvd-accuracy` share (internal to
 * that target, not a library's interface): the sweep's point, a point's
 * result, a scene's entry, the parsed command line and the run's state, and
 * the functions one file calls in another (prefixed acc_, so that no generic
 * name becomes a global symbol). The program was one file, lpvd_accuracy.c;
 * it is split into one job per file (issue 33):
 *
 *   lpvd_accuracy.c       main: the steps in order, the --emissive and
 *                         --iv-tables modes, the Pareto fronts, the outputs
 *   acc_cli.c             the command line (flags, --help)
 *   acc_points.c          a point: its settings, names and labels
 *   acc_knobs.c           --knobs and --points parsed
 *   acc_point_set.c       the point set (factorial, filters, steps, features)
 *   acc_scenes.c          --scenes parsed
 *   acc_files.c           folders made
 *   acc_reference.c       the path-traced references, rendered and cached
 *   acc_run_scene.c       a scene: its references read, its points run
 *   acc_run_point.c       a point: ticked, timed and scored
 *   acc_csv.c             results.csv
 *   acc_markdown.c        results.md
 *   acc_gnuplot.c         gnuplot scripts opened and run
 *   acc_plot.c            plot.png and features.png
 *   acc_overall_front.c   the overall front (overall.csv, overall.png)
 */
#ifndef LPV_ACCURACY_INTERNAL_H
#define LPV_ACCURACY_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "engine.h"
#include "flags.h"
#include "iv_knobs.h"
#include "metrics.h"
#include "options.h"
#include "oracle_octree.h"
#include "scene_load.h"
#include "settings.h"

#ifndef LPVD_ACCURACY_SCENES_DIR
#define LPVD_ACCURACY_SCENES_DIR "scenes"
#endif

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
static inline int step_setting(int swept, int base) { return swept == 0 ? base : swept < 0 ? 0 : swept; }

static inline int is_iv(const point *p) { return p->technique == LPV_TECHNIQUE_ID_IV; }

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

static inline lpv_switch on_off(int on)
{
    return on ? LPV_SWITCH_ON : LPV_SWITCH_OFF;
}

/* A point's technique: 0 (the presets' and the features' points) is the
 * cascaded LPV, whatever the engine's default (auto since issue 30). */
static inline lpv_technique_id lpv_of(lpv_technique_id t) { return t == LPV_TECHNIQUE_ID_DEFAULT ? LPV_TECHNIQUE_ID_LPV : t; }

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

/* --knobs SPEC: filters (value lists, empty = any) applied to the point set. */
typedef struct knob_filter {
    int grid[16], ngrid, iter[16], niter, rsm[16], nrsm, occ[2], nocc;
    int sw[4][2], nsw[4]; /* central, bins, far, surfels: off/on */
    int tech[LPV_TECHNIQUE_ID_COUNT_], ntech; /* lpv_technique_id */
    int iv[LPV_ACC_IV_KNOBS][16], niv[LPV_ACC_IV_KNOBS]; /* technique iv's knobs (iv_knobs.h) */
    int cs[16], ncs, rs[16], nrs; /* camera_step, rsm_step: -1 = auto (point.cstep, rstep) */
    int ls[16], nls;              /* lookup_step: every point at each (point.lstep) */
} knob_filter;

/* What a reference is rendered with, beside the scene and the view. */
typedef struct ref_source {
    const char *out_dir, *cmd; /* cmd NULL: the linked library */
    int spp, area_lights, ncam;
    char *const *cam_args;
} ref_source;

/* The command line, parsed (acc_parse_args). */
typedef struct acc_args {
    const char *out_dir, *scene_list, *ref_given;
    const char *knobs, *points_arg;
    int spp, conv_spp, quick, presets, ticks, warmup, no_plot, size_given;
    int features, multi_bounces, scenes_given, emissive, iv_tables;
    int iv_flag_given[LPV_ACC_IV_KNOBS]; /* --iv-resolution, ...: refused when the knob is swept */
    lpvd_options opt;
    /* the camera choice, handed on to a reference command: cam_args[0 .. ncam)
     * ("--camera" VALUE ...), the flags' names in cam_flags */
    char *cam_args[MAX_PASS];
    char cam_flags[MAX_PASS / 2][16];
    int ncam;
} acc_args;

/* The run over the scenes (acc_run_scenes): what every scene and point needs,
 * and the results so far. */
typedef struct acc_run {
    const acc_args *a;
    lpv_engine *engine;
    const point *pts;
    int npts;
    scene_entry *scenes;
    int nscenes;
    const char *ref_cmd; /* the reference command, or what renders it (acc_find_reference) */
    int ref_is_cmd;      /* 1: ref_cmd is a command to run, 0: the linked library */
    int area_lights;     /* the settings' area lights are on */
    result *results;     /* nscenes x npts */
    int nres;
    char err[1024];
} acc_run;

/* One scene's state while its points run (acc_run_point): its references
 * (NULL where it has none), the region map, the frame's buffer and the folder
 * of its error images. */
typedef struct acc_scene_run {
    int s; /* the scene's index */
    scene_entry *se;
    const lpv_scene *scene;
    const lpv_view *view;
    const ref_source *rsrc;
    const float *ref, *ref_se, *mref, *mref_se, *cref, *cref_se;
    /* the iv points' B-bounce references (B > 1), by B, read on first use */
    float **bref, **bref_se;
    const uint8_t *regions;
    float *rgba;
    const char *sub;
} acc_scene_run;

/* acc_cli.c: parses the command line into *a (which must stay where it is:
 * cam_args points into it). Returns -1 to go on, else the exit status (0
 * after --help, 2 after saying what is wrong). */
int acc_parse_args(acc_args *a, int argc, char **argv);

/* acc_points.c */
const char *acc_steps_text(const point *p, int file, char buf[48]);
const char *acc_tech_name(int technique);
int acc_technique_runs(const point *p);
const char *acc_mods_name(int mods, char buf[5]);
const char *acc_mod_letters(void);
const char *acc_point_preset(const point *p);
int acc_preset_points(point *pts);
const char *acc_occ_name(int on);
int acc_at_ref_noise(double rel_rmse, double ref_noise2);
const char *acc_md_rmse(double rel_rmse, int at_noise, char *buf, size_t size);
const char *acc_own_text(int b, char buf[32]);
const char *acc_bounces_cell(int b, char buf[16]);
const char *acc_switch_name(int v);

/* acc_knobs.c */
int acc_names_lpv_knob(const knob_filter *kf);
int acc_names_iv_knob(const knob_filter *kf);
int acc_parse_knobs(const char *spec, knob_filter *kf);
int acc_parse_points(const char *list, point *pts, int max, char *err, size_t err_size);

/* acc_point_set.c: the points to run into pts[MAX_POINTS], from the point
 * set's flags and --features (resolved: the flags' settings, resolved, for
 * the iv knobs' values). May set a->scene_list (--features alone). Returns
 * the count, or -1 after saying why. */
int acc_point_set(acc_args *a, const lpv_settings *resolved, point *pts);

/* acc_scenes.c */
int acc_parse_scenes(const char *list, scene_entry *scenes, char (*paths)[1024]);

/* acc_files.c */
int acc_mkdir_p(const char *path);

/* acc_reference.c */
int acc_find_reference(const char *given, char *out, size_t n);
int acc_ensure_reference(scene_entry *e, const lpv_scene *scene, const lpv_view *view, const char *out_dir,
                         int spp, const char *ref_cmd, char *const *cam_args, int ncam, int bounces,
                         int area_lights);
void acc_write_preview(const char *exr, const float *img, int w, int h);
const float *acc_bounce_reference(scene_entry *e, const lpv_scene *scene, const lpv_view *view,
                                  const ref_source *src, int bounces, float **img, float **se_img);
int acc_converged_reference(scene_entry *e, const lpv_scene *scene, const lpv_view *view, const ref_source *src,
                            float **img, float **se_img);

/* acc_run_scene.c: runs every scene's points into c->results (c->nres of
 * them). Returns 0, or non-zero after saying why (the results so far stay). */
int acc_run_scenes(acc_run *c);

/* acc_run_point.c: runs point p on x's scene into c->results[c->nres] (and
 * counts it). Returns 0, or 1 after saying why. */
int acc_run_point(acc_run *c, const acc_scene_run *x, int p);

/* acc_csv.c */
void acc_write_csv(FILE *f, const result *r, int n, const scene_entry *scenes);

/* acc_markdown.c */
int acc_scene_rows(const result *r, int n, int scene, const result **rows);
void acc_write_md(FILE *f, const result *r, int n, const scene_entry *scenes, int nscenes, const char *header);

/* acc_gnuplot.c */
FILE *acc_open_gnuplot_script(const char *out_dir, const char *name, const char *what, int no_plot);
int acc_run_gnuplot(const char *out_dir, const char *name);

/* acc_plot.c */
int acc_write_plot(const char *out_dir, const result *r, int n, const scene_entry *scenes, int nscenes,
                   int no_plot);
int acc_write_features_plot(const char *out_dir, const result *r, int n, const scene_entry *scenes, int nscenes,
                            int no_plot);

/* acc_overall_front.c */
int acc_write_overall(const char *out_dir, const result *r, int n, const scene_entry *scenes, int nscenes,
                      int no_plot);

#endif
