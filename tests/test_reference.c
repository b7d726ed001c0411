/*
 * test_reference.c - the path-traced reference (reference/pt.h): direct light
 * from punctual lights equals the analytic formula, one bounce off a finite
 * emissive rectangle agrees with its form factor within 3 standard errors,
 * the furnace (closed sphere, uniform albedo and emission) gives
 * pi L_e (1 + rho + ... + rho^(N-1)), converged light (Russian roulette,
 * LPV_REF_BOUNCES_CONVERGED) gives the whole series pi L_e / (1 - rho) in
 * both estimators and matches 64 fixed bounces in the Cornell box within
 * noise, a cap at or below the roulette's start is the fixed count bit for
 * bit, the standard error falls like
 * 1/sqrt(spp), primary rays map back into their pixel through
 * lpv_view_project, the Cornell image is finite, bleeds colour and is
 * bit-identical across runs and thread counts, and hostile input is skipped.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "pt.h"
#include "scene.h"
#include "view.h"

/* ---- a tiny scene builder (unshared vertices, one draw per triangle) ---- */

typedef struct builder {
    lpv_scene s;
    uint32_t cap_v, cap_d;
} builder;

static void b_init(builder *b)
{
    memset(b, 0, sizeof *b);
}

static int b_material(builder *b, float r, float g, float bl, float er, float eg, float eb)
{
    b->s.materials = realloc(b->s.materials, (b->s.material_count + 1) * sizeof *b->s.materials);
    assert_non_null(b->s.materials);
    lpv_material *m = &b->s.materials[b->s.material_count];
    lpv_material_init(m);
    m->base_color[0] = r;
    m->base_color[1] = g;
    m->base_color[2] = bl;
    m->emission[0] = er;
    m->emission[1] = eg;
    m->emission[2] = eb;
    m->double_sided = 1;
    return (int)b->s.material_count++;
}

/* Triangle a, b, c with vertex normal n (NULL: the winding's normal). */
static void b_tri(builder *b, const float a[3], const float c1[3], const float c2[3], const float *n, int material)
{
    if (b->s.vertex_count + 3 > b->cap_v) {
        b->cap_v = b->cap_v ? 2 * b->cap_v : 64;
        b->s.vertices = realloc(b->s.vertices, b->cap_v * sizeof *b->s.vertices);
        b->s.indices = realloc(b->s.indices, b->cap_v * sizeof *b->s.indices);
        assert_non_null(b->s.vertices);
        assert_non_null(b->s.indices);
    }
    if (b->s.draw_count + 1 > b->cap_d) {
        b->cap_d = b->cap_d ? 2 * b->cap_d : 32;
        b->s.draws = realloc(b->s.draws, b->cap_d * sizeof *b->s.draws);
        assert_non_null(b->s.draws);
    }
    float wn[3];
    float e1[3] = {c1[0] - a[0], c1[1] - a[1], c1[2] - a[2]}, e2[3] = {c2[0] - a[0], c2[1] - a[1], c2[2] - a[2]};
    wn[0] = e1[1] * e2[2] - e1[2] * e2[1];
    wn[1] = e1[2] * e2[0] - e1[0] * e2[2];
    wn[2] = e1[0] * e2[1] - e1[1] * e2[0];
    float l = sqrtf(wn[0] * wn[0] + wn[1] * wn[1] + wn[2] * wn[2]);
    for (int i = 0; i < 3; ++i)
        wn[i] = l > 0.0f ? wn[i] / l : 0.0f;
    const float *p[3] = {a, c1, c2};
    uint32_t first = b->s.vertex_count;
    for (int k = 0; k < 3; ++k) {
        lpv_vertex *v = &b->s.vertices[first + (uint32_t)k];
        memset(v, 0, sizeof *v);
        memcpy(v->position, p[k], sizeof v->position);
        memcpy(v->normal, n ? n : wn, sizeof v->normal);
        b->s.indices[first + (uint32_t)k] = first + (uint32_t)k;
    }
    b->s.vertex_count += 3;
    b->s.index_count += 3;
    b->s.draws[b->s.draw_count++] = (lpv_draw){.first_index = first, .index_count = 3, .material = material};
}

/* Quad a b c d (counter-clockwise seen from the side n points to). */
static void b_quad(builder *b, const float a[3], const float c1[3], const float c2[3], const float d[3],
                   const float *n, int material)
{
    b_tri(b, a, c1, c2, n, material);
    b_tri(b, a, c2, d, n, material);
}

static lpv_light *b_light(builder *b, lpv_light_type type)
{
    b->s.lights = realloc(b->s.lights, (b->s.light_count + 1) * sizeof *b->s.lights);
    assert_non_null(b->s.lights);
    lpv_light *li = &b->s.lights[b->s.light_count++];
    memset(li, 0, sizeof *li);
    li->type = type;
    li->color[0] = li->color[1] = li->color[2] = 1.0f;
    return li;
}

static lpv_ref *make_ref(const lpv_scene *s, int threads)
{
    lpv_ref *ref = NULL;
    char err[256] = "";
    lpv_ref_desc d = {.threads = threads};
    int rc = lpv_ref_create(s, &d, &ref, err, sizeof err);
    if (rc != 0)
        print_error("lpv_ref_create: %s\n", err);
    assert_int_equal(rc, 0);
    assert_non_null(ref);
    return ref;
}

static void norm3(float v[3])
{
    float l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int i = 0; i < 3; ++i)
        v[i] /= l;
}

/* ---- 1. direct light, analytic ------------------------------------------------ */

static double analytic_light(const lpv_light *li, const float p[3], const float n[3], int c)
{
    double to[3], e;
    if (li->type == LPV_LIGHT_DIRECTIONAL) {
        for (int i = 0; i < 3; ++i)
            to[i] = -li->direction[i];
        e = li->intensity;
    } else {
        double d2 = 0.0;
        for (int i = 0; i < 3; ++i) {
            to[i] = (double)li->position[i] - p[i];
            d2 += to[i] * to[i];
        }
        double d = sqrt(d2);
        for (int i = 0; i < 3; ++i)
            to[i] /= d;
        e = li->intensity / d2;
        if (li->type == LPV_LIGHT_SPOT) {
            double cd = -(to[0] * li->direction[0] + to[1] * li->direction[1] + to[2] * li->direction[2]);
            double ci = cos(li->inner_cone), co = cos(li->outer_cone);
            double t = (cd - co) / (ci - co);
            t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
            e *= t * t;
        }
        if (li->range > 0.0f) {
            double q = d / li->range, w = 1.0 - q * q * q * q;
            w = w < 0.0 ? 0.0 : w;
            e *= w * w;
        }
    }
    double cs = to[0] * n[0] + to[1] * n[1] + to[2] * n[2];
    return cs > 0.0 ? li->color[c] * e * cs : 0.0;
}

static void test_direct_analytic(void **state)
{
    (void)state;
    builder b;
    b_init(&b);
    int grey = b_material(&b, 0.5f, 0.5f, 0.5f, 0, 0, 0);
    float up[3] = {0, 1, 0};
    float c0[3] = {-200, 0, 200}, c1[3] = {200, 0, 200}, c2[3] = {200, 0, -200}, c3[3] = {-200, 0, -200};
    b_quad(&b, c0, c1, c2, c3, up, grey);
    /* A blocker over (5.5, 0, 5.5), facing down. */
    float down[3] = {0, -1, 0};
    float k0[3] = {4, 0.2f, 4}, k1[3] = {4, 0.2f, 7}, k2[3] = {7, 0.2f, 7}, k3[3] = {7, 0.2f, 4};
    b_quad(&b, k0, k1, k2, k3, down, grey);
    lpv_light *pl = b_light(&b, LPV_LIGHT_POINT);
    pl->intensity = 5.0f;
    pl->color[1] = 0.5f;
    pl->color[2] = 0.25f;
    pl->position[0] = 0.3f;
    pl->position[1] = 2.0f;
    pl->position[2] = -0.5f;
    lpv_light *sp = b_light(&b, LPV_LIGHT_SPOT);
    sp->intensity = 3.0f;
    sp->inner_cone = 0.3f;
    sp->outer_cone = 0.7f;
    sp->range = 6.0f;
    sp->position[0] = -1.0f;
    sp->position[1] = 3.0f;
    sp->position[2] = 1.0f;
    sp->direction[1] = -1.0f;
    lpv_light *dl = b_light(&b, LPV_LIGHT_DIRECTIONAL);
    dl->intensity = 0.7f;
    dl->color[0] = 0.2f;
    float dd[3] = {0.3f, -1.0f, 0.2f};
    norm3(dd);
    memcpy(dl->direction, dd, sizeof dd);

    pl = &b.s.lights[0]; /* b_light reallocates */
    lpv_ref *ref = make_ref(&b.s, 1);
    assert_int_equal(lpv_ref_triangle_count(ref), 4);
    int checked = 0;
    for (int ix = -4; ix <= 4; ++ix)
        for (int iz = -4; iz <= 4; ++iz) {
            float p[3] = {0.5f * (float)ix, 0.0f, 0.45f * (float)iz};
            float normals[3][3] = {{0, 1, 0}, {0.4f, 1, 0}, {-0.3f, 0.8f, 0.5f}};
            for (int k = 0; k < 3; ++k) {
                float n[3];
                memcpy(n, normals[k], sizeof n);
                norm3(n);
                float e[3];
                lpv_ref_direct_irradiance(ref, p, normals[k], e);
                for (int c = 0; c < 3; ++c) {
                    double want = 0.0;
                    for (uint32_t l = 0; l < b.s.light_count; ++l)
                        want += analytic_light(&b.s.lights[l], p, n, c);
                    assert_true(fabs(e[c] - want) <= 1e-5 * want + 1e-9);
                    checked++;
                }
            }
        }
    assert_int_equal(checked, 9 * 9 * 3 * 3);
    /* Under the blocker: unshadowed it would be lit, shadowed it is 0. */
    float ps[3] = {5.5f, 0.0f, 5.5f}, e[3];
    assert_true(analytic_light(pl, ps, up, 0) > 0.0);
    lpv_ref_direct_irradiance(ref, ps, up, e);
    assert_true(e[0] == 0.0f && e[1] == 0.0f && e[2] == 0.0f);
    /* Facing away from every light: 0. */
    float pa[3] = {0, 0.5f, 0};
    lpv_ref_direct_irradiance(ref, pa, down, e);
    assert_true(e[0] == 0.0f && e[1] == 0.0f && e[2] == 0.0f);
    lpv_ref_destroy(ref);
    lpv_scene_free(&b.s);
}

/* ---- 1b. one bounce: a finite emissive rectangle ----------------------------- */

/* Irradiance / L at a point on the axis through a corner of an a x b
 * rectangle parallel to the receiver at distance c: pi * F, with F the
 * classic differential-area-to-rectangle form factor. */
static double corner_integral(double a, double b, double c)
{
    double A = a / c, B = b / c;
    double sa = sqrt(1.0 + A * A), sb = sqrt(1.0 + B * B);
    return 0.5 * (A / sa * atan(B / sa) + B / sb * atan(A / sb));
}

/* double_sided as glTF's doubleSided: 1 = the back emits L too (issue 30). */
static void build_rectangle(builder *b, const float L[3], int double_sided)
{
    b_init(b);
    int m = b_material(b, 0.5f, 0.5f, 0.5f, L[0], L[1], L[2]);
    b->s.materials[m].double_sided = double_sided;
    float n[3] = {0, 0, -1};
    /* 4 x 6 m at z = 1, front side towards -z (the probe at the origin). */
    float c0[3] = {-2, -3, 1}, c1[3] = {-2, 3, 1}, c2[3] = {2, 3, 1}, c3[3] = {2, -3, 1};
    b_quad(b, c0, c1, c2, c3, n, m);
}

static void test_one_bounce_rectangle(void **state)
{
    (void)state;
    const float L[3] = {0.5f, 1.0f, 2.0f};
    builder b;
    build_rectangle(&b, L, 0);
    lpv_ref *ref = make_ref(&b.s, 0);
    double factor = 4.0 * corner_integral(2.0, 3.0, 1.0); /* E / L */
    float p[3] = {0, 0, 0}, n[3] = {0, 0, 1}, e[3], se[3];
    assert_int_equal(lpv_ref_irradiance(ref, p, n, 1, 1, 65536, e, se), 0);
    for (int c = 0; c < 3; ++c) {
        double want = factor * L[c];
        print_message("rectangle: E[%d] = %.6f +- %.6f, analytic %.6f\n", c, e[c], se[c], want);
        assert_true(se[c] > 0.0f && se[c] < 0.01 * want);
        assert_true(fabs(e[c] - want) <= 3.0 * se[c]);
    }
    /* Next-event estimation on the emitter agrees: its shadow rays do not
     * stop on the emitter short of the point they aim at (grazing angles). */
    lpv_ref *lights = NULL;
    char err[256] = "";
    assert_int_equal(lpv_ref_create(&b.s, &(lpv_ref_desc){.emitters_are_lights = 1}, &lights, err, sizeof err), 0);
    assert_int_equal(lpv_ref_emitter_irradiance(lights, p, n, 1, 65536, e, se), 0);
    for (int c = 0; c < 3; ++c) {
        double want = factor * L[c];
        print_message("rectangle: emitter sampling E[%d] = %.6f +- %.6f, analytic %.6f\n", c, e[c], se[c], want);
        assert_true(se[c] > 0.0f && se[c] < 0.01 * want);
        assert_true(fabs(e[c] - want) <= 3.0 * se[c]);
    }
    lpv_ref_destroy(lights);
    assert_int_equal(lpv_ref_irradiance(ref, p, n, 1, 1, 65536, e, se), 0);
    /* Nothing else in the scene: more bounces add nothing (same streams). */
    float e2[3], se2[3];
    assert_int_equal(lpv_ref_irradiance(ref, p, n, 1, 3, 65536, e2, se2), 0);
    assert_memory_equal(e, e2, sizeof e);
    /* The back of the (single-sided) emitter does not emit. */
    float pb[3] = {0, 0, 2}, nb[3] = {0, 0, -1};
    assert_int_equal(lpv_ref_irradiance(ref, pb, nb, 1, 1, 1024, e2, se2), 0);
    assert_true(e2[0] == 0.0f && e2[1] == 0.0f && e2[2] == 0.0f);
    /* Standard error ~ 1/sqrt(spp): 16x the samples, 1/4 the error. */
    float pts[4 * 3] = {0, 0, 0, 0.5f, 0.2f, 0, -1, 1, 0.3f, 1.5f, -2, 0.5f};
    float nrm[4 * 3] = {0, 0, 1, 0, 0, 1, 0.2f, 0, 1, -0.3f, 0.4f, 1};
    float lo[12], lo_se[12], hi[12], hi_se[12];
    assert_int_equal(lpv_ref_irradiance(ref, pts, nrm, 4, 1, 1024, lo, lo_se), 0);
    assert_int_equal(lpv_ref_irradiance(ref, pts, nrm, 4, 1, 16384, hi, hi_se), 0);
    for (int i = 0; i < 12; ++i) {
        double ratio = lo_se[i] / hi_se[i];
        assert_true(ratio > 3.3 && ratio < 4.8);
        assert_true(fabs(lo[i] - hi[i]) <= 4.0 * sqrt((double)lo_se[i] * lo_se[i] + (double)hi_se[i] * hi_se[i]));
    }
    lpv_ref_destroy(ref);
    lpv_scene_free(&b.s);
}

/* Issue 30: a double-sided emitter (glTF doubleSided) emits L from its back
 * as from its front. A probe 1 m behind the rectangle facing it gets what a
 * probe 1 m in front gets (the analytic value), by paths that hit the back
 * (emitters not lights) and by next-event estimation on the emitters; its
 * flux is counted twice in the power the emitters are picked by. */
static void test_double_sided_emitter_back(void **state)
{
    (void)state;
    const float L[3] = {0.5f, 1.0f, 2.0f};
    builder b;
    build_rectangle(&b, L, 1);
    lpv_ref *ref = make_ref(&b.s, 0);
    const double factor = 4.0 * corner_integral(2.0, 3.0, 1.0);
    const float pts[6] = {0, 0, 0, 0, 0, 2}, nrm[6] = {0, 0, 1, 0, 0, -1};
    float e[6], se[6], ee[6], ese[6];
    assert_int_equal(lpv_ref_irradiance(ref, pts, nrm, 2, 1, 65536, e, se), 0);
    lpv_ref *lights = NULL;
    char err[256] = "";
    assert_int_equal(lpv_ref_create(&b.s, &(lpv_ref_desc){.emitters_are_lights = 1}, &lights, err, sizeof err), 0);
    assert_int_equal(lpv_ref_emitter_irradiance(lights, pts, nrm, 2, 262144, ee, ese), 0);
    for (int side = 0; side < 2; ++side)
        for (int c = 0; c < 3; ++c) {
            double want = factor * L[c];
            const int i = 3 * side + c;
            print_message("double-sided rectangle, %s: E[%d] = %.6f +- %.6f (paths), %.6f +- %.6f (emitter "
                          "sampling), analytic %.6f\n",
                          side ? "behind" : "in front", c, e[i], se[i], ee[i], ese[i], want);
            assert_true(se[i] > 0.0f && se[i] < 0.01 * want);
            assert_true(fabs(e[i] - want) <= 3.0 * se[i]);
            assert_true(ese[i] > 0.0f && ese[i] < 0.01 * want);
            assert_true(fabs(ee[i] - want) <= 3.0 * ese[i]);
        }
    /* the full frame seen from behind (direct light only: the emitter's own
     * light does not reach it) is L, as from the front */
    lpv_view v;
    assert_int_equal(lpv_view_look_at((float[3]){0.3f, -0.2f, 3.0f}, (float[3]){0, 0, 1}, 0.5f, 8, 8, &v), 0);
    float rgba[8 * 8 * 4];
    assert_int_equal(lpv_ref_render_full(lights, &v, 0, 4, rgba, NULL), 0);
    for (int c = 0; c < 3; ++c)
        assert_true(fabsf(rgba[4 * (4 * 8 + 4) + c] - L[c]) < 1e-3f * L[c]);
    lpv_ref_destroy(lights);
    lpv_ref_destroy(ref);
    lpv_scene_free(&b.s);
}

/* ---- 2. the furnace ---------------------------------------------------------- */

/* An icosphere of radius 1 at the origin, flat normals pointing inwards. */
static void build_icosphere(builder *b, int subdiv, int material)
{
    const float t = (1.0f + sqrtf(5.0f)) / 2.0f;
    float v[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                      {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    const int f[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                          {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                          {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    for (int i = 0; i < 12; ++i)
        norm3(v[i]);
    int n = 1 << subdiv;
    for (int fi = 0; fi < 20; ++fi) {
        const float *A = v[f[fi][0]], *B = v[f[fi][1]], *C = v[f[fi][2]];
        /* Points of the subdivided face, projected on the sphere: each is
         * computed from its (i, j) alone, so shared edges match exactly. */
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n - i; ++j) {
                float q[4][3];
                int ij[4][2] = {{i, j}, {i + 1, j}, {i, j + 1}, {i + 1, j + 1}};
                for (int k = 0; k < 4; ++k) {
                    float a = (float)ij[k][0] / (float)n, bb = (float)ij[k][1] / (float)n, c = 1.0f - a - bb;
                    for (int x = 0; x < 3; ++x)
                        q[k][x] = c * A[x] + a * B[x] + bb * C[x];
                    norm3(q[k]);
                }
                /* Outward winding is A B C; inward normals: reverse it. */
                float nin[3], e1[3], e2[3];
                for (int x = 0; x < 3; ++x) {
                    e1[x] = q[1][x] - q[0][x];
                    e2[x] = q[2][x] - q[0][x];
                }
                nin[0] = -(e1[1] * e2[2] - e1[2] * e2[1]);
                nin[1] = -(e1[2] * e2[0] - e1[0] * e2[2]);
                nin[2] = -(e1[0] * e2[1] - e1[1] * e2[0]);
                norm3(nin);
                b_tri(b, q[0], q[2], q[1], nin, material);
                if (j + i + 1 < n) {
                    for (int x = 0; x < 3; ++x) {
                        e1[x] = q[3][x] - q[1][x];
                        e2[x] = q[2][x] - q[1][x];
                    }
                    nin[0] = -(e1[1] * e2[2] - e1[2] * e2[1]);
                    nin[1] = -(e1[2] * e2[0] - e1[0] * e2[2]);
                    nin[2] = -(e1[0] * e2[1] - e1[1] * e2[0]);
                    norm3(nin);
                    b_tri(b, q[1], q[2], q[3], nin, material);
                }
            }
    }
}

static const float FURNACE_RHO[3] = {0.5f, 0.8f, 0.2f};
static const float FURNACE_LE[3] = {0.1f, 0.2f, 0.3f};
static const float FURNACE_P[4][3] = {{0, 0, 0}, {0.3f, -0.2f, 0.4f}, {0.0f, 0.8f, 0.1f}, {-0.5f, 0.1f, -0.6f}};
static const float FURNACE_N[4][3] = {{0, 1, 0}, {1, 1, 1}, {0, -1, 0}, {0.3f, -0.7f, 0.2f}};

static void test_furnace(void **state)
{
    (void)state;
    builder b;
    b_init(&b);
    int m = b_material(&b, FURNACE_RHO[0], FURNACE_RHO[1], FURNACE_RHO[2], FURNACE_LE[0], FURNACE_LE[1],
                       FURNACE_LE[2]);
    build_icosphere(&b, 3, m);
    assert_int_equal(b.s.index_count / 3, 20 * 64);
    lpv_ref *ref = make_ref(&b.s, 0);
    assert_int_equal(lpv_ref_triangle_count(ref), 20 * 64);
    const int bounces[3] = {1, 2, 4};
    for (int k = 0; k < 3; ++k) {
        float e[12], se[12];
        assert_int_equal(lpv_ref_irradiance(ref, &FURNACE_P[0][0], &FURNACE_N[0][0], 4, bounces[k], 512, e, se), 0);
        for (int c = 0; c < 3; ++c) {
            double geo = 0.0, pw = 1.0;
            for (int j = 0; j < bounces[k]; ++j, pw *= FURNACE_RHO[c])
                geo += pw;
            double want = M_PI * FURNACE_LE[c] * geo;
            for (int i = 0; i < 4; ++i) {
                double got = e[3 * i + c];
                /* Every path of a closed uniform furnace returns the same
                 * value: the estimator has no variance, and any leak
                 * through the mesh would show as a large error. */
                assert_true(fabs(got - want) <= 3.0 * se[3 * i + c] + 1e-5 * want);
                assert_true(se[3 * i + c] <= 1e-5 * want);
            }
        }
    }
    lpv_ref_destroy(ref);
    lpv_scene_free(&b.s);
}

/* The furnace with a point light of intensity I at the centre: the walls get
 * E_d = I / R^2 (up to the faceting), so each sample varies and
 * E_N = (pi L_e + rho E_d)(1 + rho + ... + rho^(N-1)). */
static void test_furnace_lit(void **state)
{
    (void)state;
    builder b;
    b_init(&b);
    int m = b_material(&b, FURNACE_RHO[0], FURNACE_RHO[1], FURNACE_RHO[2], FURNACE_LE[0], FURNACE_LE[1],
                       FURNACE_LE[2]);
    build_icosphere(&b, 3, m);
    lpv_light *li = b_light(&b, LPV_LIGHT_POINT);
    li->intensity = 0.4f;
    lpv_ref *ref = make_ref(&b.s, 0);
    const int bounces[3] = {1, 2, 4};
    for (int k = 0; k < 3; ++k) {
        float e[12], se[12], e_hi[12], se_hi[12];
        assert_int_equal(lpv_ref_irradiance(ref, &FURNACE_P[0][0], &FURNACE_N[0][0], 4, bounces[k], 256, e, se), 0);
        assert_int_equal(
            lpv_ref_irradiance(ref, &FURNACE_P[0][0], &FURNACE_N[0][0], 4, bounces[k], 4096, e_hi, se_hi), 0);
        for (int c = 0; c < 3; ++c) {
            double geo = 0.0, pw = 1.0;
            for (int j = 0; j < bounces[k]; ++j, pw *= FURNACE_RHO[c])
                geo += pw;
            double emit = M_PI * FURNACE_LE[c] * geo, lit = FURNACE_RHO[c] * li->intensity * geo;
            for (int i = 0; i < 4; ++i) {
                double got = e_hi[3 * i + c];
                /* Faceting: a facet point's E_d lies within about +-0.7 % of
                 * I / R^2 for this subdivision. */
                assert_true(fabs(got - (emit + lit)) <= 3.0 * se_hi[3 * i + c] + 0.01 * lit);
                double ratio = se[3 * i + c] / se_hi[3 * i + c];
                assert_true(se_hi[3 * i + c] > 0.0f);
                assert_true(ratio > 3.0 && ratio < 5.3);
            }
        }
    }
    lpv_ref_destroy(ref);
    lpv_scene_free(&b.s);
}

/* ---- 2b. converged light ----------------------------------------------------- */

static lpv_ref *make_ref_desc(const lpv_scene *s, const lpv_ref_desc *d)
{
    lpv_ref *ref = NULL;
    char err[256] = "";
    int rc = lpv_ref_create(s, d, &ref, err, sizeof err);
    if (rc != 0)
        print_error("lpv_ref_create: %s\n", err);
    assert_int_equal(rc, 0);
    return ref;
}

/* 1 + rho + ... + rho^(n-1) */
static double geo_sum(double rho, int n)
{
    double geo = 0.0, pw = 1.0;
    for (int j = 0; j < n; ++j, pw *= rho)
        geo += pw;
    return geo;
}

/* The lit furnace, converged: every bounce of the series. Emission seen
 * directly (area lights off): E = (pi L_e + rho E_d) / (1 - rho); emitters as
 * lights: E = rho (pi L_e + E_d) / (1 - rho), the 1-bounce term times
 * 1 / (1 - rho). Both up to the default cap's rho^64 (< 1e-6 here). The
 * roulette gives every sample a different weight: the estimate has a
 * standard error, and must sit within it of the series sum. */
static void test_furnace_converged(void **state)
{
    (void)state;
    builder b;
    b_init(&b);
    int m = b_material(&b, FURNACE_RHO[0], FURNACE_RHO[1], FURNACE_RHO[2], FURNACE_LE[0], FURNACE_LE[1],
                       FURNACE_LE[2]);
    build_icosphere(&b, 3, m);
    lpv_light *li = b_light(&b, LPV_LIGHT_POINT);
    li->intensity = 0.4f;
    const double intensity = li->intensity;
    for (int lights = 0; lights <= 1; ++lights) {
        lpv_ref_desc d = {.emitters_are_lights = lights};
        lpv_ref *ref = make_ref_desc(&b.s, &d);
        float e[12], se[12], e1[12], se1[12];
        assert_int_equal(lpv_ref_irradiance(ref, &FURNACE_P[0][0], &FURNACE_N[0][0], 4, LPV_REF_BOUNCES_CONVERGED,
                                            4096, e, se),
                         0);
        assert_int_equal(lpv_ref_irradiance(ref, &FURNACE_P[0][0], &FURNACE_N[0][0], 4, 1, 4096, e1, se1), 0);
        for (int c = 0; c < 3; ++c) {
            double rho = FURNACE_RHO[c], geo = geo_sum(rho, LPV_REF_MAX_BOUNCES_DEFAULT);
            double emit = M_PI * FURNACE_LE[c], lit = rho * intensity;
            double want = lights ? rho * (emit + intensity) * geo : (emit + lit) * geo;
            double facets = 0.01 * (lights ? rho * intensity : lit) * geo; /* E_d within ~0.7 % of I / R^2 */
            for (int i = 0; i < 4; ++i) {
                double got = e[3 * i + c], err = se[3 * i + c];
                print_message("furnace converged (%s) point %d ch %d: %.6f want %.6f (se %.2g), 1 bounce %.6f\n",
                              lights ? "emitters as lights" : "emission seen", i, c, got, want, err, e1[3 * i + c]);
                assert_true(err > 0.0);
                assert_true(err < 0.02 * want);
                assert_true(fabs(got - want) <= 4.0 * err + facets);
                /* More than the 1-bounce estimate, by far more than both
                 * standard errors (the missing bounces are rho/(1-rho) of
                 * it: 1x, 4x and 0.25x). */
                assert_true(got - e1[3 * i + c] > 4.0 * (err + se1[3 * i + c]));
            }
        }
        lpv_ref_destroy(ref);
    }
    lpv_scene_free(&b.s);
}

/* Image mean (rgb, covered pixels) and the standard error of that mean. */
static void image_mean(const float *img, const float *se, int w, int h, double mean[3], double mean_se[3])
{
    size_t n = 0;
    double sum[3] = {0, 0, 0}, var[3] = {0, 0, 0};
    for (size_t i = 0; i < (size_t)w * (size_t)h; ++i) {
        if (!(img[4 * i + 3] > 0.0f))
            continue;
        n++;
        for (int c = 0; c < 3; ++c) {
            sum[c] += img[4 * i + (size_t)c];
            var[c] += (double)se[4 * i + (size_t)c] * se[4 * i + (size_t)c];
        }
    }
    assert_true(n > 0);
    for (int c = 0; c < 3; ++c) {
        mean[c] = sum[c] / (double)n;
        mean_se[c] = sqrt(var[c]) / (double)n;
    }
}

/* Russian roulette is unbiased: in the Cornell box (open, coloured, with
 * an area light) the converged image's mean equals 64 fixed bounces' within
 * their standard errors, for the indirect image in both emitter modes and the
 * full frame, and clearly exceeds the 1-bounce image's. */
static void test_converged_matches_fixed(void **state)
{
    (void)state;
    enum { W = 16, SPPC = 128 };
    lpv_scene s;
    assert_int_equal(lpv_scene_builtin_cornell(&s), 0);
    lpv_view v;
    lpv_view_from_camera(&s.cameras[0], W, W, &v);
    size_t n = (size_t)W * W * 4;
    float *a = malloc(n * sizeof *a), *a_se = malloc(n * sizeof *a_se);
    float *f = malloc(n * sizeof *f), *f_se = malloc(n * sizeof *f_se);
    float *o = malloc(n * sizeof *o), *o_se = malloc(n * sizeof *o_se);
    assert_true(a && a_se && f && f_se && o && o_se);
    for (int mode = 0; mode < 3; ++mode) { /* indirect lights off, indirect lights on, full */
        lpv_ref_desc d = {.emitters_are_lights = mode != 0, .seed = 7};
        lpv_ref *ref = make_ref_desc(&s, &d);
        if (mode == 2) {
            assert_int_equal(lpv_ref_render_full(ref, &v, LPV_REF_BOUNCES_CONVERGED, SPPC, a, a_se), 0);
            assert_int_equal(lpv_ref_render_full(ref, &v, 64, SPPC, f, f_se), 0);
            assert_int_equal(lpv_ref_render_full(ref, &v, 1, SPPC, o, o_se), 0);
        } else {
            assert_int_equal(lpv_ref_render_indirect(ref, &v, LPV_REF_BOUNCES_CONVERGED, SPPC, a, a_se), 0);
            assert_int_equal(lpv_ref_render_indirect(ref, &v, 64, SPPC, f, f_se), 0);
            assert_int_equal(lpv_ref_render_indirect(ref, &v, 1, SPPC, o, o_se), 0);
        }
        double ma[3], sa[3], mf[3], sf[3], mo[3], so[3];
        image_mean(a, a_se, W, W, ma, sa);
        image_mean(f, f_se, W, W, mf, sf);
        image_mean(o, o_se, W, W, mo, so);
        for (int c = 0; c < 3; ++c) {
            double tol = 4.0 * sqrt(sa[c] * sa[c] + sf[c] * sf[c]);
            print_message("cornell mode %d ch %d: converged %.6f (se %.2g), 64 bounces %.6f (se %.2g), 1 bounce %.6f\n",
                          mode, c, ma[c], sa[c], mf[c], sf[c], mo[c]);
            assert_true(fabs(ma[c] - mf[c]) <= tol);
            assert_true(ma[c] - mo[c] > 4.0 * (sa[c] + so[c]));
        }
        lpv_ref_destroy(ref);
    }
    free(a);
    free(a_se);
    free(f);
    free(f_se);
    free(o);
    free(o_se);
    lpv_scene_free(&s);
}

/* The cap: a converged path never rolls the dice before LPV_REF_RR_START
 * bounces, so a cap at or below it is the fixed bounce count bit for bit
 * (and the fixed counts are what they always were: no roulette). Bad
 * bounce values are refused. */
static void test_converged_cap(void **state)
{
    (void)state;
    enum { W = 8 };
    lpv_scene s;
    assert_int_equal(lpv_scene_builtin_cornell(&s), 0);
    lpv_view v;
    lpv_view_from_camera(&s.cameras[0], W, W, &v);
    size_t n = (size_t)W * W * 4;
    float *a = malloc(n * sizeof *a), *a_se = malloc(n * sizeof *a_se);
    float *f = malloc(n * sizeof *f), *f_se = malloc(n * sizeof *f_se);
    assert_true(a && a_se && f && f_se);
    for (int lights = 0; lights <= 1; ++lights)
        for (int cap = 1; cap <= LPV_REF_RR_START; ++cap) {
            lpv_ref_desc d = {.emitters_are_lights = lights, .max_bounces = cap};
            lpv_ref *ref = make_ref_desc(&s, &d);
            assert_int_equal(lpv_ref_render_indirect(ref, &v, LPV_REF_BOUNCES_CONVERGED, 8, a, a_se), 0);
            assert_int_equal(lpv_ref_render_indirect(ref, &v, cap, 8, f, f_se), 0);
            assert_memory_equal(a, f, n * sizeof *a);
            assert_memory_equal(a_se, f_se, n * sizeof *a);
            assert_int_equal(lpv_ref_render_full(ref, &v, LPV_REF_BOUNCES_CONVERGED, 8, a, a_se), 0);
            assert_int_equal(lpv_ref_render_full(ref, &v, cap, 8, f, f_se), 0);
            assert_memory_equal(a, f, n * sizeof *a);
            assert_int_equal(lpv_ref_render_indirect(ref, &v, -2, 8, a, a_se), -1);
            assert_int_equal(lpv_ref_render_full(ref, &v, -2, 8, a, a_se), -1);
            lpv_ref_destroy(ref);
        }
    free(a);
    free(a_se);
    free(f);
    free(f_se);
    lpv_scene_free(&s);
}

/* ---- 3. the Cornell image ------------------------------------------------------ */

static void test_pixel_rays_project_back(void **state)
{
    (void)state;
    lpv_scene s;
    assert_int_equal(lpv_scene_builtin_cornell(&s), 0);
    lpv_ref *ref = make_ref(&s, 1);
    lpv_view views[3];
    lpv_view_from_camera(&s.cameras[0], 40, 24, &views[0]);
    float eye[3] = {0.7f, 1.6f, 2.5f}, target[3] = {-0.2f, 0.4f, -0.3f};
    assert_int_equal(lpv_view_look_at(eye, target, 0.9f, 31, 37, &views[1]), 0);
    views[2] = views[0];
    views[2].orthographic = 1;
    views[2].ymag = 1.2f;
    int hits = 0;
    for (int v = 0; v < 3; ++v)
        for (int y = 0; y < views[v].height; ++y)
            for (int x = 0; x < views[v].width; ++x) {
                float org[3], dir[3], tmin, tmax, t, p[3], px, py;
                lpv_ref_pixel_ray(&views[v], x, y, org, dir, &tmin, &tmax);
                if (lpv_ref_first_hit(ref, org, dir, tmin, tmax, &t, p)) {
                    hits++;
                } else {
                    for (int i = 0; i < 3; ++i)
                        p[i] = org[i] + 2.0f * dir[i];
                }
                assert_int_equal(lpv_view_project(&views[v], p, &px, &py), 0);
                assert_true(fabsf(px - ((float)x + 0.5f)) < 2e-3f);
                assert_true(fabsf(py - ((float)y + 0.5f)) < 2e-3f);
            }
    assert_true(hits > 1000);
    lpv_ref_destroy(ref);
    lpv_scene_free(&s);
}

enum { IMG = 32, SPP = 16 };

static void render_cornell(int threads, float *img, float *se)
{
    lpv_scene s;
    assert_int_equal(lpv_scene_builtin_cornell(&s), 0);
    lpv_ref *ref = make_ref(&s, threads);
    lpv_view v;
    lpv_view_from_camera(&s.cameras[0], IMG, IMG, &v);
    assert_int_equal(lpv_ref_render_indirect(ref, &v, 1, SPP, img, se), 0);
    lpv_ref_destroy(ref);
    lpv_scene_free(&s);
}

/* Mean rgb of the 3x3 pixels around the pixel that shows world point p. */
static void floor_patch(const float *img, const float p[3], double out[3])
{
    lpv_scene s;
    assert_int_equal(lpv_scene_builtin_cornell(&s), 0);
    lpv_view v;
    lpv_view_from_camera(&s.cameras[0], IMG, IMG, &v);
    float px, py;
    assert_int_equal(lpv_view_project(&v, p, &px, &py), 0);
    int cx = (int)px, cy = (int)py;
    out[0] = out[1] = out[2] = 0.0;
    for (int y = cy - 1; y <= cy + 1; ++y)
        for (int x = cx - 1; x <= cx + 1; ++x) {
            assert_true(x >= 0 && x < IMG && y >= 0 && y < IMG);
            const float *q = &img[4 * (y * IMG + x)];
            assert_true(q[3] == 1.0f);
            for (int c = 0; c < 3; ++c)
                out[c] += q[c] / 9.0;
        }
    lpv_scene_free(&s);
}

static void test_cornell_image(void **state)
{
    (void)state;
    size_t n = (size_t)IMG * IMG * 4;
    float *a = malloc(n * sizeof *a), *a_se = malloc(n * sizeof *a_se);
    float *b = malloc(n * sizeof *b), *b_se = malloc(n * sizeof *b_se);
    float *c = malloc(n * sizeof *c), *c_se = malloc(n * sizeof *c_se);
    assert_true(a && a_se && b && b_se && c && c_se);
    render_cornell(1, a, a_se);
    render_cornell(1, b, b_se);
    render_cornell(2, c, c_se);
    assert_memory_equal(a, b, n * sizeof *a);
    assert_memory_equal(a_se, b_se, n * sizeof *a);
    assert_memory_equal(a, c, n * sizeof *a);
    assert_memory_equal(a_se, c_se, n * sizeof *a);
    int covered = 0;
    for (size_t i = 0; i < (size_t)IMG * IMG; ++i) {
        for (int ch = 0; ch < 4; ++ch) {
            assert_true(isfinite(a[4 * i + (size_t)ch]) && a[4 * i + (size_t)ch] >= 0.0f);
            assert_true(isfinite(a_se[4 * i + (size_t)ch]) && a_se[4 * i + (size_t)ch] >= 0.0f);
        }
        assert_true(a[4 * i + 3] == 0.0f || a[4 * i + 3] == 1.0f);
        covered += a[4 * i + 3] == 1.0f;
    }
    assert_true(covered > IMG * IMG * 3 / 4);
    double rel = lpv_ref_mean_relative_stderr(a, a_se, IMG, IMG);
    print_message("cornell %dx%d, %d spp: mean relative standard error %.4f\n", IMG, IMG, SPP, rel);
    assert_true(rel > 0.0 && rel < 1.0);
    /* Colour bleeding: the floor by the red (left, x = -1) wall is redder
     * than green; by the green (right) wall, greener than by the red one. */
    float near_red[3] = {-0.8f, 0.0f, 0.4f}, near_green[3] = {0.85f, 0.0f, 0.4f};
    double r[3], g[3];
    floor_patch(a, near_red, r);
    floor_patch(a, near_green, g);
    print_message("floor by red wall %.5f %.5f %.5f, by green wall %.5f %.5f %.5f\n", r[0], r[1], r[2], g[0], g[1],
                  g[2]);
    assert_true(r[0] > r[1]);
    assert_true(r[0] / r[1] > g[0] / g[1]);
    free(a);
    free(a_se);
    free(b);
    free(b_se);
    free(c);
    free(c_se);
}

/* A uniform base-colour texture scales the image exactly by its decoded
 * value (the irradiance does not depend on the surface's own albedo). */
static void test_texture_albedo(void **state)
{
    (void)state;
    const float L[3] = {0.5f, 1.0f, 2.0f};
    builder b;
    build_rectangle(&b, L, 0);
    /* A grey receiver at z = 0 facing the emitter. */
    int grey = b_material(&b, 0.8f, 0.8f, 0.8f, 0, 0, 0);
    float n[3] = {0, 0, 1};
    float c0[3] = {-1, -1, 0}, c1[3] = {1, -1, 0}, c2[3] = {1, 1, 0}, c3[3] = {-1, 1, 0};
    b_quad(&b, c0, c1, c2, c3, n, grey);
    float eye[3] = {0, 0, 0.5f}, target[3] = {0, 0, 0};
    lpv_view v;
    assert_int_equal(lpv_view_look_at(eye, target, 1.0f, 8, 8, &v), 0);
    float plain[8 * 8 * 4], textured[8 * 8 * 4];
    lpv_ref *ref = make_ref(&b.s, 0);
    assert_int_equal(lpv_ref_render_indirect(ref, &v, 1, 64, plain, NULL), 0);
    lpv_ref_destroy(ref);

    b.s.textures = calloc(1, sizeof *b.s.textures);
    assert_non_null(b.s.textures);
    b.s.texture_count = 1;
    b.s.textures[0].width = b.s.textures[0].height = 2;
    b.s.textures[0].rgba8 = malloc(16);
    assert_non_null(b.s.textures[0].rgba8);
    memset(b.s.textures[0].rgba8, 128, 16);
    b.s.materials[grey].base_color_texture = 0;
    ref = make_ref(&b.s, 0);
    assert_int_equal(lpv_ref_render_indirect(ref, &v, 1, 64, textured, NULL), 0);
    lpv_ref_destroy(ref);
    double dec = pow((128.0 / 255.0 + 0.055) / 1.055, 2.4);
    for (int i = 0; i < 8 * 8; ++i) {
        assert_true(plain[4 * i + 3] == 1.0f && textured[4 * i + 3] == 1.0f);
        for (int c = 0; c < 3; ++c) {
            assert_true(plain[4 * i + c] > 0.0f);
            assert_true(fabs(textured[4 * i + c] - dec * plain[4 * i + c]) <= 1e-5 * plain[4 * i + c]);
        }
    }
    lpv_scene_free(&b.s);
}

/* ---- 4. hostile input ------------------------------------------------------------ */

static void test_empty_scene(void **state)
{
    (void)state;
    lpv_scene s;
    memset(&s, 0, sizeof s);
    lpv_ref *ref = make_ref(&s, 2);
    assert_int_equal(lpv_ref_triangle_count(ref), 0);
    float p[6] = {0, 0, 0, 1, 2, 3}, n[6] = {0, 1, 0, 0, 0, 1}, e[6], se[6];
    memset(e, 0xff, sizeof e);
    memset(se, 0xff, sizeof se);
    assert_int_equal(lpv_ref_irradiance(ref, p, n, 2, 3, 16, e, se), 0);
    for (int i = 0; i < 6; ++i)
        assert_true(e[i] == 0.0f && se[i] == 0.0f);
    lpv_view v;
    float eye[3] = {0, 0, 5}, target[3] = {0, 0, 0};
    assert_int_equal(lpv_view_look_at(eye, target, 0.8f, 4, 4, &v), 0);
    float img[64], img_se[64];
    memset(img, 0xff, sizeof img);
    assert_int_equal(lpv_ref_render_indirect(ref, &v, 1, 4, img, img_se), 0);
    for (int i = 0; i < 64; ++i)
        assert_true(img[i] == 0.0f && img_se[i] == 0.0f);
    lpv_ref_direct_irradiance(ref, p, n, e);
    assert_true(e[0] == 0.0f && e[1] == 0.0f && e[2] == 0.0f);
    /* Bad arguments are refused, not crashed on. */
    assert_int_equal(lpv_ref_irradiance(ref, p, n, 2, 0, 16, e, se), -1);
    assert_int_equal(lpv_ref_irradiance(ref, p, n, 2, 1, 0, e, se), -1);
    assert_int_equal(lpv_ref_render_indirect(ref, &v, 1, 0, img, img_se), -1);
    assert_int_equal(lpv_ref_render_indirect(ref, NULL, 1, 1, img, img_se), -1);
    lpv_ref_destroy(ref);
    lpv_ref_destroy(NULL);
}

static void test_degenerate_input(void **state)
{
    (void)state;
    builder b;
    b_init(&b);
    int m = b_material(&b, 0.5f, 0.5f, 0.5f, 1.0f, 1.0f, 1.0f);
    float nan_n[3] = {NAN, NAN, NAN}, zero_n[3] = {0, 0, 0};
    float a[3] = {-1, -1, 1}, c[3] = {1, -1, 1}, d[3] = {0, 1, 1}, mid[3] = {0, -1, 1};
    float bad[3] = {NAN, 0, 1}, inf[3] = {INFINITY, 0, 1};
    b_tri(&b, a, d, c, nan_n, m);  /* kept: NaN normal -> geometric normal */
    b_tri(&b, a, mid, c, NULL, m); /* collinear: skipped */
    b_tri(&b, a, a, c, NULL, m);   /* repeated corner: skipped */
    b_tri(&b, a, bad, c, NULL, m); /* NaN corner: skipped */
    b_tri(&b, a, inf, c, NULL, m); /* infinite corner: skipped */
    float a2[3] = {-1, -1, 2}, c2[3] = {1, -1, 2}, d2[3] = {0, 1, 2};
    b_tri(&b, a2, d2, c2, zero_n, 7); /* kept: no such material -> black */
    b_tri(&b, a, d, c, NULL, m);
    b.s.indices[b.s.index_count - 1] = 999999; /* out-of-range index: skipped */
    /* A draw running past the index buffer. */
    b.s.draws = realloc(b.s.draws, (b.s.draw_count + 1) * sizeof *b.s.draws);
    assert_non_null(b.s.draws);
    b.s.draws[b.s.draw_count++] = (lpv_draw){.first_index = b.s.index_count - 3, .index_count = 30, .material = m};
    lpv_light *li = b_light(&b, LPV_LIGHT_POINT);
    li->intensity = NAN;
    lpv_light *li2 = b_light(&b, LPV_LIGHT_SPOT);
    li2->intensity = 1.0f;
    li2->position[2] = 3.0f; /* zero direction: the spot factor is 0 */
    lpv_ref *ref = make_ref(&b.s, 2);
    assert_int_equal(lpv_ref_triangle_count(ref), 2);
    float p[9] = {0, 0, 0, NAN, 0, 0, 0, 0, 0}, n[9] = {0, 0, 1, 0, 0, 1, NAN, 0, 1}, e[9], se[9];
    assert_int_equal(lpv_ref_irradiance(ref, p, n, 3, 2, 64, e, se), 0);
    for (int i = 0; i < 9; ++i)
        assert_true(isfinite(e[i]) && isfinite(se[i]) && e[i] >= 0.0f);
    assert_true(e[0] > 0.0f); /* the kept emitter is seen */
    for (int i = 3; i < 9; ++i)
        assert_true(e[i] == 0.0f && se[i] == 0.0f);
    lpv_view v;
    float eye[3] = {0, 0, -2}, target[3] = {0, 0, 1};
    assert_int_equal(lpv_view_look_at(eye, target, 1.0f, 8, 8, &v), 0);
    float img[8 * 8 * 4], img_se[8 * 8 * 4];
    assert_int_equal(lpv_ref_render_indirect(ref, &v, 2, 8, img, img_se), 0);
    for (int i = 0; i < 8 * 8 * 4; ++i)
        assert_true(isfinite(img[i]) && isfinite(img_se[i]) && img[i] >= 0.0f);
    lpv_ref_destroy(ref);
    lpv_scene_free(&b.s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_direct_analytic),
        cmocka_unit_test(test_one_bounce_rectangle),
        cmocka_unit_test(test_double_sided_emitter_back),
        cmocka_unit_test(test_furnace),
        cmocka_unit_test(test_furnace_lit),
        cmocka_unit_test(test_furnace_converged),
        cmocka_unit_test(test_converged_matches_fixed),
        cmocka_unit_test(test_converged_cap),
        cmocka_unit_test(test_pixel_rays_project_back),
        cmocka_unit_test(test_cornell_image),
        cmocka_unit_test(test_texture_albedo),
        cmocka_unit_test(test_empty_scene),
        cmocka_unit_test(test_degenerate_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
