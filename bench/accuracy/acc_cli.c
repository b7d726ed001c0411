/*
 * acc_cli.c - lpvd-accuracy's command line: its own flags (FLAGS), the
 * shared lpvd flags it refuses because the sweep sets them per point
 * (SWEPT), --help, and the parsing into an acc_args (accuracy_internal.h).
 * What the flags mean for the point set is acc_point_set.c's business.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy_internal.h"
#include "knob_rows.h"

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
    static char rows[2048];
    acc_knob_rows_help(rows, sizeof rows);
    fprintf(f,
            "usage: lpvd-accuracy [--out DIR] [--size WxH] [--ref-spp N] [--conv-spp N] [--scenes LIST] [--quick] [--presets]\n"
            "                     [--knobs SPEC] [--points LIST] [--ticks N] [--warmup N]\n"
            "                     [--reference PATH] [--no-plot] [--iv-tables] [lpvd flags: --backend, --camera, ...]\n"
            "Sweeps lpvd's quality knobs against a path-traced reference (docs/accuracy.md).\n"
            "%s(--quick: %d points; --size: default 128x128 here)\n"
            "--knobs names: grid (1..%d), technique, each iv_* row, and these aliases of rows of lpvd's\n"
            "knob table (docs/knobs.md), whose values and ranges they take:\n%s"
            "lpvd flags (all but the swept knobs: --preset, --grid, --iterations, --rsm-size, --occlusion,\n"
            "--central-transport, --normal-bins, --far-field, --scene-surfels; an --iv-* knob only while\n"
            "--knobs or --points does not sweep it):\n%s",
            help, (int)(sizeof QUICK / sizeof QUICK[0]), LPV_MAX_GRID_DIM, rows, LPVD_OPTIONS_HELP);
}

int acc_parse_args(acc_args *a, int argc, char **argv)
{
    *a = (acc_args){.out_dir = "accuracy-out", .scene_list = "cornell,courtyard,blinds", .spp = 256, .ticks = 5,
                    .warmup = 2, .multi_bounces = 3};
    char err[1024] = "";

    /* The shared groups come back unparsed: the swept knobs are refused and
     * the camera choice is also handed on to a reference command. */
    lpv_flag_group groups[4] = {{FLAGS, A_COUNT, NULL, NULL}};
    int ngroups = 1 + lpvd_options_groups(&a->opt, LPVD_GROUP_ALL, 0, groups + 1);
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
            if (lpvd_option_parse(&a->opt, fl->name, v, err, sizeof err) < 0) {
                fprintf(stderr, "lpvd-accuracy: %s\n", err);
                return 2;
            }
            for (int k = 0; k < LPV_ACC_IV_KNOBS; ++k) { /* "iv-rays" is the flag of "iv_rays" */
                const char *kn = lpv_acc_iv_knob_name(k);
                if (strncmp(fl->name, "iv-", 3) == 0 && strcmp(fl->name + 3, kn + 3) == 0)
                    a->iv_flag_given[k] = 1;
            }
            if (strcmp(fl->name, "size") == 0)
                a->size_given = 1;
            /* the camera choice goes to the reference command too */
            if ((strcmp(fl->name, "camera") == 0 || strcmp(fl->name, "eye") == 0 || strcmp(fl->name, "target") == 0 ||
                 strcmp(fl->name, "fov") == 0) &&
                a->ncam + 2 <= MAX_PASS) {
                snprintf(a->cam_flags[a->ncam / 2], sizeof a->cam_flags[0], "--%s", fl->name);
                a->cam_args[a->ncam] = a->cam_flags[a->ncam / 2];
                a->cam_args[a->ncam + 1] = (char *)v;
                a->ncam += 2;
            }
            continue;
        }
        const int id = (int)(fl - FLAGS);
        switch (id) {
        case A_HELP: usage(stdout); return 0;
        case A_QUICK: a->quick = 1; break;
        case A_PRESETS: a->presets = 1; break;
        case A_FEATURES: a->features = 1; break;
        case A_EMISSIVE: a->emissive = 1; break;
        case A_IV_TABLES: a->iv_tables = 1; break;
        case A_NO_PLOT: a->no_plot = 1; break;
        case A_OUT: a->out_dir = v; break;
        case A_SCENES:
            a->scene_list = v;
            a->scenes_given = 1;
            break;
        case A_REFERENCE: a->ref_given = v; break;
        case A_KNOBS: a->knobs = v; break;
        case A_POINTS: a->points_arg = v; break;
        case A_MULTI_BOUNCES: {
            char *end = NULL;
            long x = strtol(v, &end, 10);
            if (!end || *end || x < 2 || x > 64) {
                fprintf(stderr, "lpvd-accuracy: --multi-bounces expects 2..64\n");
                return 2;
            }
            a->multi_bounces = (int)x;
            break;
        }
        case A_REF_SPP:
        case A_CONV_SPP:
        case A_TICKS:
        case A_WARMUP: {
            char *end = NULL;
            long x = strtol(v, &end, 10);
            /* warmup ticks are not kept (a large probe grid settles in 1000s); timed ones are */
            const long lo = id == A_WARMUP ? 0 : 1,
                       hi = id == A_REF_SPP || id == A_CONV_SPP ? 1000000 : id == A_WARMUP ? 100000 : MAX_TICKS;
            if (!end || *end || x < lo || x > hi) {
                fprintf(stderr, "lpvd-accuracy: bad value for --%s: %s (an integer in %ld..%ld)\n", fl->name, v, lo,
                        hi);
                return 2;
            }
            if (id == A_REF_SPP)
                a->spp = (int)x;
            else if (id == A_CONV_SPP)
                a->conv_spp = (int)x;
            else if (id == A_TICKS)
                a->ticks = (int)x;
            else
                a->warmup = (int)x;
            break;
        }
        }
    }
    if (!a->size_given) /* the paper's table 1 reprojects 512^2 points */
        a->opt.cam.width = a->opt.cam.height = a->iv_tables ? 512 : 128;
    if (a->opt.cam.height == 0) {
        fprintf(stderr, "lpvd-accuracy: --size needs WxH\n");
        return 2;
    }
    return -1;
}
