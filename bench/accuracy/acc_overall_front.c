/*
 * acc_overall_front.c - the overall front over the scenes (overall.h):
 * appended to results.md, OUT/overall.csv, and overall.gp / overall.png,
 * written when there are two scenes or more.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy_internal.h"
#include "overall.h"

/* ---- The overall front (overall.h), written when there are 2+ scenes ---- */

static const char *key_preset(const int key[LPV_ACC_KEY])
{
    point p = {key[0], key[1], key[2], key[3], key[4]};
    p.technique = (lpv_technique_id)key[5];
    p.cstep = key[LPV_ACC_KEY_STEPS];
    p.rstep = key[LPV_ACC_KEY_STEPS + 1];
    p.lstep = key[LPV_ACC_KEY_STEPS + 2];
    return acc_point_preset(&p);
}

/* Appends the overall table to results.md, writes overall.csv, and
 * overall.gp / plot/overall*.dat; runs gnuplot for overall.png unless
 * no_plot. Returns 0, or -1 when a file cannot be written. */
int acc_write_overall(const char *out_dir, const result *r, int n, const scene_entry *scenes, int nscenes,
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
                acc_mods_name(x->key[4], mb);
            fprintf(md, "| %s |", acc_tech_name(x->key[LPV_ACC_KEY_TECHNIQUE]));
            if (has_lpv && iv)
                fprintf(md, " - | - | %d² | - | - | |", x->key[2]);
            else if (has_lpv)
                fprintf(md, " %s%d³%s | %d | %d² | %s | `%s`%s | %s |", b, x->key[0], b, x->key[1], x->key[2],
                        acc_occ_name(x->key[3]), mb,
                        acc_steps_text(&(point){.cstep = x->key[LPV_ACC_KEY_STEPS],
                                            .rstep = x->key[LPV_ACC_KEY_STEPS + 1],
                                            .lstep = x->key[LPV_ACC_KEY_STEPS + 2]},
                                   0, (char[48]){0}),
                        pre);
            else
                fprintf(md, " %d² |", x->key[2]);
            if (has_iv && iv)
                fprintf(md, " %s%d³%s | %d | %d | %d | %s | %d |", b, ivk[LPV_ACC_IV_RESOLUTION], b,
                        ivk[LPV_ACC_IV_POINTS], ivk[LPV_ACC_IV_RAYS], ivk[LPV_ACC_IV_BOUNCES],
                        acc_switch_name(ivk[LPV_ACC_IV_REPROJECTION]), ivk[LPV_ACC_IV_NEIGHBOURS]);
            else if (has_iv)
                fprintf(md, " - | - | - | - | - | - |");
            fprintf(md, " %s%.2f%s | %s%.3f%s |", b, x->ms, b, b, x->norm_rmse, b);
            if (iv)
                fprintf(csv, ",,%d,,,%s,%.4f,%.5f", x->key[2], acc_tech_name(x->key[LPV_ACC_KEY_TECHNIQUE]), x->ms,
                        x->norm_rmse);
            else
                fprintf(csv, "%d,%d,%d,%s,%s,%s,%.4f,%.5f", x->key[0], x->key[1], x->key[2], acc_occ_name(x->key[3]), mb,
                        acc_tech_name(x->key[LPV_ACC_KEY_TECHNIQUE]), x->ms, x->norm_rmse);
            for (int s = 0; s < nscenes; ++s) {
                char rm[40];
                fprintf(md, " %s |", acc_md_rmse(x->rel_rmse[s], acc_at_ref_noise(x->rel_rmse[s], scenes[s].ref_noise2), rm,
                                             sizeof rm));
                fprintf(csv, ",%.5f", x->rel_rmse[s]);
            }
            fprintf(md, " %s |\n", x->pareto ? "**◆**" : "");
            fprintf(csv, ",%d,%s", x->pareto, pre);
            for (int q = 0; q < LPV_ACC_IV_KNOBS; ++q) {
                if (!iv)
                    fputc(',', csv);
                else if (q == LPV_ACC_IV_REPROJECTION)
                    fprintf(csv, ",%s", acc_switch_name(ivk[q]));
                else
                    fprintf(csv, ",%d", ivk[q]);
            }
            fputc('\n', csv);
            fprintf(dat, "%.4f %.5f %d %s %s\n", x->ms, x->norm_rmse, x->pareto, *pre ? pre : "-",
                    acc_tech_name(x->key[LPV_ACC_KEY_TECHNIQUE]));
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
    FILE *f = acc_open_gnuplot_script(out_dir, "overall", "the overall front", no_plot);
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
    return acc_run_gnuplot(out_dir, "overall");
}
