/*
 * test_probes_trace_gpu.c - the GLSL traversal of the probes' BVH
 * (probes_trace.glsl, run by probes_rays.comp) against the CPU's
 * (lpv_probes_bvh_intersect), on the GL path (llvmpipe in CI).
 *
 * The same arrays are uploaded as they are built, and each ray's hit or
 * miss, triangle and distance are compared. The two sides run the same
 * float operations, but a GL compiler may fuse a multiply and an add where
 * the C compiler did not, so a ray that passes within a rounding of an edge
 * two triangles share can pick the other one: the test allows 1 ray in 500
 * to differ (and prints them), the distance within 1e-4 relative where the
 * triangle agrees. A traversal that skipped or misread nodes disagrees on
 * far more.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "context.h"
#include "engine.h"
#include "gl.h"
#include "probes_bvh.h"
#include "scene.h"
#include "shader.h"
#include "test_util.h"

typedef struct fixture {
    lpv_gl_context *ctx;
    lpv_engine *engine;
    GLuint prog;
} fixture;

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    *state = f;
    if (lpvt_gl_open(&f->ctx, &f->engine) != 0)
        return -1;
    static const char *const inc[] = {"probes_trace.glsl", NULL};
    char err[4096];
    f->prog = lpv_program_build("probes_rays.comp", NULL, NULL, inc, err, sizeof err);
    if (!f->prog) {
        fprintf(stderr, "probes_rays.comp: %s\n", err);
        return -1;
    }
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    if (f->prog)
        glDeleteProgram(f->prog);
    lpvt_gl_close(f->ctx, f->engine);
    free(f);
    return 0;
}

/* A storage buffer holding bytes (at least 16, so an empty array binds). */
static GLuint upload(const void *data, size_t bytes)
{
    GLuint buf;
    glGenBuffers(1, &buf);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, buf);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(bytes ? bytes : 16), NULL, GL_STATIC_DRAW);
    if (bytes)
        glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)bytes, data);
    return buf;
}

/* Traces n rays (8 floats each: origin, tmax, direction, unused) on the GPU
 * and on the CPU through b, and returns how many differ. */
static size_t compare_rays(const fixture *f, const lpv_probes_bvh *b, const float *rays, size_t n, size_t *hits)
{
    GLuint nodes = upload(b->nodes, b->node_count * sizeof *b->nodes);
    GLuint tris = upload(b->leaf_tris, b->leaf_tri_count * sizeof *b->leaf_tris);
    GLuint verts = upload(b->vertices, b->triangle_count * 12 * sizeof(float));
    GLuint rbuf = upload(rays, n * 8 * sizeof(float));
    GLuint hbuf = upload(NULL, n * 4 * sizeof(uint32_t));
    glUseProgram(f->prog);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_NODES, nodes);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_LEAF_TRIS, tris);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_VERTS, verts);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_RAYS, rbuf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_PROBES_HITS, hbuf);
    glUniform1ui(glGetUniformLocation(f->prog, "u_ray_count"), (GLuint)n);
    glDispatchCompute((GLuint)((n + LPV_PROBES_WG - 1) / LPV_PROBES_WG), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    uint32_t *gpu = malloc(n * 4 * sizeof *gpu);
    assert_non_null(gpu);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, hbuf);
    glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(n * 4 * sizeof *gpu), gpu);
    assert_int_equal(glGetError(), GL_NO_ERROR);

    size_t differ = 0;
    *hits = 0;
    for (size_t i = 0; i < n; ++i) {
        const float *r = rays + 8 * i;
        float t = 0.0f;
        uint32_t tri = 0;
        const int cpu_hit = lpv_probes_bvh_intersect(b, r, r + 4, r[3], &t, &tri);
        const int gpu_hit = gpu[4 * i + 2] != 0;
        float gpu_t;
        memcpy(&gpu_t, &gpu[4 * i], sizeof gpu_t);
        *hits += (size_t)cpu_hit;
        const int same = cpu_hit == gpu_hit &&
                         (!cpu_hit || (tri == gpu[4 * i + 1] && fabsf(gpu_t - t) <= 1e-4f * fabsf(t)));
        if (!same) {
            if (differ < 5)
                fprintf(stderr, "ray %zu: cpu %s tri %u t %.9g, gpu %s tri %u t %.9g\n", i, cpu_hit ? "hit" : "miss",
                        tri, (double)t, gpu_hit ? "hit" : "miss", gpu[4 * i + 1], (double)gpu_t);
            ++differ;
        }
    }
    free(gpu);
    GLuint all[5] = {nodes, tris, verts, rbuf, hbuf};
    glDeleteBuffers(5, all);
    return differ;
}

/* The built-in Cornell box's triangles (positions packed xyz). */
static float *cornell_positions(lpv_scene *s)
{
    float *p = malloc((size_t)s->vertex_count * 3 * sizeof *p);
    assert_non_null(p);
    for (uint32_t v = 0; v < s->vertex_count; ++v)
        memcpy(p + 3 * v, s->vertices[v].position, 3 * sizeof(float));
    return p;
}

/* Rays from random points inside the box's interior, in random directions,
 * unbounded: each meets a wall, a block or the ceiling's lamp. */
static void test_cornell_rays(void **state)
{
    fixture *f = *state;
    lpv_scene s;
    memset(&s, 0, sizeof s);
    assert_int_equal(lpv_scene_builtin_cornell(&s), 0);
    float *pos = cornell_positions(&s);
    lpv_probes_bvh b;
    char err[256];
    assert_int_equal(lpv_probes_bvh_build(&b, pos, s.vertex_count, s.indices, s.index_count / 3, err, sizeof err), 0);
    float lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
        lo[k] = INFINITY;
        hi[k] = -INFINITY;
    }
    for (uint32_t v = 0; v < s.vertex_count; ++v)
        for (int k = 0; k < 3; ++k) {
            lo[k] = fminf(lo[k], pos[3 * v + k]);
            hi[k] = fmaxf(hi[k], pos[3 * v + k]);
        }
    enum { N = 20000 };
    float *rays = calloc((size_t)N * 8, sizeof *rays);
    assert_non_null(rays);
    uint64_t rng = 34;
    for (size_t i = 0; i < N; ++i) {
        float *r = rays + 8 * i;
        for (int k = 0; k < 3; ++k)
            r[k] = (float)lpvt_rand(&rng, lo[k] + 0.01 * (hi[k] - lo[k]), hi[k] - 0.01 * (hi[k] - lo[k]));
        r[3] = INFINITY;
        for (int k = 0; k < 3; ++k)
            r[4 + k] = (float)lpvt_rand(&rng, -1.0, 1.0);
    }
    size_t hits = 0;
    const size_t differ = compare_rays(f, &b, rays, N, &hits);
    fprintf(stderr, "cornell: %u triangles, %zu nodes, %d rays, %zu hit, %zu differ\n", s.index_count / 3, b.node_count,
            N, hits, differ);
    /* from inside the closed box nearly every ray hits (the front is open) */
    assert_true(hits > N / 2);
    assert_true(differ * 500 <= N);
    free(rays);
    lpv_probes_bvh_free(&b);
    free(pos);
    lpv_scene_free(&s);
}

/* A soup of random triangles and rays that start anywhere, some bounded
 * short: misses, hits and hits cut by tmax. */
static void test_soup_rays(void **state)
{
    fixture *f = *state;
    enum { T = 3000, N = 20000 };
    uint64_t rng = 35;
    float *pos = malloc((size_t)T * 9 * sizeof *pos);
    uint32_t *idx = malloc((size_t)T * 3 * sizeof *idx);
    assert_non_null(pos);
    assert_non_null(idx);
    for (size_t t = 0; t < T; ++t) {
        float c[3];
        for (int k = 0; k < 3; ++k)
            c[k] = (float)lpvt_rand(&rng, -10.0, 10.0);
        for (int v = 0; v < 3; ++v) {
            for (int k = 0; k < 3; ++k)
                pos[9 * t + 3 * v + k] = c[k] + (float)lpvt_rand(&rng, -0.8, 0.8);
            idx[3 * t + v] = (uint32_t)(3 * t + v);
        }
    }
    lpv_probes_bvh b;
    char err[256];
    assert_int_equal(lpv_probes_bvh_build(&b, pos, (size_t)T * 3, idx, T, err, sizeof err), 0);
    float *rays = calloc((size_t)N * 8, sizeof *rays);
    assert_non_null(rays);
    for (size_t i = 0; i < N; ++i) {
        float *r = rays + 8 * i;
        for (int k = 0; k < 3; ++k) {
            r[k] = (float)lpvt_rand(&rng, -12.0, 12.0);
            r[4 + k] = (float)lpvt_rand(&rng, -1.0, 1.0);
        }
        r[3] = i % 4 == 0 ? (float)lpvt_rand(&rng, 0.1, 5.0) : INFINITY;
    }
    size_t hits = 0;
    const size_t differ = compare_rays(f, &b, rays, N, &hits);
    fprintf(stderr, "soup: %d triangles, %zu nodes, %d rays, %zu hit, %zu differ\n", T, b.node_count, N, hits, differ);
    assert_true(hits > N / 10 && hits < N - N / 10); /* both kinds of answer are compared */
    assert_true(differ * 500 <= N);
    free(rays);
    lpv_probes_bvh_free(&b);
    free(pos);
    free(idx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cornell_rays),
        cmocka_unit_test(test_soup_rays),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
