/*
 * auto_choose.c - technique auto's rule (core/plan.h, lpv_technique_choose):
 * which technique of the registry runs, from the preset and the scene's
 * facts, with the sentence that says why. It weighs the techniques against
 * each other (it asks where iv would place its voxels), so it lives beside
 * the registry, above the modules, not in core.
 */
#include <stdio.h>

#include "iv_points.h" /* lpv_iv_place: where auto asks what iv would place */
#include "plan.h"

lpv_technique_id lpv_technique_choose(const lpv_settings *s, const lpv_plan_facts *f, char *why, size_t n)
{
    const lpv_technique_id asked = s->technique == LPV_TECHNIQUE_ID_DEFAULT ? LPV_TECHNIQUE_ID_DEFAULT_IS : s->technique;
    if (asked != LPV_TECHNIQUE_ID_AUTO) { /* also when the default is auto: the rules below */
        snprintf(why, n, "requested");
        return asked;
    }
    /* The rules follow the front of the accuracy set against converged light
     * (docs/accuracy.md, "Which technique by default (issue 30)" and "auto
     * and the probes (issue 34)"): the imperfect volume is the most accurate
     * at the one tick a render computes on every scene whose cross-section
     * its voxels resolve; the probes beat the cascaded LPV on all thirteen
     * scenes, at the first tick and after, for about the LPV's tick once
     * their first is done, so they are the cheap choice and the one where
     * iv's voxels do not resolve the scene (a tunnel); the octree is best on
     * none. */
    if (s->preset == LPV_PRESET_FAST) {
        snprintf(why, n, "auto: preset fast: the probes, more accurate than the cascaded LPV on every scene of the "
                         "accuracy set at about its tick");
        return LPV_TECHNIQUE_ID_PROBES;
    }
    if (f && f->occluder_triangles > LPV_AUTO_IV_MAX_TRIANGLES) {
        snprintf(why, n, "auto: %zu triangles (over %d): the cascaded LPV; the imperfect volume's cloud takes seconds",
            f->occluder_triangles, LPV_AUTO_IV_MAX_TRIANGLES);
        return LPV_TECHNIQUE_ID_LPV;
    }
    lpv_settings resolved = *s;
    lpv_settings_resolve(&resolved);
    const int res = resolved.iv.resolution;
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
            snprintf(why, n, "auto: the probes: iv's %.3g m voxels (iv_resolution %d) fit %.2g times across the %s "
                "(%.3g m), under %.3g", voxel, res, across, whose, ext[1], LPV_AUTO_IV_MIN_VOXELS_ACROSS);
            return LPV_TECHNIQUE_ID_PROBES;
        }
        snprintf(why, n, "auto: the imperfect volume: its %.3g m voxels fit %.3g times across the %s (%.3g m; preset %s)",
            voxel, across, whose, ext[1], lpv_preset_name(s->preset));
        return LPV_TECHNIQUE_ID_IV;
    }
    snprintf(why, n, "auto: the imperfect volume, the most accurate technique of the accuracy set (preset %s)",
        lpv_preset_name(s->preset));
    return LPV_TECHNIQUE_ID_IV;
}
