/*
 * cascades.c - cascade placement (see cascades.h).
 */
#include "cascades.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "lpv_shared.h"

_Static_assert(LPV_MAX_CASCADES == 4, "lpv_cascade_set's arrays hold LPV_MAX_CASCADES entries");

int lpv_cascades_place(const lpv_settings *s, int count, const float bmin[3], const float bmax[3], const float *eye,
                       const float *forward, float view_chord, lpv_cascade_set *out)
{
    memset(out, 0, sizeof *out);
    if (count < 1 || count > LPV_MAX_CASCADES)
        return -1;
    if (count == 1) {
        const int given = lpv_settings_bounds_given(s);
        if (lpv_grid_place(s->grid_dims, given ? s->bounds_min : bmin, given ? s->bounds_max : bmax,
                           &out->grid[0]) != 0)
            return -1;
        for (int i = 0; i < 3; ++i)
            out->origin_cells[0][i] = out->grid[0].origin[i] / out->grid[0].cell_size;
        out->count = 1;
        for (int k = 1; k < lpv_cascades_count(s, 1); ++k) {
            lpv_grid *g = &out->grid[k];
            *g = out->grid[k - 1];
            g->cell_size = 2.0f * out->grid[k - 1].cell_size;
            for (int i = 0; i < 3; ++i) {
                double o = ((double)out->origin_cells[k - 1][i] - (double)(g->dims[i] / 2)) * 0.5;
                out->origin_cells[k][i] = (float)o;
                g->origin[i] = (float)(o * g->cell_size);
            }
            out->count = k + 1;
            out->handoff = 1;
        }
        return 0;
    }
    int longest = 1;
    for (int i = 0; i < 3; ++i) {
        if (s->grid_dims[i] < 1 || s->grid_dims[i] > LPV_MAX_GRID_DIM)
            return -1;
        if (s->grid_dims[i] > longest)
            longest = s->grid_dims[i];
    }
    double centre_scene[3], anchor[3];
    for (int i = 0; i < 3; ++i) {
        centre_scene[i] = 0.5 * ((double)bmin[i] + (double)bmax[i]);
        if (!isfinite(centre_scene[i]) || (eye && !isfinite(eye[i])) || (forward && !isfinite(forward[i])))
            return -1;
        anchor[i] = eye ? eye[i] : centre_scene[i];
    }
    /* A camera outside the bounds: anchor where its view ray enters them, or
     * at the point of the bounds nearest to it, so no cascade sits beside the
     * scene. */
    if (eye && !lpv_point_in_bounds(eye, bmin, bmax)) {
        double t0 = 0.0, t1 = INFINITY;
        for (int i = 0; i < 3 && forward; ++i) {
            if (fabs(forward[i]) < 1e-12) {
                if (eye[i] < bmin[i] || eye[i] > bmax[i])
                    t0 = INFINITY;
                continue;
            }
            double a = (bmin[i] - eye[i]) / forward[i], b = (bmax[i] - eye[i]) / forward[i];
            t0 = fmax(t0, fmin(a, b));
            t1 = fmin(t1, fmax(a, b));
        }
        int enters = forward && t0 <= t1 && isfinite(t0);
        for (int i = 0; i < 3; ++i)
            anchor[i] = enters ? eye[i] + forward[i] * t0 : fmin(fmax(eye[i], bmin[i]), bmax[i]);
    }
    const double offset = s->lpv.cascade_offset > 0.0f ? s->lpv.cascade_offset : 0.0;
    double cell = (double)lpv_cascade_finest_size(s, bmin, bmax, view_chord) / longest;
    for (int k = 0; k < count; ++k, cell *= s->lpv.cascade_ratio) {
        lpv_grid *g = &out->grid[k];
        memcpy(g->dims, s->grid_dims, sizeof g->dims);
        g->cell_size = (float)cell;
        for (int i = 0; i < 3; ++i) {
            double extent = cell * g->dims[i];
            double centre = anchor[i] + (eye && forward ? forward[i] * offset * extent : 0.0);
            /* keep the cascade over the scene: centred on it along an axis it
             * spans, else no further out than its own border */
            double span = (double)bmax[i] - (double)bmin[i];
            if (extent >= span)
                centre = centre_scene[i];
            else
                centre = fmin(fmax(centre, bmin[i] + 0.5 * extent), bmax[i] - 0.5 * extent);
            double o = floor(centre / cell) - (double)(g->dims[i] / 2);
            if (!isfinite(o) || fabs(o) > LPV_CASCADE_MAX_ORIGIN_CELLS)
                return -1;
            out->origin_cells[k][i] = (float)o;
            g->origin[i] = (float)(o * cell);
        }
    }
    out->count = count;
    out->snapped = 1;
    out->handoff = s->lpv.far_field == LPV_SWITCH_ON && s->lpv.cascade_ratio == 2.0f;
    return 0;
}

int lpv_cascades_fit(const lpv_settings *s, const float bmin[3], const float bmax[3], float view_chord, char *why,
                     size_t n)
{
    int longest = 1;
    double reach = 0.0;
    for (int i = 0; i < 3; ++i) {
        longest = s->grid_dims[i] > longest ? s->grid_dims[i] : longest;
        reach = fmax(reach, fmax(fabs((double)bmin[i]), fabs((double)bmax[i])));
    }
    const double cell = (double)lpv_cascade_finest_size(s, bmin, bmax, view_chord) / longest;
    /* lpv_cascades_place: the anchor lies in the bounds, the origin half a grid below it */
    const double room = LPV_CASCADE_MAX_ORIGIN_CELLS - longest / 2 - 1;
    if (isfinite(reach) && cell > 0.0 && reach / cell + 1.0 <= room)
        return 1;
    if (why)
        snprintf(why, n, "cascade cells of %g m cannot be counted %g m from the origin in 32-bit floats "
                 "(at most %g cells); cascade_size %g m or more would fit", cell, reach, LPV_CASCADE_MAX_ORIGIN_CELLS,
                 reach / (room - 1.0) * longest * 1.001);
    return 0;
}

int lpv_cascades_count(const lpv_settings *s, int count)
{
    if (count != 1 || s->lpv.far_field != LPV_SWITCH_ON)
        return count;
    int levels = s->lpv.far_field_levels < 0 ? 0 : s->lpv.far_field_levels;
    return 1 + levels < LPV_MAX_CASCADES ? 1 + levels : LPV_MAX_CASCADES;
}

float lpv_cascade_cross_section(const float bmin[3], const float bmax[3])
{
    float sides[3];
    lpv_box_sides(bmin, bmax, sides);
    const float longest = sides[2], second = sides[1];
    return second > 0.0f && isfinite(longest) && longest >= LPV_CASCADE_LONG_RATIO * second ? second : 0.0f;
}

float lpv_cascade_finest_size(const lpv_settings *s, const float bmin[3], const float bmax[3], float view_chord)
{
    if (s->lpv.cascade_size > 0.0f)
        return s->lpv.cascade_size;
    float longest = 0.0f;
    for (int i = 0; i < 3; ++i)
        longest = fmaxf(longest, bmax[i] - bmin[i]);
    if (!(longest > 0.0f) || !isfinite(longest))
        return 1.0f;
    const float quarter = LPV_CASCADE_AUTO_FRACTION * longest;
    int cells = 1;
    for (int i = 0; i < 3; ++i)
        cells = s->grid_dims[i] > cells ? s->grid_dims[i] : cells;
    /* the space the camera stands in, measured (core/reach.h): cells about
     * as wide as it (LPV_VIEW_ACROSS x its median chord), the
     * quarter divided by the nearest power of sqrt(2), so the size changes
     * only when the camera walks into a space 1.4 times as large or small (docs/cascades.md, "Long
     * scenes": a 240 m x 3 m tunnel at 8^3 had 7.5 m cells, wider than
     * the tunnel, and a fifth of the reference's indirect light) */
    if (view_chord > 0.0f) {
        const double fitted = (double)cells * LPV_VIEW_ACROSS * (double)view_chord;
        if (!isfinite(fitted) || fitted >= (double)quarter)
            return quarter;
        const double steps = floor(2.0 * log2((double)quarter / fitted) + 0.5); /* half octaves */
        return (float)((double)quarter * pow(2.0, -0.5 * fmin(steps, 60.0)));
    }
    /* no measure (no camera inside, no voxels): a long scene's bounds */
    const float cross = lpv_cascade_cross_section(bmin, bmax);
    const float fitted = (float)cells * LPV_CASCADE_LONG_CELL * cross;
    return cross > 0.0f && fitted < quarter ? fitted : quarter;
}

int lpv_point_in_bounds(const float p[3], const float bmin[3], const float bmax[3])
{
    for (int i = 0; i < 3; ++i)
        if (!(p[i] >= bmin[i] && p[i] <= bmax[i]))
            return 0;
    return 1;
}

int lpv_cascades_equal(const lpv_cascade_set *a, const lpv_cascade_set *b)
{
    if (a->count != b->count || a->snapped != b->snapped || a->handoff != b->handoff)
        return 0;
    for (int k = 0; k < a->count; ++k) {
        if (memcmp(a->grid[k].dims, b->grid[k].dims, sizeof a->grid[k].dims) != 0 ||
            a->grid[k].cell_size != b->grid[k].cell_size ||
            memcmp(a->origin_cells[k], b->origin_cells[k], sizeof a->origin_cells[k]) != 0)
            return 0;
    }
    return 1;
}

void lpv_cascades_grid_params(const lpv_cascade_set *set, struct LpvGridParams *out)
{
    const lpv_grid *g = &set->grid[0];
    memset(out, 0, sizeof *out);
    out->dims[0] = (float)g->dims[0];
    out->dims[1] = (float)g->dims[1];
    out->dims[2] = (float)g->dims[2];
    out->dims[3] = (float)lpv_grid_cell_count(g);
    out->info[0] = (float)set->count;
    for (int k = 0; k < set->count; ++k) {
        for (int i = 0; i < 3; ++i)
            out->cascade[k][i] = set->origin_cells[k][i];
        out->cascade[k][3] = set->grid[k].cell_size;
    }
}
