/*
 * acc_reference.c - the path-traced references every point is compared
 * with: which renderer (--reference, $LPVD_REFERENCE, the linked library or
 * the build tree's lpvd-reference), rendering and caching them under OUT/ref
 * (keyed by scene, camera, size, spp, bounces and seed), their previews, the
 * iv points' B-bounce references and the converged reference of two seeds
 * with its measured noise.
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

#include "accuracy_internal.h"
#include "hash.h"
#include "image_io.h"
#include "pt.h"
#include "tonemap.h"

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

/* The reference command: --reference, $LPVD_REFERENCE, else (returning 0)
 * the linked lpv_reference library when built with it, else the build tree's
 * reference/lpvd-reference (this binary is <build>/bench/accuracy/), PATH.
 * Returns 1 when out names a command. */
int acc_find_reference(const char *given, char *out, size_t n)
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
int acc_ensure_reference(scene_entry *e, const lpv_scene *scene, const lpv_view *view, const char *out_dir,
                         int spp, const char *ref_cmd, char *const *cam_args, int ncam, int bounces,
                         int area_lights)
{
    if (bounces > 1)
        return ensure_reference_as(e, scene, view, out_dir, spp, ref_cmd, cam_args, ncam, bounces, 0, area_lights,
                                   e->mref_exr, e->mref_se, &e->have_mse);
    return ensure_reference_as(e, scene, view, out_dir, spp, ref_cmd, cam_args, ncam, bounces, 0, area_lights,
                               e->ref_exr, e->ref_se, &e->have_se);
}

/* A tone-mapped preview next to a reference EXR (PATH.exr -> PATH.png). */
void acc_write_preview(const char *exr, const float *img, int w, int h)
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

/* The B-bounce reference (B > 1) an imperfect-volume point with B bounces is
 * compared with: rendered once per scene and bounce count and cached under
 * OUT/ref like the multi-bounce one (ensure_reference), read into *img and
 * *se_img (NULL when it has none) on first use. Returns *img, NULL when it
 * cannot be had. */
const float *acc_bounce_reference(scene_entry *e, const lpv_scene *scene, const lpv_view *view,
                                  const ref_source *src, int bounces, float **img, float **se_img)
{
    if (*img)
        return *img;
    char err[1024];
    int w = 0, h = 0;
    if (acc_ensure_reference(e, scene, view, src->out_dir, src->spp, src->cmd, src->cam_args, src->ncam, bounces,
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
    acc_write_preview(e->mref_exr, *img, w, h);
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
int acc_converged_reference(scene_entry *e, const lpv_scene *scene, const lpv_view *view, const ref_source *src,
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
    acc_write_preview(e->cref_exr[0], r[0], view->width, view->height);
    rc = 0;
done:
    for (int k = 0; k < 2; ++k) {
        free(r[k]);
        free(sd[k]);
    }
    return rc;
}
