/*
 * acc_csv.c - OUT/results.csv: one row per (scene, point), the LPV's columns
 * in their old order, then the imperfect volume's knobs and stages.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "accuracy_internal.h"

/* The CSV: the LPV's columns in their old order (an iv point leaves the
 * LPV's own knobs, grid to mods and bounces, empty), then the imperfect
 * volume's knobs and stages (empty and 0 for LPV points). */
void acc_write_csv(FILE *f, const result *r, int n, const scene_entry *scenes)
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
            fprintf(f, "%s,,,%d,,,%s,%.3f", scenes[r[i].scene].name, r[i].p.rsm, acc_tech_name(r[i].p.technique),
                    r[i].ms_total);
        else
            fprintf(f, "%s,%d,%d,%d,%s,%s,%s,%.3f", scenes[r[i].scene].name, r[i].p.grid, r[i].p.iterations,
                    r[i].p.rsm, acc_occ_name(r[i].p.occlusion), acc_mods_name(r[i].p.mods, mb), acc_tech_name(r[i].p.technique),
                    r[i].ms_total);
        for (int k = 0; k < NSTAGES_LPV; ++k)
            fprintf(f, ",%.3f", r[i].stage_ms[k]);
        fprintf(f, ",%.5f,%.5f,%.5f,%.5f,%.5f,%zu,%d,%s", r[i].m.rel_rmse, r[i].m.rel_bias, r[i].m.ref_noise,
                r[i].m.rel_rmse_excess, r[i].m.rel_mae, r[i].m.pixels, r[i].pareto,
                r[i].p.feat ? "" : acc_point_preset(&r[i].p));
        fprintf(f, ",%s,%s,%d,%g,%s,%g,%d,%.5f,", r[i].p.feat ? "features" : "sweep", r[i].p.label,
                r[i].cascades_used, (double)r[i].p.cascade_size, iv ? "" : acc_occ_name(r[i].p.bounces),
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
                fprintf(f, ",%s", acc_switch_name(r[i].iv.v[k]));
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
