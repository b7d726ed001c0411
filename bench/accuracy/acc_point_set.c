/*
 * acc_point_set.c - the points lpvd-accuracy runs: --points, --presets or
 * --quick, else the full factorial of the knobs' values (--knobs replaces a
 * knob's default list), filtered by --knobs, each at every swept lookup
 * step, plus the --features block. Parsing the knobs and points is
 * acc_knobs.c.
 */
#include <stdio.h>
#include <string.h>

#include "accuracy_internal.h"

static int in_list(int v, const int *list, int n)
{
    if (n == 0)
        return 1;
    for (int i = 0; i < n; ++i)
        if (list[i] == v)
            return 1;
    return 0;
}

int acc_point_set(acc_args *a, const lpv_settings *resolved, point *pts)
{
    char err[1024] = "";
    int npts = 0;
    if (a->features && !a->points_arg && !a->presets && !a->quick && !a->knobs) {
        /* --features alone: only the features block (its scenes by default
         * cornell-inside, courtyard, blinds); otherwise the block is added to
         * the chosen sweep points. */
        if (!a->scenes_given)
            a->scene_list = "cornell-inside,courtyard,blinds";
        goto add_features;
    }
    if (a->points_arg && a->presets) {
        fprintf(stderr, "lpvd-accuracy: --points and --presets both name the points; give one\n");
        return -1;
    }
    if (a->points_arg) {
        npts = acc_parse_points(a->points_arg, pts, MAX_POINTS, err, sizeof err);
        if (npts < 0) {
            fprintf(stderr, "lpvd-accuracy: --points: %s\n", err);
            return -1;
        }
    } else if (a->presets) {
        npts = acc_preset_points(pts);
    } else if (a->quick) {
        npts = (int)(sizeof QUICK / sizeof QUICK[0]);
        memcpy(pts, QUICK, sizeof QUICK);
    }
    knob_filter kf = {0};
    if (a->knobs && acc_parse_knobs(a->knobs, &kf) != 0) {
        fprintf(stderr, "lpvd-accuracy: --knobs expects e.g. grid=16/32,iterations=8,rsm=256,occlusion=on,"
                        "central=on,bins=off/on,far=on,surfels=on,technique=lpv/iv,iv_resolution=16/32,iv_points=8,"
                        "iv_rays=32/64,iv_bounces=1/3,iv_reprojection=on/off,iv_neighbours=6/8,camera_step=auto/1,"
                        "rsm_step=auto/1,lookup_step=1/2 (see --help)\n");
        return -1;
    }
    if (!a->points_arg && !a->presets && !a->quick) {
        /* the factorial: each knob's --knobs list, else its default values */
        const int *gl = kf.ngrid ? kf.grid : GRIDS, *il = kf.niter ? kf.iter : ITERS, *rl = kf.nrsm ? kf.rsm : RSMS,
                  *ol = kf.nocc ? kf.occ : OCCS;
        int ng = kf.ngrid ? kf.ngrid : (int)(sizeof GRIDS / sizeof *GRIDS),
            ni = kf.niter ? kf.niter : (int)(sizeof ITERS / sizeof *ITERS),
            nr = kf.nrsm ? kf.nrsm : (int)(sizeof RSMS / sizeof *RSMS),
            no = kf.nocc ? kf.nocc : (int)(sizeof OCCS / sizeof *OCCS);
        /* the techniques: --knobs technique=..., else lpv, or iv when only iv knobs are named */
        const int lpv_only[] = {LPV_TECHNIQUE_ID_LPV}, iv_only[] = {LPV_TECHNIQUE_ID_IV};
        const int implied_iv = !kf.ntech && acc_names_iv_knob(&kf);
        const int *tl = kf.ntech ? kf.tech : implied_iv ? iv_only : lpv_only, nt = kf.ntech ? kf.ntech : 1;
        int tech_lpv = 0, tech_iv = 0;
        for (int t = 0; t < nt; ++t)
            *(tl[t] == LPV_TECHNIQUE_ID_IV ? &tech_iv : &tech_lpv) = 1;
        if (implied_iv && acc_names_lpv_knob(&kf)) {
            fprintf(stderr, "lpvd-accuracy: --knobs names LPV and iv knobs: say which techniques (technique=lpv/iv)\n");
            return -1;
        }
        if (acc_names_iv_knob(&kf) && !tech_iv) {
            fprintf(stderr, "lpvd-accuracy: --knobs names iv knobs but technique= has no iv\n");
            return -1;
        }
        if (acc_names_lpv_knob(&kf) && !tech_lpv) {
            fprintf(stderr, "lpvd-accuracy: --knobs names LPV knobs (grid, iterations, occlusion, central, bins, "
                            "far, surfels) but technique= has neither lpv nor octree\n");
            return -1;
        }
        for (int t = 0; t < nt; ++t) {
            if (tl[t] == LPV_TECHNIQUE_ID_IV) { /* the iv knobs' factorial (unnamed: not set) x rsm */
                int idx[LPV_ACC_IV_KNOBS] = {0};
                for (int r = 0; r < nr; ++r)
                    for (int done = 0; !done && npts < MAX_POINTS;) {
                        point q = {.rsm = rl[r], .technique = LPV_TECHNIQUE_ID_IV};
                        for (int k = 0; k < LPV_ACC_IV_KNOBS; ++k)
                            q.iv.v[k] = kf.niv[k] ? kf.iv[k][idx[k]] : 0;
                        pts[npts++] = q;
                        int k = LPV_ACC_IV_KNOBS - 1; /* the next combination, the last knob fastest */
                        while (k >= 0 && ++idx[k] >= (kf.niv[k] ? kf.niv[k] : 1))
                            idx[k--] = 0;
                        done = k < 0;
                    }
                continue;
            }
            for (int g = 0; g < ng; ++g)
                for (int it = 0; it < ni; ++it)
                    for (int r = 0; r < nr; ++r)
                        for (int o = 0; o < no; ++o)
                            for (size_t m = 0; m < sizeof MODS / sizeof *MODS && npts < MAX_POINTS; ++m) {
                                point q = {gl[g], il[it], rl[r], ol[o], MODS[m]};
                                q.technique = (lpv_technique_id)tl[t];
                                if (!acc_technique_runs(&q))
                                    continue;
                                for (int c = 0; c < (kf.ncs ? kf.ncs : 1); ++c) /* the steps, when swept */
                                    for (int e = 0; e < (kf.nrs ? kf.nrs : 1) && npts < MAX_POINTS; ++e) {
                                        q.cstep = kf.ncs ? kf.cs[c] : 0;
                                        q.rstep = kf.nrs ? kf.rs[e] : 0;
                                        pts[npts++] = q;
                                    }
                            }
        }
    }
    if (a->knobs) {
        int k = 0;
        for (int i = 0; i < npts; ++i) {
            int keep = in_list(pts[i].rsm, kf.rsm, kf.nrsm) &&
                       in_list(pts[i].technique ? (int)pts[i].technique : LPV_TECHNIQUE_ID_LPV, kf.tech, kf.ntech);
            if (is_iv(&pts[i])) { /* its iv knobs as it will run them; the LPV's do not apply */
                for (int q = 0; q < LPV_ACC_IV_KNOBS; ++q)
                    keep = keep && in_list(pts[i].iv.v[q] ? pts[i].iv.v[q] : lpv_acc_iv_get(&resolved->iv, q),
                                           kf.iv[q], kf.niv[q]);
                if (keep)
                    pts[k++] = pts[i];
                continue;
            }
            keep = keep && in_list(pts[i].grid, kf.grid, kf.ngrid) && in_list(pts[i].iterations, kf.iter, kf.niter) &&
                   in_list(pts[i].occlusion, kf.occ, kf.nocc) && in_list(pts[i].cstep, kf.cs, kf.ncs) &&
                   in_list(pts[i].rstep, kf.rs, kf.nrs);
            for (int m = 0; m < 4; ++m)
                keep = keep && in_list((pts[i].mods >> m) & 1, kf.sw[m], kf.nsw[m]);
            if (keep)
                pts[k++] = pts[i];
        }
        npts = k;
        if (npts == 0) {
            fprintf(stderr, "lpvd-accuracy: --knobs %s leaves no point\n", a->knobs);
            return -1;
        }
    }
    if (kf.nls) { /* the lookup step: every point (of any point set) at each swept step */
        static point base[MAX_POINTS];
        memcpy(base, pts, (size_t)npts * sizeof *pts);
        const int nbase = npts;
        npts = 0;
        for (int i = 0; i < nbase; ++i)
            for (int l = 0; l < kf.nls && npts < MAX_POINTS; ++l) {
                pts[npts] = base[i];
                pts[npts++].lstep = kf.ls[l];
            }
    }
    for (int k = 0; k < LPV_ACC_IV_KNOBS; ++k) { /* a swept iv knob is not also a flag */
        int swept = kf.niv[k] > 0;
        for (int i = 0; i < npts; ++i)
            swept |= is_iv(&pts[i]) && pts[i].iv.v[k];
        if (swept && a->iv_flag_given[k]) {
            fprintf(stderr, "lpvd-accuracy: %s is swept by --knobs/--points; drop --iv-%s\n", lpv_acc_iv_knob_name(k),
                    lpv_acc_iv_knob_name(k) + 3);
            return -1;
        }
    }
add_features:
    if (a->features) {
        lpv_settings b;
        lpv_preset_settings(LPV_PRESET_BALANCED, &b);
        for (int k = 0; k < NFEATURES && npts < MAX_POINTS; ++k) {
            point fp = {b.grid_dims[0], b.lpv.iterations, b.rsm_size, b.lpv.occlusion == LPV_SWITCH_ON};
            fp.feat = 1;
            fp.cascades = FEATURES[k].cascades;
            fp.bounces = FEATURES[k].bounces;
            fp.damping = FEATURES[k].damping;
            snprintf(fp.label, sizeof fp.label, "%s", FEATURES[k].label);
            pts[npts++] = fp;
        }
    }
    return npts;
}
