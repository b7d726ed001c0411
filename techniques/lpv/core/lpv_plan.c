/*
 * lpv_plan.c - the cascaded LPV's plan (also the octree's): which of its
 * passes a tick runs and why, from the shared rules of core/plan.h.
 */
#include "lpv_rules.h"

#include <stdio.h>
#include <string.h>

#include "cascades.h"
#include "lpv_shared.h"

void lpv_plan_make_lpv(const lpv_settings *s, const lpv_plan_facts *f, lpv_plan *p)
{
    memset(p, 0, sizeof *p);
    const int all = s->planner == LPV_SWITCH_OFF;
    p->cascades = lpv_plan_cascades(s, f, p->cascades_reason, sizeof p->cascades_reason);
    const int in_use = lpv_cascades_count(s, p->cascades);
    if (in_use > p->cascades) {
        size_t len = strlen(p->cascades_reason);
        snprintf(p->cascades_reason + len, sizeof p->cascades_reason - len, "; far field: %d coarser levels",
            in_use - p->cascades);
        p->cascades = in_use;
    }

    p->iterations_warning = lpv_settings_iterations_note(s, p->iterations_reason, sizeof p->iterations_reason);

    lpv_plan_render_passes(s, f, p, all);

    const int occlusion = s->lpv.occlusion == LPV_SWITCH_ON;
    const int gv = occlusion && (all || f->occluder_triangles > 0);
    const int camera_in_gv = gv && f->has_view;
    p->recompute = lpv_plan_needs_recompute(s, f, camera_in_gv ? "its surfels feed the geometry volume" : NULL,
                                   p->recompute_reason, sizeof p->recompute_reason);
    for (int i = LPV_PASS_IV_POINTS; i <= LPV_PASS_IV_AO; ++i)
        lpv_plan_decide(p, (lpv_pass_id)i, 0, "the imperfect volume's (technique " LPV_TECHNIQUE_IV ")");
    lpv_plan_decide(p, LPV_PASS_PROBES, 0, "the probes' (technique " LPV_TECHNIQUE_PROBES ")");
    if (!p->recompute) {
        for (int i = 0; i <= LPV_PASS_BOUNCE; ++i)
            lpv_plan_decide(p, (lpv_pass_id)i, 0, "%s", p->recompute_reason);
        return;
    }

    char area[LPV_PLAN_REASON_MAX];
    lpv_plan_rsm_pass(f, p, all, area, sizeof area);
    /* Not a saving but correctness, so also with the planner off: emitters
     * that light the scene directly must not enter the LPV a second time. */
    if (f->area_light_samples)
        lpv_plan_decide(p, LPV_PASS_EMISSIVE, 0, "%s light the scene directly (their VPLs would count it twice)", area);
    else if (all || f->emissive_vpls)
        lpv_plan_decide(p, LPV_PASS_EMISSIVE, 1, "%zu emissive VPLs%s", f->emissive_vpls,
               s->area_lights == LPV_SWITCH_OFF && f->emissive_vpls ? " (area lights off)" : "");
    else
        lpv_plan_decide(p, LPV_PASS_EMISSIVE, 0, "no emissive surfaces");
    const int inject = all || p->pass[LPV_PASS_RSM].run || p->pass[LPV_PASS_EMISSIVE].run;
    if (inject)
        lpv_plan_decide(p, LPV_PASS_INJECT, 1, "%d cascades receive the VPLs", p->cascades);
    else
        lpv_plan_decide(p, LPV_PASS_INJECT, 0, "no light sources");

    if (!occlusion)
        lpv_plan_decide(p, LPV_PASS_GV, 0, "occlusion off");
    else if (!gv)
        lpv_plan_decide(p, LPV_PASS_GV, 0, "no occluders (no non-emissive triangles)");
    else
        lpv_plan_decide(p, LPV_PASS_GV, 1, "%zu occluder triangles", f->occluder_triangles);
    if (!f->has_view)
        lpv_plan_decide(p, LPV_PASS_GBUFFER, 0, "no camera");
    else if (!gv)
        lpv_plan_decide(p, LPV_PASS_GBUFFER, 0, "the geometry volume does not run (render draws its own)");
    else
        lpv_plan_decide(p, LPV_PASS_GBUFFER, 1, "camera surfels for the geometry volume");

    if (s->lpv.iterations == 0)
        lpv_plan_decide(p, LPV_PASS_PROPAGATE, 0, "iterations = 0");
    else if (!inject)
        lpv_plan_decide(p, LPV_PASS_PROPAGATE, 0, "nothing injected");
    else
        lpv_plan_decide(p, LPV_PASS_PROPAGATE, 1, "%d steps in %d cascades", s->lpv.iterations, p->cascades);

    if (s->lpv.bounces != LPV_SWITCH_ON)
        lpv_plan_decide(p, LPV_PASS_BOUNCE, 0, "bounces off");
    else if (!p->pass[LPV_PASS_GV].run)
        lpv_plan_decide(p, LPV_PASS_BOUNCE, 0, "needs the geometry volume, which does not run");
    else if (!p->pass[LPV_PASS_PROPAGATE].run)
        lpv_plan_decide(p, LPV_PASS_BOUNCE, 0, "propagation does not run");
    else
        lpv_plan_decide(p, LPV_PASS_BOUNCE, 1, "bounces on, intensity %.2f", (double)s->lpv.bounce_intensity);

    p->consumes.emissive_vpls = p->pass[LPV_PASS_EMISSIVE].run;
    p->consumes.surfels = p->pass[LPV_PASS_GV].run;
    p->consumes.camera_surfels = p->pass[LPV_PASS_GV].run && p->pass[LPV_PASS_GBUFFER].run;
}


void lpv_plan_grid_reach_note(const lpv_settings *s, lpv_plan *p)
{
    int shortest = s->grid_dims[0];
    for (int i = 1; i < 3; ++i)
        shortest = s->grid_dims[i] < shortest ? s->grid_dims[i] : shortest;
    if (shortest <= LPV_GRID_REACH_CELLS)
        return;
    size_t len = strlen(p->iterations_reason);
    snprintf(p->iterations_reason + len, sizeof p->iterations_reason - len,
             "%sgrid %dx%dx%d is finer than %d cells on every axis: the LPV's transport spreads light sideways each "
             "step, so finer cells carry it fewer metres and the frame gets darker (docs/accuracy.md, \"Knobs that "
             "never make it worse\"); technique iv or grid %d give better light",
             len ? "; " : "", s->grid_dims[0], s->grid_dims[1], s->grid_dims[2], LPV_GRID_REACH_CELLS,
             LPV_GRID_REACH_CELLS);
    p->iterations_warning = 1;
}
