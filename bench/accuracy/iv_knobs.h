/*
 * iv_knobs.h - the imperfect volume's knobs as `lpvd-accuracy` sweeps them
 * (docs/accuracy.md): their names in --knobs, their value lists, and the
 * explicit point form of --points,
 *
 *   iv[:RES[:POINTS[:RAYS[:BOUNCES[:REPROJ[:NEIGHBOURS]]]]]]
 *
 * e.g. "iv:32:8:64:3:on:8"; a field left out, empty or "-" is not set (the
 * point takes --iv-* or the engine's default). Plain C, no GL: the sweep and
 * tests/test_accuracy_iv.c use it.
 */
#ifndef LPV_ACC_IV_KNOBS_H
#define LPV_ACC_IV_KNOBS_H

#include <stddef.h>

#include "settings.h"

/* The swept knobs, in the --points field order and the CSV's. */
typedef enum lpv_acc_iv_knob {
    LPV_ACC_IV_RESOLUTION,   /* iv_resolution, voxels along the longest side */
    LPV_ACC_IV_POINTS,       /* iv_points, per triangle */
    LPV_ACC_IV_RAYS,         /* iv_rays, per voxel */
    LPV_ACC_IV_BOUNCES,      /* iv_bounces */
    LPV_ACC_IV_REPROJECTION, /* iv_reprojection, an lpv_switch: 1 on, 2 off */
    LPV_ACC_IV_NEIGHBOURS,   /* iv_neighbours, 1..8 */
    LPV_ACC_IV_KNOBS
} lpv_acc_iv_knob;

/* A point's iv knobs: 0 = not set (the base settings' value). */
typedef struct lpv_acc_iv_knobs {
    int v[LPV_ACC_IV_KNOBS];
} lpv_acc_iv_knobs;

/* "iv_resolution", ... ("iv_reprojection"), the settings field's name; NULL
 * out of range. */
const char *lpv_acc_iv_knob_name(int knob);
/* The knob of a --knobs name, or -1. */
int lpv_acc_iv_knob_from_name(const char *name);

/* Parses one value of the knob ("on"/"off" for reprojection, else an integer
 * within the settings' range) into *out. Returns 0 or -1. */
int lpv_acc_iv_parse_value(int knob, const char *s, int *out);
/* A "/"-separated list ("16/32/48") into out[max]; returns the count or -1. */
int lpv_acc_iv_parse_list(int knob, const char *s, int *out, int max);

/* "iv" or "iv:..." (above) into *out. Returns 1 when tok is an iv point and
 * parsed, 0 when it is not one (does not start with "iv" followed by ':' or
 * the end), -1 when it is one but malformed (err says why). */
int lpv_acc_iv_parse_point(const char *tok, lpv_acc_iv_knobs *out, char *err, size_t err_size);

/* The knobs that are set, over s (a settings' iv block). */
void lpv_acc_iv_apply(const lpv_acc_iv_knobs *k, lpv_iv_settings *s);
/* A resolved iv block's values as knobs (every one set). */
lpv_acc_iv_knobs lpv_acc_iv_of_settings(const lpv_iv_settings *s);
/* The knob's value in a settings' iv block. */
int lpv_acc_iv_get(const lpv_iv_settings *s, int knob);

/* "res32-pts8-rays64-b3-reproj-on-nb8": a file-name-safe label. */
const char *lpv_acc_iv_label(const lpv_acc_iv_knobs *k, char *buf, size_t n);

#endif /* LPV_ACC_IV_KNOBS_H */
