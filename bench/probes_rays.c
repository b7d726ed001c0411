/*
 * probes_rays.c - lpvd-probes-rays: what tracing rays through the probes'
 * BVH costs (issue 34: the probes' update budget is rays per tick). Loads a
 * scene (default: the built-in Cornell box), builds the BVH
 * (techniques/probes/core/probes_bvh.h), and traces the same rays (from
 * random points inside the scene's bounds, random directions, unbounded) on
 * the CPU (lpv_probes_bvh_intersect, one thread) and on the GL path
 * (probes_rays.comp), printing the build time, rays per second of each and
 * how many answers differ. Prints figures; never a test.
 *
 *   lpvd-probes-rays [SCENE.glb|.gltf] [--rays N] [--repeat N]
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "context.h"
#include "gl.h"
#include "probes_bvh.h"
#include "scene.h"
#include "scene_load.h"
#include "shader.h"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* xorshift64: the rays are the same on every run */
static double rnd(uint64_t *s, double lo, double hi)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return lo + (hi - lo) * (double)(*s >> 11) / 9007199254740992.0;
}

static GLuint buffer(const void *data, size_t bytes)
{
    GLuint b;
    glGenBuffers(1, &b);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, b);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(bytes ? bytes : 16), data, GL_STATIC_DRAW);
    return b;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    const char *path = NULL;
    long rays_n = 1 << 18, repeat = 5;
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--rays") == 0 && i + 1 < argc)
            rays_n = strtol(argv[++i], NULL, 10);
        else if (strcmp(argv[i], "--repeat") == 0 && i + 1 < argc)
            repeat = strtol(argv[++i], NULL, 10);
        else if (argv[i][0] != '-' && !path)
            path = argv[i];
        else {
            fprintf(stderr, "usage: lpvd-probes-rays [SCENE] [--rays N (1..16777216)] [--repeat N (1..100)]\n");
            return 2;
        }
    }
    if (rays_n < 1 || rays_n > (1 << 24) || repeat < 1 || repeat > 100) {
        fprintf(stderr, "lpvd-probes-rays: --rays 1..16777216, --repeat 1..100\n");
        return 2;
    }
    const size_t n = (size_t)rays_n;
    char err[1024];
    lpv_scene scene;
    if (lpv_scene_load_user(path, NULL, &scene, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd-probes-rays: %s\n", err);
        return 1;
    }
    const size_t tris = scene.index_count / 3;
    float *pos = malloc((size_t)scene.vertex_count * 3 * sizeof *pos + 1);
    float *rays = malloc(n * 8 * sizeof *rays);
    uint32_t *gpu = malloc(n * 4 * sizeof *gpu);
    if (!pos || !rays || !gpu) {
        fprintf(stderr, "lpvd-probes-rays: out of memory\n");
        return 1;
    }
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t v = 0; v < scene.vertex_count; ++v)
        for (int k = 0; k < 3; ++k) {
            pos[3 * v + k] = scene.vertices[v].position[k];
            lo[k] = fminf(lo[k], pos[3 * v + k]);
            hi[k] = fmaxf(hi[k], pos[3 * v + k]);
        }

    lpv_probes_bvh bvh;
    const double t_build = now_s();
    if (lpv_probes_bvh_build(&bvh, pos, scene.vertex_count, scene.indices, tris, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd-probes-rays: %s\n", err);
        return 1;
    }
    const double build_ms = 1e3 * (now_s() - t_build);

    uint64_t rng = 0x9e3779b97f4a7c15ull;
    for (size_t i = 0; i < n; ++i) {
        float *r = rays + 8 * i;
        for (int k = 0; k < 3; ++k) {
            const double m = 0.01 * (hi[k] - lo[k]);
            r[k] = (float)rnd(&rng, lo[k] + m, hi[k] - m);
            r[4 + k] = (float)rnd(&rng, -1.0, 1.0);
        }
        r[3] = INFINITY;
        r[7] = 0.0f;
    }

    /* CPU, one thread */
    size_t hits = 0;
    const double t_cpu = now_s();
    for (size_t i = 0; i < n; ++i)
        hits += (size_t)lpv_probes_bvh_intersect(&bvh, rays + 8 * i, rays + 8 * i + 4, rays[8 * i + 3], NULL, NULL);
    const double cpu_s = now_s() - t_cpu;

    /* GL */
    lpv_gl_context *ctx = lpv_gl_context_create(&(lpv_gl_context_desc){0}, err, sizeof err);
    if (!ctx) {
        fprintf(stderr, "lpvd-probes-rays: %s\n", err);
        return 1;
    }
    static const char *const inc[] = {"probes_trace.glsl", NULL};
    const GLuint prog = lpv_program_build("probes_rays.comp", NULL, NULL, inc, err, sizeof err);
    if (!prog) {
        fprintf(stderr, "lpvd-probes-rays: %s\n", err);
        return 1;
    }
    GLuint bufs[5] = {buffer(bvh.nodes, bvh.node_count * sizeof *bvh.nodes),
                      buffer(bvh.leaf_tris, bvh.leaf_tri_count * sizeof *bvh.leaf_tris),
                      buffer(bvh.vertices, bvh.triangle_count * 12 * sizeof(float)), buffer(rays, n * 8 * sizeof *rays),
                      buffer(NULL, n * 4 * sizeof *gpu)};
    const GLuint binding[5] = {LPV_SSBO_PROBES_NODES, LPV_SSBO_PROBES_LEAF_TRIS, LPV_SSBO_PROBES_VERTS,
                               LPV_SSBO_PROBES_RAYS, LPV_SSBO_PROBES_HITS};
    glUseProgram(prog);
    for (int i = 0; i < 5; ++i)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding[i], bufs[i]);
    glUniform1ui(glGetUniformLocation(prog, "u_ray_count"), (GLuint)n);
    double *ms = malloc((size_t)(repeat + 1) * sizeof *ms);
    for (long r = 0; r <= repeat; ++r) { /* the first run warms up (the shader's compile is lazy on some drivers) */
        glFinish();
        const double t0 = now_s();
        glDispatchCompute((GLuint)((n + LPV_PROBES_WG - 1) / LPV_PROBES_WG), 1, 1);
        glFinish();
        ms[r] = 1e3 * (now_s() - t0);
    }
    qsort(ms + 1, (size_t)repeat, sizeof *ms, cmp_double);
    const double gpu_ms = ms[1 + repeat / 2];
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, bufs[4]);
    glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(n * 4 * sizeof *gpu), gpu);
    size_t differ = 0;
    for (size_t i = 0; i < n; ++i) {
        float t = 0.0f, gt;
        uint32_t tri = 0;
        const int h = lpv_probes_bvh_intersect(&bvh, rays + 8 * i, rays + 8 * i + 4, rays[8 * i + 3], &t, &tri);
        memcpy(&gt, &gpu[4 * i], sizeof gt);
        differ += (size_t)!(h == (int)gpu[4 * i + 2] && (!h || (tri == gpu[4 * i + 1] && fabsf(gt - t) <= 1e-4f * t)));
    }

    printf("# lpvd-probes-rays: %s, GL_RENDERER %s\n", scene.source, lpv_gl_context_renderer(ctx));
    printf("triangles %zu (%zu skipped), nodes %zu, depth %u, build %.1f ms (Embree, one thread)\n", tris, bvh.skipped,
           bvh.node_count, bvh.depth, build_ms);
    printf("rays %zu, hit %zu (%.1f %%)\n", n, hits, 100.0 * (double)hits / (double)n);
    printf("cpu (one thread): %.1f ms, %.2f Mrays/s\n", 1e3 * cpu_s, (double)n / cpu_s * 1e-6);
    printf("gl (median of %ld): %.1f ms, %.2f Mrays/s; %zu of %zu answers differ from the cpu's\n", repeat, gpu_ms,
           (double)n / gpu_ms * 1e-3, differ, n);
    free(ms);
    glDeleteBuffers(5, bufs);
    glDeleteProgram(prog);
    lpv_gl_context_destroy(ctx);
    lpv_probes_bvh_free(&bvh);
    free(pos);
    free(rays);
    free(gpu);
    lpv_scene_free(&scene);
    return differ ? 3 : 0;
}
