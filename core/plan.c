/*
 * plan.c - the tick planner's rules (see plan.h). Each rule is one `if`
 * with the sentence that explains it; the order of the checks is the order
 * in which a reader would ask "why did this not run?".
 */
#include "plan.h"

#include <math.h>

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "cascades.h"
#include "lpv_shared.h"

static const char *const PASS_NAMES[LPV_PASS_COUNT] = {
    [LPV_PASS_RSM] = "rsm",         [LPV_PASS_EMISSIVE] = "emissive", [LPV_PASS_INJECT] = "inject",
    [LPV_PASS_GBUFFER] = "gbuffer", [LPV_PASS_GV] = "gv",             [LPV_PASS_PROPAGATE] = "propagate",
    [LPV_PASS_BOUNCE] = "bounce",   [LPV_PASS_GLOSSY] = "glossy",     [LPV_PASS_MEDIA] = "media",
    [LPV_PASS_IV_POINTS] = "iv_points", [LPV_PASS_IV_REPROJECT] = "iv_reproject",
    [LPV_PASS_IV_GATHER] = "iv_gather", [LPV_PASS_IV_AO] = "iv_ao",
    [LPV_PASS_TRANSLUCENT] = "translucent", [LPV_PASS_PROBES] = "probes",
};

const char *lpv_pass_name(lpv_pass_id id)
{
    return ((int)id >= 0 && id < LPV_PASS_COUNT) ? PASS_NAMES[id] : NULL;
}

static void say(char *dst, size_t n, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(dst, n, fmt, ap);
    va_end(ap);
}

static int plan_cascades_wanted(const lpv_settings *s, const lpv_plan_facts *f, char *reason, size_t n);

int lpv_plan_cascades(const lpv_settings *s, const lpv_plan_facts *f, char *reason, size_t n)
{
    int count = plan_cascades_wanted(s, f, reason, n);
    if (count > 1 && f->cascades_unfit) { /* the tick must still run: one grid, and the plan says why */
        say(reason, n, "%d cascades cannot be placed %.3g m from the origin (cells too fine for 32-bit floats): "
            "one grid", count, (double)f->scene_reach);
        return 1;
    }
    return count;
}

static int plan_cascades_wanted(const lpv_settings *s, const lpv_plan_facts *f, char *reason, size_t n)
{
    if (f->bounds_given) {
        say(reason, n, "the settings fix the grid bounds: one grid over them");
        return 1;
    }
    if (s->lpv.cascades > 0) {
        say(reason, n, "cascades = %d set explicitly", s->lpv.cascades);
        return s->lpv.cascades;
    }
    if (s->planner == LPV_SWITCH_OFF) {
        say(reason, n, "planner off: the default %d cascades", LPV_AUTO_CASCADES);
        return LPV_AUTO_CASCADES;
    }
    if (s->lpv.cascade_size > 0.0f) { /* an explicit size in m: the scene fits in it or not */
        if (f->scene_extent <= s->lpv.cascade_size) {
            say(reason, n, "the scene (%.3g m) fits in the finest cascade (%.3g m): one grid over the scene",
                (double)f->scene_extent, (double)s->lpv.cascade_size);
            return 1;
        }
        say(reason, n, "the scene (%.3g m) is larger than the finest cascade (%.3g m)", (double)f->scene_extent,
            (double)s->lpv.cascade_size);
        return LPV_AUTO_CASCADES;
    }
    /* cascade_size auto (relative to the scene): cascades pay where the camera
     * sees parts of the scene up close, i.e. stands inside it */
    if (!f->has_view) {
        say(reason, n, "no camera: one grid over the scene");
        return 1;
    }
    if (!f->camera_inside) {
        say(reason, n, "the camera stands outside the scene (%.3g m): one grid over all of it",
            (double)f->scene_extent);
        return 1;
    }
    /* the space the camera stands in (core/reach.h), whatever the bounds: a
     * tunnel under a wide terrain, a corridor of a level */
    if (f->view_chord > 0.0f && isfinite(f->view_chord) &&
        f->cascade_finest < LPV_CASCADE_AUTO_FRACTION * f->scene_extent * 0.999f) {
        say(reason, n, "the camera's space is %.3g m across (median chord) in a %.3g m scene: cascades from %.3g m",
            (double)f->view_chord, (double)f->scene_extent, (double)f->cascade_finest);
        return LPV_AUTO_CASCADES;
    }
    if (f->scene_extent < LPV_CASCADE_WIDE_RATIO * f->scene_shortest) {
        say(reason, n, "the camera is inside a scene of similar sides (%.3g m, shortest %.3g m): one grid over it",
            (double)f->scene_extent, (double)f->scene_shortest);
        return 1;
    }
    if (f->scene_cross > 0.0f && f->cascade_finest < LPV_CASCADE_AUTO_FRACTION * f->scene_extent * 0.999f) {
        say(reason, n, "the camera is inside a long scene (%.3g m, %.3g m across): cascades from %.3g m, cells "
            "about as wide as it", (double)f->scene_extent, (double)f->scene_cross, (double)f->cascade_finest);
        return LPV_AUTO_CASCADES;
    }
    say(reason, n, "the camera is inside a wide scene (%.3g m, shortest side %.3g m): cascades from a quarter of it",
        (double)f->scene_extent, (double)f->scene_shortest);
    return LPV_AUTO_CASCADES;
}

void lpv_plan_decide(lpv_plan *p, lpv_pass_id id, int run, const char *fmt, ...)
{
    p->pass[id].run = run;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(p->pass[id].reason, sizeof p->pass[id].reason, fmt, ap);
    va_end(ap);
}

int lpv_plan_needs_recompute(const lpv_settings *s, const lpv_plan_facts *f, const char *camera_use, char *why,
                           size_t n)
{
    if (s->planner == LPV_SWITCH_OFF)
        return say(why, n, "planner off: every tick recomputes"), 1;
    if (f->first_tick)
        return say(why, n, "first tick"), 1;
    if (f->scene_changed)
        return say(why, n, "the scene changed"), 1;
    if (f->lights_changed)
        return say(why, n, "the lights changed"), 1;
    if (f->settings_changed && f->settings_knob[0])
        return say(why, n, "the settings changed (%s)", f->settings_knob), 1;
    if (f->settings_changed)
        return say(why, n, "the settings changed"), 1;
    if (f->forced)
        return say(why, n, "recompute requested"), 1;
    if (f->placement_changed)
        return say(why, n, "the camera moved a cascade to a new cell"), 1;
    if (camera_use && f->camera_move_cells >= 1.0f)
        return say(why, n, "the camera moved %.2f cells and %s", (double)f->camera_move_cells, camera_use), 1;
    if (f->camera_move_cells > 0.0f)
        return say(why, n, "only the camera moved (%.2f cells, within a cell of every cascade): cached volume served",
                   (double)f->camera_move_cells), 0;
    return say(why, n, "nothing changed: cached volume served"), 0;
}

void lpv_plan_render_passes(const lpv_settings *s, const lpv_plan_facts *f, lpv_plan *p, int all)
{
    if (all)
        lpv_plan_decide(p, LPV_PASS_GLOSSY, 1, "planner off");
    else if (s->glossy == LPV_SWITCH_OFF)
        lpv_plan_decide(p, LPV_PASS_GLOSSY, 0, "glossy off");
    else if (!f->glossy_draws)
        lpv_plan_decide(p, LPV_PASS_GLOSSY, 0, "no material has roughness below %.2f", (double)s->glossy_roughness);
    else
        lpv_plan_decide(p, LPV_PASS_GLOSSY, 1, "%zu draws are glossy", f->glossy_draws);
    if (all)
        lpv_plan_decide(p, LPV_PASS_MEDIA, 1, "planner off");
    else if (s->media == LPV_SWITCH_OFF)
        lpv_plan_decide(p, LPV_PASS_MEDIA, 0, "media off");
    else if (!f->has_medium)
        lpv_plan_decide(p, LPV_PASS_MEDIA, 0, "no medium in the scene and no fog set");
    else
        lpv_plan_decide(p, LPV_PASS_MEDIA, 1, "the scene has a participating medium");
    /* BLEND surfaces need their own layer in a frame; the light's passes
     * take their alpha as coverage per texel without one */
    if (all)
        lpv_plan_decide(p, LPV_PASS_TRANSLUCENT, 1, "planner off");
    else if (!f->blend_draws)
        lpv_plan_decide(p, LPV_PASS_TRANSLUCENT, 0, "no material is alphaMode BLEND");
    else
        lpv_plan_decide(p, LPV_PASS_TRANSLUCENT, 1, "%zu draws are alphaMode BLEND", f->blend_draws);
}

void lpv_plan_rsm_pass(const lpv_plan_facts *f, lpv_plan *p, int all, char *area, size_t area_size)
{
    say(area, area_size, "area lights: %u emissive surfaces -> %zu samples", f->emissive_surfaces,
        f->area_light_samples);
    if (f->lights && f->area_light_samples)
        lpv_plan_decide(p, LPV_PASS_RSM, 1, "%u punctual lights; %s", f->lights, area);
    else if (f->area_light_samples)
        lpv_plan_decide(p, LPV_PASS_RSM, 1, "%s", area);
    else if (all || f->lights)
        lpv_plan_decide(p, LPV_PASS_RSM, 1, "%u punctual lights", f->lights);
    else
        lpv_plan_decide(p, LPV_PASS_RSM, 0, "no punctual lights");
}
