/*
 * main.c - lpvd-reference: the path-traced reference image (or irradiance at
 * points) for lpvd's indirect light. See docs/reference.md.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "image_io.h"
#include "pt.h"
#include "scene_load.h"
#include "view_choice.h"

static const char USAGE_HEAD[] =
    "usage: lpvd-reference [SCENE.glb] -o OUT.exr [--stderr STDERR.exr] [options]\n"
    "       lpvd-reference [SCENE.glb] --points IN.csv -o OUT.csv [options]\n"
    "\n"
    "Path-traced indirect light (docs/reference.md): the image is albedo/pi * E_ind\n"
    "at the first surface of each pixel (what `lpvd render --indirect-only` shows);\n"
    "with --full, the whole frame (what `lpvd render` shows); points mode reads\n"
    "px,py,pz,nx,ny,nz lines and writes E_r,E_g,E_b,se_r,se_g,se_b (W/m^2).\n"
    "Without SCENE: the built-in Cornell box.\n"
    "\n";

enum { F_OUT, F_STDERR, F_FULL, F_AREA, F_BOUNCES, F_MAX_BOUNCES, F_SPP, F_THREADS, F_SEED, F_POINTS, F_HELP, F_COUNT };

/* Long-only parsing: "-spp 64" is "--spp 64", as it always was here. */
static const lpv_flag FLAGS[F_COUNT] = {
    [F_OUT] = {"output", 'o', "PATH", "output image (.exr: float) or, with --points, CSV (required)"},
    [F_STDERR] = {"stderr", 0, "PATH", "per-pixel standard error image (default: none)"},
    [F_FULL] = {"full", 0, NULL, "the full frame: emission + direct + bounced light"},
    [F_AREA] = {"area-lights", 0, "on|off", "on (default, as lpvd): emissive surfaces are lights, their\n"
                                            "direct light is not in E_ind; off: it is (lpvd --area-lights off)"},
    [F_BOUNCES] = {"bounces", 0, "N|converged", "diffuse bounces (default 1 = lpvd's LPV term; --full: 0..64);\n"
                                               "converged (or all): every bounce until the path's throughput\n"
                                               "is negligible (Russian roulette), the light a user sees"},
    [F_MAX_BOUNCES] = {"max-bounces", 0, "N", "the cap on a converged path's bounces (default 64)"},
    [F_SPP] = {"spp", 0, "N", "samples per pixel or point (default 64)"},
    [F_THREADS] = {"threads", 0, "N", "worker threads (default: the number of cores)"},
    [F_SEED] = {"seed", 0, "N", "RNG seed (default 0)"},
    [F_POINTS] = {"points", 0, "PATH", "irradiance at the points of a CSV file (default: an image)"},
    [F_HELP] = {"help", 'h', NULL, "this text"},
};

/* The usage: the head, this program's flags and the camera's, from their tables. */
static const char *usage(void)
{
    static char text[8192];
    if (!text[0]) {
        size_t len = 0;
        lpv_flags_append(text, sizeof text, &len, "%s", USAGE_HEAD);
        lpv_flags_help(text, sizeof text, &len, FLAGS, F_COUNT);
        lpv_flags_append(text, sizeof text, &len, "%s", lpv_view_flags_help());
        lpv_flags_append(text, sizeof text, &len, "%s", lpv_scene_pose_flags_help());
    }
    return text;
}

static int parse_int(const char *s, int lo, int hi, int *out)
{
    char *end = NULL;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || end == s || *end || v < lo || v > hi)
        return -1;
    *out = (int)v;
    return 0;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Reads px,py,pz,nx,ny,nz lines (lines that do not parse, e.g. a header or
 * '#' comments, are skipped). Returns the count or -1. */
static long read_points(const char *path, float **pts, float **nrm)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        fprintf(stderr, "lpvd-reference: %s: %s\n", path, strerror(errno));
        return -1;
    }
    size_t cap = 0, n = 0;
    float *p = NULL, *q = NULL;
    char line[1024];
    while (fgets(line, sizeof line, f)) {
        float v[6];
        if (line[0] == '#' || sscanf(line, " %f , %f , %f , %f , %f , %f", &v[0], &v[1], &v[2], &v[3], &v[4],
                                     &v[5]) != 6)
            continue;
        if (n == cap) {
            cap = cap ? 2 * cap : 1024;
            float *np = realloc(p, cap * 3 * sizeof *p), *nq = np ? realloc(q, cap * 3 * sizeof *q) : NULL;
            if (np)
                p = np;
            if (nq)
                q = nq;
            if (!np || !nq) {
                fprintf(stderr, "lpvd-reference: out of memory reading %s\n", path);
                free(p);
                free(q);
                fclose(f);
                return -1;
            }
        }
        memcpy(&p[3 * n], v, 3 * sizeof *v);
        memcpy(&q[3 * n], v + 3, 3 * sizeof *v);
        n++;
    }
    fclose(f);
    *pts = p;
    *nrm = q;
    return (long)n;
}

/* "3 bounce(s)" or "converged bounces". */
static void bounce_label(int bounces, char *buf, size_t size)
{
    if (bounces == LPV_REF_BOUNCES_CONVERGED)
        snprintf(buf, size, "%s", "converged bounces");
    else
        snprintf(buf, size, "%d bounce(s)", bounces);
}

static int run_points(const lpv_ref *ref, const char *in, const char *out, int bounces, int spp)
{
    float *pts = NULL, *nrm = NULL;
    long n = read_points(in, &pts, &nrm);
    if (n < 0)
        return 1;
    float *e = malloc(((size_t)n + 1) * 3 * sizeof *e), *se = malloc(((size_t)n + 1) * 3 * sizeof *se);
    int rc = 1;
    if (!e || !se) {
        fprintf(stderr, "lpvd-reference: out of memory\n");
        goto done;
    }
    double t0 = now_s();
    if (lpv_ref_irradiance(ref, pts, nrm, (size_t)n, bounces, spp, e, se) != 0) {
        fprintf(stderr, "lpvd-reference: irradiance failed\n");
        goto done;
    }
    double secs = now_s() - t0;
    FILE *f = fopen(out, "w");
    if (!f) {
        fprintf(stderr, "lpvd-reference: %s: %s\n", out, strerror(errno));
        goto done;
    }
    fprintf(f, "E_r,E_g,E_b,se_r,se_g,se_b\n");
    double rel = 0.0;
    long rel_n = 0;
    for (long i = 0; i < n; ++i) {
        fprintf(f, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", e[3 * i], e[3 * i + 1], e[3 * i + 2], se[3 * i],
                se[3 * i + 1], se[3 * i + 2]);
        for (int c = 0; c < 3; ++c)
            if (e[3 * i + c] > 0.0f) {
                rel += se[3 * i + c] / e[3 * i + c];
                rel_n++;
            }
    }
    if (fclose(f) != 0) {
        fprintf(stderr, "lpvd-reference: writing %s failed\n", out);
        goto done;
    }
    char bl[32];
    bounce_label(bounces, bl, sizeof bl);
    printf("lpvd-reference: %ld points, %d spp, %s, %d threads, %.3f s, mean relative standard error "
           "%.4g, wrote %s\n",
           n, spp, bl, lpv_ref_threads(ref), secs, rel_n ? rel / (double)rel_n : 0.0, out);
    rc = 0;
done:
    free(pts);
    free(nrm);
    free(e);
    free(se);
    return rc;
}

int main(int argc, char **argv)
{
    const char *scene_path = NULL, *out = NULL, *se_out = NULL, *points = NULL;
    int bounces = 1, max_bounces = 0, spp = 64, threads = 0, full = 0, area_lights = 1;
    unsigned long long seed = 0;
    lpv_view_choice cam;
    memset(&cam, 0, sizeof cam);
    char err[512];

    lpv_scene_pose pose = {0};
    lpv_flag_group groups[3] = {{FLAGS, F_COUNT, NULL, NULL}, lpv_view_flag_group(&cam),
                                lpv_scene_pose_flag_group(&pose)};
    lpv_flags p;
    if (lpv_flags_begin(&p, argc, argv, groups, 3, 1) != 0) {
        fprintf(stderr, "lpvd-reference: %s\n", p.err);
        return 2;
    }
    int g;
    const lpv_flag *fl;
    const char *val;
    for (lpv_flags_item it; (it = lpv_flags_next(&p, &g, &fl, &val)) != LPV_FLAGS_END;) {
        if (lpv_flags_refuse(&p, it, val, "lpvd-reference", 1))
            return 2;
        if (it == LPV_FLAGS_POSITIONAL) {
            if (scene_path) {
                fprintf(stderr, "lpvd-reference: more than one scene given (%s, %s)\n", scene_path, val);
                return 2;
            }
            scene_path = val;
            continue;
        }
        switch (fl - FLAGS) {
        case F_HELP: fputs(usage(), stdout); return 0;
        case F_OUT: out = val; break;
        case F_STDERR: se_out = val; break;
        case F_POINTS: points = val; break;
        case F_FULL: full = 1; break;
        case F_AREA:
            if (strcmp(val, "on") != 0 && strcmp(val, "off") != 0) {
                fprintf(stderr, "lpvd-reference: --area-lights %s: expected on or off\n", val);
                return 2;
            }
            area_lights = strcmp(val, "on") == 0;
            break;
        case F_BOUNCES:
            if (strcmp(val, "converged") == 0 || strcmp(val, "all") == 0) {
                bounces = LPV_REF_BOUNCES_CONVERGED;
            } else if (parse_int(val, 0, 64, &bounces) != 0) {
                fprintf(stderr, "lpvd-reference: --bounces %s: expected 1..64 (0..64 with --full) or converged\n",
                        val);
                return 2;
            }
            break;
        case F_MAX_BOUNCES:
            if (parse_int(val, 1, 1 << 16, &max_bounces) != 0) {
                fprintf(stderr, "lpvd-reference: --max-bounces %s: expected 1..65536\n", val);
                return 2;
            }
            break;
        case F_SPP:
            if (parse_int(val, 1, 1 << 24, &spp) != 0) {
                fprintf(stderr, "lpvd-reference: --spp %s: expected 1..16777216\n", val);
                return 2;
            }
            break;
        case F_THREADS:
            if (parse_int(val, 1, 256, &threads) != 0) {
                fprintf(stderr, "lpvd-reference: --threads %s: expected 1..256\n", val);
                return 2;
            }
            break;
        case F_SEED: {
            char *end = NULL;
            errno = 0;
            seed = strtoull(val, &end, 10);
            if (errno || end == val || *end) {
                fprintf(stderr, "lpvd-reference: --seed %s: expected a non-negative integer\n", val);
                return 2;
            }
            break;
        }
        }
    }
    if (!out) {
        fprintf(stderr, "lpvd-reference: -o is required\n%s", usage());
        return 2;
    }
    if (bounces == 0 && !full) {
        fprintf(stderr, "lpvd-reference: --bounces 0 needs --full (the indirect light has at least one bounce)\n");
        return 2;
    }
    if (full && points) {
        fprintf(stderr, "lpvd-reference: --full renders an image; it does not go with --points\n");
        return 2;
    }

    lpv_scene scene;
    lpv_gltf_animation_time at_buf;
    const lpv_gltf_animation_time *at = NULL;
    if (lpv_scene_pose_at(&pose, &at_buf, &at, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd-reference: %s\n", err);
        return 2;
    }
    if (lpv_scene_load_user(scene_path, at, &scene, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd-reference: %s\n", err);
        return 1;
    }
    lpv_ref *ref = NULL;
    lpv_ref_desc desc = {
        .threads = threads, .seed = seed, .emitters_are_lights = area_lights, .max_bounces = max_bounces};
    double t0 = now_s();
    if (lpv_ref_create(&scene, &desc, &ref, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd-reference: %s: %s\n", scene.source, err);
        lpv_scene_free(&scene);
        return 1;
    }
    double build_s = now_s() - t0;
    int rc = 1;
    if (points) {
        lpv_scene_free(&scene);
        rc = run_points(ref, points, out, bounces, spp);
        lpv_ref_destroy(ref);
        return rc;
    }

    lpv_view view;
    if (lpv_view_resolve(&cam, &scene, &view, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd-reference: %s\n", err);
        goto done_scene;
    }
    size_t px = (size_t)view.width * (size_t)view.height;
    float *img = malloc(px * 4 * sizeof *img), *se = malloc(px * 4 * sizeof *se);
    if (!img || !se) {
        fprintf(stderr, "lpvd-reference: out of memory for a %dx%d image\n", view.width, view.height);
        free(img);
        free(se);
        goto done_scene;
    }
    t0 = now_s();
    if (full)
        lpv_ref_render_full(ref, &view, bounces, spp, img, se);
    else
        lpv_ref_render_indirect(ref, &view, bounces, spp, img, se);
    double secs = now_s() - t0;
    double rel = lpv_ref_mean_relative_stderr(img, se, view.width, view.height);
    if (lpv_image_write_f32(out, view.width, view.height, 4, img, err, sizeof err) != 0 ||
        (se_out && lpv_image_write_f32(se_out, view.width, view.height, 4, se, err, sizeof err) != 0)) {
        fprintf(stderr, "lpvd-reference: %s\n", err);
    } else {
        char bl[32];
        bounce_label(bounces, bl, sizeof bl);
        printf("lpvd-reference: %s, %u triangles (build %.3f s), %dx%d, %s, %d spp, %s, %d threads, "
               "%.3f s, mean relative standard error %.4g, wrote %s%s%s\n",
               scene.source, lpv_ref_triangle_count(ref), build_s, view.width, view.height,
               full ? "full frame" : area_lights ? "indirect, area lights on" : "indirect, area lights off", spp,
               bl, lpv_ref_threads(ref), secs, rel, out, se_out ? " and " : "", se_out ? se_out : "");
        rc = 0;
    }
    free(img);
    free(se);
done_scene:
    lpv_ref_destroy(ref);
    lpv_scene_free(&scene);
    return rc;
}
