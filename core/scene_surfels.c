/* scene_surfels.c - see scene_surfels.h. */
#include "scene_surfels.h"

#include <math.h>
#include <string.h>

/* The draw's material, or NULL when it has none. */
static const lpv_material *material_of(const lpv_scene *s, const lpv_draw *dr)
{
    return dr->material >= 0 && (uint32_t)dr->material < s->material_count ? &s->materials[dr->material] : NULL;
}

/* Draws left out: emitters are light sources only in the geometry volume,
 * as in the RSM and camera surfels (camera_surfels.comp), and the planner
 * counts only non-emissive triangles as occluders; cut-out materials (alpha
 * MASK and BLEND) block only where the RSM and the camera see them opaque,
 * since these surfels do not sample the alpha texture. */
static int left_out(const lpv_scene *s, const lpv_draw *dr)
{
    const lpv_material *m = material_of(s, dr);
    return m && ((m->emission[0] > 0.0f || m->emission[1] > 0.0f || m->emission[2] > 0.0f) ||
                 m->alpha_mode == LPV_ALPHA_MASK || m->alpha_mode == LPV_ALPHA_BLEND);
}

static double total_area(const lpv_scene *s)
{
    double sum = 0.0;
    for (uint32_t d = 0; d < s->draw_count; ++d) {
        const lpv_draw *dr = &s->draws[d];
        if (left_out(s, dr))
            continue;
        for (uint32_t t = 0; t + 3 <= dr->index_count; t += 3) {
            const lpv_vertex *v[3];
            float n[3];
            double area;
            if (dr->first_index + t + 3 <= s->index_count && lpv_scene_triangle(s, dr->first_index + t, v, n, &area))
                sum += area;
        }
    }
    return sum;
}

size_t lpv_scene_surfels(const lpv_scene *s, size_t target, lpv_surfel *out, size_t max)
{
    const double total = total_area(s);
    if (!(total > 0.0) || !isfinite(total) || target == 0)
        return 0;
    /* R2 low-discrepancy sequence (generalised golden ratio), warped onto
     * each triangle; samples are handed out by error diffusion, so the count
     * stays near target however many small triangles there are. */
    const double a1 = 0.7548776662466927, a2 = 0.5698402909980532;
    double carry = 0.0, pending_area = 0.0;
    size_t count = 0;
    for (uint32_t d = 0; d < s->draw_count && count < max; ++d) {
        const lpv_draw *dr = &s->draws[d];
        if (left_out(s, dr))
            continue;
        const lpv_material *m = material_of(s, dr);
        const float *albedo = m ? m->base_color : NULL;
        for (uint32_t t = 0; t + 3 <= dr->index_count && count < max; t += 3) {
            const lpv_vertex *v[3];
            float n[3];
            double area;
            if (dr->first_index + t + 3 > s->index_count || !lpv_scene_triangle(s, dr->first_index + t, v, n, &area))
                continue;
            carry += (double)target * area / total;
            size_t k = (size_t)floor(carry);
            carry -= (double)k;
            if (k == 0) {
                pending_area += area;
                continue;
            }
            if (k > max - count)
                k = max - count;
            for (size_t j = 0; j < k; ++j) {
                double u = fmod(0.5 + a1 * (double)(j + 1), 1.0), w = fmod(0.5 + a2 * (double)(j + 1), 1.0);
                double r = sqrt(u), b0 = 1.0 - r, b1 = r * (1.0 - w), b2 = r * w;
                lpv_surfel *o = &out[count++];
                memset(o, 0, sizeof *o);
                for (int i = 0; i < 3; ++i) {
                    o->position[i] =
                        (float)(b0 * v[0]->position[i] + b1 * v[1]->position[i] + b2 * v[2]->position[i]);
                    o->normal[i] = n[i];
                    o->albedo[i] = albedo ? albedo[i] : 1.0f;
                }
                o->position[3] = (float)(area / (double)k + (j == 0 ? pending_area : 0.0));
            }
            pending_area = 0.0;
        }
    }
    return count;
}
