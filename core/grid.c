/*
 * grid.c - placement of a light propagation volume (see grid.h).
 */
#include "grid.h"

#include <math.h>

#include "lpv_shared.h"


static int bounds_finite(const float bmin[3], const float bmax[3])
{
    for (int i = 0; i < 3; i++) {
        if (!isfinite(bmin[i]) || !isfinite(bmax[i]))
            return 0;
    }
    return 1;
}

double lpv_grid_cell_size_over(const int dims[3], const float bmin[3], const float bmax[3])
{
    double size = 0.0;
    for (int i = 0; i < 3; i++) {
        double extent = (double)bmax[i] - (double)bmin[i];
        double steps = dims[i] > 1 ? (double)(dims[i] - 1) : 1.0;
        double s = extent / steps;
        if (s > size)
            size = s;
    }
    return size;
}

static double cell_size_for(const int dims[3], const float bmin[3], const float bmax[3])
{
    double size = lpv_grid_cell_size_over(dims, bmin, bmax);
    if (!(size >= LPV_MIN_CELL_SIZE && size <= LPV_MAX_CELL_SIZE))
        return 1.0;
    return size;
}

int lpv_grid_place(const int dims[3], const float bmin[3], const float bmax[3], lpv_grid *out)
{
    for (int i = 0; i < 3; i++) {
        if (dims[i] < 1 || dims[i] > LPV_MAX_GRID_DIM)
            return -1;
    }
    if (!bounds_finite(bmin, bmax))
        return -1;

    double cs = cell_size_for(dims, bmin, bmax);
    for (int i = 0; i < 3; i++) {
        double centre = 0.5 * ((double)bmin[i] + (double)bmax[i]);
        out->dims[i] = dims[i];
        out->origin[i] = (float)(centre - 0.5 * dims[i] * cs);
    }
    out->cell_size = (float)cs;
    return 0;
}

int lpv_grid_place_cubic(int resolution, const float bmin[3], const float bmax[3], lpv_grid *out)
{
    if (resolution < 1 || resolution > LPV_MAX_GRID_DIM || !bounds_finite(bmin, bmax))
        return -1;
    double longest = 0.0;
    for (int i = 0; i < 3; i++)
        longest = fmax(longest, (double)bmax[i] - (double)bmin[i]);
    const double cs = longest > 0.0 ? longest / resolution : 1.0;
    for (int i = 0; i < 3; i++) {
        /* the bounds on voxel centres: a wall on the bounds (a room's) lies
         * inside its voxel, not on a face where rounding splits its points */
        double extent = (double)bmax[i] - (double)bmin[i];
        double span = extent / cs;
        int n = (int)floor(span + 0.5) + 1;
        if (n < 1)
            n = 1;
        if (n > LPV_MAX_GRID_DIM)
            n = LPV_MAX_GRID_DIM;
        out->dims[i] = n;
        out->origin[i] = (float)(0.5 * ((double)bmin[i] + (double)bmax[i]) - 0.5 * n * cs);
    }
    out->cell_size = (float)cs;
    return 0;
}

size_t lpv_grid_cell_count(const lpv_grid *g)
{
    return (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2];
}

size_t lpv_grid_gv_count(const lpv_grid *g)
{
    return (size_t)(g->dims[0] + 1) * (size_t)(g->dims[1] + 1) * (size_t)(g->dims[2] + 1);
}

/* Both lookups work in float, like the shaders. The range test happens on the
 * float value before the int conversion, so no position (huge, Inf, NaN) can
 * make an out-of-range conversion or index. */
int lpv_grid_cell_of(const lpv_grid *g, const float p[3], int cell[3])
{
    for (int i = 0; i < 3; i++) {
        float f = floorf(p[i] / g->cell_size - g->origin[i] / g->cell_size); /* as grid.glsl */
        if (!(f >= 0.0f && f < (float)g->dims[i]))
            return 0;
        cell[i] = (int)f;
    }
    return 1;
}

int lpv_grid_gv_point_of(const lpv_grid *g, const float p[3], int point[3])
{
    for (int i = 0; i < 3; i++) {
        float f = floorf(p[i] / g->cell_size - g->origin[i] / g->cell_size + 0.5f);
        if (!(f >= 0.0f && f <= (float)g->dims[i]))
            return 0;
        point[i] = (int)f;
    }
    return 1;
}

void lpv_box_sides(const float bmin[3], const float bmax[3], float sides[3])
{
    for (int i = 0; i < 3; ++i)
        sides[i] = bmax[i] - bmin[i];
    for (int i = 0; i < 2; ++i) /* three elements: two passes of bubble sort */
        for (int j = 0; j < 2 - i; ++j)
            if (sides[j] > sides[j + 1]) {
                const float t = sides[j];
                sides[j] = sides[j + 1];
                sides[j + 1] = t;
            }
}
