/*
 * oracle_iv.c - reference imperfect volumes (see oracle_iv.h): literal loops
 * over voxels, rays and corners, sums in double.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "oracle_iv.h"
#include "sh.h"

#define IV_PI 3.14159265358979323846

/* ---- small helpers --------------------------------------------------------- */

static void basis(const float d[3], float y[4])
{
    y[0] = LPV_SH_C0;
    y[1] = LPV_SH_C1 * d[1];
    y[2] = LPV_SH_C1 * d[2];
    y[3] = LPV_SH_C1 * d[0];
}

static void hemi(const float n[3], float h[4])
{
    h[0] = LPV_IV_HEMI0;
    h[1] = LPV_IV_HEMI1 * n[1];
    h[2] = LPV_IV_HEMI1 * n[2];
    h[3] = LPV_IV_HEMI1 * n[0];
}

static float *channel(lpv_cell *c, int ch) { return ch == 0 ? c->r : ch == 1 ? c->g : c->b; }

static const float *cchannel(const lpv_cell *c, int ch) { return ch == 0 ? c->r : ch == 1 ? c->g : c->b; }

static float dot4(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]; }

static int finite3(const float *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

/* The centre of voxel v along one axis, in float. */
static float centre_of(const lpv_grid *g, int axis, int v)
{
    return g->origin[axis] + ((float)v + 0.5f) * g->cell_size;
}

/* The range test happens on the float before the int conversion, so no
 * position (huge, Inf, NaN) can make an out-of-range conversion. */
int lpv_iv_voxel_of(const lpv_grid *g, const float p[3], int cell[3])
{
    for (int a = 0; a < 3; a++) {
        float fc = floorf((p[a] - g->origin[a]) / g->cell_size);
        if (!(fc >= 0.0f && fc < (float)g->dims[a]))
            return 0;
        cell[a] = (int)fc;
    }
    return 1;
}

/* p in voxels from the grid's corner, moved LPV_IV_BEHIND against unit n
 * (iv_volume.glsl's iv_coords_of). */
static void surface_coords(const lpv_grid *g, const float p[3], const float n[3], float u[3])
{
    float nh[3] = {0.0f, 0.0f, 0.0f};
    if (!lpv_unit_direction(n, nh))
        nh[0] = nh[1] = nh[2] = 0.0f;
    for (int a = 0; a < 3; a++)
        u[a] = (p[a] - g->origin[a]) / g->cell_size - LPV_IV_BEHIND * nh[a];
}

int lpv_iv_surface_voxel_of(const lpv_grid *g, const float p[3], const float n[3], int cell[3])
{
    float u[3];
    surface_coords(g, p, n, u);
    for (int a = 0; a < 3; a++) {
        float fc = floorf(u[a]);
        if (!(fc >= 0.0f && fc < (float)g->dims[a]))
            return 0;
        cell[a] = (int)fc;
    }
    return 1;
}

/* 1 when any voxel of the 3x3x3 block around (x, y, z), itself included and
 * clipped to the grid, is occupied. */
/* 1 when voxel (x, y, z) is inside the grid and holds a surface. */
static int occupied_at(const lpv_grid *g, const lpv_iv_voxel *voxels, int x, int y, int z)
{
    return x >= 0 && y >= 0 && z >= 0 && x < g->dims[0] && y < g->dims[1] && z < g->dims[2] &&
           lpv_iv_occupied(&voxels[lpv_grid_index(g, x, y, z)]);
}

static int near_occupied(const lpv_grid *g, const lpv_iv_voxel *voxels, int x, int y, int z)
{
    for (int dz = -1; dz <= 1; dz++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++)
                if (occupied_at(g, voxels, x + dx, y + dy, z + dz))
                    return 1;
    return 0;
}

/* ---- Creation (3.1) -------------------------------------------------------- */

/* Accumulators per voxel: 12 SH, 3 normal, 3 albedo, 1 count, 3 folded normal. */
/* per voxel: 12 SH, normal (3), albedo (3), count, fold (3), area, signed area,
 * greatest place (3), 1 - least place (3) */
#define ACC 30

/* LPV_IV_FOLD (lpv_shared.h): n times the sign of its largest component,
 * ties x before y before z, as iv_splat.vert folds it. */
static float fold(const float n[3], float out[3])
{
    const float ax = fabsf(n[0]), ay = fabsf(n[1]), az = fabsf(n[2]);
    const float major = ax >= ay && ax >= az ? n[0] : ay >= az ? n[1] : n[2];
    const float s = major >= 0.0f ? 1.0f : -1.0f;
    for (int k = 0; k < 3; k++)
        out[k] = s * n[k];
    return s;
}

int lpv_iv_create(const lpv_grid *g, const lpv_iv_point *points, const float (*radiosity)[3], size_t n,
                  lpv_iv_voxel *voxels, size_t *taken)
{
    size_t cells = lpv_grid_cell_count(g);
    memset(voxels, 0, cells * sizeof *voxels);
    if (taken)
        *taken = 0;
    double *acc = calloc(cells, ACC * sizeof *acc);
    if (!acc)
        return -1;
    size_t used = 0;
    for (size_t i = 0; i < n; i++) {
        const lpv_iv_point *pt = &points[i];
        const float zero[3] = {0.0f, 0.0f, 0.0f};
        const float *B = radiosity ? radiosity[i] : zero;
        if (pt->position[3] == 0.0f || !finite3(pt->position) || !finite3(pt->normal) || !finite3(pt->albedo) ||
            !finite3(B))
            continue;
        int v[3];
        if (!lpv_iv_surface_voxel_of(g, pt->position, pt->normal, v))
            continue;
        double *a = &acc[ACC * lpv_grid_index(g, v[0], v[1], v[2])];
        float h[4];
        hemi(pt->normal, h);
        for (int ch = 0; ch < 3; ch++)
            for (int k = 0; k < 4; k++)
                a[4 * ch + k] += (double)B[ch] * (double)h[k];
        float f[3];
        const float fs = fold(pt->normal, f);
        const float area = pt->normal[3] >= 0.0f && isfinite(pt->normal[3]) ? pt->normal[3] : 0.0f;
        float u[3];
        surface_coords(g, pt->position, pt->normal, u);
        for (int k = 0; k < 3; k++) {
            a[12 + k] += pt->normal[k];
            a[15 + k] += pt->albedo[k];
            a[19 + k] += f[k];
            float local = u[k] - (float)v[k];
            local = local < 0.0f ? 0.0f : local > 1.0f ? 1.0f : local;
            a[24 + k] = local > a[24 + k] ? local : a[24 + k];
            a[27 + k] = 1.0f - local > a[27 + k] ? 1.0f - local : a[27 + k];
        }
        a[18] += 1.0;
        a[22] += area;
        a[23] += fs * area;
        used++;
    }
    for (size_t c = 0; c < cells; c++) {
        const double *a = &acc[ACC * c];
        if (a[18] == 0.0)
            continue;
        lpv_iv_voxel *o = &voxels[c];
        for (int k = 0; k < 4; k++) {
            o->r[k] = (float)(a[k] / a[18]);
            o->g[k] = (float)(a[4 + k] / a[18]);
            o->b[k] = (float)(a[8 + k] / a[18]);
        }
        for (int k = 0; k < 3; k++) {
            o->normal[k] = (float)(a[12 + k] / a[18]);
            o->albedo[k] = (float)(a[15 + k] / a[18]);
            o->fold[k] = (float)(a[19 + k] / a[18]);
        }
        o->normal[3] = (float)a[18];
        /* LPV_IV_COVER: the cloud's area over a voxel face's, plain and
         * signed; the points' extent, widened by (N + 1) / (N - 1) */
        const double face = 1.0 / ((double)g->cell_size * (double)g->cell_size);
        o->albedo[3] = (float)(a[22] * face);
        o->fold[3] = (float)(a[23] * face);
        const float widen = a[18] >= 2.0 ? (float)((a[18] + 1.0) / (a[18] - 1.0)) : 0.0f;
        float span[3], lo[3], hi[3];
        for (int k = 0; k < 3; k++) {
            hi[k] = (float)a[24 + k];
            lo[k] = 1.0f - (float)a[27 + k];
            span[k] = hi[k] - lo[k];
            const float e = span[k] * widen;
            o->extent[k] = e < 0.0f ? 0.0f : e > 1.0f ? 1.0f : e;
        }
        /* LPV_IV_SLAB: across the axis the points' folded normals agree on, if they lie thin on it */
        const float fx = fabsf(o->fold[0]), fy = fabsf(o->fold[1]), fz = fabsf(o->fold[2]);
        const int axis = fx >= fy && fx >= fz ? 0 : fy >= fz ? 1 : 2;
        o->slab[0] = -1.0f;
        if (fabsf(o->fold[axis]) >= LPV_IV_FLAT && span[axis] <= LPV_IV_SLAB_MAX) {
            o->slab[0] = (float)axis;
            o->slab[1] = lo[axis];
            o->slab[2] = hi[axis];
        }
    }
    free(acc);
    if (taken)
        *taken = used;
    return 0;
}

/* ---- Reconstruction (3.4) -------------------------------------------------- */

/* Which voxels hold a surface: the created voxels (lpv_iv_occupied) or one
 * flag per voxel (non-zero: holds one, as a volume's index on the wire, SPEC
 * R5.14); neither: none does. */
typedef struct held_by {
    const lpv_iv_voxel *voxels;
    const uint32_t *flags;
} held_by;

static int holds(const held_by *h, size_t i)
{
    return h->voxels ? lpv_iv_occupied(&h->voxels[i]) : h->flags ? h->flags[i] != 0 : 0;
}

/* The corners reconstruction blends at p for n, and their weights w_c (not
 * yet divided by the sum). Returns how many were written to index[] and
 * weight[] (at most 8); 0 when nothing contributes. */
static int corners(const lpv_grid *g, const held_by *held, const float p[3], const float n[3], int neighbours,
                   size_t index[8], double weight[8])
{
    float nh[3];
    if (!finite3(p) || !lpv_unit_direction(n, nh))
        return 0;
    const float s = g->cell_size;
    float f[3];
    int base[3];
    for (int a = 0; a < 3; a++) {
        float q = p[a] + 0.5f * s * nh[a];
        float u = (q - g->origin[a]) / s - 0.5f;
        /* base and base + 1 both outside the grid (or u not finite): nothing */
        if (!(u >= -1.0f && u < (float)g->dims[a]))
            return 0;
        float b = floorf(u);
        base[a] = (int)b;
        f[a] = u - b;
    }
    /* the corners by distance to q, then index (insertion sort, stable) */
    int order[8];
    float d2[8];
    for (int c = 0; c < 8; c++) {
        d2[c] = 0.0f;
        for (int a = 0; a < 3; a++) {
            float e = f[a] - (float)((c >> a) & 1);
            d2[c] += e * e;
        }
        int k = c;
        while (k > 0 && d2[order[k - 1]] > d2[c]) {
            order[k] = order[k - 1];
            k--;
        }
        order[k] = c;
    }
    if (neighbours < 1)
        neighbours = 1;
    if (neighbours > 8)
        neighbours = 8;
    int m = 0;
    for (int r = 0; r < neighbours; r++) {
        const int c = order[r];
        int v[3], inside = 1;
        for (int a = 0; a < 3; a++) {
            v[a] = base[a] + ((c >> a) & 1);
            inside &= v[a] >= 0 && v[a] < g->dims[a];
        }
        if (!inside)
            continue;
        float t = 1.0f;
        for (int a = 0; a < 3; a++)
            t *= (c >> a) & 1 ? f[a] : 1.0f - f[a];
        float d[3];
        for (int a = 0; a < 3; a++)
            d[a] = centre_of(g, a, v[a]) - p[a];
        float len = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        float cosine = 0.0f;
        if (len > 0.0f)
            cosine = nh[0] * (d[0] / len) + nh[1] * (d[1] / len) + nh[2] * (d[2] / len);
        float w = t * (cosine > 0.0f ? cosine : 0.0f);
        const size_t vi = lpv_grid_index(g, v[0], v[1], v[2]);
        if (holds(held, vi))
            w *= LPV_IV_HELD_WEIGHT;
        if (!(w > 0.0f))
            continue;
        index[m] = vi;
        weight[m] = w;
        m++;
    }
    return m;
}

static void reconstruct(const lpv_grid *g, const held_by *held, const lpv_cell *vol, const float p[3], const float n[3],
                        int neighbours, lpv_cell *out)
{
    memset(out, 0, sizeof *out);
    size_t index[8];
    double weight[8], sum = 0.0, acc[3][4] = {{0.0}};
    int m = corners(g, held, p, n, neighbours, index, weight);
    for (int i = 0; i < m; i++) {
        sum += weight[i];
        for (int ch = 0; ch < 3; ch++)
            for (int k = 0; k < 4; k++)
                acc[ch][k] += weight[i] * cchannel(&vol[index[i]], ch)[k];
    }
    if (!(sum > 0.0))
        return;
    for (int ch = 0; ch < 3; ch++)
        for (int k = 0; k < 4; k++)
            channel(out, ch)[k] = (float)(acc[ch][k] / sum);
}

/* lobe(-n^) for a unit-able n; 0 and a zero lobe otherwise. */
static int lobe_minus(const float n[3], float lobe[4])
{
    float nh[3], m[3];
    if (!lpv_unit_direction(n, nh)) {
        memset(lobe, 0, 4 * sizeof *lobe);
        return 0;
    }
    m[0] = -nh[0];
    m[1] = -nh[1];
    m[2] = -nh[2];
    lpv_sh_cosine_lobe(m, lobe);
    return 1;
}

/* The 2-band irradiance e (any sign per channel) as light, one rule for the
 * whole colour, as iv_lookup.glsl's iv_physical: none where its luminance
 * y <= 0; else y kept and the chroma scaled by y / (y - 2 m), m the most
 * negative channel (1 where none is negative), so no channel is clipped to
 * exactly 0 while another stays lit. */
static void physical(const float e[3], float rgb[3])
{
    const float y = e[0] * LPV_IV_LUMA_R + e[1] * LPV_IV_LUMA_G + e[2] * LPV_IV_LUMA_B;
    if (!(y > 0.0f)) {
        rgb[0] = rgb[1] = rgb[2] = 0.0f;
        return;
    }
    float m = e[0] < e[1] ? e[0] : e[1];
    m = m < e[2] ? m : e[2];
    const float s = m >= 0.0f ? 1.0f : y / (y - 2.0f * m);
    for (int ch = 0; ch < 3; ch++)
        rgb[ch] = m >= 0.0f ? e[ch] : y + (e[ch] - y) * s;
}

static void irradiance(const lpv_grid *g, const held_by *held, const lpv_cell *vol, const float p[3], const float n[3],
                       int neighbours, float rgb[3])
{
    lpv_cell L;
    float lobe[4];
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    if (!lobe_minus(n, lobe))
        return;
    reconstruct(g, held, vol, p, n, neighbours, &L);
    float e[3];
    for (int ch = 0; ch < 3; ch++)
        e[ch] = dot4(cchannel(&L, ch), lobe);
    physical(e, rgb);
}

void lpv_iv_reconstruct(const lpv_grid *g, const lpv_iv_voxel *voxels, const lpv_cell *vol, const float p[3],
                        const float n[3], int neighbours, lpv_cell *out)
{
    const held_by held = {.voxels = voxels};
    reconstruct(g, &held, vol, p, n, neighbours, out);
}

void lpv_iv_reconstruct_held(const lpv_grid *g, const uint32_t *held, const lpv_cell *vol, const float p[3],
                             const float n[3], int neighbours, lpv_cell *out)
{
    const held_by by = {.flags = held};
    reconstruct(g, &by, vol, p, n, neighbours, out);
}

void lpv_iv_irradiance(const lpv_grid *g, const lpv_iv_voxel *voxels, const lpv_cell *vol, const float p[3],
                       const float n[3], int neighbours, float rgb[3])
{
    const held_by held = {.voxels = voxels};
    irradiance(g, &held, vol, p, n, neighbours, rgb);
}

void lpv_iv_irradiance_held(const lpv_grid *g, const uint32_t *held, const lpv_cell *vol, const float p[3],
                            const float n[3], int neighbours, float rgb[3])
{
    const held_by by = {.flags = held};
    irradiance(g, &by, vol, p, n, neighbours, rgb);
}

float lpv_iv_ao(const lpv_grid *g, const lpv_iv_voxel *voxels, const vec4 *ao, const float p[3], const float n[3],
                int neighbours)
{
    float lobe[4];
    if (!lobe_minus(n, lobe))
        return 1.0f;
    size_t index[8];
    double weight[8], sum = 0.0, acc[4] = {0.0};
    const held_by held = {.voxels = voxels};
    int m = corners(g, &held, p, n, neighbours, index, weight);
    for (int i = 0; i < m; i++) {
        sum += weight[i];
        for (int k = 0; k < 4; k++)
            acc[k] += weight[i] * ao[index[i]][k];
    }
    if (!(sum > 0.0))
        return 1.0f; /* nothing to blend: open, as the GPU lookup answers */
    float L[4];
    for (int k = 0; k < 4; k++)
        L[k] = (float)(acc[k] / sum);
    float a = dot4(L, lobe) / LPV_PI;
    return a > 1.0f ? 1.0f : a > 0.0f ? a : 0.0f;
}

/* ---- Emission per bounce --------------------------------------------------- */

/* The voxel's axis a and the share *front of its points facing it (the
 * rest face -a, if every normal is +-a): the mean normal m where the points
 * mostly agree (one surface, a corner), else the folded mean f (LPV_IV_FOLD:
 * a wall's two faces); *front = (1 + m.a) / 2. 0 where neither gives an
 * axis. As iv_emit.comp's iv_axis. */
static int axis_of(const lpv_iv_voxel *h, float a[3], float *front)
{
    const float *m = h->normal, *f = h->fold;
    const float lm = sqrtf(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    const float lf = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    const float *src = m;
    float len = lm;
    if (!(lm >= LPV_IV_ONE_SIDED * lf && lm > 1e-3f)) {
        if (!(lf > 1e-3f))
            return 0;
        src = f;
        len = lf;
    }
    for (int k = 0; k < 3; k++)
        a[k] = src[k] / len;
    const float c = 0.5f * (1.0f + (m[0] * a[0] + m[1] * a[1] + m[2] * a[2]));
    *front = c < 0.0f ? 0.0f : c > 1.0f ? 1.0f : c;
    return 1;
}

static float clampf(float x, float lo, float hi) { return x < lo ? lo : x > hi ? hi : x; }

/* How much of its mean radiance each side shows, *kf and *kb
 * (LPV_IV_COVER): where the points all lie along one axis and the cloud
 * gave their area, the part of the voxel face the side covers (its area
 * over LPV_IV_COVER_AREA of the face's, at most the points' extent across
 * the axis over LPV_IV_COVER_ACROSS), between its share and 1; elsewhere
 * c + t (1 - c), t = 1 - |m| / |f|. As iv_emit.comp's iv_cover. */
static void cover(const lpv_iv_voxel *h, const float a[3], float front, float *kf, float *kb)
{
    const float back = 1.0f - front;
    const float *m = h->normal, *f = h->fold;
    const float lm = sqrtf(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    const float lf = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    if (lf >= LPV_IV_FLAT && h->albedo[3] > 0.0f) {
        const float plus = 0.5f * (h->albedo[3] + h->fold[3]), minus = 0.5f * (h->albedo[3] - h->fold[3]);
        const int front_plus = a[0] * f[0] + a[1] * f[1] + a[2] * f[2] >= 0.0f;
        const float ax = fabsf(a[0]), ay = fabsf(a[1]), az = fabsf(a[2]);
        const float *e = h->extent;
        const float across = ax >= ay && ax >= az ? e[1] * e[2] : ay >= az ? e[0] * e[2] : e[0] * e[1];
        const float af = (front_plus ? plus : minus) / LPV_IV_COVER_AREA, ab = (front_plus ? minus : plus) / LPV_IV_COVER_AREA;
        const float x = across / LPV_IV_COVER_ACROSS;
        *kf = clampf(af < x ? af : x, front, 1.0f);
        *kb = clampf(ab < x ? ab : x, back, 1.0f);
        return;
    }
    const float t = lf > 1e-3f ? clampf(1.0f - lm / lf, 0.0f, 1.0f) : 0.0f;
    *kf = front + t * (1.0f - front);
    *kb = back + t * (1.0f - back);
}

/* One channel's SH e read along the axis as two hemispheres, B_f and B_b,
 * each shown at the part kf, kb of its mean radiance B / share (cover);
 * iv_emit.comp's iv_sides says why. */
static void sides(float e[4], const float a[3], float front, float back, float kf, float kb, const float hf[4],
                  const float hb[4])
{
    const float sum = e[0] / LPV_IV_HEMI0;
    if (!(sum > 0.0f))
        return;
    float diff = (e[3] * a[0] + e[1] * a[1] + e[2] * a[2]) / LPV_IV_HEMI1;
    diff = diff < -sum ? -sum : diff > sum ? sum : diff;
    const float bf = 0.5f * (sum + diff), bb = 0.5f * (sum - diff);
    float xf = kf / (front > LPV_IV_SIDE_MIN ? front : LPV_IV_SIDE_MIN) - 1.0f;
    float xb = kb / (back > LPV_IV_SIDE_MIN ? back : LPV_IV_SIDE_MIN) - 1.0f;
    xf = xf > 0.0f ? xf : 0.0f;
    xb = xb > 0.0f ? xb : 0.0f;
    for (int k = 0; k < 4; k++)
        e[k] += bf * xf * hf[k] + bb * xb * hb[k];
}

void lpv_iv_emit(const lpv_grid *g, const lpv_iv_voxel *voxels, const lpv_cell *incoming, int bounce, int neighbours,
                 lpv_cell *emit)
{
    for (int z = 0; z < g->dims[2]; z++) {
        for (int y = 0; y < g->dims[1]; y++) {
            for (int x = 0; x < g->dims[0]; x++) {
                size_t i = lpv_grid_index(g, x, y, z);
                const lpv_iv_voxel *h = &voxels[i];
                lpv_cell *e = &emit[i];
                memset(e, 0, sizeof *e);
                if (!lpv_iv_occupied(h))
                    continue;
                memcpy(e->r, h->r, sizeof e->r);
                memcpy(e->g, h->g, sizeof e->g);
                memcpy(e->b, h->b, sizeof e->b);
                float nh[3], front;
                if (!axis_of(h, nh, &front))
                    continue;
                const float back = 1.0f - front, nb[3] = {-nh[0], -nh[1], -nh[2]};
                float hf[4], hb[4];
                hemi(nh, hf);
                hemi(nb, hb);
                if (bounce > 1 && incoming) {
                    const float p[3] = {centre_of(g, 0, x), centre_of(g, 1, y), centre_of(g, 2, z)};
                    float Ef[3], Eb[3] = {0.0f, 0.0f, 0.0f};
                    lpv_iv_irradiance(g, voxels, incoming, p, nh, neighbours, Ef);
                    if (back > 0.0f)
                        lpv_iv_irradiance(g, voxels, incoming, p, nb, neighbours, Eb);
                    for (int ch = 0; ch < 3; ch++) {
                        float af = h->albedo[ch] * Ef[ch] * front, ab = h->albedo[ch] * Eb[ch] * back;
                        float *c = channel(e, ch);
                        for (int k = 0; k < 4; k++)
                            c[k] += af * hf[k] + ab * hb[k];
                    }
                }
                float kf, kb;
                cover(h, nh, front, &kf, &kb);
                for (int ch = 0; ch < 3; ch++)
                    sides(channel(e, ch), nh, front, back, kf, kb, hf, hb);
            }
        }
    }
}

/* ---- The march (3.3, 3.5) -------------------------------------------------- */


float lpv_iv_emitted(const float e[4], const float t[3])
{
    const float sum = e[0] / LPV_IV_HEMI0;
    const float v[3] = {e[3] / LPV_IV_HEMI1, e[1] / LPV_IV_HEMI1, e[2] / LPV_IV_HEMI1};
    float diff = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (diff > sum)
        diff = sum;
    const float side = v[0] * t[0] + v[1] * t[1] + v[2] * t[2] > 0.0f ? sum + diff : sum - diff;
    return side > 0.0f ? side * (float)(0.5 / IV_PI) : 0.0f;
}

/* Y(-w) of ray j of voxel (x, y, z); w to dir. */
static void ray(const lpv_grid *g, uint32_t seed, int x, int y, int z, int j, int rays, float dir[3], float y4[4])
{
    lpv_iv_ray(seed, (uint32_t)lpv_grid_index(g, x, y, z), (uint32_t)j, (uint32_t)rays, dir);
    const float back[3] = {-dir[0], -dir[1], -dir[2]};
    basis(back, y4);
}

/* c's one occupied face neighbour own (and the unit axis side from it to c),
 * if it has exactly one. As iv_gather.comp's surface_beside. */
static int surface_beside(const lpv_grid *g, const lpv_iv_voxel *voxels, const int c[3], int own[3], float side[3])
{
    int n = 0;
    for (int k = 0; k < 3; k++)
        for (int sgn = -1; sgn <= 1; sgn += 2) {
            int q[3] = {c[0], c[1], c[2]};
            q[k] += sgn;
            if (occupied_at(g, voxels, q[0], q[1], q[2])) {
                n++;
                memcpy(own, q, sizeof q);
                side[0] = side[1] = side[2] = 0.0f;
                side[k] = -(float)sgn;
            }
        }
    return n == 1;
}

/* Whether a surface ray's stretch through occupied voxel h at q, from
 * o + t_in w to o + t_out w (in voxels), meets its surface: passes through
 * its slab (LPV_IV_SLAB, widened by LPV_IV_SLAB_PAD), anywhere in it where
 * it has none. As iv_gather.comp's meets. */
static int meets(const lpv_iv_voxel *h, const int q[3], const float o[3], const float w[3], float t_in, float t_out)
{
    if (h->slab[0] < 0.0f)
        return 1;
    const int k = (int)h->slab[0];
    const float x_in = o[k] - (float)q[k] + t_in * w[k], x_out = o[k] - (float)q[k] + t_out * w[k];
    const float top = x_in > x_out ? x_in : x_out, bottom = x_in < x_out ? x_in : x_out;
    return top >= h->slab[1] - LPV_IV_SLAB_PAD && bottom <= h->slab[2] + LPV_IV_SLAB_PAD;
}

/* The march from o (in voxels) along w (Amanatides & Woo, as iv_gather.comp
 * walks it): every voxel the ray crosses but c and own, until an occupied
 * one (with surf, one whose slab it meets: LPV_IV_SURFACE_GATHER), the
 * grid's edge (LPV_IV_ESCAPED) or, entering a voxel more than reach voxels
 * from the start (start + the distance from o), LPV_IV_BEYOND. */
static long march_from(const lpv_grid *g, const lpv_iv_voxel *voxels, const int c[3], const int own[3],
                       const float o[3], const float w[3], int surf, float start, float reach)
{
    float inv[3], cross[3];
    int q[3], st[3];
    for (int a = 0; a < 3; a++) {
        q[a] = (int)floorf(o[a]);
        st[a] = w[a] > 0.0f ? 1 : w[a] < 0.0f ? -1 : 0;
        inv[a] = fabsf(w[a]) > 1e-12f ? 1.0f / fabsf(w[a]) : 1e30f;
        cross[a] = (w[a] > 0.0f ? (float)q[a] + 1.0f - o[a] : o[a] - (float)q[a]) * inv[a];
    }
    float t = 0.0f;
    const long max_steps = (long)g->dims[0] + g->dims[1] + g->dims[2] + 3;
    for (long i = 0; i < max_steps; i++) {
        if (start + t > reach)
            return LPV_IV_BEYOND;
        if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= g->dims[0] || q[1] >= g->dims[1] || q[2] >= g->dims[2])
            return LPV_IV_ESCAPED;
        const size_t h = lpv_grid_index(g, q[0], q[1], q[2]);
        const int a = cross[0] < cross[1] ? (cross[0] < cross[2] ? 0 : 2) : (cross[1] < cross[2] ? 1 : 2);
        const int skip = (q[0] == c[0] && q[1] == c[1] && q[2] == c[2]) ||
                         (q[0] == own[0] && q[1] == own[1] && q[2] == own[2]);
        if (!skip && lpv_iv_occupied(&voxels[h]) && (!surf || meets(&voxels[h], q, o, w, t, cross[a])))
            return (long)h;
        t = cross[a];
        q[a] += st[a];
        cross[a] += inv[a];
    }
    return LPV_IV_ESCAPED;
}

long lpv_iv_march(const lpv_grid *g, const lpv_iv_voxel *voxels, int x, int y, int z, const float w[3], float reach)
{
    /* occupied voxels start LPV_IV_START out (their own surface), empty
     * ones at the centre */
    const int c[3] = {x, y, z};
    const float start = lpv_iv_occupied(&voxels[lpv_grid_index(g, x, y, z)]) ? LPV_IV_START : 0.0f;
    float o[3];
    for (int a = 0; a < 3; a++)
        o[a] = (float)c[a] + 0.5f + start * w[a];
    return march_from(g, voxels, c, c, o, w, 0, start, reach / g->cell_size);
}

void lpv_iv_gather(const lpv_grid *g, const lpv_iv_voxel *voxels, const lpv_cell *emit, uint32_t seed, int rays,
                   lpv_cell *incoming)
{
    const double scale = 4.0 * IV_PI / (double)rays;
    for (int z = 0; z < g->dims[2]; z++) {
        for (int y = 0; y < g->dims[1]; y++) {
            for (int x = 0; x < g->dims[0]; x++) {
                lpv_cell *out = &incoming[lpv_grid_index(g, x, y, z)];
                memset(out, 0, sizeof *out);
                if (!near_occupied(g, voxels, x, y, z))
                    continue;
                const int c[3] = {x, y, z};
                const float start = lpv_iv_occupied(&voxels[lpv_grid_index(g, x, y, z)]) ? LPV_IV_START : 0.0f;
                float axis[3] = {0.0f, 0.0f, 0.0f}, side[3] = {0.0f, 0.0f, 0.0f}, origin[3];
                int own[3] = {x, y, z}, surf = 0;
                for (int k = 0; k < 3; k++)
                    origin[k] = (float)c[k] + 0.5f;
                /* LPV_IV_SURFACE_GATHER: on the slab of the one surface beside it */
                if (start == 0.0f && surface_beside(g, voxels, c, own, side)) {
                    const int k = side[0] != 0.0f ? 0 : side[1] != 0.0f ? 1 : 2;
                    const float *slab = voxels[lpv_grid_index(g, own[0], own[1], own[2])].slab;
                    surf = slab[0] == (float)k;
                    if (surf) {
                        origin[k] = (float)own[k] + (side[k] > 0.0f ? slab[2] : slab[1]) + LPV_IV_SLAB_PAD * side[k];
                        memcpy(axis, side, sizeof axis); /* LPV_IV_AXIS_L0 */
                    } else {
                        memcpy(own, c, sizeof own);
                    }
                }
                double acc[3][4] = {{0.0}}, e_plus[3] = {0.0}, e_minus[3] = {0.0};
                for (int j = 0; j < rays; j++) {
                    float w[3], yb[4];
                    ray(g, seed, x, y, z, j, rays, w, yb);
                    long h;
                    if (surf && w[0] * side[0] + w[1] * side[1] + w[2] * side[2] <= 0.0f) {
                        h = (long)lpv_grid_index(g, own[0], own[1], own[2]); /* into the surface */
                    } else {
                        float o[3];
                        for (int k = 0; k < 3; k++)
                            o[k] = surf ? origin[k] : (float)c[k] + 0.5f + start * w[k];
                        h = march_from(g, voxels, c, own, o, w, surf, start, INFINITY);
                    }
                    if (h < 0)
                        continue; /* escaped: no light */
                    const float back[3] = {-w[0], -w[1], -w[2]};
                    const float up = axis[0] * w[0] + axis[1] * w[1] + axis[2] * w[2];
                    for (int ch = 0; ch < 3; ch++) {
                        float L = lpv_iv_emitted(cchannel(&emit[h], ch), back);
                        if (!(L > 0.0f))
                            continue;
                        for (int k = 0; k < 4; k++)
                            acc[ch][k] += (double)(L * yb[k]);
                        e_plus[ch] += (double)(L * (up > 0.0f ? up : 0.0f));
                        e_minus[ch] += (double)(L * (up < 0.0f ? -up : 0.0f));
                    }
                }
                if (axis[0] != 0.0f || axis[1] != 0.0f || axis[2] != 0.0f) /* LPV_IV_AXIS_L0 */
                    for (int ch = 0; ch < 3; ch++)
                        acc[ch][0] = (e_plus[ch] + e_minus[ch]) / (2.0 * LPV_SH_LOBE0);
                for (int ch = 0; ch < 3; ch++)
                    for (int k = 0; k < 4; k++)
                        channel(out, ch)[k] = (float)(acc[ch][k] * scale);
            }
        }
    }
}

void lpv_iv_gather_ao(const lpv_grid *g, const lpv_iv_voxel *voxels, uint32_t seed, int rays, float reach, vec4 *ao)
{
    const double scale = 4.0 * IV_PI / (double)rays;
    for (int z = 0; z < g->dims[2]; z++) {
        for (int y = 0; y < g->dims[1]; y++) {
            for (int x = 0; x < g->dims[0]; x++) {
                float *out = ao[lpv_grid_index(g, x, y, z)];
                if (!near_occupied(g, voxels, x, y, z)) {
                    /* all visible: the projection of the constant 1 */
                    out[0] = 4.0f * LPV_PI * LPV_SH_C0;
                    out[1] = out[2] = out[3] = 0.0f;
                    continue;
                }
                double acc[4] = {0.0};
                for (int j = 0; j < rays; j++) {
                    float w[3], yb[4];
                    ray(g, seed, x, y, z, j, rays, w, yb);
                    if (lpv_iv_march(g, voxels, x, y, z, w, reach) >= 0)
                        continue; /* hit: V = 0 */
                    for (int k = 0; k < 4; k++)
                        acc[k] += yb[k];
                }
                for (int k = 0; k < 4; k++)
                    out[k] = (float)(acc[k] * scale);
            }
        }
    }
}

/* ---- Entry points ------------------------------------------------------------ */

static int check(const lpv_iv_desc *d, int need_bounces, char *err, size_t err_size)
{
    const lpv_grid *g = &d->grid;
    for (int a = 0; a < 3; a++)
        if (g->dims[a] < 1 || g->dims[a] > LPV_MAX_GRID_DIM)
            return lpv_error(err, err_size, "iv: grid dims %d x %d x %d outside 1..%d", g->dims[0], g->dims[1],
                             g->dims[2], LPV_MAX_GRID_DIM);
    if (!finite3(g->origin) || !isfinite(g->cell_size) || !(g->cell_size > 0.0f))
        return lpv_error(err, err_size, "iv: the grid's origin and cell size must be finite (cell size > 0)");
    if (d->point_count > 0 && !d->points)
        return lpv_error(err, err_size, "iv: %zu points but no point array", d->point_count);
    if (d->rays < 1)
        return lpv_error(err, err_size, "iv: rays = %d, need >= 1", d->rays);
    if (need_bounces && d->bounces < 1)
        return lpv_error(err, err_size, "iv: bounces = %d, need >= 1", d->bounces);
    if (need_bounces && (d->neighbours < 1 || d->neighbours > 8))
        return lpv_error(err, err_size, "iv: neighbours = %d, need 1..8", d->neighbours);
    return 0;
}

void lpv_iv_total(size_t cells, const lpv_cell *incoming, double total[3])
{
    total[0] = total[1] = total[2] = 0.0;
    for (size_t i = 0; i < cells; i++) {
        total[0] += incoming[i].r[0];
        total[1] += incoming[i].g[0];
        total[2] += incoming[i].b[0];
    }
}

void lpv_iv_tail_share(const double (*totals)[3], int K, float q[3])
{
    const double most = (double)LPV_IV_TAIL_MAX_RATIO * (double)LPV_IV_TAIL_MAX_RATIO;
    for (int ch = 0; ch < 3; ch++) {
        q[ch] = 0.0f;
        if (K < 3)
            continue;
        const double d0 = totals[K - 2][ch] - (K >= 4 ? totals[K - 3][ch] : 0.0);
        const double d1 = totals[K][ch] - totals[K - 1][ch];
        if (!(d0 > 0.0) || !(d1 > 0.0))
            continue;
        const double v = d1 / d0;
        q[ch] = (float)(v < most ? v : most);
    }
}

void lpv_iv_add_tail(size_t cells, const lpv_cell *base, const float q[3], lpv_cell *last)
{
    for (size_t i = 0; i < cells; i++)
        for (int ch = 0; ch < 3; ch++) {
            float *a = channel(&last[i], ch);
            const float *b = cchannel(&base[i], ch);
            if (!(q[ch] > 0.0f) || !(a[0] - b[0] > 0.0f)) /* no light from the last two bounces here: no tail */
                continue;
            const float f = q[ch] / (1.0f - q[ch]);
            for (int k = 0; k < 4; k++)
                a[k] += (a[k] - b[k]) * f;
        }
}

int lpv_iv_run(const lpv_iv_desc *d, lpv_iv_voxel *voxels, lpv_cell *incoming, char *err, size_t err_size)
{
    if (check(d, 1, err, err_size) != 0)
        return -1;
    const lpv_grid *g = &d->grid;
    size_t cells = lpv_grid_cell_count(g);
    lpv_iv_voxel *own = voxels ? NULL : malloc(cells * sizeof *own);
    lpv_cell *emit = malloc(cells * sizeof *emit);
    lpv_cell *prev = malloc(cells * sizeof *prev);
    lpv_cell *base = d->tail ? malloc(cells * sizeof *base) : NULL; /* I_{K-2} */
    int rc = -1;
    if ((!voxels && !own) || !emit || !prev || (d->tail && !base)) {
        lpv_error(err, err_size, "iv: out of memory for %zu voxels", cells);
        goto done;
    }
    lpv_iv_voxel *vox = voxels ? voxels : own;
    if (lpv_iv_create(g, d->points, d->radiosity, d->point_count, vox, NULL) != 0) {
        lpv_error(err, err_size, "iv: out of memory creating the volume");
        goto done;
    }
    memset(incoming, 0, cells * sizeof *incoming); /* I_0 */
    double totals[LPV_IV_TAIL_SLOTS][3] = {{0.0}};
    for (int k = 1; k <= d->bounces; k++) {
        if (base && k == d->bounces && k >= 3)
            memcpy(base, prev, cells * sizeof *base); /* prev still holds I_{k-2} */
        memcpy(prev, incoming, cells * sizeof *prev);
        lpv_iv_emit(g, vox, prev, k, d->neighbours, emit);
        lpv_iv_gather(g, vox, emit, d->seed, d->rays, incoming);
        if (base && k >= d->bounces - 3 && k < LPV_IV_TAIL_SLOTS) /* the tail's four totals */
            lpv_iv_total(cells, incoming, totals[k]);
    }
    if (base && d->bounces >= 3 && d->bounces < LPV_IV_TAIL_SLOTS) {
        float q[3];
        lpv_iv_tail_share((const double(*)[3])totals, d->bounces, q);
        lpv_iv_add_tail(cells, base, q, incoming);
    }
    rc = 0;
done:
    free(own);
    free(emit);
    free(prev);
    free(base);
    return rc;
}

int lpv_iv_run_ao(const lpv_iv_desc *d, float reach, lpv_iv_voxel *voxels, vec4 *ao, char *err, size_t err_size)
{
    if (check(d, 0, err, err_size) != 0)
        return -1;
    const lpv_grid *g = &d->grid;
    size_t cells = lpv_grid_cell_count(g);
    lpv_iv_voxel *own = voxels ? NULL : malloc(cells * sizeof *own);
    lpv_iv_voxel *vox = voxels ? voxels : own;
    if (!vox)
        return lpv_error(err, err_size, "iv: out of memory for %zu voxels", cells);
    int rc = lpv_iv_create(g, d->points, d->radiosity, d->point_count, vox, NULL);
    if (rc != 0)
        lpv_error(err, err_size, "iv: out of memory creating the volume");
    else
        lpv_iv_gather_ao(g, vox, d->seed, d->rays, reach, ao);
    free(own);
    return rc;
}
