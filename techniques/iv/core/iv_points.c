/*
 * iv_points.c - the imperfect volume's point cloud (see iv_points.h).
 */
#include "iv_points.h"
#include "material_sample.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A piece of a triangle: its corners in the triangle's barycentric
 * coordinates, so the pieces interpolate the original vertex normals. */
typedef struct piece {
    double b[3][3];
} piece;

typedef struct walk {
    const lpv_scene *scene;
    const lpv_vertex *v[3];
    float front[3];
    double limit;          /* m: the longest edge a piece may keep */
    const float *box_min, *box_max; /* NULL: every piece */
    size_t pieces;         /* counted or written so far */
    /* writing (NULL when counting) */
    struct IvPoint *out;
    size_t count, max;
    int n;
    uint32_t seed;
    const lpv_material *m;
    int vertex_color; /* the draw's lpv_draw.vertex_color */
    int emission;
    float voxel;          /* m, the volume's voxel side (BLEND's draw per voxel) */
    float origin[3];      /* m, a corner of the volume's voxels (the box's, else the world's origin) */
} walk;

/* The draw u for a BLEND surface's points in the voxel holding p (core/
 * material_sample.h lpv_material_covers_at): one per voxel, so a voxel's
 * points of a surface of alpha a all stay or all go, and the voxels a
 * translucent pane passes through are occupied with probability a (iv's
 * voxels block or not; a fraction 1 - a of them lets its rays through). */
static float voxel_draw(const walk *w, const float p[3])
{
    uint32_t h = w->seed ^ 0xb5297a4du;
    for (int i = 0; i < 3; ++i) {
        const double c = w->voxel > 0.0f ? floor((double)(p[i] - w->origin[i]) / (double)w->voxel) : 0.0;
        h = lpv_hash_u32(h ^ (uint32_t)(int32_t)(isfinite(c) && fabs(c) < 1e9 ? c : 0.0));
    }
    return lpv_hash_unit(h);
}

/* One triangle's splitting (lpv_iv_split_triangle). */
typedef struct splitter {
    const float *p[3];     /* the triangle's corners, world */
    double limit;
    const float *box_min, *box_max; /* NULL: keep every piece */
    lpv_iv_piece_fn fn;
    void *user;
    size_t pieces;
} splitter;

static void world_of(const splitter *sp, const double b[3], double p[3])
{
    for (int i = 0; i < 3; ++i)
        p[i] = b[0] * sp->p[0][i] + b[1] * sp->p[1][i] + b[2] * sp->p[2][i];
}

static double dist(const double a[3], const double b[3])
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

/* Splits across the longest edge until every edge is within the limit; the
 * depth bound keeps a huge triangle (the budget's coarser split catches it)
 * from recursing without end. */
static void split(splitter *sp, const piece *pc, int depth)
{
    double p[3][3];
    for (int i = 0; i < 3; ++i)
        world_of(sp, pc->b[i], p[i]);
    if (sp->box_min) /* a piece wholly outside the box, and all its halves, go */
        for (int i = 0; i < 3; ++i)
            if (fmax(fmax(p[0][i], p[1][i]), p[2][i]) < (double)sp->box_min[i] ||
                fmin(fmin(p[0][i], p[1][i]), p[2][i]) > (double)sp->box_max[i])
                return;
    int longest = 0;
    double best = -1.0;
    for (int e = 0; e < 3; ++e) {
        double d = dist(p[e], p[(e + 1) % 3]);
        if (d > best) {
            best = d;
            longest = e;
        }
    }
    if (!(best > sp->limit) || depth >= 40) {
        if (sp->fn)
            sp->fn(pc->b, sp->user);
        sp->pieces++;
        return;
    }
    const int a = longest, b = (longest + 1) % 3, c = (longest + 2) % 3;
    double mid[3];
    for (int i = 0; i < 3; ++i)
        mid[i] = 0.5 * (pc->b[a][i] + pc->b[b][i]);
    piece l = *pc, r = *pc;
    memcpy(l.b[b], mid, sizeof mid); /* (a, mid, c) */
    memcpy(r.b[a], mid, sizeof mid); /* (mid, b, c) */
    (void)c;
    split(sp, &l, depth + 1);
    split(sp, &r, depth + 1);
}

size_t lpv_iv_split_triangle(const float a[3], const float b[3], const float c[3], double limit, lpv_iv_piece_fn fn,
                             void *user)
{
    return lpv_iv_split_triangle_in(a, b, c, limit, NULL, NULL, fn, user);
}

size_t lpv_iv_split_triangle_in(const float a[3], const float b[3], const float c[3], double limit,
                                const float box_min[3], const float box_max[3], lpv_iv_piece_fn fn, void *user)
{
    splitter sp = {{a, b, c}, limit, box_min && box_max ? box_min : NULL, box_min && box_max ? box_max : NULL, fn,
                   user, 0};
    piece whole = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    split(&sp, &whole, 0);
    return sp.pieces;
}

static void turk(uint32_t seed, uint32_t key, int k, double *b0, double *b1, double *b2)
{
    uint32_t h = lpv_hash_u32(seed ^ lpv_hash_u32(key * 0x9e3779b1u + (uint32_t)k));
    double r1 = lpv_hash_unit(h), r2 = lpv_hash_unit(lpv_hash_u32(h ^ 0x85ebca6bu));
    double s = sqrt(r1);
    *b0 = 1.0 - s;
    *b1 = (1.0 - r2) * s;
    *b2 = r2 * s;
}

static void emit_piece(walk *w, const double pb[3][3])
{
    /* the area each of the piece's points stands for (LPV_IV_COVER) */
    double corner[3][3], e1[3], e2[3];
    for (int c = 0; c < 3; ++c)
        for (int i = 0; i < 3; ++i)
            corner[c][i] = pb[c][0] * w->v[0]->position[i] + pb[c][1] * w->v[1]->position[i] +
                           pb[c][2] * w->v[2]->position[i];
    for (int i = 0; i < 3; ++i) {
        e1[i] = corner[1][i] - corner[0][i];
        e2[i] = corner[2][i] - corner[0][i];
    }
    const double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2],
                 cz = e1[0] * e2[1] - e1[1] * e2[0];
    const double piece_area = 0.5 * sqrt(cx * cx + cy * cy + cz * cz);
    const float point_area = w->n > 0 && isfinite(piece_area) ? (float)(piece_area / w->n) : 0.0f;
    for (int k = 0; k < w->n && w->count < w->max; ++k) {
        double t0, t1, t2;
        turk(w->seed, (uint32_t)w->pieces, k, &t0, &t1, &t2);
        double b[3];
        for (int i = 0; i < 3; ++i)
            b[i] = t0 * pb[0][i] + t1 * pb[1][i] + t2 * pb[2][i];
        struct IvPoint *o = &w->out[w->count++];
        memset(o, 0, sizeof *o);
        double n[3] = {0, 0, 0}, len2 = 0.0;
        for (int i = 0; i < 3; ++i) {
            o->position[i] = (float)(b[0] * w->v[0]->position[i] + b[1] * w->v[1]->position[i] +
                                     b[2] * w->v[2]->position[i]);
            n[i] = b[0] * w->v[0]->normal[i] + b[1] * w->v[1]->normal[i] + b[2] * w->v[2]->normal[i];
            len2 += n[i] * n[i];
        }
        /* the file's normals where they are usable and agree with the front
         * side, else the winding's */
        double dot = n[0] * w->front[0] + n[1] * w->front[1] + n[2] * w->front[2];
        const int usable = isfinite(len2) && len2 > 1e-12 && dot > 0.0;
        /* the material at the point (its textures: core/material_sample.h) */
        float uv0[2] = {0, 0}, uv1[2] = {0, 0}, col[4] = {0, 0, 0, 0}, albedo[3] = {1, 1, 1}, emission[3] = {0, 0, 0};
        for (int j = 0; j < 3; ++j) {
            for (int c = 0; c < 2; ++c) {
                uv0[c] += (float)b[j] * w->v[j]->uv[c];
                uv1[c] += (float)b[j] * w->v[j]->uv1[c];
            }
            for (int c = 0; c < 4; ++c)
                col[c] += (float)b[j] * w->v[j]->color[c];
        }
        if (w->m && !lpv_material_covers_at(w->scene, w->m, uv0, uv1, w->vertex_color ? col[3] : 1.0f,
                                            voxel_draw(w, o->position))) {
            w->count--; /* a cut-away texel or a voxel BLEND's coverage left empty: no surface there */
            continue;
        }
        if (w->m) {
            lpv_material_albedo_at(w->scene, w->m, uv0, uv1, w->vertex_color ? col : NULL, albedo);
            if (w->emission)
                lpv_material_emission_at(w->scene, w->m, uv0, uv1, emission);
        }
        for (int i = 0; i < 3; ++i) {
            o->normal[i] = usable ? (float)(n[i] / sqrt(len2)) : w->front[i];
            o->albedo[i] = albedo[i];
            o->emission[i] = emission[i];
        }
        o->position[3] = 1.0f;
        o->normal[3] = point_area;
    }
}

/* A piece of the walk's triangle: its points (when writing), then the count
 * that keys the next piece's points. */
static void walk_piece(const double b[3][3], void *user)
{
    walk *w = user;
    if (w->out)
        emit_piece(w, b);
    w->pieces++;
}

/* Runs the walk over every non-degenerate triangle: counts pieces (w->out
 * NULL) or writes points. */
static void walk_scene(walk *w)
{
    const lpv_scene *s = w->scene;
    for (uint32_t d = 0; d < s->draw_count; ++d) {
        const lpv_draw *dr = &s->draws[d];
        w->m = dr->material >= 0 && (uint32_t)dr->material < s->material_count ? &s->materials[dr->material] : NULL;
        w->vertex_color = dr->vertex_color;
        for (uint32_t t = 0; t + 3 <= dr->index_count; t += 3) {
            double area;
            if (dr->first_index + t + 3 > s->index_count ||
                !lpv_scene_triangle(s, dr->first_index + t, w->v, w->front, &area))
                continue;
            lpv_iv_split_triangle_in(w->v[0]->position, w->v[1]->position, w->v[2]->position, w->limit, w->box_min,
                                     w->box_max, walk_piece, w);
        }
    }
}

static size_t count_triangles(const lpv_scene *s)
{
    size_t n = 0;
    for (uint32_t d = 0; d < s->draw_count; ++d) {
        const lpv_draw *dr = &s->draws[d];
        for (uint32_t t = 0; t + 3 <= dr->index_count; t += 3) {
            const lpv_vertex *v[3];
            float f[3];
            double area;
            if (dr->first_index + t + 3 <= s->index_count && lpv_scene_triangle(s, dr->first_index + t, v, f, &area))
                ++n;
        }
    }
    return n;
}

int lpv_iv_points_make(const lpv_scene *scene, const lpv_iv_point_params *p, struct IvPoint **out, size_t *count,
                       lpv_iv_point_stats *stats)
{
    *out = NULL;
    *count = 0;
    lpv_iv_point_stats st = {0};
    st.triangles = count_triangles(scene);
    st.split = p->split > 0.0f ? p->split : 1.0f;
    st.points_per_piece = p->points > 0 ? p->points : 1;
    const size_t budget = p->max_points > 0 ? p->max_points : 1;
    /* the pieces at this split; coarser splits until one point each fits */
    walk w = {.scene = scene,
              .box_min = p->has_box ? p->box_min : NULL,
              .box_max = p->has_box ? p->box_max : NULL,
              .voxel = p->voxel};
    for (int i = 0; p->has_box && i < 3; ++i)
        w.origin[i] = p->box_min[i];
    for (;;) {
        w.limit = (double)st.split * (double)p->voxel;
        w.pieces = 0;
        walk_scene(&w);
        if (w.pieces <= budget || !(w.limit > 0.0) || st.split > 1e6f)
            break;
        st.split *= 2.0f;
        st.budget_cut = 1;
    }
    st.pieces = w.pieces;
    if (st.pieces * (size_t)st.points_per_piece > budget) {
        st.points_per_piece = (int)(budget / (st.pieces ? st.pieces : 1));
        if (st.points_per_piece < 1)
            st.points_per_piece = 1;
        st.budget_cut = 1;
    }
    size_t max = st.pieces * (size_t)st.points_per_piece;
    if (max > budget)
        max = budget;
    if (max > 0) {
        w.out = malloc(max * sizeof **out);
        if (!w.out)
            return -1;
        w.max = max;
        w.n = st.points_per_piece;
        w.seed = p->seed;
        w.emission = p->emission;
        w.pieces = 0;
        walk_scene(&w);
    }
    st.points = w.count;
    *out = w.out;
    *count = w.count;
    if (stats)
        *stats = st;
    return 0;
}

void lpv_iv_triangle_points(const float a[3], const float b[3], const float c[3], int n, uint32_t seed, uint32_t key,
                            float *out)
{
    for (int k = 0; k < n; ++k) {
        double t0, t1, t2;
        turk(seed, key, k, &t0, &t1, &t2);
        for (int i = 0; i < 3; ++i)
            out[3 * k + i] = (float)(t0 * a[i] + t1 * b[i] + t2 * c[i]);
    }
}

int lpv_iv_place(const lpv_settings *s, const float smin[3], const float smax[3], float free_path, lpv_grid *out)
{
    const int given = lpv_settings_bounds_given(s);
    const float *lo = given ? s->bounds_min : smin, *hi = given ? s->bounds_max : smax;
    int res = s->iv.resolution;
    double longest = 0.0;
    for (int i = 0; i < 3; i++)
        longest = fmax(longest, (double)hi[i] - (double)lo[i]);
    const double want = free_path > 0.0f && longest > LPV_IV_LONG_FREE_PATHS * (double)free_path
                            ? longest / ((double)free_path / LPV_IV_FREE_PATH_VOXELS)
                            : 0.0;
    if (isfinite(want) && want > (double)res) {
        /* the finest resolution up to `want` whose grid fits the cube's budget */
        const double budget = pow((double)s->iv.resolution + 1.0, 3.0);
        int lo_r = res, hi_r = (int)fmin(ceil(want), (double)LPV_MAX_GRID_DIM);
        while (lo_r < hi_r) {
            const int mid = lo_r + (hi_r - lo_r + 1) / 2;
            lpv_grid g;
            if (lpv_grid_place_cubic(mid, lo, hi, &g) == 0 && (double)lpv_grid_cell_count(&g) <= budget)
                lo_r = mid;
            else
                hi_r = mid - 1;
        }
        res = lo_r;
    }
    return lpv_grid_place_cubic(res, lo, hi, out);
}

lpv_iv_point_params lpv_iv_point_params_of(const lpv_settings *s, const lpv_grid *g)
{
    lpv_iv_point_params p = {.voxel = g->cell_size,
                             .points = s->iv.points,
                             .split = s->iv.split,
                             .seed = (uint32_t)s->iv.seed,
                             .max_points = (size_t)s->iv.max_points,
                             .emission = 1,
                             .has_box = 1};
    for (int i = 0; i < 3; ++i) {
        p.box_min[i] = g->origin[i];
        p.box_max[i] = g->origin[i] + (float)g->dims[i] * g->cell_size;
    }
    return p;
}
