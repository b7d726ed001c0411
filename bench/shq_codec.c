/*
 * shq_codec.c - the "shq" codec (SPEC R5.16) alone, on volumes saved from a
 * daemon: bytes per update, the bound, and the encoder's time, without a
 * socket or a GL context in the way (issue 35; docs/streaming.md).
 *
 *   lpvd-shq-codec [--bound E]... [--region NXxNYxNZ]... VOL0.bin VOL1.bin ...
 *
 * Each VOLn.bin is a raw fp32 volume of R5.1's 12 values per cell (what
 * GET_VOLUME "fp32", "none" carries up to any index; bench/stream_bench.py
 * --save DIR writes them), in update order. For each bound: a keyframe of
 * the first, then a delta chain (each against the previous update's
 * reconstruction, as a subscriber that ACKs everything gets), beside
 * fp16 + zstd XOR deltas of the same volumes; with --region (the volume's
 * cascades in order, e.g. three of 32x32x32 for the box's LPV, one of
 * 17x17x17 for its iv) also the deltas that may move cells by blocks
 * (R5.16 bit 2), as lpvd sends them. Then, for each bound, what a
 * client that extrapolates could save (replenish_estimate): the cells a
 * delta re-sends when the client holds each cell, against when it carries
 * each cell on by the change it had when it was last sent.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "proto.h"
#include "volume_codec.h"

#define CELL_BYTES (LPVP_VALUES_PER_CELL * 4)

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

static uint8_t *read_all(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *b = n > 0 ? malloc((size_t)n) : NULL;
    if (b && fread(b, 1, (size_t)n, f) != (size_t)n) {
        free(b);
        b = NULL;
    }
    fclose(f);
    *len = b ? (size_t)n : 0;
    return b;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Conditional replenishment with exact values (no quantisation: only where
 * the cells go past the bound): the mean cells re-sent per update when the
 * client's cell stands until it is re-sent (extrapolate 0), or when the
 * client moves each cell on, every update, by the change the cell had over
 * the update before it was last sent (extrapolate 1: a rate per re-sent
 * cell, which shq does not carry yet). An estimate of what rates would
 * save, for docs/streaming.md. */
static double replenish_estimate(uint8_t *const *vol, int nv, size_t cells, double bound, int extrapolate)
{
    float *held = malloc(cells * CELL_BYTES), *rate = calloc(cells * LPVP_VALUES_PER_CELL, sizeof(float));
    if (!held || !rate) {
        free(held);
        free(rate);
        return -1.0;
    }
    memcpy(held, vol[0], cells * CELL_BYTES);
    double resent = 0.0;
    for (int t = 1; t < nv; ++t)
        for (size_t c = 0; c < cells; ++c) {
            float v[LPVP_VALUES_PER_CELL], before[LPVP_VALUES_PER_CELL], *h = held + c * LPVP_VALUES_PER_CELL;
            float *dr = rate + c * LPVP_VALUES_PER_CELL;
            memcpy(v, vol[t] + c * CELL_BYTES, CELL_BYTES);
            memcpy(before, vol[t - 1] + c * CELL_BYTES, CELL_BYTES);
            for (int k = 0; extrapolate && k < LPVP_VALUES_PER_CELL; ++k)
                h[k] += dr[k];
            if (lpvp_shq_cell_error(h, v) <= bound * lpvp_shq_cell_magnitude(v))
                continue;
            resent += 1.0;
            for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k) {
                h[k] = v[k];
                dr[k] = v[k] - before[k];
            }
        }
    free(held);
    free(rate);
    return resent / (nv - 1);
}

/* The 99th percentile and the largest D / M over the cells with M > 0. */
static void bound_figures(const uint8_t *held, const uint8_t *exact, size_t cells, double *p99, double *max)
{
    double *r = malloc(cells * sizeof *r);
    size_t n = 0;
    for (size_t i = 0; i < cells; ++i) {
        float a[LPVP_VALUES_PER_CELL], b[LPVP_VALUES_PER_CELL];
        memcpy(a, held + i * CELL_BYTES, CELL_BYTES); /* little-endian hosts: the bench's files are */
        memcpy(b, exact + i * CELL_BYTES, CELL_BYTES);
        double m = lpvp_shq_cell_magnitude(b);
        if (m > 0.0)
            r[n++] = lpvp_shq_cell_error(a, b) / m;
    }
    qsort(r, n, sizeof *r, cmp_double);
    *p99 = n ? r[(size_t)floor(0.99 * (double)(n - 1))] : 0.0;
    *max = n ? r[n - 1] : 0.0;
    free(r);
}

int main(int argc, char **argv)
{
    double bounds[16];
    int nb = 0, first = 1;
    lpvp_shq_layout lay;
    memset(&lay, 0, sizeof lay);
    uint64_t next_cell = 0;
    for (; first < argc && strncmp(argv[first], "--", 2) == 0; first += 2) {
        if (first + 1 >= argc)
            break;
        unsigned d[3];
        if (strcmp(argv[first], "--bound") == 0 && nb < 16)
            bounds[nb++] = atof(argv[first + 1]);
        else if (strcmp(argv[first], "--region") == 0 && lay.count < LPVP_SHQ_MAX_REGIONS &&
                 sscanf(argv[first + 1], "%ux%ux%u", &d[0], &d[1], &d[2]) == 3) {
            lay.region[lay.count].first = next_cell;
            for (int a = 0; a < 3; ++a)
                lay.region[lay.count].dims[a] = d[a];
            next_cell += (uint64_t)d[0] * d[1] * d[2];
            lay.count++;
        } else {
            fprintf(stderr, "lpvd-shq-codec: unknown flag %s\n", argv[first]);
            return 2;
        }
    }
    if (!nb) {
        const double dflt[] = {0.005, 0.01, 0.02, 0.05};
        memcpy(bounds, dflt, sizeof dflt);
        nb = 4;
    }
    int nv = argc - first;
    if (nv < 2) {
        fprintf(stderr, "usage: lpvd-shq-codec [--bound E]... [--region NXxNYxNZ]... VOL0.bin VOL1.bin ...\n");
        return 2;
    }
    uint8_t **vol = calloc((size_t)nv, sizeof *vol);
    size_t len = 0;
    for (int i = 0; i < nv; ++i) {
        size_t l = 0;
        vol[i] = read_all(argv[first + i], &l);
        if (!vol[i] || (i && l != len) || l % CELL_BYTES) {
            fprintf(stderr, "lpvd-shq-codec: %s: unreadable, or not a volume of %zu bytes\n", argv[first + i], len);
            return 1;
        }
        len = l;
    }
    const size_t cells = len / CELL_BYTES;
    char err[256];
    /* today's: fp16 + zstd XOR deltas */
    uint8_t *h0 = malloc(cells * 24), *h1 = malloc(cells * 24), *x = malloc(cells * 24);
    float *f = malloc(len);
    double xor_bytes = 0.0;
    for (int i = 0; i < nv; ++i) {
        memcpy(f, vol[i], len);
        lpvp_volume_pack(f, cells, LPVP_FMT_FP16, h1);
        if (i) {
            lpvp_xor(x, h1, h0, cells * 24);
            uint8_t *z = NULL;
            size_t zl = 0;
            lpvp_zstd_compress(x, cells * 24, 0, &z, &zl, err, sizeof err);
            xor_bytes += (double)zl;
            free(z);
        }
        memcpy(h0, h1, cells * 24);
    }
    xor_bytes /= nv - 1;
    printf("%zu cells, %d updates; fp16 + zstd XOR delta: %.0f bytes per update\n", cells, nv - 1, xor_bytes);
    /* how far the exact volume itself moves between updates: what any codec
     * held to a bound per cell has to send */
    double *r = malloc(cells * (size_t)(nv - 1) * sizeof *r), corr_xy = 0.0, corr_xx = 0.0, corr_yy = 0.0;
    size_t nr = 0;
    for (int i = 1; i < nv; ++i)
        for (size_t c = 0; c < cells; ++c) {
            float a[LPVP_VALUES_PER_CELL], b[LPVP_VALUES_PER_CELL];
            memcpy(a, vol[i - 1] + c * CELL_BYTES, CELL_BYTES);
            memcpy(b, vol[i] + c * CELL_BYTES, CELL_BYTES);
            double m = lpvp_shq_cell_magnitude(b);
            if (m > 0.0)
                r[nr++] = lpvp_shq_cell_error(a, b) / m;
            if (c + 1 < cells && (c + 1) % 32 != 0) { /* c0's change against the next cell's, along x */
                float a1[LPVP_VALUES_PER_CELL], b1[LPVP_VALUES_PER_CELL];
                memcpy(a1, vol[i - 1] + (c + 1) * CELL_BYTES, CELL_BYTES);
                memcpy(b1, vol[i] + (c + 1) * CELL_BYTES, CELL_BYTES);
                double dx = (double)b[0] - a[0], dy = (double)b1[0] - a1[0];
                corr_xy += dx * dy;
                corr_xx += dx * dx;
                corr_yy += dy * dy;
            }
        }
    qsort(r, nr, sizeof *r, cmp_double);
    size_t over[3] = {0, 0, 0};
    for (size_t k = 0; k < nr; ++k)
        for (int t = 0; t < 3; ++t)
            over[t] += r[k] > (t == 0 ? 0.005 : t == 1 ? 0.01 : 0.02);
    printf("the exact volume between updates, over the lit cells: D/M median %.4f; over 0.5 %% / 1 %% / 2 %%: "
           "%.2f / %.2f / %.2f of them; c0's change against its x neighbour's: correlation %.2f (dims as 32 per "
           "row)\n\n",
           nr ? r[nr / 2] : 0.0, nr ? (double)over[0] / (double)nr : 0.0, nr ? (double)over[1] / (double)nr : 0.0,
           nr ? (double)over[2] / (double)nr : 0.0,
           corr_xx > 0 && corr_yy > 0 ? corr_xy / sqrt(corr_xx * corr_yy) : 0.0);
    free(r);
    printf("| bound | blocks | keyframe bytes | delta bytes (mean) | delta / fp16 XOR | cells re-sent per update | "
           "blocks moving per update | D/M p99 (worst update) | D/M max | encode ms per delta |\n"
           "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    uint8_t *held = malloc(len), *client = malloc(len);
    for (int b = 0; b < nb; ++b)
        for (int blocks = 0; blocks <= (lay.count > 0); ++blocks) {
            uint8_t *att = NULL;
            size_t att_len = 0, key_bytes = 0;
            lpvp_shq_counts sent;
            double bytes = 0.0, resent = 0.0, moving = 0.0, ms = 0.0, p99w = 0.0, maxw = 0.0;
            for (int i = 0; i < nv; ++i) {
                double t0 = now_ms();
                if (lpvp_shq_encode(vol[i], len, cells, i ? held : NULL, bounds[b], blocks ? &lay : NULL, held, &att,
                                    &att_len, &sent, err, sizeof err) != 0) {
                    fprintf(stderr, "lpvd-shq-codec: %s\n", err);
                    return 1;
                }
                double t1 = now_ms();
                if (lpvp_shq_decode(att, att_len, len, cells, i ? client : NULL, client, NULL, err, sizeof err) != 0 ||
                    memcmp(client, held, len) != 0) {
                    fprintf(stderr, "lpvd-shq-codec: update %d does not decode to the encoder's volume: %s\n", i,
                            err);
                    return 1;
                }
                double p99, mx;
                bound_figures(client, vol[i], cells, &p99, &mx);
                p99w = fmax(p99w, p99);
                maxw = fmax(maxw, mx);
                if (i) {
                    bytes += (double)att_len;
                    resent += (double)sent.sent;
                    moving += (double)sent.blocks;
                    ms += t1 - t0;
                } else {
                    key_bytes = att_len;
                }
                free(att);
            }
            printf("| %g | %s | %zu | %.0f | %.3f | %.0f of %zu | %.0f | %.4f | %.4f | %.1f |\n", bounds[b],
                   blocks ? "yes" : "no", key_bytes, bytes / (nv - 1), bytes / (nv - 1) / xor_bytes, resent / (nv - 1),
                   cells, moving / (nv - 1), p99w, maxw, ms / (nv - 1));
        }
    printf("\nCells past the bound per update, values exact (no quantisation), if the client holds each cell / "
           "carries it on by its last change:\n");
    for (int b = 0; b < nb; ++b)
        printf("  bound %g: %.0f / %.0f\n", bounds[b], replenish_estimate(vol, nv, cells, bounds[b], 0),
               replenish_estimate(vol, nv, cells, bounds[b], 1));
    return 0;
}
