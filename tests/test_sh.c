/*
 * test_sh.c - the SH conventions and propagation constants of
 * shaders/lpv_shared.h, re-derived numerically: lobe projection, round trip,
 * the orthonormality identity, the face solid angles and the sparse
 * propagation matrices (docs/propagation.md).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "lpv_shared.h"
#include "sh.h"

#define PI_D 3.14159265358979323846

/* cmocka 1.1's assert_float_equal compares in float; these checks need
 * double (1e-7 on values near 2). */
#define assert_near(a, b, tol) near_impl((double)(a), (double)(b), (double)(tol), #a, #b, __FILE__, __LINE__)

static void near_impl(double a, double b, double tol, const char *as, const char *bs, const char *file, int line)
{
    if (!(fabs(a - b) <= tol)) {
        print_error("%s = %.12g and %s = %.12g differ by %.3g > %.3g\n", as, a, bs, b, fabs(a - b), tol);
        _fail(file, line);
    }
}

/* Reference basis in double, written from the formulas, not the header's
 * float constants: Y00 = 1 / (2 sqrt(pi)), Y1m = sqrt(3 / (4 pi)) * (y, z, x),
 * no Condon-Shortley phase. */
static void ref_basis(const double w[3], double y[4])
{
    double c0 = 0.5 / sqrt(PI_D), c1 = sqrt(3.0 / (4.0 * PI_D));
    y[0] = c0;
    y[1] = c1 * w[1];
    y[2] = c1 * w[2];
    y[3] = c1 * w[0];
}

/* Midpoint rule on the sphere, uniform in (z = cos theta, phi): dw = dz dphi.
 * Exact in phi for the trigonometric polynomials here, O(h^2) in z. */
#define QUAD_NZ 1000
#define QUAD_NPHI 2000

typedef double (*sphere_fn)(const double w[3], const void *ctx);

/* Projects fn onto the basis: coef_i = integral fn Y_i dw. */
static void project(sphere_fn fn, const void *ctx, double coef[4])
{
    double dz = 2.0 / QUAD_NZ, dphi = 2.0 * PI_D / QUAD_NPHI;
    for (int i = 0; i < 4; i++)
        coef[i] = 0.0;
    for (int iz = 0; iz < QUAD_NZ; iz++) {
        double z = -1.0 + (iz + 0.5) * dz, r = sqrt(1.0 - z * z);
        for (int ip = 0; ip < QUAD_NPHI; ip++) {
            double phi = (ip + 0.5) * dphi;
            double w[3] = {r * cos(phi), r * sin(phi), z}, y[4];
            double f = fn(w, ctx) * dz * dphi;
            ref_basis(w, y);
            for (int i = 0; i < 4; i++)
                coef[i] += f * y[i];
        }
    }
}

static double integrate(sphere_fn fn, const void *ctx)
{
    double dz = 2.0 / QUAD_NZ, dphi = 2.0 * PI_D / QUAD_NPHI, sum = 0.0;
    for (int iz = 0; iz < QUAD_NZ; iz++) {
        double z = -1.0 + (iz + 0.5) * dz, r = sqrt(1.0 - z * z);
        for (int ip = 0; ip < QUAD_NPHI; ip++) {
            double phi = (ip + 0.5) * dphi;
            double w[3] = {r * cos(phi), r * sin(phi), z};
            sum += fn(w, ctx);
        }
    }
    return sum * dz * dphi;
}

static double clamped_cosine(const double w[3], const void *ctx)
{
    const double *n = ctx;
    double c = n[0] * w[0] + n[1] * w[1] + n[2] * w[2];
    return c > 0.0 ? c : 0.0;
}

/* An L1 function a + b.w, ctx = (a, bx, by, bz). */
static double linear_fn(const double w[3], const void *ctx)
{
    const double *p = ctx;
    return p[0] + p[1] * w[0] + p[2] * w[1] + p[3] * w[2];
}

static double linear_product(const double w[3], const void *ctx)
{
    const double *p = ctx;
    return linear_fn(w, p) * linear_fn(w, p + 4);
}

static double eval_coeffs(const double w[3], const void *ctx)
{
    const float *c = ctx;
    float d[3] = {(float)w[0], (float)w[1], (float)w[2]};
    return lpv_sh_eval(c, d);
}

static void normalise(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int i = 0; i < 3; i++)
        v[i] /= l;
}

/* Axis-aligned (both signs) and oblique normals. */
static const double test_normals[][3] = {
    {1, 0, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {1, 1, 1}, {-0.3, 0.8, 0.5}, {0.2, -0.1, -0.97},
};
#define N_TEST_NORMALS (sizeof test_normals / sizeof test_normals[0])

static void test_basis_convention(void **state)
{
    (void)state;
    /* Y1-1 is +C1 y: no Condon-Shortley minus sign. */
    float d[3] = {0.6f, -0.8f, 0.0f}, y[4];
    lpv_sh_basis(d, y);
    assert_near(y[0], 0.28209479f, 1e-7);
    assert_near(y[1], -0.8f * 0.48860251f, 1e-7);
    assert_near(y[2], 0.0f, 1e-7);
    assert_near(y[3], 0.6f * 0.48860251f, 1e-7);
}

/* (1) The closed-form lobe equals the projection of max(0, <n, w>). */
static void test_lobe_matches_quadrature(void **state)
{
    (void)state;
    for (size_t i = 0; i < N_TEST_NORMALS; i++) {
        double n[3] = {test_normals[i][0], test_normals[i][1], test_normals[i][2]}, ref[4];
        normalise(n);
        project(clamped_cosine, n, ref);
        float nf[3] = {(float)n[0], (float)n[1], (float)n[2]}, lobe[4];
        lpv_sh_cosine_lobe(nf, lobe);
        for (int k = 0; k < 4; k++)
            assert_near(lobe[k], ref[k], 1e-3);
    }
}

/* (2) Project a + b.w by quadrature and evaluate back. */
static void test_projection_round_trip(void **state)
{
    (void)state;
    static const double fns[][4] = {{1.0, 0.3, -0.2, 0.4}, {0.2, -1.0, 0.5, 0.0}, {-0.5, 0.0, 0.0, 2.0}};
    for (size_t f = 0; f < sizeof fns / sizeof fns[0]; f++) {
        double coef[4];
        project(linear_fn, fns[f], coef);
        float c[4] = {(float)coef[0], (float)coef[1], (float)coef[2], (float)coef[3]};
        for (size_t i = 0; i < N_TEST_NORMALS; i++) {
            double w[3] = {test_normals[i][0], test_normals[i][1], test_normals[i][2]};
            normalise(w);
            float wf[3] = {(float)w[0], (float)w[1], (float)w[2]};
            assert_near(lpv_sh_eval(c, wf), linear_fn(w, fns[f]), 1e-4);
        }
    }
}

/* (3) integral f g over the sphere = dot of the coefficient vectors. */
static void test_dot_is_product_integral(void **state)
{
    (void)state;
    const double fg[8] = {0.7, 0.2, -0.4, 0.1, 0.3, -0.6, 0.25, 0.9};
    double cf[4], cg[4];
    project(linear_fn, fg, cf);
    project(linear_fn, fg + 4, cg);
    float a[4], b[4];
    for (int i = 0; i < 4; i++) {
        a[i] = (float)cf[i];
        b[i] = (float)cg[i];
    }
    assert_near(lpv_sh_dot(a, b), integrate(linear_product, fg), 1e-3);
}

/* (4) The lobe integrates to pi; lpv_sh_integral agrees with quadrature. */
static void test_integral(void **state)
{
    (void)state;
    for (size_t i = 0; i < N_TEST_NORMALS; i++) {
        double n[3] = {test_normals[i][0], test_normals[i][1], test_normals[i][2]};
        normalise(n);
        float nf[3] = {(float)n[0], (float)n[1], (float)n[2]}, lobe[4];
        lpv_sh_cosine_lobe(nf, lobe);
        assert_near(lpv_sh_integral(lobe), PI_D, 1e-6);
        assert_near(integrate(eval_coeffs, lobe), PI_D, 1e-4);
    }
    const float c[4] = {0.8f, -0.3f, 0.5f, 0.1f};
    assert_near(lpv_sh_integral(c), integrate(eval_coeffs, c), 1e-4);
}

/* Solid angle of the axis-aligned rectangle {x = dist} x [y0, y1] x [z0, z1]
 * seen from the origin: integral dist / r^3 dA, midpoint rule (smooth
 * integrand: error ~ 1e-8 at distance 1.5, ~ 1e-7 at distance 0.5). */
static double rect_solid_angle(double dist, double y0, double y1, double z0, double z1)
{
    const int n = 2000;
    double hy = (y1 - y0) / n, hz = (z1 - z0) / n, sum = 0.0;
    for (int i = 0; i < n; i++) {
        double y = y0 + (i + 0.5) * hy;
        for (int j = 0; j < n; j++) {
            double z = z0 + (j + 0.5) * hz;
            double r2 = dist * dist + y * y + z * z;
            sum += dist / (r2 * sqrt(r2));
        }
    }
    return sum * hy * hz;
}

/* (5) Source at the origin, destination cell centred at (0, 0, 1): the far
 * face is z = 1.5, a side face x = 0.5 with z in [0.5, 1.5]. */
static void test_face_solid_angles(void **state)
{
    (void)state;
    double far = rect_solid_angle(1.5, -0.5, 0.5, -0.5, 0.5);
    double side = rect_solid_angle(0.5, -0.5, 0.5, 0.5, 1.5);
    double shared = rect_solid_angle(0.5, -0.5, 0.5, -0.5, 0.5);
    assert_near(far, LPV_FACE_SOLID_ANGLE_FAR, 1e-5);
    assert_near(side, LPV_FACE_SOLID_ANGLE_SIDE, 1e-5);
    assert_near(far, 4.0 * asin(0.1), 1e-7);
    assert_near(shared, 2.0 * PI_D / 3.0, 1e-6);
    /* The rays through the shared face leave through the five others. */
    assert_near(far + 4.0 * side, 2.0 * PI_D / 3.0, 1e-6);
    assert_near((double)LPV_FACE_SOLID_ANGLE_FAR + 4.0 * (double)LPV_FACE_SOLID_ANGLE_SIDE,
                       2.0 * PI_D / 3.0, 1e-6);
}

static const int axis_slot[3] = {3, 1, 2};

/* Dense M_d = sum over the destination's five faces of
 * (solid angle / pi) lobe(n_f) Y(w_c)^T, with w_c from the source centre to
 * the face centre and n_f the face's outward normal. */
static void dense_matrix_with(int d, int central, double m[4][4])
{
    int k = d / 2;
    double s = (d & 1) ? -1.0 : 1.0;
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            m[r][c] = 0.0;
    for (int face = 0; face < 5; face++) {
        double centre[3] = {0, 0, 0}, normal[3] = {0, 0, 0}, omega;
        centre[k] = s; /* destination centre */
        if (face == 0) {
            centre[k] += 0.5 * s;
            normal[k] = s;
            omega = LPV_FACE_SOLID_ANGLE_FAR;
        } else {
            int j = (k + 1 + (face - 1) / 2) % 3;
            double t = (face & 1) ? 1.0 : -1.0;
            centre[j] = 0.5 * t;
            normal[j] = t;
            omega = LPV_FACE_SOLID_ANGLE_SIDE;
        }
        normalise(centre);
        if (central) /* the central transport re-emits along w_c, not n_f */
            for (int i = 0; i < 3; i++)
                normal[i] = centre[i];
        float nf[3] = {(float)normal[0], (float)normal[1], (float)normal[2]}, lobe[4];
        lpv_sh_cosine_lobe(nf, lobe);
        double y[4];
        ref_basis(centre, y);
        for (int r = 0; r < 4; r++)
            for (int c = 0; c < 4; c++)
                m[r][c] += omega / PI_D * lobe[r] * y[c];
    }
}

/* (6) The sparse A, B, E, F, G form equals the dense matrices, for the
 * paper's transport and for the central one (lpv_shared.h: only the band-1
 * rows E, F, G differ). */
static void test_sparse_matrices(void **state)
{
    (void)state;
    for (int central = 0; central < 2; central++) {
        double e = central ? LPV_PROP_CENTRAL_E : LPV_PROP_E, f = central ? LPV_PROP_CENTRAL_F : LPV_PROP_F,
               g = central ? LPV_PROP_CENTRAL_G : LPV_PROP_G;
        for (int d = 0; d < 6; d++) {
            double m[4][4], sp[4][4] = {{0}};
            double s = (d & 1) ? -1.0 : 1.0;
            int k = axis_slot[d / 2];
            dense_matrix_with(d, central, m);
            sp[0][0] = LPV_PROP_A;
            sp[0][k] = s * LPV_PROP_B;
            sp[k][0] = s * e;
            sp[k][k] = f;
            for (int j = 1; j < 4; j++)
                if (j != k)
                    sp[j][j] = g;
            for (int r = 0; r < 4; r++)
                for (int c = 0; c < 4; c++)
                    assert_near(m[r][c], sp[r][c], 1e-6);
        }
    }
    /* A is exactly 1/6: the six neighbours share the source's flux. */
    assert_near(LPV_PROP_A, 1.0 / 6.0, 1e-8);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_basis_convention),
        cmocka_unit_test(test_lobe_matches_quadrature),
        cmocka_unit_test(test_projection_round_trip),
        cmocka_unit_test(test_dot_is_product_integral),
        cmocka_unit_test(test_integral),
        cmocka_unit_test(test_face_solid_angles),
        cmocka_unit_test(test_sparse_matrices),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
