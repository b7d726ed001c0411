/*
 * acc_plot.c - OUT/plot.gp (plot.png: error vs ms per tick per scene,
 * fronts connected, presets labelled) and OUT/features.gp (features.png:
 * what each --features knob costs and buys), with their data under OUT/plot.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy_internal.h"

/* plot/SCENE-presets.dat: "ms rel_rmse name" of the scene's points that equal
 * a named preset, for gnuplot's labels. Returns how many, or -1. */
static int write_preset_labels(const char *out_dir, const char *scene, const result *const *rows, int k)
{
    char path[1200];
    if (snprintf(path, sizeof path, "%s/plot/%s-presets.dat", out_dir, scene) >= (int)sizeof path)
        return -1; /* too long a path: no labels rather than a wrong file */
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    int count = 0;
    fprintf(f, "# ms_per_tick rel_rmse preset\n");
    for (int i = 0; i < k; ++i) {
        const char *name = acc_point_preset(&rows[i]->p);
        if (*name) {
            fprintf(f, "%.4f %.5f %s\n", rows[i]->ms_total, rows[i]->m.rel_rmse, name);
            ++count;
        }
    }
    fclose(f);
    return count;
}

/* plot.gp + data files; runs gnuplot unless no_plot. */
int acc_write_plot(const char *out_dir, const result *r, int n, const scene_entry *scenes, int nscenes,
                   int no_plot)
{
    char path[1200];
    int labels[MAX_SCENES] = {0};
    const result **rows = malloc((size_t)n * sizeof *rows);
    if (!rows)
        return -1;
    snprintf(path, sizeof path, "%s/plot", out_dir);
    acc_mkdir_p(path);
    for (int s = 0; s < nscenes; ++s) {
        int k = acc_scene_rows(r, n, s, rows);
        labels[s] = write_preset_labels(out_dir, scenes[s].name, rows, k);
        for (int front = 0; front < 2; ++front) {
            int len = snprintf(path, sizeof path, "%s/plot/%s%s.dat", out_dir, scenes[s].name,
                               front ? "-pareto" : "");
            FILE *f = len < (int)sizeof path ? fopen(path, "w") : NULL;
            if (!f) {
                free(rows);
                return -1;
            }
            fprintf(f, "# ms_per_tick rel_rmse grid iterations rsm occlusion\n");
            for (int i = 0; i < k; ++i)
                if (!front || rows[i]->pareto)
                    fprintf(f, "%.4f %.5f %d %d %d %d\n", rows[i]->ms_total, rows[i]->m.rel_rmse, rows[i]->p.grid,
                            rows[i]->p.iterations, rows[i]->p.rsm, rows[i]->p.occlusion);
            fclose(f);
        }
    }
    free(rows);
    FILE *f = acc_open_gnuplot_script(out_dir, "plot", "error vs milliseconds per tick", no_plot);
    if (!f)
        return -1;
    fprintf(f, "set title 'lpvd indirect light vs path-traced reference: what accuracy costs in time'\n");
    fprintf(f, "set xlabel 'GPU ms per tick (median; tick + indirect-only render)'\n");
    fprintf(f, "set ylabel 'relative RMSE vs converged light'\n");
    fprintf(f, "set logscale x\nset grid xtics ytics mxtics\nset key outside right top\nset yrange [0:*]\n");
    fprintf(f, "plot \\\n");
    for (int s = 0; s < nscenes; ++s) {
        fprintf(f,
                "  'plot/%s.dat' using 1:2 with points pt 7 ps 0.8 lc %d title '%s', \\\n"
                "  'plot/%s-pareto.dat' using 1:2 with linespoints pt 6 ps 1.6 lw 2 lc %d title '%s Pareto front'",
                scenes[s].name, s + 1, scenes[s].name, scenes[s].name, s + 1, scenes[s].name);
        if (labels[s] > 0) /* the named presets, labelled next to their points */
            fprintf(f, ", \\\n  'plot/%s-presets.dat' using 1:2:3 with labels left offset 0.8,0.6 tc lt %d notitle",
                    scenes[s].name, s + 1);
        fprintf(f, "%s\n", s + 1 < nscenes ? ", \\" : "");
    }
    fclose(f);
    if (no_plot)
        return 0;
    return acc_run_gnuplot(out_dir, "plot");
}

/* features.gp + plot/features.dat: per knob of the features block, the ms per
 * tick (top) and the rel. RMSE against the point's own reference (bottom),
 * one bar per scene. Returns 0 (nothing to do without feature points). */
int acc_write_features_plot(const char *out_dir, const result *r, int n, const scene_entry *scenes, int nscenes,
                            int no_plot)
{
    int any = 0;
    for (int i = 0; i < n; ++i)
        any |= r[i].p.feat;
    if (!any)
        return 0;
    char path[1200];
    snprintf(path, sizeof path, "%s/plot", out_dir);
    acc_mkdir_p(path);
    snprintf(path, sizeof path, "%s/plot/features.dat", out_dir);
    FILE *d = fopen(path, "w");
    if (!d)
        return -1;
    fprintf(d, "# knob, then per scene: ms_per_tick rel_rmse (NaN = not measured)\n# knob");
    for (int s = 0; s < nscenes; ++s)
        fprintf(d, " ms_%s rmse_%s", scenes[s].name, scenes[s].name);
    fputc('\n', d);
    for (int k = 0; k < NFEATURES; ++k) {
        fprintf(d, "%s", FEATURES[k].label);
        for (int s = 0; s < nscenes; ++s) {
            const result *x = NULL;
            for (int i = 0; i < n; ++i)
                if (r[i].scene == s && r[i].p.feat && strcmp(r[i].p.label, FEATURES[k].label) == 0)
                    x = &r[i];
            if (x)
                fprintf(d, " %.4f %.5f", x->ms_total, x->m.rel_rmse);
            else
                fprintf(d, " NaN NaN");
        }
        fputc('\n', d);
    }
    fclose(d);
    FILE *f = acc_open_gnuplot_script(out_dir, "features", "what each new knob costs and buys", no_plot);
    if (!f)
        return -1;
    fprintf(f, "set terminal pngcairo size 960,900 font 'sans,11'\nset output 'features.png'\n");
    fprintf(f, "set multiplot layout 2,1 title 'one knob at a time around balanced (32^3, 4 it., RSM 128^2, "
               "occlusion on, 1 cascade)'\n");
    fprintf(f, "set style data histograms\nset style histogram clustered gap 1\nset style fill solid 0.8 border -1\n"
               "set boxwidth 0.9\nset grid ytics\nset key top left\nset yrange [0:*]\nset datafile missing 'NaN'\n");
    for (int panel = 0; panel < 2; ++panel) {
        fprintf(f, "set ylabel '%s'\n", panel == 0 ? "GPU ms per tick (median)"
                                                     : "relative RMSE vs converged light");
        fprintf(f, "plot ");
        for (int s = 0; s < nscenes; ++s)
            fprintf(f, "%s'plot/features.dat' using %d%s title '%s'", s ? ", " : "", 2 + 2 * s + panel,
                    s == 0 ? ":xtic(1)" : "", scenes[s].name);
        fputc('\n', f);
    }
    fprintf(f, "unset multiplot\n");
    fclose(f);
    if (no_plot)
        return 0;
    return acc_run_gnuplot(out_dir, "features");
}
