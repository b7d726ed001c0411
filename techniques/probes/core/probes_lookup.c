/* probes_lookup.c - see probes_lookup.h. Each step follows
 * shaders/probes_lookup.glsl's function of the same name, in float. */
#include "probes_lookup.h"

#include <math.h>

#include "probes_math.h"

static float clampf(float x, float lo, float hi) { return x < lo ? lo : x > hi ? hi : x; }
static int mini(int a, int b) { return a < b ? a : b; }
static int maxi(int a, int b) { return a > b ? a : b; }

void lpv_probes_oct_bilinear(int side, const float d[3], int i[4], float w[4])
{
    float uv[2];
    lpv_probes_oct_encode(d, uv);
    int b[2], b1[2];
    float f[2];
    for (int a = 0; a < 2; ++a) {
        const float st = clampf((uv[a] * 0.5f + 0.5f) * (float)side - 0.5f, 0.0f, (float)(side - 1));
        b[a] = mini((int)floorf(st), maxi(side - 2, 0));
        f[a] = st - (float)b[a];
        b1[a] = mini(b[a] + 1, side - 1);
    }
    i[0] = b[1] * side + b[0];
    i[1] = b[1] * side + b1[0];
    i[2] = b1[1] * side + b[0];
    i[3] = b1[1] * side + b1[0];
    w[0] = (1.0f - f[0]) * (1.0f - f[1]);
    w[1] = f[0] * (1.0f - f[1]);
    w[2] = (1.0f - f[0]) * f[1];
    w[3] = f[0] * f[1];
}

static const float *record(const lpv_probes_field *f, int k, const int c[3])
{
    const lpv_probes_level *l = &f->level[k];
    const size_t cell = (size_t)c[0] + (size_t)l->dims[0] * ((size_t)c[1] + (size_t)l->dims[1] * (size_t)c[2]);
    return l->records + cell * lpv_probes_record_values(f->irradiance_side, f->distance_side);
}

/* Probe r's distance moments toward unit d (probes_moments_toward). */
static void moments_toward(const lpv_probes_field *f, const float *r, const float d[3], float m[2])
{
    int i[4];
    float w[4];
    lpv_probes_oct_bilinear(f->distance_side, d, i, w);
    const float *t = r + lpv_probes_record_distance_at(f->irradiance_side);
    m[0] = m[1] = 0.0f;
    for (int j = 0; j < 4; ++j) {
        m[0] += w[j] * t[2 * i[j]];
        m[1] += w[j] * t[2 * i[j] + 1];
    }
}

/* Probe r's irradiance on a surface facing unit n (probes_irradiance_toward). */
static void irradiance_toward(const lpv_probes_field *f, const float *r, const float n[3], float e[3])
{
    int i[4];
    float w[4];
    lpv_probes_oct_bilinear(f->irradiance_side, n, i, w);
    const float *t = r + LPV_PROBES_RECORD_IRRADIANCE;
    e[0] = e[1] = e[2] = 0.0f;
    for (int j = 0; j < 4; ++j)
        for (int c = 0; c < 3; ++c)
            e[c] += w[j] * t[3 * i[j] + c];
}

static float len3(const float v[3]) { return sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

/* n / |n| into u; 0 (and no direction) when p or n is not finite or n is
 * too short to have one. */
static int unit_normal(const float p[3], const float n[3], float u[3])
{
    for (int a = 0; a < 3; ++a)
        if (!isfinite(p[a]) || !isfinite(n[a]))
            return 0;
    const float l = len3(n);
    if (!(l > 1e-8f && l < 1e18f)) /* SPEC R5.15: no direction, or one a float cannot normalise */
        return 0;
    for (int a = 0; a < 3; ++a)
        u[a] = n[a] / l;
    return 1;
}

static float probes_in(const lpv_probes_field *f, int k, const float p[3], const float n[3], float e[3])
{
    const lpv_probes_level *l = &f->level[k];
    const float cell = l->cell_size, min_var = LPV_PROBES_MIN_VAR * cell * cell;
    float ps[3], q[3], fr[3];
    int b[3];
    for (int a = 0; a < 3; ++a) {
        ps[a] = p[a] + n[a] * (f->bias_cells * cell);
        q[a] = clampf((ps[a] - l->origin[a]) / cell - 0.5f, 0.0f, (float)(l->dims[a] - 1));
        b[a] = mini((int)floorf(q[a]), maxi(l->dims[a] - 2, 0));
        fr[a] = q[a] - (float)b[a];
    }
    float sum[3] = {0.0f, 0.0f, 0.0f}, wsum = 0.0f, seen = 0.0f;
    for (int i = 0; i < 8; ++i) {
        const int o[3] = {i & 1, (i >> 1) & 1, i >> 2};
        int c[3];
        for (int a = 0; a < 3; ++a)
            c[a] = mini(b[a] + o[a], l->dims[a] - 1);
        const float *r = record(f, k, c);
        if (r[LPV_PROBES_RECORD_ACTIVE] == 0.0f)
            continue; /* off: inside geometry */
        float pp[3], to[3], v[3], t = 1.0f;
        for (int a = 0; a < 3; ++a) {
            pp[a] = l->origin[a] + ((float)c[a] + 0.5f) * cell + r[LPV_PROBES_RECORD_OFFSET + a];
            t *= o[a] ? fr[a] : 1.0f - fr[a];
            to[a] = pp[a] - p[a];
            v[a] = ps[a] - pp[a];
        }
        const float dl = len3(to);
        const float facing = dl > 0.0f ? ((to[0] * n[0] + to[1] * n[1] + to[2] * n[2]) / dl + 1.0f) * 0.5f : 1.0f;
        float w = facing * facing + LPV_PROBES_FACING_FLOOR;
        const float d = len3(v);
        float dir[3], m[2];
        for (int a = 0; a < 3; ++a)
            dir[a] = d > 0.0f ? v[a] / d : n[a];
        moments_toward(f, r, dir, m);
        w *= lpv_probes_chebyshev(m[0], m[1], d, min_var);
        if (w < LPV_PROBES_CRUSH)
            w *= w * w / (LPV_PROBES_CRUSH * LPV_PROBES_CRUSH); /* the paper's crush: less light through walls */
        seen += w * t;
        w = fmaxf(w, 1e-6f) * t;
        float pe[3];
        irradiance_toward(f, r, n, pe);
        for (int c3 = 0; c3 < 3; ++c3)
            sum[c3] += w * pe[c3];
        wsum += w;
    }
    for (int c3 = 0; c3 < 3; ++c3)
        e[c3] = wsum > 0.0f ? sum[c3] / wsum : 0.0f;
    return seen;
}

float lpv_probes_irradiance_in(const lpv_probes_field *f, int k, const float p[3], const float n[3], float e[3])
{
    float u[3];
    e[0] = e[1] = e[2] = 0.0f;
    if (k < 0 || k >= f->levels || !unit_normal(p, n, u))
        return 0.0f;
    return probes_in(f, k, p, u, e);
}

/* How far p lies inside level k's probes, in its cells (probes_inside). */
static float inside(const lpv_probes_field *f, int k, const float p[3])
{
    const lpv_probes_level *l = &f->level[k];
    float m = INFINITY;
    for (int a = 0; a < 3; ++a) {
        const float q = (p[a] - l->origin[a]) / l->cell_size;
        m = fminf(m, fminf(q, (float)l->dims[a] - q));
    }
    return m;
}

static int usable(const lpv_probes_field *f)
{
    if (!f || f->levels < 1 || f->levels > 4 || f->irradiance_side < 1 || f->distance_side < 1 ||
        !(f->bias_cells >= 0.0f))
        return 0;
    for (int k = 0; k < f->levels; ++k) {
        const lpv_probes_level *l = &f->level[k];
        if (!l->records || l->dims[0] < 1 || l->dims[1] < 1 || l->dims[2] < 1 || !(l->cell_size > 0.0f) ||
            !isfinite(l->cell_size))
            return 0;
    }
    return 1;
}

int lpv_probes_irradiance(const lpv_probes_field *f, const float p[3], const float n[3], float e[3])
{
    e[0] = e[1] = e[2] = 0.0f;
    if (!usable(f))
        return -1;
    float u[3];
    if (!unit_normal(p, n, u))
        return 0;
    const int last = f->levels - 1;
    int k = last;
    for (int j = 0; j < last; ++j)
        if (inside(f, j, p) >= 0.5f) {
            k = j;
            break;
        }
    float seen = probes_in(f, k, p, u, e);
    /* a fine level's probes may all sit in the geometry around p: a coarser one's may not */
    while (seen < LPV_PROBES_UNSEEN && k + 1 < f->levels)
        seen = probes_in(f, ++k, p, u, e);
    const float w = clampf((inside(f, k, p) - 0.5f) * 0.5f, 0.0f, 1.0f);
    if (w < 1.0f && k + 1 < f->levels) {
        float c[3];
        if (probes_in(f, k + 1, p, u, c) >= LPV_PROBES_UNSEEN)
            for (int a = 0; a < 3; ++a)
                e[a] = c[a] + (e[a] - c[a]) * w; /* mix(c, e, w) */
    }
    return 0;
}
