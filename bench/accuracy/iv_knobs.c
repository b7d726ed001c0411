/* iv_knobs.c - see iv_knobs.h. */
#include "iv_knobs.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "knob_rows.h"
#include "lpv_shared.h"

static const char *const NAMES[LPV_ACC_IV_KNOBS] = {
    [LPV_ACC_IV_RESOLUTION] = "iv_resolution", [LPV_ACC_IV_POINTS] = "iv_points",
    [LPV_ACC_IV_RAYS] = "iv_rays",             [LPV_ACC_IV_BOUNCES] = "iv_bounces",
    [LPV_ACC_IV_REPROJECTION] = "iv_reprojection", [LPV_ACC_IV_NEIGHBOURS] = "iv_neighbours",
};

const char *lpv_acc_iv_knob_name(int knob)
{
    return knob >= 0 && knob < LPV_ACC_IV_KNOBS ? NAMES[knob] : NULL;
}

int lpv_acc_iv_knob_from_name(const char *name)
{
    for (int k = 0; k < LPV_ACC_IV_KNOBS; ++k)
        if (strcmp(name, NAMES[k]) == 0)
            return k;
    return -1;
}

int lpv_acc_iv_parse_value(int knob, const char *s, int *out)
{
    if (knob < 0 || knob >= LPV_ACC_IV_KNOBS || !s)
        return -1;
    double v;
    const lpv_field *f = lpv_field_by_key(NAMES[knob]);
    if (acc_knob_value(f, s, &v, NULL, 0) != 0)
        return -1;
    if (f->kind == LPV_FIELD_SWITCH) {
        *out = v != 0.0 ? LPV_SWITCH_ON : LPV_SWITCH_OFF;
        return 0;
    }
    if (v < 1.0) /* 0 is "not set" in a point (lpv_acc_iv_knobs) */
        return -1;
    *out = (int)v;
    return 0;
}

int lpv_acc_iv_parse_list(int knob, const char *s, int *out, int max)
{
    char buf[256];
    if (!s || snprintf(buf, sizeof buf, "%s", s) >= (int)sizeof buf)
        return -1;
    int n = 0;
    for (char *save = NULL, *tok = strtok_r(buf, "/", &save); tok; tok = strtok_r(NULL, "/", &save)) {
        if (n >= max || lpv_acc_iv_parse_value(knob, tok, &out[n]) != 0)
            return -1;
        ++n;
    }
    return n > 0 ? n : -1;
}

int lpv_acc_iv_parse_point(const char *tok, lpv_acc_iv_knobs *out, char *err, size_t err_size)
{
    if (!tok || strncmp(tok, "iv", 2) != 0 || (tok[2] != '\0' && tok[2] != ':'))
        return 0;
    memset(out, 0, sizeof *out);
    const char *at = tok[2] ? tok + 3 : NULL;
    for (int k = 0; at; ++k) {
        const char *colon = strchr(at, ':');
        size_t len = colon ? (size_t)(colon - at) : strlen(at);
        if (k >= LPV_ACC_IV_KNOBS) {
            snprintf(err, err_size, "%s: at most %d fields after iv: RES:POINTS:RAYS:BOUNCES:REPROJ:NEIGHBOURS", tok,
                     LPV_ACC_IV_KNOBS);
            return -1;
        }
        char field[32];
        if (len >= sizeof field) {
            snprintf(err, err_size, "%s: field %d is too long", tok, k + 1);
            return -1;
        }
        memcpy(field, at, len);
        field[len] = '\0';
        if (len > 0 && strcmp(field, "-") != 0 && lpv_acc_iv_parse_value(k, field, &out->v[k]) != 0) {
            char want[96];
            snprintf(err, err_size, "%s: %s expects %s, not '%s'", tok, NAMES[k],
                     lpv_field_expect(lpv_field_by_key(NAMES[k]), want, sizeof want), field);
            return -1;
        }
        at = colon ? colon + 1 : NULL;
    }
    return 1;
}

int lpv_acc_iv_get(const lpv_iv_settings *s, int knob)
{
    switch ((lpv_acc_iv_knob)knob) {
    case LPV_ACC_IV_RESOLUTION: return s->resolution;
    case LPV_ACC_IV_POINTS: return s->points;
    case LPV_ACC_IV_RAYS: return s->rays;
    case LPV_ACC_IV_BOUNCES: return s->bounces;
    case LPV_ACC_IV_REPROJECTION: return (int)s->reprojection;
    case LPV_ACC_IV_NEIGHBOURS: return s->neighbours;
    case LPV_ACC_IV_KNOBS: break;
    }
    return 0;
}

void lpv_acc_iv_apply(const lpv_acc_iv_knobs *k, lpv_iv_settings *s)
{
    if (k->v[LPV_ACC_IV_RESOLUTION])
        s->resolution = k->v[LPV_ACC_IV_RESOLUTION];
    if (k->v[LPV_ACC_IV_POINTS])
        s->points = k->v[LPV_ACC_IV_POINTS];
    if (k->v[LPV_ACC_IV_RAYS])
        s->rays = k->v[LPV_ACC_IV_RAYS];
    if (k->v[LPV_ACC_IV_BOUNCES])
        s->bounces = k->v[LPV_ACC_IV_BOUNCES];
    if (k->v[LPV_ACC_IV_REPROJECTION])
        s->reprojection = (lpv_switch)k->v[LPV_ACC_IV_REPROJECTION];
    if (k->v[LPV_ACC_IV_NEIGHBOURS])
        s->neighbours = k->v[LPV_ACC_IV_NEIGHBOURS];
}

lpv_acc_iv_knobs lpv_acc_iv_of_settings(const lpv_iv_settings *s)
{
    lpv_acc_iv_knobs k;
    for (int i = 0; i < LPV_ACC_IV_KNOBS; ++i)
        k.v[i] = lpv_acc_iv_get(s, i);
    return k;
}

const char *lpv_acc_iv_label(const lpv_acc_iv_knobs *k, char *buf, size_t n)
{
    const int rp = k->v[LPV_ACC_IV_REPROJECTION];
    snprintf(buf, n, "res%d-pts%d-rays%d-b%d-reproj-%s-nb%d", k->v[LPV_ACC_IV_RESOLUTION], k->v[LPV_ACC_IV_POINTS],
             k->v[LPV_ACC_IV_RAYS], k->v[LPV_ACC_IV_BOUNCES],
             rp == LPV_SWITCH_ON ? "on" : rp == LPV_SWITCH_OFF ? "off" : "default", k->v[LPV_ACC_IV_NEIGHBOURS]);
    return buf;
}
