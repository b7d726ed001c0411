/*
 * overall.h - one front over several scenes, to choose defaults from.
 *
 * Each scene has its own Pareto front, and a setting good on one can be poor
 * on another. To name defaults the sweep also ranks every point measured on
 * all scenes by
 *   cost  = mean over the scenes of ms per tick
 *   error = mean over the scenes of rel_rmse / (the scene's best rel_rmse)
 * so error 1 would be "the best this sweep achieves, on every scene", and a
 * scene whose errors are large in absolute terms does not outweigh the rest.
 */
#ifndef LPV_ACC_OVERALL_H
#define LPV_ACC_OVERALL_H

#include <stddef.h>

#define LPV_ACC_MAX_SCENES 16

/* One measured (scene, point): the point is identified by key[LPV_ACC_KEY]. */
/* grid, iterations, rsm, occlusion, mods, technique, then the imperfect
 * volume's knobs (iv_knobs.h's order: resolution, points, rays, bounces,
 * reprojection, neighbours; 0 for the LPV's points, whose iv knobs do not
 * apply, as grid..mods but rsm are 0 for iv points) */
#define LPV_ACC_KEY 15
#define LPV_ACC_KEY_TECHNIQUE 5
#define LPV_ACC_KEY_IV 6 /* .. 11 */
#define LPV_ACC_KEY_STEPS 12 /* camera surfel step, RSM VPL step, lookup step (accuracy_internal.h point.cstep, rstep, lstep) */
typedef struct lpv_acc_row {
    int scene; /* 0 .. nscenes-1 */
    int key[LPV_ACC_KEY];
    double ms, rel_rmse;
} lpv_acc_row;

typedef struct lpv_acc_overall {
    int key[LPV_ACC_KEY];
    double ms;                          /* mean over the scenes */
    double norm_rmse;                   /* mean of rel_rmse / best of the scene */
    double rel_rmse[LPV_ACC_MAX_SCENES]; /* per scene */
    int pareto;                         /* 1 = on the overall front */
} lpv_acc_overall;

/* Fills out (at most max entries, in first-seen order) with the points that
 * have a finite rel_rmse on every one of nscenes scenes, and marks the
 * front (lpv_acc_pareto on ms vs norm_rmse). Returns the count; 0 when
 * nscenes < 1 or > LPV_ACC_MAX_SCENES. */
size_t lpv_acc_overall_front(const lpv_acc_row *rows, size_t n, int nscenes, lpv_acc_overall *out, size_t max);

#endif /* LPV_ACC_OVERALL_H */
