/*
 * acc_gnuplot.c - gnuplot for the plots and the overall front: a script
 * OUT/NAME.gp opened with its terminal (pngcairo when gnuplot has it) and
 * run in OUT.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy_internal.h"

static int have_pngcairo(void)
{
    FILE *p = popen("gnuplot -e 'set terminal' 2>&1", "r");
    if (!p)
        return 0;
    char line[512];
    int found = 0;
    while (fgets(line, sizeof line, p))
        if (strstr(line, "pngcairo"))
            found = 1;
    pclose(p);
    return found;
}

/* OUT/NAME.gp opened for writing, with the terminal (pngcairo when there,
 * else png) and the output OUT/NAME.png set; the caller adds the plot. */
FILE *acc_open_gnuplot_script(const char *out_dir, const char *name, const char *what, int no_plot)
{
    char path[1200];
    if (snprintf(path, sizeof path, "%s/%s.gp", out_dir, name) >= (int)sizeof path)
        return NULL;
    FILE *f = fopen(path, "w");
    if (!f)
        return NULL;
    int cairo = no_plot ? 1 : have_pngcairo();
    fprintf(f, "# lpvd-accuracy: %s; run from %s: gnuplot %s.gp\n", what, out_dir, name);
    fprintf(f, "set terminal %s size 960,640%s\n", cairo ? "pngcairo" : "png", cairo ? " font 'sans,11'" : "");
    fprintf(f, "set output '%s.png'\n", name);
    return f;
}

/* Runs gnuplot on OUT/NAME.gp in OUT. Returns 0, or -1 (and says so). */
int acc_run_gnuplot(const char *out_dir, const char *name)
{
    char cmd[1400];
    if (snprintf(cmd, sizeof cmd, "cd '%s' && gnuplot %s.gp", out_dir, name) >= (int)sizeof cmd)
        return -1;
    int rc = system(cmd);
    if (rc != 0) {
        fprintf(stderr, "lpvd-accuracy: gnuplot failed (status %d); %s.gp and plot/*.dat are written\n", rc, name);
        return -1;
    }
    return 0;
}
