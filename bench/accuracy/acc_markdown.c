/*
 * acc_markdown.c - OUT/results.md: per scene its points' table (the LPV's
 * and the imperfect volume's), Pareto points marked, sorted by ms per tick
 * (acc_scene_rows, which the plots use too).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy_internal.h"

static int cmp_ms(const void *a, const void *b)
{
    const result *x = *(const result *const *)a, *y = *(const result *const *)b;
    return (x->ms_total > y->ms_total) - (x->ms_total < y->ms_total);
}

/* The results of one scene sorted by ms; returns the count. */
int acc_scene_rows(const result *r, int n, int scene, const result **rows)
{
    int k = 0;
    for (int i = 0; i < n; ++i)
        if (r[i].scene == scene && !r[i].p.feat)
            rows[k++] = &r[i];
    qsort(rows, (size_t)k, sizeof *rows, cmp_ms);
    return k;
}

/* A "-" for a knob or stage the row's technique does not have. */
static void md_cell_int(FILE *f, int have, int v, const char *b)
{
    if (have)
        fprintf(f, " %s%d%s |", b, v, b);
    else
        fprintf(f, " - |");
}

static void md_cell_ms(FILE *f, int have, double v)
{
    if (have)
        fprintf(f, " %.2f |", v);
    else
        fprintf(f, " - |");
}

/* One scene's table when it has imperfect-volume rows: the LPV's columns
 * ("-" on iv rows) only when LPV rows are there too, then the iv knobs and
 * stages ("-" on LPV rows), the error against converged light, the own
 * reference's bounces and the error against it and against the 1-bounce
 * reference. */
static void write_md_iv_table(FILE *f, const result *const *rows, int k)
{
    int has_lpv = 0;
    for (int i = 0; i < k; ++i)
        has_lpv |= !is_iv(&rows[i]->p);
    fprintf(f, "| technique |%s RSM |%s iv res. | points | rays | bounces | reproj. | nbrs | ms/tick |%s points ms "
               "| reproject ms | resolve ms | gather ms | shade ms | rel. RMSE | rel. bias | rel. MAE | ref. noise "
               "| ref. bounces | rel. RMSE vs own | rel. bias vs own | vs 1-bounce ref | Pareto |\n",
            has_lpv ? " grid | iterations |" : "", has_lpv ? " occlusion | mods | preset |" : "",
            has_lpv ? " propagate ms | gv ms |" : "");
    fprintf(f, "|:---:|%s---:|%s---:|---:|---:|---:|:---:|---:|---:|%s---:|---:|---:|---:|---:|---:|---:|---:|---:|"
               "---:|---:|---:|---:|:---:|\n",
            has_lpv ? "---:|---:|" : "", has_lpv ? ":---:|:---:|:---:|" : "", has_lpv ? "---:|---:|" : "");
    for (int i = 0; i < k; ++i) {
        const result *x = rows[i];
        const int iv = is_iv(&x->p);
        const char *b = x->pareto ? "**" : "";
        fprintf(f, "| %s |", acc_tech_name(x->p.technique));
        if (has_lpv) {
            if (iv)
                fprintf(f, " - | - |");
            else
                fprintf(f, " %s%d³%s | %d |", b, x->p.grid, b, x->p.iterations);
        }
        fprintf(f, " %d² |", x->p.rsm);
        if (has_lpv) {
            if (iv)
                fprintf(f, " - | - | |");
            else
                fprintf(f, " %s | `%s` | %s |", acc_occ_name(x->p.occlusion), acc_mods_name(x->p.mods, (char[5]){0}),
                        acc_point_preset(&x->p));
        }
        if (iv)
            fprintf(f, " %s%d³%s |", b, x->iv.v[LPV_ACC_IV_RESOLUTION], b);
        else
            fprintf(f, " - |");
        md_cell_int(f, iv, x->iv.v[LPV_ACC_IV_POINTS], "");
        md_cell_int(f, iv, x->iv.v[LPV_ACC_IV_RAYS], "");
        md_cell_int(f, iv, x->iv.v[LPV_ACC_IV_BOUNCES], "");
        fprintf(f, " %s |", iv ? acc_switch_name(x->iv.v[LPV_ACC_IV_REPROJECTION]) : "-");
        md_cell_int(f, iv, x->iv.v[LPV_ACC_IV_NEIGHBOURS], "");
        fprintf(f, " %s%.2f%s |", b, x->ms_total, b);
        if (has_lpv) {
            md_cell_ms(f, !iv, x->stage_ms[ST_PROPAGATE]);
            md_cell_ms(f, !iv, x->stage_ms[ST_GV]);
        }
        for (int st = ST_IV_POINTS; st <= ST_IV_GATHER; ++st)
            md_cell_ms(f, iv, x->stage_ms[st]);
        char rm[40];
        fprintf(f, " %.2f | %s%s%s | %+.3f | %.3f | %.3f | %s | %.3f | %+.3f | %.3f | %s |\n", x->stage_ms[ST_SHADE],
                b, acc_md_rmse(x->m.rel_rmse, x->at_noise, rm, sizeof rm), b, x->m.rel_bias, x->m.rel_mae,
                x->m.ref_noise, acc_bounces_cell(x->ref_bounces, (char[16]){0}),
                x->own.rel_rmse, x->own.rel_bias, x->rel_rmse_1b,
                x->pareto ? "**◆**" : "");
    }
    fputc('\n', f);
}

void acc_write_md(FILE *f, const result *r, int n, const scene_entry *scenes, int nscenes, const char *header)
{
    fprintf(f, "# lpvd accuracy sweep\n\n%s\n", header);
    fprintf(f, "Error metrics: docs/accuracy.md. ms/tick: median GPU ms of one tick + the indirect-only render "
               "(sum of the stages). Pareto: no other point of the scene is both faster and more accurate "
               "(rel. RMSE). Rows sorted by ms/tick; Pareto rows marked **◆**; preset: the named preset "
               "(`--preset`) the point equals. rel. RMSE, rel. bias, rel. MAE, ref. noise, the Pareto front, "
               "plots and error images: against converged light (`lpvd-reference --bounces converged`, the mean of "
               "two seeds), the light a user sees; \"at the reference's noise\" where rel. RMSE is below twice "
               "the converged reference's measured noise (ref_noise2 below). rel. RMSE / bias vs own: against the "
               "reference with as many bounces as the point computes (ref. bounces: 1 for the LPV and the octree, "
               "its iv_bounces for an imperfect volume, the multi-bounce count for bounces on). Imperfect-volume "
               "(iv) stage ms are the medians of iv_points, iv_reproject, iv_resolve, iv_gather (all bounces) and "
               "shade.\n\n");
    const result **rows = malloc((size_t)n * sizeof *rows);
    if (!rows)
        return;
    for (int s = 0; s < nscenes; ++s) {
        const result *base = NULL;
        int nf = 0;
        for (int i = 0; i < n; ++i)
            if (r[i].scene == s && r[i].p.feat) {
                if (!base)
                    base = &r[i];
                ++nf;
            }
        if (nf == 0)
            continue;
        fprintf(f, "## %s: one factor at a time (--features)\n\n", scenes[s].name);
        fprintf(f, "Each row changes one knob of `base` (balanced: 32³, 4 iterations, RSM 128², occlusion on; "
                   "cascades 1 = one grid over the scene, bounces off, damping 0). rel. RMSE and bias: against "
                   "converged light; the two columns after it compare every point with the 1-bounce and the "
                   "%d-bounce references.%s\n\n",
                base->ref_bounces > 1 ? base->ref_bounces : 3,
                scenes[s].has_cam ? " This scene uses its own camera inside the box (see docs), so that 1 m "
                                    "cascades nest in the 2 m box." : "");
        fprintf(f, "| point | cascades (size) | bounces | damping | ms/tick | Δ ms vs base | propagate ms | rel. RMSE "
                   "| vs 1-bounce ref | vs multi-bounce ref | rel. bias | rel. MAE |\n");
        fprintf(f, "|---|---:|:---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
        for (int i = 0; i < n; ++i) {
            const result *x = &r[i];
            if (x->scene != s || !x->p.feat)
                continue;
            char csz[32] = "";
            if (x->cascades_used > 1)
                snprintf(csz, sizeof csz, " (%g m)", (double)x->p.cascade_size);
            char rm[40];
            fprintf(f, "| %s | %d%s | %s | %g | %.2f | %+.2f | %.2f | %s | %.3f | ", x->p.label, x->cascades_used,
                    csz, acc_occ_name(x->p.bounces), (double)x->p.damping, x->ms_total, x->ms_total - base->ms_total,
                    x->stage_ms[5], acc_md_rmse(x->m.rel_rmse, x->at_noise, rm, sizeof rm), x->rel_rmse_1b);
            if (isfinite(x->rel_rmse_multi))
                fprintf(f, "%.3f", x->rel_rmse_multi);
            else
                fprintf(f, "–");
            fprintf(f, " | %+.3f | %.3f |\n", x->m.rel_bias, x->m.rel_mae);
        }
        fputc('\n', f);
    }
    for (int s = 0; s < nscenes; ++s) {
        int k = acc_scene_rows(r, n, s, rows);
        if (k == 0)
            continue;
        fprintf(f, "## %s\n\n", scenes[s].name);
        fprintf(f, "converged reference (scored against): the mean of `%s` and `%s` (%d spp each); its noise "
                   "ref_noise2 = sqrt(mean((R1 - R2)^2)) / 2 / mean(R) = %.4f.\n\n",
                scenes[s].cref_exr[0], scenes[s].cref_exr[1], scenes[s].conv_spp, scenes[s].ref_noise2);
        fprintf(f, "1-bounce reference: `%s`%s", scenes[s].ref_exr, scenes[s].have_se ? "" : " (no stderr image)");
        for (int j = 0; j < scenes[s].nxref; ++j)
            fprintf(f, "; %d bounces (iv points with %d bounces): `%s`", scenes[s].xref_bounces[j],
                    scenes[s].xref_bounces[j], scenes[s].xref_exr[j]);
        fprintf(f, "\n\n");
        int has_iv = 0;
        for (int i = 0; i < k; ++i)
            has_iv |= is_iv(&rows[i]->p);
        if (has_iv) {
            write_md_iv_table(f, rows, k);
            continue;
        }
        fprintf(f, "| technique | grid | iterations | RSM | occlusion | mods | preset | ms/tick | propagate ms | gv ms "
                   "| rel. RMSE | rel. bias | rel. MAE | ref. noise | ref. bounces | rel. RMSE vs own | rel. bias vs own "
                   "| Pareto |\n");
        fprintf(f, "|:---:|---:|---:|---:|:---:|:---:|:---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|:---:|\n");
        for (int i = 0; i < k; ++i) {
            const result *x = rows[i];
            const char *b = x->pareto ? "**" : "";
            char rm[40];
            fprintf(f,
                    "| %s | %s%d³%s | %d | %d² | %s | `%s`%s | %s | %s%.2f%s | %.2f | %.2f | %s%s%s | %+.3f | %.3f | %.3f "
                    "| %d | %.3f | %+.3f | %s |\n",
                    acc_tech_name(x->p.technique), b, x->p.grid, b, x->p.iterations, x->p.rsm, acc_occ_name(x->p.occlusion),
                    acc_mods_name(x->p.mods, (char[5]){0}), acc_steps_text(&x->p, 0, (char[48]){0}), acc_point_preset(&x->p), b,
                    x->ms_total, b,
                    x->stage_ms[5], x->stage_ms[4], b, acc_md_rmse(x->m.rel_rmse, x->at_noise, rm, sizeof rm), b,
                    x->m.rel_bias, x->m.rel_mae, x->m.ref_noise, x->ref_bounces, x->own.rel_rmse, x->own.rel_bias,
                    x->pareto ? "**◆**" : "");
        }
        fputc('\n', f);
    }
    free(rows);
}
