/*
 * acc_run_scene.c - one scene of the sweep: loads it, resolves its view,
 * reads (rendering where not cached) its 1-bounce, multi-bounce and
 * converged references, makes its region map and error-image folder, and
 * runs its points (acc_run_point.c); then frees what it read. The loop over
 * the scenes is acc_run_scenes.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy_internal.h"
#include "image_io.h"
#include "pt.h"

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

/* Runs scene s's points into c->results. Returns 0, else non-zero (said). */
static int run_scene(acc_run *c, int s)
{
    const acc_args *a = c->a;
    int rc = 0;
    char sub[1200];
    scene_entry *se = &c->scenes[s];
    lpv_scene scene;
    if (lpv_scene_load_user(se->path, NULL, &scene, c->err, sizeof c->err) != 0) {
        fprintf(stderr, "lpvd-accuracy: %s\n", c->err);
        return 1;
    }
    lpv_view view;
    float *ref = NULL, *ref_se = NULL, *rgba = NULL;
    /* the iv points' B-bounce references (B > 1), by B, read on first use */
    float *bref[LPV_IV_MAX_BOUNCES + 1] = {0}, *bref_se[LPV_IV_MAX_BOUNCES + 1] = {0};
    const ref_source rsrc = {a->out_dir, c->ref_is_cmd ? c->ref_cmd : NULL, a->spp, c->area_lights, se->has_cam ? 0 : a->ncam,
                             a->cam_args};
    uint8_t *regions = NULL;
    int rw = 0, rh = 0;
    lpv_view_choice cam = a->opt.cam;
    if (se->has_cam) {
        cam.has_eye = cam.has_target = cam.has_fov = 1;
        memcpy(cam.eye, se->eye, sizeof cam.eye);
        memcpy(cam.target, se->target, sizeof cam.target);
        cam.fov_deg = se->fov;
    }
    if (lpv_view_resolve(&cam, &scene, &view, c->err, sizeof c->err) != 0) {
        fprintf(stderr, "lpvd-accuracy: %s\n", c->err);
        rc = 2;
        goto next_scene;
    }
    if (acc_ensure_reference(se, &scene, &view, a->out_dir, a->spp, c->ref_is_cmd ? c->ref_cmd : NULL, a->cam_args,
                         se->has_cam ? 0 : a->ncam, 1, c->area_lights) != 0) {
        rc = 1;
        goto next_scene;
    }
    float *mref = NULL, *mref_se = NULL, *cref = NULL, *cref_se = NULL;
    if (a->features) { /* the multi-bounce reference: for bounces on, and to compare every point with */
        int mw = 0, mh = 0;
        if (acc_ensure_reference(se, &scene, &view, a->out_dir, a->spp, c->ref_is_cmd ? c->ref_cmd : NULL, a->cam_args,
                             se->has_cam ? 0 : a->ncam, a->multi_bounces, c->area_lights) != 0 ||
            lpv_image_read_f32(se->mref_exr, 4, &mw, &mh, &mref, c->err, sizeof c->err) != 0 || mw != view.width ||
            mh != view.height) {
            fprintf(stderr, "lpvd-accuracy: %s: no multi-bounce reference\n", se->name);
            rc = 1;
            goto next_scene;
        }
        se->have_mref = 1;
        if (se->have_mse && (lpv_image_read_f32(se->mref_se, 4, &mw, &mh, &mref_se, c->err, sizeof c->err) != 0 ||
                             mw != view.width || mh != view.height)) {
            free(mref_se);
            mref_se = NULL;
        }
    }
    if (lpv_image_read_f32(se->ref_exr, 4, &rw, &rh, &ref, c->err, sizeof c->err) != 0) {
        fprintf(stderr, "lpvd-accuracy: %s\n", c->err);
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
        if (lpv_image_read_f32(se->ref_se, 4, &sw, &sh, &ref_se, c->err, sizeof c->err) != 0 || sw != rw ||
            sh != rh) {
            fprintf(stderr, "lpvd-accuracy: %s: unreadable or wrong size; ignoring it\n", se->ref_se);
            free(ref_se);
            ref_se = NULL;
            se->have_se = 0;
        }
    }
    acc_write_preview(se->ref_exr, ref, rw, rh); /* a tone-mapped preview of the reference next to it */
    se->conv_spp = a->conv_spp > 0 ? a->conv_spp : (a->spp / 2 > 0 ? a->spp / 2 : 1);
    if (acc_converged_reference(se, &scene, &view, &rsrc, &cref, &cref_se) != 0) {
        rc = 1;
        goto next_scene;
    }
    fprintf(stderr, "lpvd-accuracy: %s: converged reference, 2 seeds x %d spp, ref_noise2 %.4f\n", se->name,
            se->conv_spp, se->ref_noise2);
    if (snprintf(sub, sizeof sub, "%s/err/%s", a->out_dir, se->name) >= (int)sizeof sub || acc_mkdir_p(sub) != 0) {
        fprintf(stderr, "lpvd-accuracy: cannot create %s/err/%s\n", a->out_dir, se->name);
        rc = 1;
        goto next_scene;
    }
    rgba = malloc((size_t)view.width * (size_t)view.height * 4 * sizeof(float));
    regions = region_map(&scene, &view);
    const acc_scene_run x = {s,       se,      &scene, &view, &rsrc, ref,     ref_se, mref,
                             mref_se, cref,    cref_se, bref,  bref_se, regions, rgba,   sub};
    for (int p = 0; p < c->npts && rc == 0 && rgba; ++p)
        rc = acc_run_point(c, &x, p);
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
    return rc;
}

int acc_run_scenes(acc_run *c)
{
    int rc = 0;
    for (int s = 0; s < c->nscenes && rc == 0; ++s)
        rc = run_scene(c, s);
    return rc;
}
