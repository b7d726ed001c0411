/*
 * reach.c - the scene's air spaces and which of them a light reaches
 * (reach.h). Voxelization by techniques/iv/core/iv_voxelize.h's triangle/box test, the
 * components by a breadth-first flood fill over 6-connected air voxels.
 */
#include "reach.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "iv_voxelize.h"

static size_t voxel_index(const lpv_reach *r, int x, int y, int z)
{
    return (size_t)x + (size_t)r->dims[0] * ((size_t)y + (size_t)r->dims[1] * (size_t)z);
}

static size_t voxel_count(const int dims[3]) { return (size_t)dims[0] * (size_t)dims[1] * (size_t)dims[2]; }

/* Cubic voxels over the bounds grown by the margin: the smallest side (up to
 * a few percent) whose grid fits max_voxels and LPV_REACH_MAX_DIM per axis. */
static int place(lpv_reach *r, const float bmin[3], const float bmax[3], size_t max_voxels)
{
    double ext[3], longest = 0.0, volume = 1.0;
    for (int k = 0; k < 3; ++k) {
        ext[k] = (double)bmax[k] - (double)bmin[k];
        if (!isfinite(ext[k]) || ext[k] < 0.0)
            return -1;
        longest = fmax(longest, ext[k]);
    }
    if (!(longest > 0.0))
        return -1;
    for (int k = 0; k < 3; ++k)
        volume *= fmax(ext[k], longest * 1e-3);
    double s = fmax(cbrt(volume / (double)max_voxels), longest / (double)(LPV_REACH_MAX_DIM - 2 * LPV_REACH_MARGIN - 1));
    for (int tries = 0; tries < 200; ++tries, s *= 1.05) {
        int dims[3];
        for (int k = 0; k < 3; ++k)
            dims[k] = (int)floor(ext[k] / s) + 1 + 2 * LPV_REACH_MARGIN;
        if (dims[0] > LPV_REACH_MAX_DIM || dims[1] > LPV_REACH_MAX_DIM || dims[2] > LPV_REACH_MAX_DIM ||
            voxel_count(dims) > max_voxels)
            continue;
        memcpy(r->dims, dims, sizeof dims);
        r->voxel = (float)s;
        for (int k = 0; k < 3; ++k) /* centred: the margin on both sides */
            r->origin[k] = (float)(0.5 * ((double)bmin[k] + (double)bmax[k]) - 0.5 * dims[k] * s);
        return 0;
    }
    return -1;
}

/* Triangle p's conservative voxels in a grid of cubic voxels (lower corner
 * origin, side, dims; x fastest) set to 0 in cells (0 = solid). */
static void voxelize_into(const float origin[3], double side, const int dims[3], uint32_t *cells, const float *p[3])
{
    double tri[3][3];
    int lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
        for (int i = 0; i < 3; ++i)
            tri[i][k] = ((double)p[i][k] - (double)origin[k]) / side;
        double mn = fmin(tri[0][k], fmin(tri[1][k], tri[2][k])) - LPV_IV_VOXELIZE_EPS;
        double mx = fmax(tri[0][k], fmax(tri[1][k], tri[2][k])) + LPV_IV_VOXELIZE_EPS;
        if (!(mx >= 0.0 && mn < (double)dims[k]))
            return;
        lo[k] = mn < 0.0 ? 0 : (int)floor(mn);
        hi[k] = mx >= (double)dims[k] ? dims[k] - 1 : (int)floor(mx);
    }
    const double half[3] = {0.5 + LPV_IV_VOXELIZE_EPS, 0.5 + LPV_IV_VOXELIZE_EPS, 0.5 + LPV_IV_VOXELIZE_EPS};
    for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
            for (int x = lo[0]; x <= hi[0]; ++x) {
                const double centre[3] = {x + 0.5, y + 0.5, z + 0.5};
                const size_t v = (size_t)x + (size_t)dims[0] * ((size_t)y + (size_t)dims[1] * (size_t)z);
                if (cells[v] != 0 && lpv_iv_tri_box_overlap(centre, half, tri))
                    cells[v] = 0;
            }
}

/* Marks every voxel triangle p touches as solid (label 0; the labels start
 * at 1 = air). */
static void voxelize_triangle(lpv_reach *r, const float *p[3])
{
    voxelize_into(r->origin, (double)r->voxel, r->dims, r->label, p);
}

/* Labels the air (label 1 on entry) with components 1..n by flood fill. */
static int label_components(lpv_reach *r)
{
    const size_t n = voxel_count(r->dims);
    uint32_t *queue = malloc(n * sizeof *queue);
    if (!queue)
        return -1;
    /* air starts as UINT32_MAX (unvisited), solid stays 0 */
    for (size_t v = 0; v < n; ++v)
        if (r->label[v])
            r->label[v] = UINT32_MAX;
    const size_t sx = 1, sy = (size_t)r->dims[0], sz = (size_t)r->dims[0] * (size_t)r->dims[1];
    uint32_t next = 0;
    for (size_t seed = 0; seed < n; ++seed) {
        if (r->label[seed] != UINT32_MAX)
            continue;
        const uint32_t id = ++next;
        size_t head = 0, tail = 0;
        r->label[seed] = id;
        queue[tail++] = (uint32_t)seed;
        while (head < tail) {
            const size_t v = queue[head++];
            const int x = (int)(v % sy), y = (int)((v / sy) % (size_t)r->dims[1]), z = (int)(v / sz);
            const size_t nb[6] = {v - sx, v + sx, v - sy, v + sy, v - sz, v + sz};
            const int ok[6] = {x > 0, x + 1 < r->dims[0], y > 0, y + 1 < r->dims[1], z > 0, z + 1 < r->dims[2]};
            for (int k = 0; k < 6; ++k)
                if (ok[k] && r->label[nb[k]] == UINT32_MAX) {
                    r->label[nb[k]] = id;
                    queue[tail++] = (uint32_t)nb[k];
                }
        }
    }
    free(queue);
    r->components = next;
    return 0;
}

static int is_emissive(const lpv_material *m)
{
    return m && (m->emission[0] > 0.0f || m->emission[1] > 0.0f || m->emission[2] > 0.0f);
}

/* Only opaque surfaces are voxelized: cut-out and blended ones let light through. */
static int is_opaque(const lpv_material *m) { return !m || m->alpha_mode == LPV_ALPHA_OPAQUE; }

static const lpv_material *material_of(const lpv_scene *scene, const lpv_draw *dr)
{
    return dr->material >= 0 && (uint32_t)dr->material < scene->material_count ? &scene->materials[dr->material]
                                                                                 : NULL;
}

int lpv_reach_build(lpv_reach *r, const lpv_scene *scene, size_t max_voxels, char *err, size_t err_size)
{
    memset(r, 0, sizeof *r);
    if (!max_voxels)
        max_voxels = LPV_REACH_DEFAULT_VOXELS;
    if (place(r, scene->bounds_min, scene->bounds_max, max_voxels) != 0)
        return lpv_error(err, err_size, "reach: the scene has no finite, non-empty bounds");
    const size_t n = voxel_count(r->dims);
    r->label = malloc(n * sizeof *r->label);
    r->mask = malloc(n);
    size_t emissive = 0;
    for (uint32_t d = 0; d < scene->draw_count; ++d) {
        const lpv_draw *dr = &scene->draws[d];
        const lpv_material *m = material_of(scene, dr);
        if (is_emissive(m))
            emissive += dr->index_count / 3;
    }
    r->emitter_seeds = malloc((2 * emissive + 1) * 6 * sizeof(float));
    if (!r->label || !r->mask || !r->emitter_seeds)
        return lpv_error(err, err_size, "reach: out of memory for %zu voxels", n);
    for (size_t v = 0; v < n; ++v)
        r->label[v] = 1;
    double opaque_area = 0.0;
    r->all_opaque = 1;
    for (uint32_t d = 0; d < scene->draw_count; ++d) {
        const lpv_draw *dr = &scene->draws[d];
        const lpv_material *m = material_of(scene, dr);
        const int opaque = is_opaque(m);
        const int emits = is_emissive(m);
        r->all_opaque &= opaque;
        if (!opaque && !emits)
            continue;
        for (uint32_t i = 0; i + 2 < dr->index_count; i += 3) {
            const lpv_vertex *v[3];
            float front[3];
            double area;
            if (!lpv_scene_triangle(scene, dr->first_index + i, v, front, &area))
                continue;
            if (opaque) {
                const float *p[3] = {v[0]->position, v[1]->position, v[2]->position};
                voxelize_triangle(r, p);
                opaque_area += area;
            }
            if (emits) /* both sides: a seed only ever adds light, never takes it away */
                for (int side = -1; side <= 1; side += 2) {
                    float *s = &r->emitter_seeds[6 * r->emitter_seed_count++];
                    for (int k = 0; k < 3; ++k) {
                        s[k] = (v[0]->position[k] + v[1]->position[k] + v[2]->position[k]) / 3.0f;
                        s[3 + k] = (float)side * front[k];
                    }
                }
        }
    }
    if (label_components(r) != 0)
        return lpv_error(err, err_size, "reach: out of memory for the flood fill of %zu voxels", n);
    /* the air inside the bounds (the margin left out), and half of each
     * solid voxel next to air: a surface runs through the middle of its
     * conservative voxels, so half of them is air (without, a 3 m tunnel on
     * 0.24 m voxels lost a quarter of its volume) */
    double air = 0.0;
    const size_t sy = (size_t)r->dims[0], sz = (size_t)r->dims[0] * (size_t)r->dims[1];
    for (int z = LPV_REACH_MARGIN; z < r->dims[2] - LPV_REACH_MARGIN; ++z)
        for (int y = LPV_REACH_MARGIN; y < r->dims[1] - LPV_REACH_MARGIN; ++y)
            for (int x = LPV_REACH_MARGIN; x < r->dims[0] - LPV_REACH_MARGIN; ++x) {
                const size_t v = voxel_index(r, x, y, z);
                if (r->label[v])
                    air += 1.0;
                else if (r->label[v - 1] || r->label[v + 1] || r->label[v - sy] || r->label[v + sy] ||
                         r->label[v - sz] || r->label[v + sz])
                    air += 0.5; /* within the margin: the neighbours exist */
            }
    const double vox = (double)r->voxel;
    r->free_path = opaque_area > 0.0 ? (float)(4.0 * air * vox * vox * vox / opaque_area) : 0.0f;
    r->unsure = 1; /* until lpv_reach_light sees the lights */
    for (size_t v = 0; v < n; ++v)
        r->mask[v] = r->label[v] ? LPV_REACH_LIT : LPV_REACH_SOLID;
    return 0;
}

/* The voxel holding p, or -1 outside the grid. */
static long voxel_at(const lpv_reach *r, const float p[3])
{
    int c[3];
    for (int k = 0; k < 3; ++k) {
        double q = floor(((double)p[k] - (double)r->origin[k]) / (double)r->voxel);
        if (!(q >= 0.0 && q < (double)r->dims[k]))
            return -1;
        c[k] = (int)q;
    }
    return (long)voxel_index(r, c[0], c[1], c[2]);
}

/* Lights the air components among the 26 voxels around voxel v (dir NULL),
 * or among those on dir's side of it (their offset . dir >= 0.5). Returns
 * how many air voxels it found. */
static int light_around(const lpv_reach *r, long v, const float *dir, unsigned char *lit)
{
    const int x = (int)((size_t)v % (size_t)r->dims[0]), y = (int)(((size_t)v / (size_t)r->dims[0]) % (size_t)r->dims[1]),
              z = (int)((size_t)v / ((size_t)r->dims[0] * (size_t)r->dims[1]));
    int found = 0;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int X = x + dx, Y = y + dy, Z = z + dz;
                if (X < 0 || Y < 0 || Z < 0 || X >= r->dims[0] || Y >= r->dims[1] || Z >= r->dims[2] ||
                    (dir && (float)dx * dir[0] + (float)dy * dir[1] + (float)dz * dir[2] < 0.5f))
                    continue;
                const uint32_t l = r->label[voxel_index(r, X, Y, Z)];
                if (l) {
                    lit[l] = 1;
                    found++;
                }
            }
    return found;
}

/* Whether triangle t's box meets [lo, hi]. */
static int box_touches(const lpv_vertex *const t[3], const float lo[3], const float hi[3])
{
    for (int k = 0; k < 3; ++k)
        if (fmaxf(t[0]->position[k], fmaxf(t[1]->position[k], t[2]->position[k])) < lo[k] ||
            fminf(t[0]->position[k], fminf(t[1]->position[k], t[2]->position[k])) > hi[k])
            return 0;
    return 1;
}

/* Whether the segment from p to q crosses triangle t (Moller-Trumbore, both
 * sides; a touch at either end counts). */
static int segment_crosses(const float p[3], const double q[3], const lpv_vertex *const t[3])
{
    double d[3], e1[3], e2[3], h[3], sv[3], qv[3];
    for (int k = 0; k < 3; ++k) {
        d[k] = q[k] - (double)p[k];
        e1[k] = (double)t[1]->position[k] - (double)t[0]->position[k];
        e2[k] = (double)t[2]->position[k] - (double)t[0]->position[k];
        sv[k] = (double)p[k] - (double)t[0]->position[k];
    }
    h[0] = d[1] * e2[2] - d[2] * e2[1];
    h[1] = d[2] * e2[0] - d[0] * e2[2];
    h[2] = d[0] * e2[1] - d[1] * e2[0];
    const double a = e1[0] * h[0] + e1[1] * h[1] + e1[2] * h[2];
    if (fabs(a) < 1e-18)
        return 0; /* parallel: the segment runs along its plane */
    const double f = 1.0 / a, u = f * (sv[0] * h[0] + sv[1] * h[1] + sv[2] * h[2]);
    if (u < 0.0 || u > 1.0)
        return 0;
    qv[0] = sv[1] * e1[2] - sv[2] * e1[1];
    qv[1] = sv[2] * e1[0] - sv[0] * e1[2];
    qv[2] = sv[0] * e1[1] - sv[1] * e1[0];
    const double v = f * (d[0] * qv[0] + d[1] * qv[1] + d[2] * qv[2]);
    if (v < 0.0 || u + v > 1.0)
        return 0;
    const double w = f * (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]);
    return w >= 0.0 && w <= 1.0;
}

/* A light in a solid voxel, looked at closer: the scene's opaque triangles
 * voxelized again over the 3 x 3 x 3 voxels around it, LPV_REACH_CLOSER
 * times finer, and the air around the light flood-filled there; the
 * components of the voxels that air reaches are lit. The voxels alone
 * cannot tell which side of a surface in the light's voxel the light is on:
 * a lamp 0.2 m under a ceiling, in a 240 m scene's 0.78 m voxels, lit every
 * air voxel around, the hollow inside of the hill over the ceiling as well
 * as the tunnel under it, and the imperfect volume then spread over the
 * whole hill (docs/propagation.md, "Enclosed lights"). Where the light
 * lies in a surface even at the finer size, its air is the fine voxels
 * around it that the segment from it crosses no triangle to. Returns the
 * fine voxels of air voxels reached (0 when none: the caller then lights
 * every air voxel around), -1 out of memory. */
static int light_in_solid(const lpv_reach *r, const lpv_scene *scene, const float p[3], long v, unsigned char *lit)
{
    const int S = LPV_REACH_CLOSER;
    const int c[3] = {(int)(v % r->dims[0]), (int)((v / r->dims[0]) % r->dims[1]),
                      (int)(v / ((long)r->dims[0] * r->dims[1]))};
    int lo[3], dims[3];
    float origin[3], top[3];
    for (int k = 0; k < 3; ++k) {
        lo[k] = c[k] > 0 ? c[k] - 1 : 0;
        const int hi = c[k] + 1 < r->dims[k] ? c[k] + 1 : r->dims[k] - 1;
        dims[k] = (hi - lo[k] + 1) * S;
        origin[k] = r->origin[k] + (float)lo[k] * r->voxel;
        top[k] = r->origin[k] + (float)(hi + 1) * r->voxel;
    }
    const size_t n = (size_t)dims[0] * (size_t)dims[1] * (size_t)dims[2];
    uint32_t *cell = malloc(n * sizeof *cell), *queue = malloc(n * sizeof *queue);
    if (!cell || !queue) {
        free(cell);
        free(queue);
        return -1;
    }
    for (size_t i = 0; i < n; ++i)
        cell[i] = 1; /* air, not yet reached */
    const double side = (double)r->voxel / S;
    int s[3];
    float near_lo[3], near_hi[3]; /* the light's fine voxel and the 26 around it */
    for (int k = 0; k < 3; ++k) {
        const double q = floor(((double)p[k] - (double)origin[k]) / side);
        s[k] = q < 0.0 ? 0 : q >= (double)dims[k] ? dims[k] - 1 : (int)q;
        near_lo[k] = origin[k] + (float)((s[k] - 1) * side);
        near_hi[k] = origin[k] + (float)((s[k] + 2) * side);
    }
    const lpv_vertex **close = NULL; /* triangles by the light, 3 corners each: the side it is on */
    size_t close_n = 0, close_cap = 0;
    int failed = 0;
    for (uint32_t d = 0; d < scene->draw_count && !failed; ++d) {
        const lpv_draw *dr = &scene->draws[d];
        if (!is_opaque(material_of(scene, dr)))
            continue;
        for (uint32_t i = 0; i + 2 < dr->index_count; i += 3) {
            const lpv_vertex *t[3];
            float front[3];
            double area;
            if (!lpv_scene_triangle(scene, dr->first_index + i, t, front, &area) ||
                !box_touches(t, origin, top))
                continue;
            voxelize_into(origin, side, dims, cell, (const float *[3]){t[0]->position, t[1]->position, t[2]->position});
            if (!box_touches(t, near_lo, near_hi))
                continue;
            if (close_n == close_cap) {
                close_cap = close_cap ? 2 * close_cap : 48;
                const lpv_vertex **grown = realloc(close, close_cap * 3 * sizeof *close);
                if (!grown) {
                    failed = 1;
                    break;
                }
                close = grown;
            }
            memcpy(&close[3 * close_n++], t, sizeof t);
        }
    }
    if (failed) {
        free(close);
        free(cell);
        free(queue);
        return -1;
    }
    /* the light's own fine voxel, or where it lies in a surface even at this
     * size, the air ones around it that no surface separates from it */
    const size_t own = (size_t)s[0] + (size_t)dims[0] * ((size_t)s[1] + (size_t)dims[1] * (size_t)s[2]);
    size_t head = 0, tail = 0;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int x = s[0] + dx, y = s[1] + dy, z = s[2] + dz;
                if (x < 0 || y < 0 || z < 0 || x >= dims[0] || y >= dims[1] || z >= dims[2])
                    continue;
                const size_t i = (size_t)x + (size_t)dims[0] * ((size_t)y + (size_t)dims[1] * (size_t)z);
                if (cell[i] != 1 || (i != own && cell[own] != 0))
                    continue;
                const double q[3] = {origin[0] + (x + 0.5) * side, origin[1] + (y + 0.5) * side,
                                     origin[2] + (z + 0.5) * side};
                int clear = 1;
                for (size_t k = 0; k < close_n && clear && i != own; ++k)
                    clear = !segment_crosses(p, q, &close[3 * k]);
                if (clear) {
                    cell[i] = 2;
                    queue[tail++] = (uint32_t)i;
                }
            }
    free(close);
    int found = 0;
    const size_t sy = (size_t)dims[0], sz = (size_t)dims[0] * (size_t)dims[1];
    while (head < tail) {
        const size_t i = queue[head++];
        const int x = (int)(i % sy), y = (int)((i / sy) % (size_t)dims[1]), z = (int)(i / sz);
        const uint32_t l = r->label[voxel_index(r, lo[0] + x / S, lo[1] + y / S, lo[2] + z / S)];
        if (l) {
            lit[l] = 1;
            found++;
        }
        const size_t nb[6] = {i - 1, i + 1, i - sy, i + sy, i - sz, i + sz};
        const int ok[6] = {x > 0, x + 1 < dims[0], y > 0, y + 1 < dims[1], z > 0, z + 1 < dims[2]};
        for (int k = 0; k < 6; ++k)
            if (ok[k] && cell[nb[k]] == 1) {
                cell[nb[k]] = 2;
                queue[tail++] = (uint32_t)nb[k];
            }
    }
    free(cell);
    free(queue);
    return found;
}

/* Lights the component of the voxel holding p, or, when that voxel is
 * solid, the components its light reaches (light_in_solid; without the
 * scene, or where that finds none, every air voxel around it). Returns 0,
 * or -1 when there is no air there at all. A point outside the grid lights
 * the outside. */
static int light_at(const lpv_reach *r, const lpv_scene *scene, const float p[3], unsigned char *lit)
{
    long v = voxel_at(r, p);
    if (v < 0) {
        lit[r->label[0]] = 1; /* voxel 0 is in the margin: outside air */
        return 0;
    }
    if (r->label[v]) {
        lit[r->label[v]] = 1;
        return 0;
    }
    if (scene && light_in_solid(r, scene, p, v, lit) > 0)
        return 0;
    return light_around(r, v, NULL, lit) ? 0 : -1;
}

int lpv_reach_light(lpv_reach *r, const lpv_scene *scene, const lpv_light *lights, size_t light_count)
{
    unsigned char *lit = calloc((size_t)r->components + 1, 1);
    if (!lit || !r->label || !r->mask) {
        free(lit);
        const int changed = !r->unsure;
        r->unsure = 1;
        r->lit_box = 0;
        return changed;
    }
    int unsure = 0;
    for (size_t i = 0; i < light_count; ++i) {
        const lpv_light *l = &lights[i];
        if (l->type == LPV_LIGHT_DIRECTIONAL)
            lit[r->label[0]] = 1;
        else if (light_at(r, scene, l->position, lit) != 0)
            unsure = 1;
    }
    /* An emitter lights the air voxels next to its centroid's voxel on each
     * side (of the 26 around it, those on that side of the triangle). A side
     * closer to a surface than a voxel (a panel flush on a ceiling) finds
     * none and lights nothing: its light goes into that surface. */
    for (size_t i = 0; i < r->emitter_seed_count; ++i) {
        const float *c = &r->emitter_seeds[6 * i];
        const long v = voxel_at(r, c);
        if (v >= 0)
            light_around(r, v, c + 3, lit);
    }
    lit[0] = 0; /* solid: never read */
    if (r->lit && unsure == r->unsure && memcmp(lit, r->lit, (size_t)r->components + 1) == 0) {
        free(lit);
        return 0;
    }
    free(r->lit);
    r->lit = lit;
    r->unsure = unsure;
    r->lit_components = 0;
    r->solid_voxels = r->dark_voxels = r->lit_voxels = 0;
    for (uint32_t c = 1; c <= r->components; ++c)
        r->lit_components += lit[c];
    /* in the same pass, the lit air's box and the faces between it and
     * solid voxels (its free path; lit_box, lit_min, lit_max) */
    int lo[3] = {r->dims[0], r->dims[1], r->dims[2]}, hi[3] = {-1, -1, -1};
    size_t faces = 0;
    for (int z = 0; z < r->dims[2]; ++z)
        for (int y = 0; y < r->dims[1]; ++y)
            for (int x = 0; x < r->dims[0]; ++x) {
                const size_t v = voxel_index(r, x, y, z);
                const uint32_t l = r->label[v];
                r->mask[v] = !l ? LPV_REACH_SOLID : (lit[l] || r->unsure) ? LPV_REACH_LIT : LPV_REACH_DARK;
                r->solid_voxels += !l;
                r->dark_voxels += r->mask[v] == LPV_REACH_DARK;
                if (r->mask[v] != LPV_REACH_LIT)
                    continue;
                r->lit_voxels++;
                const int c[3] = {x, y, z};
                for (int k = 0; k < 3; ++k) {
                    lo[k] = c[k] < lo[k] ? c[k] : lo[k];
                    hi[k] = c[k] > hi[k] ? c[k] : hi[k];
                    for (int sgn = -1; sgn <= 1; sgn += 2) {
                        int q[3] = {x, y, z};
                        q[k] += sgn;
                        faces += q[k] >= 0 && q[k] < r->dims[k] && r->label[voxel_index(r, q[0], q[1], q[2])] == 0;
                    }
                }
            }
    r->lit_box = !r->unsure && r->lit_voxels > 0;
    for (int k = 0; k < 3 && r->lit_box; ++k) {
        r->lit_min[k] = r->origin[k] + r->voxel * (float)(lo[k] - 1);
        r->lit_max[k] = r->origin[k] + r->voxel * (float)(hi[k] + 2);
    }
    r->lit_free_path =
        r->lit_box && faces ? (float)(4.0 * (double)r->lit_voxels * (double)r->voxel / (double)faces) : 0.0f;
    return 1;
}

float lpv_reach_at(const lpv_reach *r, const float p[3], const float n[3])
{
    if (!r->mask || r->unsure)
        return 1.0f;
    static const float steps[] = {0.75f, 1.5f, 2.5f, 3.5f};
    for (size_t i = 0; i < sizeof steps / sizeof steps[0]; ++i) {
        float q[3];
        for (int k = 0; k < 3; ++k)
            q[k] = p[k] + n[k] * steps[i] * r->voxel;
        long v = voxel_at(r, q);
        if (v < 0)
            return 1.0f;
        if (r->mask[v] != LPV_REACH_SOLID)
            return r->mask[v] == LPV_REACH_LIT ? 1.0f : 0.0f;
    }
    /* a corner: the 27 voxels around 2 voxels along n */
    int c[3];
    for (int k = 0; k < 3; ++k)
        c[k] = (int)floor(((double)p[k] + 2.0 * (double)n[k] * (double)r->voxel - (double)r->origin[k]) /
                          (double)r->voxel);
    int dark = 0;
    for (int k = 0; k < 27; ++k) {
        const int x = c[0] + k % 3 - 1, y = c[1] + (k / 3) % 3 - 1, z = c[2] + k / 9 - 1;
        if (x < 0 || y < 0 || z < 0 || x >= r->dims[0] || y >= r->dims[1] || z >= r->dims[2])
            continue;
        const uint8_t m = r->mask[voxel_index(r, x, y, z)];
        if (m == LPV_REACH_LIT)
            return 1.0f;
        dark |= m == LPV_REACH_DARK;
    }
    return dark ? 0.0f : 1.0f;
}

int lpv_reach_lit_at(const lpv_reach *r, const float p[3])
{
    if (!r->mask || r->unsure)
        return 0;
    const long v = voxel_at(r, p);
    return r->mask[v >= 0 ? (size_t)v : 0] == LPV_REACH_LIT; /* outside the grid: the margin's air, voxel 0 */
}

int lpv_reach_solid_within(const lpv_reach *r, const float p[3], float within)
{
    if (!r->label || !(r->voxel > 0.0f))
        return 1;
    const float v = r->voxel;
    int lo[3], hi[3];
    for (int i = 0; i < 3; ++i) {
        lo[i] = (int)floorf((p[i] - within - r->origin[i]) / v);
        hi[i] = (int)floorf((p[i] + within - r->origin[i]) / v);
        if (lo[i] < 0)
            lo[i] = 0;
        if (hi[i] > r->dims[i] - 1)
            hi[i] = r->dims[i] - 1;
        if (hi[i] - lo[i] > 2 * LPV_REACH_SEARCH_MAX)
            return 1;
    }
    for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
            for (int x = lo[0]; x <= hi[0]; ++x) {
                if (r->label[voxel_index(r, x, y, z)] != 0)
                    continue; /* air */
                const int idx[3] = {x, y, z};
                float d2 = 0.0f;
                for (int i = 0; i < 3; ++i) {
                    const float b0 = r->origin[i] + v * (float)idx[i], b1 = b0 + v;
                    const float out = p[i] < b0 ? b0 - p[i] : (p[i] > b1 ? p[i] - b1 : 0.0f);
                    d2 += out * out;
                }
                if (d2 <= within * within)
                    return 1;
            }
    return 0;
}

/* How far from o (a point inside the grid, in voxels) along unit w a ray
 * runs before it enters a solid voxel, in voxels (Amanatides & Woo);
 * INFINITY when it leaves the grid first. */
static double free_run(const lpv_reach *r, const double o[3], const float w[3])
{
    int q[3], st[3];
    double next[3], step[3];
    for (int a = 0; a < 3; ++a) {
        q[a] = (int)floor(o[a]);
        st[a] = w[a] > 0.0f ? 1 : -1;
        step[a] = fabs((double)w[a]) > 1e-12 ? 1.0 / fabs((double)w[a]) : INFINITY;
        next[a] = w[a] > 0.0f ? ((double)q[a] + 1.0 - o[a]) * step[a] : (o[a] - (double)q[a]) * step[a];
    }
    double t = 0.0;
    for (;;) {
        for (int a = 0; a < 3; ++a)
            if (q[a] < 0 || q[a] >= r->dims[a])
                return INFINITY;
        if (r->label[voxel_index(r, q[0], q[1], q[2])] == 0)
            return t;
        const int a = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
        t = next[a];
        next[a] += step[a];
        q[a] += st[a];
    }
}

static int compare_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

float lpv_reach_view_chord(const lpv_reach *r, const float p[3])
{
    if (!r->label || !(r->voxel > 0.0f))
        return 0.0f;
    const long v = voxel_at(r, p);
    if (v < 0 || r->label[v] == 0)
        return 0.0f;
    double o[3], run[LPV_REACH_VIEW_RAYS];
    for (int k = 0; k < 3; ++k)
        o[k] = ((double)p[k] - (double)r->origin[k]) / (double)r->voxel;
    for (uint32_t j = 0; j < LPV_REACH_VIEW_RAYS; ++j) {
        float w[3];
        lpv_iv_ray(1u, 0u, j, LPV_REACH_VIEW_RAYS, w);
        const float back[3] = {-w[0], -w[1], -w[2]};
        run[j] = free_run(r, o, w) + free_run(r, o, back);
    }
    qsort(run, LPV_REACH_VIEW_RAYS, sizeof run[0], compare_double);
    const double median = 0.5 * (run[LPV_REACH_VIEW_RAYS / 2 - 1] + run[LPV_REACH_VIEW_RAYS / 2]);
    return isfinite(median) ? (float)(median * (double)r->voxel) : INFINITY;
}

void lpv_reach_free(lpv_reach *r)
{
    free(r->label);
    free(r->mask);
    free(r->emitter_seeds);
    free(r->lit);
    memset(r, 0, sizeof *r);
}
