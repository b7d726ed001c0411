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
#include "iv_points.h"
#include "lpv_shared.h"

static const char *const PASS_NAMES[LPV_PASS_COUNT] = {
    [LPV_PASS_RSM] = "rsm",         [LPV_PASS_EMISSIVE] = "emissive", [LPV_PASS_INJECT] = "inject",
    [LPV_PASS_GBUFFER] = "gbuffer", [LPV_PASS_GV] = "gv",             [LPV_PASS_PROPAGATE] = "propagate",
    [LPV_PASS_BOUNCE] = "bounce",   [LPV_PASS_GLOSSY] = "glossy",     [LPV_PASS_MEDIA] = "media",
    [LPV_PASS_IV_POINTS] = "iv_points", [LPV_PASS_IV_REPROJECT] = "iv_reproject",
    [LPV_PASS_IV_GATHER] = "iv_gather", [LPV_PASS_IV_AO] = "iv_ao",
    [LPV_PASS_TRANSLUCENT] = "translucent",
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
        say(reason, n, "planner off: the default %d cascades", LPV_DEFAULT_CASCADES);
        return LPV_DEFAULT_CASCADES;
    }
    if (s->lpv.cascade_size > 0.0f) { /* an explicit size in m: the scene fits in it or not */
        if (f->scene_extent <= s->lpv.cascade_size) {
            say(reason, n, "the scene (%.3g m) fits in the finest cascade (%.3g m): one grid over the scene",
                (double)f->scene_extent, (double)s->lpv.cascade_size);
            return 1;
        }
        say(reason, n, "the scene (%.3g m) is larger than the finest cascade (%.3g m)", (double)f->scene_extent,
            (double)s->lpv.cascade_size);
        return LPV_DEFAULT_CASCADES;
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
        return LPV_DEFAULT_CASCADES;
    }
    if (f->scene_extent < LPV_CASCADE_WIDE_RATIO * f->scene_shortest) {
        say(reason, n, "the camera is inside a scene of similar sides (%.3g m, shortest %.3g m): one grid over it",
            (double)f->scene_extent, (double)f->scene_shortest);
        return 1;
    }
    if (f->scene_cross > 0.0f && f->cascade_finest < LPV_CASCADE_AUTO_FRACTION * f->scene_extent * 0.999f) {
        say(reason, n, "the camera is inside a long scene (%.3g m, %.3g m across): cascades from %.3g m, cells "
            "about as wide as it", (double)f->scene_extent, (double)f->scene_cross, (double)f->cascade_finest);
        return LPV_DEFAULT_CASCADES;
    }
    say(reason, n, "the camera is inside a wide scene (%.3g m, shortest side %.3g m): cascades from a quarter of it",
        (double)f->scene_extent, (double)f->scene_shortest);
    return LPV_DEFAULT_CASCADES;
}

/* Sets pass id to run (1) or skip (0) with a reason. */
static void decide(lpv_plan *p, lpv_pass_id id, int run, const char *fmt, ...)
{
    p->pass[id].run = run;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(p->pass[id].reason, sizeof p->pass[id].reason, fmt, ap);
    va_end(ap);
}

/* Whether the tick must recompute the volume, with the reason. */
/* camera_use: what the camera's view feeds (a recompute when it moves a
 * cell), NULL when nothing computed depends on it. */
static int needs_recompute(const lpv_settings *s, const lpv_plan_facts *f, const char *camera_use, char *why,
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

/* Render-time passes: decided first, they do not depend on a recompute. */
static void render_passes(const lpv_settings *s, const lpv_plan_facts *f, lpv_plan *p, int all)
{
    if (all)
        decide(p, LPV_PASS_GLOSSY, 1, "planner off");
    else if (s->glossy == LPV_SWITCH_OFF)
        decide(p, LPV_PASS_GLOSSY, 0, "glossy off");
    else if (!f->glossy_draws)
        decide(p, LPV_PASS_GLOSSY, 0, "no material has roughness below %.2f", (double)s->glossy_roughness);
    else
        decide(p, LPV_PASS_GLOSSY, 1, "%zu draws are glossy", f->glossy_draws);
    if (all)
        decide(p, LPV_PASS_MEDIA, 1, "planner off");
    else if (s->media == LPV_SWITCH_OFF)
        decide(p, LPV_PASS_MEDIA, 0, "media off");
    else if (!f->has_medium)
        decide(p, LPV_PASS_MEDIA, 0, "no medium in the scene and no fog set");
    else
        decide(p, LPV_PASS_MEDIA, 1, "the scene has a participating medium");
    /* BLEND surfaces need their own layer in a frame; the light's passes
     * take their alpha as coverage per texel without one */
    if (all)
        decide(p, LPV_PASS_TRANSLUCENT, 1, "planner off");
    else if (!f->blend_draws)
        decide(p, LPV_PASS_TRANSLUCENT, 0, "no material is alphaMode BLEND");
    else
        decide(p, LPV_PASS_TRANSLUCENT, 1, "%zu draws are alphaMode BLEND", f->blend_draws);
}

/* The lights' RSMs (the LPV's VPLs and surfels, the imperfect volume's
 * shadows); area: the area lights' summary, for other reasons. */
static void rsm_pass(const lpv_plan_facts *f, lpv_plan *p, int all, char *area, size_t area_size)
{
    say(area, area_size, "area lights: %u emissive surfaces -> %zu samples", f->emissive_surfaces,
        f->area_light_samples);
    if (f->lights && f->area_light_samples)
        decide(p, LPV_PASS_RSM, 1, "%u punctual lights; %s", f->lights, area);
    else if (f->area_light_samples)
        decide(p, LPV_PASS_RSM, 1, "%s", area);
    else if (all || f->lights)
        decide(p, LPV_PASS_RSM, 1, "%u punctual lights", f->lights);
    else
        decide(p, LPV_PASS_RSM, 0, "no punctual lights");
}

void lpv_plan_make(const lpv_settings *s, const lpv_plan_facts *f, lpv_plan *p)
{
    memset(p, 0, sizeof *p);
    const int all = s->planner == LPV_SWITCH_OFF;
    p->cascades = lpv_plan_cascades(s, f, p->cascades_reason, sizeof p->cascades_reason);
    const int in_use = lpv_cascades_count(s, p->cascades);
    if (in_use > p->cascades) {
        size_t len = strlen(p->cascades_reason);
        say(p->cascades_reason + len, sizeof p->cascades_reason - len, "; far field: %d coarser levels",
            in_use - p->cascades);
        p->cascades = in_use;
    }

    p->iterations_warning = lpv_settings_iterations_note(s, p->iterations_reason, sizeof p->iterations_reason);

    render_passes(s, f, p, all);

    const int occlusion = s->lpv.occlusion == LPV_SWITCH_ON;
    const int gv = occlusion && (all || f->occluder_triangles > 0);
    const int camera_in_gv = gv && f->has_view;
    p->recompute = needs_recompute(s, f, camera_in_gv ? "its surfels feed the geometry volume" : NULL,
                                   p->recompute_reason, sizeof p->recompute_reason);
    for (int i = LPV_PASS_IV_POINTS; i <= LPV_PASS_IV_AO; ++i)
        decide(p, (lpv_pass_id)i, 0, "the imperfect volume's (technique " LPV_TECHNIQUE_IV ")");
    if (!p->recompute) {
        for (int i = 0; i <= LPV_PASS_BOUNCE; ++i)
            decide(p, (lpv_pass_id)i, 0, "%s", p->recompute_reason);
        return;
    }

    char area[LPV_PLAN_REASON_MAX];
    rsm_pass(f, p, all, area, sizeof area);
    /* Not a saving but correctness, so also with the planner off: emitters
     * that light the scene directly must not enter the LPV a second time. */
    if (f->area_light_samples)
        decide(p, LPV_PASS_EMISSIVE, 0, "%s light the scene directly (their VPLs would count it twice)", area);
    else if (all || f->emissive_vpls)
        decide(p, LPV_PASS_EMISSIVE, 1, "%zu emissive VPLs%s", f->emissive_vpls,
               s->area_lights == LPV_SWITCH_OFF && f->emissive_vpls ? " (area lights off)" : "");
    else
        decide(p, LPV_PASS_EMISSIVE, 0, "no emissive surfaces");
    const int inject = all || p->pass[LPV_PASS_RSM].run || p->pass[LPV_PASS_EMISSIVE].run;
    if (inject)
        decide(p, LPV_PASS_INJECT, 1, "%d cascades receive the VPLs", p->cascades);
    else
        decide(p, LPV_PASS_INJECT, 0, "no light sources");

    if (!occlusion)
        decide(p, LPV_PASS_GV, 0, "occlusion off");
    else if (!gv)
        decide(p, LPV_PASS_GV, 0, "no occluders (no non-emissive triangles)");
    else
        decide(p, LPV_PASS_GV, 1, "%zu occluder triangles", f->occluder_triangles);
    if (!f->has_view)
        decide(p, LPV_PASS_GBUFFER, 0, "no camera");
    else if (!gv)
        decide(p, LPV_PASS_GBUFFER, 0, "the geometry volume does not run (render draws its own)");
    else
        decide(p, LPV_PASS_GBUFFER, 1, "camera surfels for the geometry volume");

    if (s->lpv.iterations == 0)
        decide(p, LPV_PASS_PROPAGATE, 0, "iterations = 0");
    else if (!inject)
        decide(p, LPV_PASS_PROPAGATE, 0, "nothing injected");
    else
        decide(p, LPV_PASS_PROPAGATE, 1, "%d steps in %d cascades", s->lpv.iterations, p->cascades);

    if (s->lpv.bounces != LPV_SWITCH_ON)
        decide(p, LPV_PASS_BOUNCE, 0, "bounces off");
    else if (!p->pass[LPV_PASS_GV].run)
        decide(p, LPV_PASS_BOUNCE, 0, "needs the geometry volume, which does not run");
    else if (!p->pass[LPV_PASS_PROPAGATE].run)
        decide(p, LPV_PASS_BOUNCE, 0, "propagation does not run");
    else
        decide(p, LPV_PASS_BOUNCE, 1, "bounces on, intensity %.2f", (double)s->lpv.bounce_intensity);

    p->consumes.emissive_vpls = p->pass[LPV_PASS_EMISSIVE].run;
    p->consumes.surfels = p->pass[LPV_PASS_GV].run;
    p->consumes.camera_surfels = p->pass[LPV_PASS_GV].run && p->pass[LPV_PASS_GBUFFER].run;
}

void lpv_plan_make_iv(const lpv_settings *s, const lpv_plan_facts *f, lpv_plan *p)
{
    memset(p, 0, sizeof *p);
    const int all = s->planner == LPV_SWITCH_OFF;
    p->cascades = 1;
    say(p->cascades_reason, sizeof p->cascades_reason, "%s: one volume, %d voxels along the scene's longest side",
        LPV_TECHNIQUE_IV, s->iv.resolution);
    render_passes(s, f, p, all);
    const int reproject = s->iv.reprojection == LPV_SWITCH_ON && f->has_view;
    p->recompute = needs_recompute(s, f, reproject ? "its visible points refine the imperfect volume" : NULL,
                                   p->recompute_reason, sizeof p->recompute_reason);
    for (int i = 0; i <= LPV_PASS_BOUNCE; ++i)
        if (i != LPV_PASS_RSM && i != LPV_PASS_GBUFFER)
            decide(p, (lpv_pass_id)i, 0, "the LPV's (technique " LPV_TECHNIQUE_IV " gathers by ray marching)");
    if (!p->recompute) {
        for (int i = 0; i < LPV_PASS_COUNT; ++i)
            if (i != LPV_PASS_GLOSSY && i != LPV_PASS_MEDIA && i != LPV_PASS_TRANSLUCENT)
                decide(p, (lpv_pass_id)i, 0, "%s", p->recompute_reason);
        return;
    }
    char area[LPV_PLAN_REASON_MAX];
    rsm_pass(f, p, all, area, sizeof area);
    if (p->pass[LPV_PASS_RSM].run) {
        size_t len = strlen(p->pass[LPV_PASS_RSM].reason);
        say(p->pass[LPV_PASS_RSM].reason + len, sizeof p->pass[LPV_PASS_RSM].reason - len,
            " (shadows of the points' direct light)");
    }
    if (!f->iv_points)
        decide(p, LPV_PASS_IV_POINTS, 0, "no triangles to sample");
    else if (f->iv_budget_cut)
        decide(p, LPV_PASS_IV_POINTS, 1, "%zu points (%d per piece: the %d-point budget cut %d)", f->iv_points,
               f->iv_points_per_piece, s->iv.max_points, s->iv.points);
    else
        decide(p, LPV_PASS_IV_POINTS, 1, "%zu points, %d per triangle piece", f->iv_points, f->iv_points_per_piece);
    if (s->iv.reprojection == LPV_SWITCH_OFF)
        decide(p, LPV_PASS_IV_REPROJECT, 0, "reprojection off");
    else if (!f->has_view)
        decide(p, LPV_PASS_IV_REPROJECT, 0, "reprojection skipped: no camera");
    else
        decide(p, LPV_PASS_IV_REPROJECT, 1, "the camera's visible points refine the volume");
    if (p->pass[LPV_PASS_IV_REPROJECT].run)
        decide(p, LPV_PASS_GBUFFER, 1, "the camera's visible points for reprojection");
    else
        decide(p, LPV_PASS_GBUFFER, 0, "reprojection does not run (render draws its own)");
    const int filled = p->pass[LPV_PASS_IV_POINTS].run || p->pass[LPV_PASS_IV_REPROJECT].run;
    const int lit = all || p->pass[LPV_PASS_RSM].run || (f->emissive_surfaces && !f->area_light_samples);
    if (!filled)
        decide(p, LPV_PASS_IV_GATHER, 0, "the volume is empty");
    else if (!lit)
        decide(p, LPV_PASS_IV_GATHER, 0, "no light sources");
    else
        decide(p, LPV_PASS_IV_GATHER, 1, "%s: %d bounces requested, %d rays per voxel%s", LPV_TECHNIQUE_IV,
               s->iv.bounces, s->iv.rays,
               s->iv.tail != LPV_SWITCH_ON ? ", no tail (iv_tail off)"
               : s->iv.bounces < 3         ? ", no tail (fewer than 3 bounces set no ratio)"
                                           : ", the bounces after them as the series they set");
    if (s->iv.ao != LPV_SWITCH_ON)
        decide(p, LPV_PASS_IV_AO, 0, "ambient occlusion off");
    else if (!filled)
        decide(p, LPV_PASS_IV_AO, 0, "the volume is empty");
    else
        decide(p, LPV_PASS_IV_AO, 1, "ambient occlusion on, %d rays per voxel", s->iv.rays);
}

lpv_technique_id lpv_technique_choose(const lpv_settings *s, const lpv_plan_facts *f, char *why, size_t n)
{
    const lpv_technique_id asked = s->technique == LPV_TECHNIQUE_ID_DEFAULT ? LPV_TECHNIQUE_ID_DEFAULT_IS : s->technique;
    if (asked != LPV_TECHNIQUE_ID_AUTO) { /* also when the default is auto: the rules below */
        say(why, n, "requested");
        return asked;
    }
    /* The rules follow the front of the accuracy set against converged light
     * (docs/accuracy.md, "Which technique by default (issue 30)"): the
     * imperfect volume is the most accurate on every scene whose cross-section
     * its voxels resolve, the cascaded LPV the cheaper, and the better where
     * they do not (a tunnel); the octree is best on none. */
    if (s->preset == LPV_PRESET_FAST) {
        say(why, n, "auto: preset fast asks for the cheapest technique, the cascaded LPV");
        return LPV_TECHNIQUE_ID_LPV;
    }
    if (f && f->occluder_triangles > LPV_AUTO_IV_MAX_TRIANGLES) {
        say(why, n, "auto: %zu triangles (over %d): the cascaded LPV; the imperfect volume's cloud takes seconds",
            f->occluder_triangles, LPV_AUTO_IV_MAX_TRIANGLES);
        return LPV_TECHNIQUE_ID_LPV;
    }
    const int res = s->iv.resolution > 0 ? s->iv.resolution : LPV_IV_DEFAULT_RESOLUTION;
    if (f && f->scene_extent > 0.0f && f->scene_middle > 0.0f && !f->bounds_given) {
        /* the voxels iv would place with these settings (lpv_iv_place: over
         * where light can go, finer in long scenes from the free path), and
         * the middle side of that box */
        const int lit = f->lit_max[0] > f->lit_min[0];
        float side[3];
        if (lit)
            lpv_box_sides(f->lit_min, f->lit_max, side);
        const float ext[3] = {lit ? side[2] : f->scene_extent, lit ? side[1] : f->scene_middle,
                              lit ? side[0] : (f->scene_shortest > 0.0f ? f->scene_shortest : 0.0f)};
        const float origin[3] = {0.0f, 0.0f, 0.0f};
        lpv_settings placed = *s;
        placed.iv.resolution = res;
        lpv_grid g;
        const float voxel = lpv_iv_place(&placed, origin, ext, lit ? f->lit_free_path : f->free_path, &g) == 0
                                ? g.cell_size
                                : ext[0] / (float)res;
        const float across = ext[1] / voxel;
        const char *whose = lit ? "lit space" : "scene";
        if (across < LPV_AUTO_IV_MIN_VOXELS_ACROSS) {
            say(why, n, "auto: the cascaded LPV: iv's %.3g m voxels (iv_resolution %d) fit %.2g times across the %s "
                "(%.3g m), under %.3g", voxel, res, across, whose, ext[1], LPV_AUTO_IV_MIN_VOXELS_ACROSS);
            return LPV_TECHNIQUE_ID_LPV;
        }
        say(why, n, "auto: the imperfect volume: its %.3g m voxels fit %.3g times across the %s (%.3g m; preset %s)",
            voxel, across, whose, ext[1], lpv_preset_name(s->preset));
        return LPV_TECHNIQUE_ID_IV;
    }
    say(why, n, "auto: the imperfect volume, the most accurate technique of the accuracy set (preset %s)",
        lpv_preset_name(s->preset));
    return LPV_TECHNIQUE_ID_IV;
}
