/*
 * iv_tables.h - `lpvd-accuracy --iv-tables`: the imperfect volumes paper's
 * tables (Mavridis & Papaioannou, section 4; docs/imperfect-volumes.md) on
 * lpvd's scenes.
 *
 *   Table 1  volume creation vs points per triangle N = 3, 7, 12, 19: the CPU
 *            time to make the point cloud (techniques/iv/core/iv_points.h,
 *            lpv_iv_points_make, what lpv_engine_set_settings re-samples)
 *            plus the iv_points stage's GPU ms (lighting and splatting the
 *            points), and the reprojection (iv_reproject) of the view's
 *            pixels (512^2 by default, the paper's T_rp)
 *   Table 2  with iv_ao on: the AO march (iv_ao), the GI march per bounce
 *            (iv_gather / bounces; each bounce's emission pass included), and
 *            the reconstruction (shade: the lookup per pixel)
 *
 * Times are medians over the timed ticks (every tick a full one), GPU ms from
 * timer queries; on llvmpipe they are CPU ms of the emulation. Writes
 * OUT/iv-tables.md and prints it. No reference, no error.
 */
#ifndef LPV_ACCURACY_IV_TABLES_H
#define LPV_ACCURACY_IV_TABLES_H

#include "engine.h"
#include "options.h"

typedef struct lpv_acc_iv_scene {
    const char *name;
    const char *path; /* NULL: the built-in Cornell box */
    int has_cam;      /* its own camera (eye, target, fov) instead of the view flags' */
    float eye[3], target[3], fov;
} lpv_acc_iv_scene;

typedef struct lpv_acc_iv_tables_desc {
    const char *out_dir;
    const lpvd_options *opt;  /* base settings (--iv-* knobs) and the view (--size) */
    const lpv_acc_iv_scene *scenes;
    int nscenes;
    int ticks, warmup;
    const char *machine;      /* backend and GL_RENDERER */
    const char *command;      /* the command line, for the header */
} lpv_acc_iv_tables_desc;

/* Measures and writes the tables; returns 0, or non-zero after saying why. */
int lpv_acc_iv_tables_run(lpv_engine *engine, const lpv_acc_iv_tables_desc *d);

#endif
