/*
 * roofline.c - `lpvd-roofline`: the machine's roofs for the propagation
 * kernel (bench/README.md, "Engine"): fp32 FMA rate, the rate of
 * 8-wide AVX2 gathers (llvmpipe turns every texelFetch of a buffer texture
 * into one gather per channel), and memory bandwidth (a STREAM-like triad
 * over arrays far larger than the caches), each on every core at once (one
 * thread per core, as llvmpipe runs). Prints Markdown; asserts nothing.
 *
 *   lpvd-roofline [--seconds S]
 */
#define _GNU_SOURCE
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

typedef struct job {
    int kind; /* 0 FMA, 1 gather, 2 triad */
    double seconds;
    double work; /* flops, gathered elements or bytes done */
    float sink;
} job;

#define TRIAD_N (16u << 20) /* floats per array: 64 MiB each, three arrays per thread */

#if defined(__x86_64__)
__attribute__((target("avx2,fma"))) static double fma_loop(long iters, float *sink)
{
    /* 10 independent chains hide the FMA latency */
    __m256 a[10], m = _mm256_set1_ps(0.999999f), c = _mm256_set1_ps(1e-7f);
    for (int i = 0; i < 10; ++i)
        a[i] = _mm256_set1_ps((float)i);
    for (long k = 0; k < iters; ++k)
        for (int i = 0; i < 10; ++i)
            a[i] = _mm256_fmadd_ps(a[i], m, c);
    __m256 s = a[0];
    for (int i = 1; i < 10; ++i)
        s = _mm256_add_ps(s, a[i]);
    float out[8];
    _mm256_storeu_ps(out, s);
    *sink += out[0];
    return (double)iters * 10.0 * 8.0 * 2.0;
}

__attribute__((target("avx2"))) static double gather_loop(const float *table, int mask, long iters, float *sink)
{
    /* 4 independent gathers per round from a 64 KiB table (in L2, as a
     * 32^3 volume's neighbours mostly are), indices changing every round */
    __m256i idx[4], step = _mm256_set1_epi32(97), m = _mm256_set1_epi32(mask);
    __m256 acc = _mm256_setzero_ps();
    for (int i = 0; i < 4; ++i)
        idx[i] = _mm256_setr_epi32(i * 8 + 0, i * 8 + 131, i * 8 + 262, i * 8 + 393, i * 8 + 524, i * 8 + 655,
                                   i * 8 + 786, i * 8 + 917);
    for (long k = 0; k < iters; ++k)
        for (int i = 0; i < 4; ++i) {
            acc = _mm256_add_ps(acc, _mm256_i32gather_ps(table, idx[i], 4));
            idx[i] = _mm256_and_si256(_mm256_add_epi32(idx[i], step), m);
        }
    float out[8];
    _mm256_storeu_ps(out, acc);
    *sink += out[0];
    return (double)iters * 4.0 * 8.0;
}
#endif

static void *run(void *arg)
{
    job *j = arg;
    double t0 = now_s(), done = 0.0;
    if (j->kind == 2) {
        float *a = malloc(TRIAD_N * sizeof *a), *b = malloc(TRIAD_N * sizeof *b), *c = malloc(TRIAD_N * sizeof *c);
        if (!a || !b || !c) {
            free(a), free(b), free(c);
            return NULL;
        }
        for (size_t i = 0; i < TRIAD_N; ++i)
            b[i] = 1.0f, c[i] = 2.0f;
        t0 = now_s();
        while (now_s() - t0 < j->seconds) {
            for (size_t i = 0; i < TRIAD_N; ++i)
                a[i] = b[i] + 0.5f * c[i];
            done += 3.0 * TRIAD_N * sizeof(float); /* read b, c; write a (plus write-allocate, not counted) */
            b[TRIAD_N / 2] = a[TRIAD_N / 3];
        }
        j->sink += a[7];
        free(a), free(b), free(c);
    }
#if defined(__x86_64__)
    else if (j->kind == 0) {
        while (now_s() - t0 < j->seconds)
            done += fma_loop(1 << 20, &j->sink);
    } else {
        enum { TABLE = 16384 }; /* floats: 64 KiB */
        float *table = malloc(TABLE * sizeof *table);
        for (int i = 0; i < TABLE; ++i)
            table[i] = (float)i;
        while (now_s() - t0 < j->seconds)
            done += gather_loop(table, TABLE - 1, 1 << 18, &j->sink);
        free(table);
    }
#endif
    j->work = done;
    j->seconds = now_s() - t0;
    return NULL;
}

/* Work per second over all threads. */
static double measure(int kind, int threads, double seconds)
{
    pthread_t t[64];
    job j[64];
    for (int i = 0; i < threads; ++i) {
        j[i] = (job){.kind = kind, .seconds = seconds};
        pthread_create(&t[i], NULL, run, &j[i]);
    }
    double rate = 0.0;
    for (int i = 0; i < threads; ++i) {
        pthread_join(t[i], NULL);
        rate += j[i].seconds > 0.0 ? j[i].work / j[i].seconds : 0.0;
    }
    return rate;
}

int main(int argc, char **argv)
{
    double seconds = 2.0;
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--seconds") == 0 && i + 1 < argc)
            seconds = atof(argv[++i]);
        else {
            fprintf(stderr, "usage: lpvd-roofline [--seconds S]\n");
            return 2;
        }
    }
    if (!(seconds > 0.0) || seconds > 600.0) {
        fprintf(stderr, "lpvd-roofline: --seconds in (0, 600]\n");
        return 2;
    }
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    int threads = cores < 1 ? 1 : (cores > 64 ? 64 : (int)cores);
    printf("# lpvd-roofline: %d threads, %.1f s each\n\n| roof | all cores |\n|---|---:|\n", threads, seconds);
#if defined(__x86_64__)
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
        printf("| fp32 FMA (AVX2, 8 lanes) | %.1f GFLOP/s |\n", measure(0, threads, seconds) / 1e9);
        printf("| 8-wide gathers (AVX2, from L2) | %.2f G elements/s |\n", measure(1, threads, seconds) / 1e9);
    } else
        printf("| fp32 FMA, gathers | no AVX2/FMA: not measured |\n");
#else
    printf("| fp32 FMA, gathers | not x86-64: not measured |\n");
#endif
    printf("| memory (triad, 3 x 64 MiB per thread) | %.1f GB/s |\n", measure(2, threads, seconds) / 1e9);
    return 0;
}
