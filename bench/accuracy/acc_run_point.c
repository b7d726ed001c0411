/*
 * acc_run_point.c - one point of the sweep on one scene: the engine set to
 * the point's settings, ticked (warm-up, then the timed ticks, every one a
 * full tick) for the median ms per tick and per stage, the frame compared
 * with the references (own bounces, converged light, baselines, regions,
 * the octree's own metric), its error image and frame written, and a line
 * on stderr. The result goes to c->results.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy_internal.h"
#include "image_io.h"
#include "tonemap.h"

/* The thesis' correctness metric (section 6.2) on the octree the GPU
 * computed: every level's accumulation read back into the oracle's octree,
 * each level above 0 against the mean of its children (techniques/octree/core/oracle_octree.h). */
static void octree_metric(lpv_engine *engine, lpv_octree_error *out)
{
    memset(out, 0, sizeof *out);
    char err[256];
    lpv_octree o = {0};
    if (lpv_octree_create(lpv_engine_grid(engine), 0, &o, err, sizeof err) != 0)
        return;
    size_t all = 0;
    for (int i = 0; i < o.levels; ++i)
        all += lpv_grid_cell_count(&o.level[i].grid);
    lpv_cell *levels = malloc(all * sizeof *levels);
    if (levels && lpv_engine_read_volumes(engine, LPV_GRID_ACCUMULATED, levels, all) == all) {
        size_t at = 0;
        for (int i = 0; i < o.levels; at += lpv_grid_cell_count(&o.level[i].grid), ++i)
            memcpy(o.level[i].acc, levels + at, lpv_grid_cell_count(&o.level[i].grid) * sizeof *levels);
        lpv_octree_measure(&o, out);
    }
    free(levels);
    lpv_octree_free(&o);
}

/* Techniques whose error images name them (lpv's and the presets' do not:
 * their names predate the others). */
static int named_file(lpv_technique_id t) { return t == LPV_TECHNIQUE_ID_OCTREE || t == LPV_TECHNIQUE_ID_PROBES; }

int acc_run_point(acc_run *c, const acc_scene_run *x, int p)
{
    const acc_args *a = c->a;
    int rc = 0;
    result *res = &c->results[c->nres];
    res->scene = x->s;
    res->p = c->pts[p];
    lpv_settings st = a->opt.settings;
    if (is_iv(&c->pts[p])) { /* its knobs over --iv-* and the defaults; the LPV's knobs do not apply */
        st.technique = LPV_TECHNIQUE_ID_IV;
        st.rsm_size = c->pts[p].rsm;
        lpv_acc_iv_apply(&c->pts[p].iv, &st.iv);
        goto settings_made;
    }
    st.grid_dims[0] = st.grid_dims[1] = st.grid_dims[2] = c->pts[p].grid;
    st.lpv.iterations = c->pts[p].iterations;
    st.rsm_size = c->pts[p].rsm;
    st.lpv.occlusion = c->pts[p].occlusion ? LPV_SWITCH_ON : LPV_SWITCH_OFF;
    st.lpv.central_transport = on_off(c->pts[p].mods & MOD_CENTRAL);
    st.lpv.normal_bins = on_off(c->pts[p].mods & MOD_BINS);
    st.lpv.far_field = on_off(c->pts[p].mods & MOD_FAR);
    st.scene_surfels = on_off(c->pts[p].mods & MOD_SURFELS);
    st.technique = lpv_of(c->pts[p].technique);
    st.camera_surfel_step = step_setting(c->pts[p].cstep, st.camera_surfel_step);
    st.rsm_vpl_step = step_setting(c->pts[p].rstep, st.rsm_vpl_step);
    if (c->pts[p].lstep)
        st.lookup_step = c->pts[p].lstep;
    if (c->pts[p].feat) {
        st.lpv.cascades = c->pts[p].cascades;
        if (c->pts[p].cascades > 1) {
            st.lpv.cascade_size = x->se->cascade_size;
            res->p.cascade_size = x->se->cascade_size;
        }
        st.lpv.bounces = c->pts[p].bounces ? LPV_SWITCH_ON : LPV_SWITCH_OFF;
        st.lpv.damping = c->pts[p].damping;
    }
settings_made:
    const lpv_engine_item item = {.settings = &st, .scene = x->scene, .view = x->view};
    if (lpv_engine_run_item(c->engine, &item, c->err, sizeof c->err) != 0) {
        fprintf(stderr, "lpvd-accuracy: %s\n", c->err);
        return 1;
    }
    {
        lpv_settings rs = st;
        lpv_settings_resolve(&rs);
        res->iv = lpv_acc_iv_of_settings(&rs.iv);
    }
    static double totals[MAX_TICKS], stage[NSTAGES][MAX_TICKS];
    for (int t = 0; t < a->warmup + a->ticks; ++t) {
        /* With the planner on, a tick on an unchanged scene serves the
         * cached volume and runs no stage: every timed tick is a full one. */
        lpv_engine_invalidate(c->engine);
        if (lpv_engine_tick(c->engine, c->err, sizeof c->err) != 0 ||
            lpv_engine_render(c->engine, LPV_TERMS_INDIRECT_ONLY, x->rgba, c->err, sizeof c->err) != 0) {
            fprintf(stderr, "lpvd-accuracy: %s\n", c->err);
            rc = 1;
            break;
        }
        if (t < a->warmup)
            continue;
        const lpv_engine_stats *es = lpv_engine_last_stats(c->engine);
        double total = 0.0;
        for (int k = 0; k < NSTAGES; ++k)
            stage[k][t - a->warmup] = 0.0;
        for (int j = 0; j < es->stage_count; ++j) {
            total += es->stages[j].gpu_ms;
            for (int k = 0; k < NSTAGES; ++k)
                if (strcmp(es->stages[j].name, STAGES[k]) == 0)
                    stage[k][t - a->warmup] = es->stages[j].gpu_ms;
        }
        totals[t - a->warmup] = total;
    }
    if (rc)
        return 1;
    res->ms_total = lpv_acc_median(totals, (size_t)a->ticks);
    for (int k = 0; k < NSTAGES; ++k)
        res->stage_ms[k] = lpv_acc_median(stage[k], (size_t)a->ticks);
    res->cascades_used = lpv_engine_cascade_count(c->engine);
    if (c->pts[p].technique == LPV_TECHNIQUE_ID_OCTREE)
        octree_metric(c->engine, &res->octree);
    if (lpv_acc_compare(x->rgba, x->ref, x->ref_se, x->view->width, x->view->height, &res->m) != 0)
        fprintf(stderr, "lpvd-accuracy: %s: warning: no pixel seen by both, or a black reference\n",
                x->se->name);
    res->rel_rmse_1b = res->m.rel_rmse;
    res->ref_bounces = 1;
    res->rel_rmse_multi = NAN;
    const float *cmp_ref = x->ref;
    if (x->mref) {
        lpv_acc_metrics mm;
        if (lpv_acc_compare(x->rgba, x->mref, x->mref_se, x->view->width, x->view->height, &mm) == 0) {
            res->rel_rmse_multi = mm.rel_rmse;
            if (c->pts[p].bounces) { /* bounces on models more than one bounce: its own reference */
                res->m = mm;
                res->ref_bounces = a->multi_bounces;
                cmp_ref = x->mref;
            }
        }
    }
    const int ivb = res->iv.v[LPV_ACC_IV_BOUNCES];
    /* an imperfect volume whose tail adds the bounces after its last (iv_tail, 3 or more bounces) models
     * every bounce: its own reference is converged light (ref_bounces 0) */
    const int iv_all = is_iv(&c->pts[p]) && ivb >= 3 && lpv_engine_settings(c->engine)->iv.tail == LPV_SWITCH_ON;
    if (is_iv(&c->pts[p]) && !iv_all && ivb > 1 && ivb <= LPV_IV_MAX_BOUNCES) { /* its own bounces' reference */
        const float *bimg = acc_bounce_reference(x->se, x->scene, x->view, x->rsrc, ivb, &x->bref[ivb], &x->bref_se[ivb]);
        lpv_acc_metrics mb;
        if (!bimg)
            return 1;
        if (lpv_acc_compare(x->rgba, bimg, x->bref_se[ivb], x->view->width, x->view->height, &mb) != 0)
            fprintf(stderr, "lpvd-accuracy: %s: warning: no pixel seen by both the %d-bounce reference and "
                            "lpvd\n", x->se->name, ivb);
        res->m = mb;
        res->ref_bounces = ivb;
        cmp_ref = bimg;
    }
    /* The score: against converged light (what a user sees), the
     * own-bounce figures beside it; the baselines, regions and
     * error image against converged light too. */
    res->own = res->m;
    if (lpv_acc_compare(x->rgba, x->cref, x->cref_se, x->view->width, x->view->height, &res->m) != 0)
        fprintf(stderr, "lpvd-accuracy: %s: warning: no pixel seen by both the converged reference and "
                        "lpvd\n", x->se->name);
    /* the probes' feedback carries every bounce too (techniques/probes/README.md) */
    if (iv_all || c->pts[p].technique == LPV_TECHNIQUE_ID_PROBES) {
        res->own = res->m;
        res->ref_bounces = 0;
    }
    res->at_noise = acc_at_ref_noise(res->m.rel_rmse, x->se->ref_noise2);
    cmp_ref = x->cref;
    const float *base_ref = x->cref;
    lpv_acc_baselines(x->rgba, base_ref, x->view->width, x->view->height, &res->black, &res->constant);
    for (int g = 0; g < LPV_ACC_REGIONS; ++g)
        res->region_share[g] = res->region_rmse[g] = res->region_ratio[g] = NAN;
    if (x->regions)
        lpv_acc_region_errors(x->rgba, base_ref, x->regions, x->view->width, x->view->height, res->region_share,
                              res->region_rmse, res->region_ratio);
    char ep[1400];
    if (c->pts[p].feat)
        snprintf(ep, sizeof ep, "%s/features-%s.png", x->sub, c->pts[p].label);
    else if (is_iv(&c->pts[p]))
        snprintf(ep, sizeof ep, "%s/iv-%s-r%d.png", x->sub, lpv_acc_iv_label(&res->iv, (char[96]){0}, 96),
                 c->pts[p].rsm);
    else
        snprintf(ep, sizeof ep, "%s/g%d-i%d-r%d-occ%s-%s%s%s%s.png", x->sub, c->pts[p].grid, c->pts[p].iterations,
                 c->pts[p].rsm, acc_occ_name(c->pts[p].occlusion), acc_mods_name(c->pts[p].mods, (char[5]){0}),
                 named_file(c->pts[p].technique) ? "-" : "",
                 named_file(c->pts[p].technique) ? acc_tech_name(c->pts[p].technique) : "",
                 acc_steps_text(&c->pts[p], 1, (char[48]){0}));
    if (lpv_acc_write_error_png(ep, x->rgba, cmp_ref, x->view->width, x->view->height, res->m.mean_ref, c->err,
                                sizeof c->err) != 0)
        fprintf(stderr, "lpvd-accuracy: %s\n", c->err);
    { /* lpvd's own frame beside it, tone-mapped like the reference's preview */
        size_t np = (size_t)x->view->width * (size_t)x->view->height;
        uint8_t *px = malloc(np * 4);
        char lp[1500];
        snprintf(lp, sizeof lp, "%.*s.lpvd.png", (int)strlen(ep) - 4, ep);
        if (px) {
            lpv_tonemap_rgba8(x->rgba, np, 1.0f, px);
            if (lpv_image_write_u8(lp, x->view->width, x->view->height, 4, px, c->err, sizeof c->err) != 0)
                fprintf(stderr, "lpvd-accuracy: %s\n", c->err);
            free(px);
        }
    }
    if (is_iv(&c->pts[p]))
        fprintf(stderr,
                "lpvd-accuracy: %s %d/%d: iv, resolution %d, points %d, rays %d, bounces %d, reprojection %s, "
                "neighbours %d, rsm %d: %.2f ms/tick (iv_points %.2f, iv_reproject %.2f, iv_resolve %.2f, "
                "iv_gather %.2f, shade %.2f), rel_rmse %.4f rel_bias %+.4f vs converged%s; %.4f %+.4f vs %s "
                "(%.4f vs 1)\n",
                x->se->name, p + 1, c->npts, res->iv.v[0], res->iv.v[1], res->iv.v[2], res->iv.v[3],
                acc_switch_name(res->iv.v[4]), res->iv.v[5], c->pts[p].rsm, res->ms_total,
                res->stage_ms[ST_IV_POINTS], res->stage_ms[ST_IV_REPROJECT], res->stage_ms[ST_IV_RESOLVE],
                res->stage_ms[ST_IV_GATHER], res->stage_ms[ST_SHADE], res->m.rel_rmse, res->m.rel_bias,
                res->at_noise ? " (at the reference's noise)" : "", res->own.rel_rmse, res->own.rel_bias,
                acc_own_text(res->ref_bounces, (char[32]){0}), res->rel_rmse_1b);
    else
        fprintf(stderr,
                "lpvd-accuracy: %s %d/%d: %s, grid %d, iterations %d, rsm %d, occlusion %s, mods %s%s: "
                "%.2f ms/tick, rel_rmse %.4f, rel_bias %+.4f vs converged%s (ref_noise2 %.4f); %.4f %+.4f vs "
                "%s%s%s\n",
                x->se->name, p + 1, c->npts, acc_tech_name(c->pts[p].technique), c->pts[p].grid, c->pts[p].iterations, c->pts[p].rsm,
                acc_occ_name(c->pts[p].occlusion), acc_mods_name(c->pts[p].mods, (char[5]){0}),
                acc_steps_text(&c->pts[p], 0, (char[48]){0}),
                res->ms_total, res->m.rel_rmse, res->m.rel_bias,
                res->at_noise ? " (at the reference's noise)" : "", x->se->ref_noise2, res->own.rel_rmse,
                res->own.rel_bias, acc_own_text(res->ref_bounces, (char[32]){0}), c->pts[p].feat ? "; " : "",
                c->pts[p].label);
    ++c->nres;
    return 0;
}
