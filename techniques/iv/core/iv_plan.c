/*
 * iv_plan.c - the imperfect volume's plan: the shared producers it reads
 * (the RSMs for shadows, the G-buffer for reprojection) and its passes, from
 * the shared rules of core/plan.h.
 */
#include "iv_rules.h"

#include <stdio.h>
#include <string.h>

#include "lpv_shared.h"

void lpv_plan_make_iv(const lpv_settings *s, const lpv_plan_facts *f, const lpv_iv_point_stats *cloud,
                      lpv_plan *p)
{
    memset(p, 0, sizeof *p);
    const int all = s->planner == LPV_SWITCH_OFF;
    p->cascades = 1;
    snprintf(p->cascades_reason, sizeof p->cascades_reason, "%s: one volume, %d voxels along the scene's longest side",
        LPV_TECHNIQUE_IV, s->iv.resolution);
    lpv_plan_render_passes(s, f, p, all);
    const int reproject = s->iv.reprojection == LPV_SWITCH_ON && f->has_view;
    p->recompute = lpv_plan_needs_recompute(s, f, reproject ? "its visible points refine the imperfect volume" : NULL,
                                   p->recompute_reason, sizeof p->recompute_reason);
    for (int i = 0; i <= LPV_PASS_BOUNCE; ++i)
        if (i != LPV_PASS_RSM && i != LPV_PASS_GBUFFER)
            lpv_plan_decide(p, (lpv_pass_id)i, 0, "the LPV's (technique " LPV_TECHNIQUE_IV " gathers by ray marching)");
    lpv_plan_decide(p, LPV_PASS_PROBES, 0, "the probes' (technique " LPV_TECHNIQUE_PROBES ")");
    if (!p->recompute) {
        for (int i = 0; i < LPV_PASS_COUNT; ++i)
            if (i != LPV_PASS_GLOSSY && i != LPV_PASS_MEDIA && i != LPV_PASS_TRANSLUCENT)
                lpv_plan_decide(p, (lpv_pass_id)i, 0, "%s", p->recompute_reason);
        return;
    }
    char area[LPV_PLAN_REASON_MAX];
    lpv_plan_rsm_pass(f, p, all, area, sizeof area);
    if (p->pass[LPV_PASS_RSM].run) {
        size_t len = strlen(p->pass[LPV_PASS_RSM].reason);
        snprintf(p->pass[LPV_PASS_RSM].reason + len, sizeof p->pass[LPV_PASS_RSM].reason - len,
            " (shadows of the points' direct light)");
    }
    if (!cloud->points)
        lpv_plan_decide(p, LPV_PASS_IV_POINTS, 0, "no triangles to sample");
    else if (cloud->budget_cut)
        lpv_plan_decide(p, LPV_PASS_IV_POINTS, 1, "%zu points (%d per piece: the %d-point budget cut %d)", cloud->points,
               cloud->points_per_piece, s->iv.max_points, s->iv.points);
    else
        lpv_plan_decide(p, LPV_PASS_IV_POINTS, 1, "%zu points, %d per triangle piece", cloud->points, cloud->points_per_piece);
    if (s->iv.reprojection == LPV_SWITCH_OFF)
        lpv_plan_decide(p, LPV_PASS_IV_REPROJECT, 0, "reprojection off");
    else if (!f->has_view)
        lpv_plan_decide(p, LPV_PASS_IV_REPROJECT, 0, "reprojection skipped: no camera");
    else
        lpv_plan_decide(p, LPV_PASS_IV_REPROJECT, 1, "the camera's visible points refine the volume");
    if (p->pass[LPV_PASS_IV_REPROJECT].run)
        lpv_plan_decide(p, LPV_PASS_GBUFFER, 1, "the camera's visible points for reprojection");
    else
        lpv_plan_decide(p, LPV_PASS_GBUFFER, 0, "reprojection does not run (render draws its own)");
    const int filled = p->pass[LPV_PASS_IV_POINTS].run || p->pass[LPV_PASS_IV_REPROJECT].run;
    const int lit = all || p->pass[LPV_PASS_RSM].run || (f->emissive_surfaces && !f->area_light_samples);
    if (!filled)
        lpv_plan_decide(p, LPV_PASS_IV_GATHER, 0, "the volume is empty");
    else if (!lit)
        lpv_plan_decide(p, LPV_PASS_IV_GATHER, 0, "no light sources");
    else
        lpv_plan_decide(p, LPV_PASS_IV_GATHER, 1, "%s: %d bounces requested, %d rays per voxel%s", LPV_TECHNIQUE_IV,
               s->iv.bounces, s->iv.rays,
               s->iv.tail != LPV_SWITCH_ON ? ", no tail (iv_tail off)"
               : s->iv.bounces < 3         ? ", no tail (fewer than 3 bounces set no ratio)"
                                           : ", the bounces after them as the series they set");
    if (s->iv.ao != LPV_SWITCH_ON)
        lpv_plan_decide(p, LPV_PASS_IV_AO, 0, "ambient occlusion off");
    else if (!filled)
        lpv_plan_decide(p, LPV_PASS_IV_AO, 0, "the volume is empty");
    else
        lpv_plan_decide(p, LPV_PASS_IV_AO, 1, "ambient occlusion on, %d rays per voxel", s->iv.rays);
}

