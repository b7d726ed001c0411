/*
 * engine_facts.c - what the planner and the technique are told: the facts
 * about the scene, the settings and what changed since the last tick
 * (core/plan.h), and where the technique's volume must go under them.
 * Reads the engine; calls nothing above it.
 */
#include <math.h>
#include <string.h>

#include "engine_internal.h"

/* Draws using a material rougher than nothing but below the glossy threshold. */
static size_t glossy_draws(const lpv_engine *e)
{
    size_t n = 0;
    for (uint32_t i = 0; i < e->geo.draw_count; ++i) {
        int m = e->geo.draws[i].material;
        if (m >= 0 && (uint32_t)m < e->geo.material_count && e->geo.materials[m].roughness < e->settings.glossy_roughness)
            ++n;
    }
    return n;
}

/* The planner's facts about the scene, the settings and what changed. */
void lpv_engine_gather_facts(const lpv_engine *e, lpv_plan_facts *f)
{
    memset(f, 0, sizeof *f);
    f->lights = e->light_count;
    f->emissive_vpls = e->emissive_vpl_count;
    f->emissive_surfaces = e->emitters.surfaces;
    f->area_light_samples = e->area_sample_count;
    f->occluder_triangles = e->occluder_triangles;
    f->glossy_draws = glossy_draws(e);
    f->blend_draws = e->geo.blend_draws;
    f->has_medium = e->medium.medium.present || e->settings.fog_sigma_s > 0.0f || e->settings.fog_sigma_a > 0.0f;
    f->has_view = e->has_view;
    f->camera_inside = e->has_view && lpv_point_in_bounds(e->view.eye, e->scene_min, e->scene_max);
    float sides[3];
    lpv_box_sides(e->scene_min, e->scene_max, sides);
    f->scene_shortest = sides[0];
    f->scene_middle = sides[1];
    f->scene_extent = sides[2];
    f->view_chord = f->camera_inside ? e->view_chord : 0.0f;
    f->cascade_finest = lpv_cascade_finest_size(&e->settings, e->scene_min, e->scene_max, f->view_chord);
    f->scene_cross = lpv_cascade_cross_section(e->scene_min, e->scene_max);
    f->free_path = e->reach.free_path;
    if (!lpv_engine_lit_region(e, f->lit_min, f->lit_max, &f->lit_free_path)) { /* the scene's: as unknown */
        memset(f->lit_min, 0, sizeof f->lit_min);
        memset(f->lit_max, 0, sizeof f->lit_max);
        f->lit_free_path = 0.0f;
    }
    f->bounds_given = lpv_settings_bounds_given(&e->settings);
    f->cascades_unfit = !lpv_cascades_fit(&e->settings, e->scene_min, e->scene_max, f->view_chord, NULL, 0);
    for (int i = 0; i < 3; ++i)
        f->scene_reach = fmaxf(f->scene_reach, fmaxf(fabsf(e->scene_min[i]), fabsf(e->scene_max[i])));
    f->first_tick = !e->computed;
    f->scene_changed = e->scene_dirty;
    f->lights_changed = e->lights_dirty;
    f->settings_changed = e->settings_dirty;
    memcpy(f->settings_knob, e->settings_knob, sizeof f->settings_knob);
    f->forced = e->forced;
    if (e->has_view != e->computed_has_view) {
        f->camera_move_cells = INFINITY;
    } else if (e->has_view) {
        float d2 = 0.0f;
        for (int i = 0; i < 3; ++i)
            d2 += (e->view.eye[i] - e->computed_eye[i]) * (e->view.eye[i] - e->computed_eye[i]);
        f->camera_move_cells = sqrtf(d2) / e->desc.level[0].cell_size;
    }
}

void lpv_engine_where(const lpv_engine *e, const lpv_plan_facts *f, lpv_technique_where *w)
{
    memset(w, 0, sizeof *w);
    w->settings = &e->settings;
    w->facts = f;
    memcpy(w->bounds_min, e->scene_min, sizeof w->bounds_min);
    memcpy(w->bounds_max, e->scene_max, sizeof w->bounds_max);
    w->eye = e->has_view ? e->view.eye : NULL;
    w->forward = e->has_view ? e->view.forward : NULL;
    lpv_engine_memory_need(e, &w->others);
    w->limits = &e->mem_limits;
}
