/*
 * acc_points.c - a point of the sweep (accuracy_internal.h): its engine
 * settings, the preset it equals, whether its technique can run it, and its
 * names in labels, file names, tables and messages. Every other file of
 * lpvd-accuracy names points through these, so they are here, apart from
 * the files that make, run or write the points.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "accuracy_internal.h"

/* The swept steps of a point, "" when it sweeps none: for a label
 * (file = 0) " cam 4, vpl auto lookup 2", for an image's file name (file =
 * 1) "-cam4-vplauto-lookup2", so points that differ only in their steps do
 * not overwrite each other's images. */
const char *acc_steps_text(const point *p, int file, char buf[48])
{
    buf[0] = '\0';
    size_t at = 0;
    if (p->cstep || p->rstep) {
        char c[12], r[12];
        snprintf(c, sizeof c, p->cstep > 0 ? "%d" : "auto", p->cstep);
        snprintf(r, sizeof r, p->rstep > 0 ? "%d" : "auto", p->rstep);
        at = (size_t)snprintf(buf, 48, file ? "-cam%s-vpl%s" : " cam %s, vpl %s", p->cstep ? c : "-",
                              p->rstep ? r : "-");
    }
    if (p->lstep && at < 48)
        snprintf(buf + at, 48 - at, file ? "-lookup%d" : " lookup %d", p->lstep);
    return buf;
}

/* The engine settings of a point: exactly its knobs, nothing from a preset. */
static lpv_settings point_settings(const point *p)
{
    return (lpv_settings){.grid_dims = {p->grid, p->grid, p->grid},
                          .lpv.iterations = p->iterations,
                          .rsm_size = p->rsm,
                          .lpv.occlusion = on_off(p->occlusion),
                          .lpv.central_transport = on_off(p->mods & MOD_CENTRAL),
                          .lpv.normal_bins = on_off(p->mods & MOD_BINS),
                          .lpv.far_field = on_off(p->mods & MOD_FAR),
                          .scene_surfels = on_off(p->mods & MOD_SURFELS),
                          .technique = lpv_of(p->technique)};
}

/* The point's technique by name: "lpv", "octree". */
const char *acc_tech_name(int technique) { return lpv_technique_name(lpv_of((lpv_technique_id)technique)); }

/* Whether the technique can run the point: the octree halves a cubic
 * power-of-two grid, and its levels are single grids (no normal bins, no far
 * field), so it has no points that differ only in those two switches. */
int acc_technique_runs(const point *p)
{
    if (p->technique != LPV_TECHNIQUE_ID_OCTREE)
        return 1;
    return (p->grid & (p->grid - 1)) == 0 && !(p->mods & (MOD_BINS | MOD_FAR));
}

/* "cbfs" with '-' for the switches that are off: the point's departures. */
const char *acc_mods_name(int mods, char buf[5])
{
    lpv_settings s = point_settings(&(point){.mods = mods});
    return lpv_settings_departures(&s, buf);
}

/* The four letters, in the order of the MOD_* bits. */
const char *acc_mod_letters(void)
{
    static char all[5];
    return acc_mods_name(MOD_ALL, all);
}

static int mods_of_settings(const lpv_settings *s)
{
    return (s->lpv.central_transport == LPV_SWITCH_ON ? MOD_CENTRAL : 0) |
           (s->lpv.normal_bins == LPV_SWITCH_ON ? MOD_BINS : 0) | (s->lpv.far_field == LPV_SWITCH_ON ? MOD_FAR : 0) |
           (s->scene_surfels == LPV_SWITCH_ON ? MOD_SURFELS : 0);
}

/* The named preset the point equals (settings.h), or "" when none: the sweep
 * labels the presets so one can see where they sit on the front. */
const char *acc_point_preset(const point *p)
{
    lpv_settings s = point_settings(p);
    if (p->technique != LPV_TECHNIQUE_ID_DEFAULT && p->technique != LPV_TECHNIQUE_ID_LPV)
        return ""; /* the presets are the cascaded LPV's */
    if (p->cstep > 0 || p->rstep > 0 || p->lstep > 1)
        return ""; /* a preset down-samples automatically and looks every pixel up */
    lpv_preset m = lpv_preset_match(&s);
    return m == LPV_PRESET_DEFAULT ? "" : lpv_preset_name(m);
}

/* --presets: exactly the named presets, in the table's order. */
int acc_preset_points(point *pts)
{
    const lpv_preset order[] = {LPV_PRESET_FAST, LPV_PRESET_BALANCED, LPV_PRESET_ACCURATE};
    int n = 0;
    for (size_t i = 0; i < sizeof order / sizeof order[0]; ++i) {
        lpv_settings s;
        if (lpv_preset_settings(order[i], &s) != 0)
            continue;
        pts[n++] = (point){s.grid_dims[0], s.lpv.iterations, s.rsm_size, s.lpv.occlusion == LPV_SWITCH_ON,
                           mods_of_settings(&s)};
    }
    return n;
}

const char *acc_occ_name(int on)
{
    return on ? "on" : "off";
}

/* "at the reference's noise": a rel. RMSE below twice the converged
 * reference's measured noise tells nothing about the technique. */
int acc_at_ref_noise(double rel_rmse, double ref_noise2)
{
    return isfinite(rel_rmse) && isfinite(ref_noise2) && rel_rmse < 2.0 * ref_noise2;
}

/* A Markdown rel. RMSE cell's text: the figure, or "at the reference's noise". */
const char *acc_md_rmse(double rel_rmse, int at_noise, char *buf, size_t size)
{
    if (at_noise)
        snprintf(buf, size, "%s", "at the reference's noise");
    else
        snprintf(buf, size, "%.3f", rel_rmse);
    return buf;
}

/* "on"/"off" of an lpv_switch value (iv_reprojection). */
/* The own reference of a point with ref_bounces b: "converged" (0: an
 * imperfect volume whose tail models every bounce) or "B bounce(s)"; and as
 * a table cell, "all" or B. */
const char *acc_own_text(int b, char buf[32])
{
    if (b == 0)
        return "converged";
    snprintf(buf, 32, "%d bounce(s)", b);
    return buf;
}

const char *acc_bounces_cell(int b, char buf[16])
{
    if (b == 0)
        return "all";
    snprintf(buf, 16, "%d", b);
    return buf;
}

const char *acc_switch_name(int v)
{
    return v == LPV_SWITCH_ON ? "on" : v == LPV_SWITCH_OFF ? "off" : "default";
}
