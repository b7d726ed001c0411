/*
 * acc_knobs.c - the sweep's two point languages parsed: --knobs SPEC (value
 * lists per knob, into a knob_filter) and --points LIST (explicit points).
 * Making the point set from them is acc_point_set.c.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy_internal.h"
#include "knob_rows.h"

/* A "16/32" list of the row's values into out[max]; returns the count or
 * -1. Switches give 1 (on) and 0 (off); auto_as replaces a zero value (the
 * steps keep "auto" as -1, point.cstep / rstep). */
static int parse_row_list(const lpv_field *f, const char *s, int *out, int max, int auto_as)
{
    int n = 0;
    char buf[256];
    if (snprintf(buf, sizeof buf, "%s", s) >= (int)sizeof buf)
        return -1;
    for (char *save = NULL, *tok = strtok_r(buf, "/", &save); tok; tok = strtok_r(NULL, "/", &save)) {
        double v;
        char err[256];
        if (n >= max)
            return -1;
        if (acc_knob_value(f, tok, &v, err, sizeof err) != 0) {
            fprintf(stderr, "lpvd-accuracy: --knobs %s\n", err);
            return -1;
        }
        out[n++] = v == 0.0 && f->kind != LPV_FIELD_SWITCH ? auto_as : (int)v;
    }
    return n > 0 ? n : -1;
}

/* The grid is not a row (three sizes, grid_dims): 1..LPV_MAX_GRID_DIM, as
 * lpv_settings_validate checks it. */
static int parse_grid(const char *s, int *out, int max)
{
    int n = 0;
    char buf[256];
    if (snprintf(buf, sizeof buf, "%s", s) >= (int)sizeof buf)
        return -1;
    for (char *save = NULL, *tok = strtok_r(buf, "/", &save); tok; tok = strtok_r(NULL, "/", &save)) {
        char *end = NULL;
        long v = strtol(tok, &end, 10);
        if (n >= max || !end || *end || v < 1 || v > LPV_MAX_GRID_DIM)
            return -1;
        out[n++] = (int)v;
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

/* The mods' rows, in the point's mods bit order (c, b, f, s). */
static const char *const MOD_KEYS[4] = {"central_transport", "normal_bins", "far_field", "scene_surfels"};

static int m_not_swept(const char *key)
{
    for (int m = 0; m < 4; ++m)
        if (strcmp(key, MOD_KEYS[m]) == 0)
            return 0;
    return 1;
}

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
        const lpv_field *f = acc_knob_row(tok);
        const char *key = f ? f->key : tok;
        if (strcmp(tok, "grid") == 0)
            r = kf->ngrid = parse_grid(v, kf->grid, 16);
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
        } else if (!f) {
            fprintf(stderr, "lpvd-accuracy: --knobs %s: not a swept knob\n", tok);
            return -1;
        } else if (strcmp(key, "iterations") == 0)
            r = kf->niter = parse_row_list(f, v, kf->iter, 16, 0);
        else if (strcmp(key, "rsm_size") == 0)
            r = kf->nrsm = parse_row_list(f, v, kf->rsm, 16, 0);
        else if (strcmp(key, "occlusion") == 0)
            r = kf->nocc = parse_row_list(f, v, kf->occ, 2, 0);
        else if (strcmp(key, "camera_surfel_step") == 0)
            r = kf->ncs = parse_row_list(f, v, kf->cs, 16, -1);
        else if (strcmp(key, "rsm_vpl_step") == 0)
            r = kf->nrs = parse_row_list(f, v, kf->rs, 16, -1);
        else if (strcmp(key, "lookup_step") == 0)
            r = kf->nls = parse_row_list(f, v, kf->ls, 16, 0);
        else if (lpv_acc_iv_knob_from_name(key) >= 0) {
            const int ik = lpv_acc_iv_knob_from_name(key);
            r = kf->niv[ik] = lpv_acc_iv_parse_list(ik, v, kf->iv[ik], 16);
        } else {
            r = -1;
            for (int m = 0; m < 4; ++m)
                if (strcmp(key, MOD_KEYS[m]) == 0)
                    r = kf->nsw[m] = parse_row_list(f, v, kf->sw[m], 2, 0);
            if (r < 0 && m_not_swept(key))
                fprintf(stderr, "lpvd-accuracy: --knobs %s: a knob of lpvd (%s) the sweep does not vary\n", tok, key);
        }
        if (r < 0)
            return -1;
    }
    return 0;
}

/* Whether the row with this key accepts the integer v. */
static int row_accepts(const char *key, int v)
{
    char tok[24];
    double out;
    snprintf(tok, sizeof tok, "%d", v);
    return acc_knob_value(lpv_field_by_key(key), tok, &out, NULL, 0) == 0;
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
            char *vpl = strchr(steps + 1, '/');
            if (vpl)
                *vpl++ = '\0';
            if (!vpl || parse_row_list(lpv_field_by_key("camera_surfel_step"), steps + 1, &st[0], 1, -1) != 1 ||
                parse_row_list(lpv_field_by_key("rsm_vpl_step"), vpl, &st[1], 1, -1) != 1) {
                snprintf(err, err_size, "@CAM/VPL expects two steps, each a number or auto");
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
        if (p.grid < 1 || p.grid > LPV_MAX_GRID_DIM || (p.iterations != 0 && !row_accepts("iterations", p.iterations)) ||
            !row_accepts("rsm_size", p.rsm) || !acc_technique_runs(&p))
            return -1;
        if (is_iv(&p)) /* the old form with technique iv: its RSM, the iv knobs' defaults */
            p = (point){.rsm = p.rsm, .technique = LPV_TECHNIQUE_ID_IV, .cstep = p.cstep, .rstep = p.rstep};
        pts[n++] = p;
    }
    if (n == 0)
        snprintf(err, err_size, "--points is empty");
    return n > 0 ? n : -1;
}
