/*
 * acc_knobs.c - the sweep's two point languages parsed: --knobs SPEC (value
 * lists per knob, into a knob_filter) and --points LIST (explicit points).
 * Making the point set from them is acc_point_set.c.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy_internal.h"

/* Parses "16/32" style value lists into out; returns the count or -1. */
static int parse_values(const char *s, int *out, int max, int is_switch)
{
    int n = 0;
    char buf[256];
    snprintf(buf, sizeof buf, "%s", s);
    for (char *save = NULL, *tok = strtok_r(buf, "/", &save); tok; tok = strtok_r(NULL, "/", &save)) {
        if (n >= max)
            return -1;
        if (is_switch) {
            if (strcmp(tok, "on") == 0 || strcmp(tok, "1") == 0)
                out[n++] = 1;
            else if (strcmp(tok, "off") == 0 || strcmp(tok, "0") == 0)
                out[n++] = 0;
            else
                return -1;
        } else {
            char *end = NULL;
            long v = strtol(tok, &end, 10);
            if (!end || *end || v < 1 || v > 4096)
                return -1;
            out[n++] = (int)v;
        }
    }
    return n > 0 ? n : -1;
}

/* "auto/1/4": the steps' list, auto as -1. */
static int parse_steps(const char *v, int *out, int max)
{
    char buf[128];
    snprintf(buf, sizeof buf, "%s", v);
    int n = 0;
    for (char *save = NULL, *t = strtok_r(buf, "/", &save); t; t = strtok_r(NULL, "/", &save)) {
        char *end;
        long x = strcmp(t, "auto") == 0 ? -1 : strtol(t, &end, 10);
        if (n >= max || (x != -1 && (*end || x < 1 || x > LPV_MAX_CAMERA_SURFEL_STEP)))
            return -1;
        out[n++] = (int)x;
    }
    return n > 0 ? n : -1;
}

/* Whether the filter names one of the LPV's own knobs (not rsm: the imperfect
 * volume's shadow maps are RSMs too), or one of the imperfect volume's. */
int acc_names_lpv_knob(const knob_filter *kf)
{
    return kf->ngrid || kf->niter || kf->nocc || kf->nsw[0] || kf->nsw[1] || kf->nsw[2] || kf->nsw[3];
}

int acc_names_iv_knob(const knob_filter *kf)
{
    for (int k = 0; k < LPV_ACC_IV_KNOBS; ++k)
        if (kf->niv[k])
            return 1;
    return 0;
}

static const char *const MOD_KNOBS[4] = {"central", "bins", "far", "surfels"};

int acc_parse_knobs(const char *spec, knob_filter *kf)
{
    char buf[512];
    snprintf(buf, sizeof buf, "%s", spec);
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(tok, '=');
        if (!eq)
            return -1;
        *eq = '\0';
        const char *v = eq + 1;
        int r;
        if (strcmp(tok, "grid") == 0)
            r = kf->ngrid = parse_values(v, kf->grid, 16, 0);
        else if (strcmp(tok, "iterations") == 0)
            r = kf->niter = parse_values(v, kf->iter, 16, 0);
        else if (strcmp(tok, "rsm") == 0)
            r = kf->nrsm = parse_values(v, kf->rsm, 16, 0);
        else if (strcmp(tok, "occlusion") == 0)
            r = kf->nocc = parse_values(v, kf->occ, 2, 1);
        else if (strcmp(tok, "camera_step") == 0)
            r = kf->ncs = parse_steps(v, kf->cs, 16);
        else if (strcmp(tok, "rsm_step") == 0)
            r = kf->nrs = parse_steps(v, kf->rs, 16);
        else if (strcmp(tok, "lookup_step") == 0) {
            r = kf->nls = parse_values(v, kf->ls, 16, 0);
            for (int i = 0; i < kf->nls; ++i)
                if (kf->ls[i] < 1 || kf->ls[i] > LPV_MAX_LOOKUP_STEP)
                    r = -1;
        }
        else if (strcmp(tok, "technique") == 0) {
            char names[128];
            snprintf(names, sizeof names, "%s", v);
            r = kf->ntech = 0;
            for (char *s2 = NULL, *t = strtok_r(names, "/", &s2); t; t = strtok_r(NULL, "/", &s2)) {
                lpv_technique_id id;
                if (kf->ntech >= LPV_TECHNIQUE_ID_COUNT_ || lpv_technique_from_name(t, &id) != 0)
                    return -1;
                kf->tech[kf->ntech++] = (int)id;
            }
            r = kf->ntech > 0 ? kf->ntech : -1;
        } else if (lpv_acc_iv_knob_from_name(tok) >= 0) {
            const int ik = lpv_acc_iv_knob_from_name(tok);
            r = kf->niv[ik] = lpv_acc_iv_parse_list(ik, v, kf->iv[ik], 16);
        } else {
            r = -1;
            for (int m = 0; m < 4; ++m)
                if (strcmp(tok, MOD_KNOBS[m]) == 0)
                    r = kf->nsw[m] = parse_values(v, kf->sw[m], 2, 1);
            if (r < 0)
                return -1;
        }
        if (r < 0)
            return -1;
    }
    return 0;
}

/* --points: "GRID:ITER:RSM:on|off[:MODS[:TECHNIQUE]][@CAM/VPL]" (the steps,
 * a number or auto) or the imperfect
 * volume's "iv[:RES:POINTS:RAYS:BOUNCES:REPROJ:NEIGHBOURS]" (iv_knobs.h),
 * comma-separated. Returns the count, or -1 with err set. */
int acc_parse_points(const char *list, point *pts, int max, char *err, size_t err_size)
{
    int n = 0;
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", list);
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        char occ[8] = "", mods[8] = "", tech[16] = "";
        point p = {0};
        char *steps = strchr(tok, '@'); /* the steps */
        if (steps) {
            int st[2];
            *steps = '\0';
            if (parse_steps(steps + 1, st, 2) != 2) {
                snprintf(err, err_size, "%s: @CAM/VPL expects two steps, each a number or auto", steps + 1);
                return -1;
            }
            p.cstep = st[0];
            p.rstep = st[1];
        }
        if (n >= max) {
            snprintf(err, err_size, "at most %d points", max);
            return -1;
        }
        int iv = lpv_acc_iv_parse_point(tok, &p.iv, err, err_size);
        if (iv < 0)
            return -1;
        if (iv > 0) { /* RSM as the sweep's default (RSMS) */
            p.technique = LPV_TECHNIQUE_ID_IV;
            p.rsm = RSMS[0];
            pts[n++] = p;
            continue;
        }
        snprintf(err, err_size, "%s: expected GRID:ITER:RSM:on|off[:MODS[:TECHNIQUE]] or "
                                "iv[:RES:POINTS:RAYS:BOUNCES:REPROJ:NEIGHBOURS]", tok);
        int got = sscanf(tok, "%d:%d:%d:%7[a-z]:%7[-a-z]:%15s", &p.grid, &p.iterations, &p.rsm, occ, mods, tech);
        if (got < 4)
            return -1;
        lpv_technique_id id = LPV_TECHNIQUE_ID_LPV;
        if (got == 6 && lpv_technique_from_name(tech, &id) != 0)
            return -1;
        p.technique = id;
        if (strcmp(occ, "on") == 0)
            p.occlusion = 1;
        else if (strcmp(occ, "off") == 0)
            p.occlusion = 0;
        else
            return -1;
        for (const char *c = got >= 5 ? mods : ""; *c; ++c) { /* letters of cbfs, '-' for off */
            const char *at = strchr(acc_mod_letters(), *c);
            if (*c != '-' && !at)
                return -1;
            if (*c != '-')
                p.mods |= 1 << (at - acc_mod_letters());
        }
        if (p.grid < 1 || p.grid > 256 || p.iterations < 0 || p.iterations > 4096 || p.rsm < 16 || p.rsm > 8192 ||
            !acc_technique_runs(&p))
            return -1;
        if (is_iv(&p)) /* the old form with technique iv: its RSM, the iv knobs' defaults */
            p = (point){.rsm = p.rsm, .technique = LPV_TECHNIQUE_ID_IV, .cstep = p.cstep, .rstep = p.rstep};
        pts[n++] = p;
    }
    if (n == 0)
        snprintf(err, err_size, "--points is empty");
    return n > 0 ? n : -1;
}
