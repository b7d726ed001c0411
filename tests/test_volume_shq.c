/*
 * test_volume_shq.c - the "shq" volume codec (protocol/volume_shq.c, SPEC
 * R5.16): the bound held on every cell of keyframes and of a chain of
 * deltas, keyframes predicted from the cell before, unchanged cells cost nothing, a static volume sends no cell, the
 * bytes after the values travel exactly, hostile values stay finite, and
 * the decoder refuses every malformed payload the SPEC names; deltas with
 * blocks carry light that changes smoothly in fewer bytes.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "proto.h"
#include "volume_codec.h"

#define CELL_BYTES (LPVP_VALUES_PER_CELL * 4)

static uint64_t rng = 0x9E3779B97F4A7C15ull;
static double uniform(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

/* A physically shaped cell: a non-negative lobe of each channel (|v| <= c0
 * sqrt(3)), scaled over many decades so every exponent range is tried. */
static void make_cell(float v[LPVP_VALUES_PER_CELL], double scale)
{
    for (int c = 0; c < 3; ++c) {
        double c0 = scale * (0.2 + uniform());
        v[4 * c] = (float)c0;
        for (int k = 1; k < 4; ++k)
            v[4 * c + k] = (float)(c0 * (uniform() * 2.0 - 1.0));
    }
}

static void get_cell(const uint8_t *raw, size_t i, float v[LPVP_VALUES_PER_CELL])
{
    for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k) {
        uint32_t u = lpvp_get_u32(raw + i * CELL_BYTES + 4 * (size_t)k);
        memcpy(&v[k], &u, 4);
    }
}

static void put_cell(uint8_t *raw, size_t i, const float v[LPVP_VALUES_PER_CELL])
{
    for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k) {
        uint32_t u;
        memcpy(&u, &v[k], 4);
        lpvp_put_u32(raw + i * CELL_BYTES + 4 * (size_t)k, u);
    }
}

/* The largest D(held, exact) / M(exact) over the cells (0 for equal zero cells). */
static double worst_ratio(const uint8_t *held, const uint8_t *exact, size_t cells)
{
    double worst = 0.0;
    for (size_t i = 0; i < cells; ++i) {
        float a[LPVP_VALUES_PER_CELL], b[LPVP_VALUES_PER_CELL];
        get_cell(held, i, a);
        get_cell(exact, i, b);
        double d = lpvp_shq_cell_error(a, b), m = lpvp_shq_cell_magnitude(b);
        double r = m > 0.0 ? d / m : (d > 0.0 ? INFINITY : 0.0);
        worst = r > worst ? r : worst;
    }
    return worst;
}

/* Encode (with blocks over lay, when given), decode (in place on the
 * client's copy), check both sides agree; *att_bytes (may be NULL) gets
 * the attachment's size. */
static lpvp_shq_counts round_trip_in(const uint8_t *raw, size_t len, size_t cells, uint8_t *server_held,
                                     uint8_t *client, int delta, double bound, const lpvp_shq_layout *lay,
                                     size_t *att_bytes)
{
    char err[256];
    uint8_t *att = NULL, *recon = malloc(len);
    size_t att_len = 0, got = 7777;
    lpvp_shq_counts sent = {9999, 9999};
    assert_non_null(recon);
    assert_int_equal(lpvp_shq_encode(raw, len, cells, delta ? server_held : NULL, bound, lay, recon, &att, &att_len,
                                     &sent, err, sizeof err),
                     0);
    assert_int_equal(lpvp_shq_decode(att, att_len, len, cells, delta ? client : NULL, client, &got, err, sizeof err), 0);
    assert_int_equal(got, sent.sent);
    assert_memory_equal(recon, client, len); /* the server knows what the client holds, bit for bit */
    memcpy(server_held, recon, len);
    free(recon);
    free(att);
    if (att_bytes)
        *att_bytes = att_len;
    return sent;
}

static size_t round_trip(const uint8_t *raw, size_t len, size_t cells, uint8_t *server_held, uint8_t *client,
                         int delta, double bound)
{
    return round_trip_in(raw, len, cells, server_held, client, delta, bound, NULL, NULL).sent;
}

static void test_keyframe_holds_the_bound(void **state)
{
    (void)state;
    const size_t cells = 4096;
    const double bounds[] = {LPVP_SHQ_BOUND_MIN, 0.01, 0.1, LPVP_SHQ_BOUND_MAX};
    uint8_t *raw = malloc(cells * CELL_BYTES), *held = malloc(cells * CELL_BYTES), *client = malloc(cells * CELL_BYTES);
    for (size_t i = 0; i < cells; ++i) {
        float v[LPVP_VALUES_PER_CELL];
        make_cell(v, pow(10.0, -25.0 + 50.0 * uniform()));
        put_cell(raw, i, v);
    }
    for (size_t b = 0; b < sizeof bounds / sizeof bounds[0]; ++b) {
        assert_int_equal(round_trip(raw, cells * CELL_BYTES, cells, held, client, 0, bounds[b]), cells);
        double worst = worst_ratio(client, raw, cells);
        assert_true(worst <= bounds[b] * (1.0 + 1e-6)); /* rounding spends a share of the bound */
        assert_true(worst > bounds[b] * 0.05); /* and it is a quantisation, not a copy */
    }
    free(raw);
    free(held);
    free(client);
}

/* A keyframe is predicted (flag bit 1): a cell equal to the one before it
 * costs mantissas of 0, one at twice the value (one exponent up) is
 * predicted as the value before it, rounded half to even to its step, and
 * the decoder gives back every cell; the random
 * volumes of the other tests cover exponent jumps beyond 15 and the 16-bit
 * wrap. */
static void test_keyframes_are_predicted(void **state)
{
    (void)state;
    char err[256];
    enum { CELLS = 64 };
    const size_t len = CELLS * CELL_BYTES;
    uint8_t raw[CELLS * CELL_BYTES], held[CELLS * CELL_BYTES], client[CELLS * CELL_BYTES];
    float v[LPVP_VALUES_PER_CELL];
    make_cell(v, 1.0);
    for (size_t i = 0; i < CELLS; ++i) {
        float w[LPVP_VALUES_PER_CELL];
        for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k)
            w[k] = i == CELLS / 2 ? 2.0f * v[k] : v[k]; /* one cell at twice the light */
        put_cell(raw, i, w);
    }
    uint8_t *att = NULL, *p = NULL;
    size_t att_len = 0, plen = 0;
    assert_int_equal(lpvp_shq_encode(raw, len, CELLS, NULL, 0.01, NULL, held, &att, &att_len, NULL, err, sizeof err),
                     0);
    assert_int_equal(lpvp_zstd_decompress(att, att_len, 1 << 20, &p, &plen, err, sizeof err), 0);
    assert_int_equal(lpvp_get_u32(p + 4), 3); /* keyframe, predicted */
    const uint8_t *exps = p + 32, *lo = exps + CELLS, *hi = lo + 12 * CELLS;
    assert_int_equal((int8_t)exps[CELLS / 2], (int8_t)exps[0] + 1);
    int nonzero_first = 0;
    for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k) {
        int32_t r[CELLS];
        for (size_t j = 0; j < CELLS; ++j) {
            const unsigned z = lo[(size_t)k * CELLS + j] | (unsigned)hi[(size_t)k * CELLS + j] << 8;
            r[j] = (z & 1) ? -(int32_t)(z >> 1) - 1 : (int32_t)(z >> 1);
        }
        nonzero_first += r[0] != 0; /* the first cell has no predecessor: its mantissas as they are */
        for (size_t j = 1; j < CELLS; ++j)
            if (j == CELLS / 2) /* twice the light one step up: the same mantissa, predicted as half of it */
                assert_int_equal(r[j], r[0] - (int32_t)nearbyint(r[0] / 2.0));
            else if (j == CELLS / 2 + 1) /* back down: predicted as twice the doubled cell's */
                assert_int_equal(r[j], -r[0]);
            else /* a cell like the one before costs nothing */
                assert_int_equal(r[j], 0);
    }
    assert_true(nonzero_first > 0);
    assert_int_equal(lpvp_shq_decode(att, att_len, len, CELLS, NULL, client, NULL, err, sizeof err), 0);
    assert_memory_equal(client, held, len);
    assert_true(worst_ratio(client, raw, CELLS) <= 0.01);
    free(att);
    free(p);
}

/* A light that keeps moving: each step changes every cell a little and a
 * few cells a lot; every delta holds the bound on every cell, unchanged
 * cells are not re-sent, and the drift is caught before it passes the bound. */
static void test_deltas_hold_the_bound(void **state)
{
    (void)state;
    const size_t cells = 2048;
    const double bound = 0.01;
    uint8_t *raw = malloc(cells * CELL_BYTES), *held = malloc(cells * CELL_BYTES), *client = malloc(cells * CELL_BYTES);
    for (size_t i = 0; i < cells; ++i) {
        float v[LPVP_VALUES_PER_CELL];
        make_cell(v, 1.0 + 10.0 * uniform());
        put_cell(raw, i, v);
    }
    round_trip(raw, cells * CELL_BYTES, cells, held, client, 0, bound);
    size_t total = 0;
    for (int step = 0; step < 40; ++step) {
        for (size_t i = 0; i < cells; ++i) {
            float v[LPVP_VALUES_PER_CELL];
            get_cell(raw, i, v);
            double f = (i % 97 == (size_t)step) ? 1.5 : 1.0 + 0.002 * (uniform() - 0.3); /* a slow drift up */
            for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k)
                v[k] = (float)(v[k] * f);
            put_cell(raw, i, v);
        }
        size_t sent = round_trip(raw, cells * CELL_BYTES, cells, held, client, 1, bound);
        total += sent;
        assert_true(worst_ratio(client, raw, cells) <= bound * (1.0 + 1e-6));
        assert_true(sent < cells / 2); /* most cells stand */
    }
    /* the 1.5x cells are re-sent each time they jump (about 21 per step) and the drift
     * re-sends the rest every few steps; far fewer than 40 keyframes */
    assert_true(total > 40 * 21);
    assert_true(total < 40 * cells / 4);
    free(raw);
    free(held);
    free(client);
}

static void test_static_volume_sends_nothing(void **state)
{
    (void)state;
    const size_t cells = 1000, extra = 37, len = cells * CELL_BYTES + extra;
    uint8_t *raw = malloc(len), *held = malloc(len), *client = malloc(len);
    for (size_t i = 0; i < cells; ++i) {
        float v[LPVP_VALUES_PER_CELL];
        make_cell(v, (i % 3) ? 1.0 : 0.0); /* a third of the cells black */
        put_cell(raw, i, v);
    }
    for (size_t i = 0; i < extra; ++i)
        raw[cells * CELL_BYTES + i] = (uint8_t)(i * 7 + 1);
    round_trip(raw, len, cells, held, client, 0, 0.01);
    assert_memory_equal(client + cells * CELL_BYTES, raw + cells * CELL_BYTES, extra); /* the index exactly */
    for (int step = 0; step < 3; ++step)
        assert_int_equal(round_trip(raw, len, cells, held, client, 1, 0.01), 0);
    raw[cells * CELL_BYTES + 5] ^= 0x40; /* the index changed: it travels, exactly */
    assert_int_equal(round_trip(raw, len, cells, held, client, 1, 0.01), 0);
    assert_memory_equal(client + cells * CELL_BYTES, raw + cells * CELL_BYTES, extra);
    /* a black cell lit, a lit cell black: both re-sent */
    float v[LPVP_VALUES_PER_CELL], z[LPVP_VALUES_PER_CELL] = {0};
    make_cell(v, 1.0);
    put_cell(raw, 0, v);
    put_cell(raw, 1, z);
    assert_int_equal(round_trip(raw, len, cells, held, client, 1, 0.01), 2);
    assert_true(worst_ratio(client, raw, cells) <= 0.01);
    free(raw);
    free(held);
    free(client);
}

/* NaN, Inf, huge and subnormal values decode finite, and the bound holds
 * wherever the cell is in the codec's range. */
static void test_hostile_values(void **state)
{
    (void)state;
    const size_t cells = 4, len = cells * CELL_BYTES;
    uint8_t raw[4 * CELL_BYTES], held[4 * CELL_BYTES], client[4 * CELL_BYTES];
    float v[4][LPVP_VALUES_PER_CELL];
    for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k) {
        v[0][k] = k == 3 ? NAN : 1.0f;
        v[1][k] = k == 0 ? INFINITY : (k == 5 ? -INFINITY : 2.0f);
        v[2][k] = k % 4 == 0 ? FLT_MAX : 0.0f;
        v[3][k] = k % 4 == 0 ? 1e-40f : 0.0f; /* subnormal: below the codec's 1e-30, sent as zero */
    }
    for (size_t i = 0; i < cells; ++i)
        put_cell(raw, i, v[i]);
    round_trip(raw, len, cells, held, client, 0, 0.01);
    for (size_t i = 0; i < cells; ++i) {
        float a[LPVP_VALUES_PER_CELL];
        get_cell(client, i, a);
        for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k)
            assert_true(isfinite(a[k]));
        if (i == 3)
            for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k)
                assert_true(a[k] == 0.0f);
    }
    float a[LPVP_VALUES_PER_CELL];
    get_cell(client, 0, a);
    assert_true(fabsf(a[3]) < 0.02f && fabsf(a[0] - 1.0f) < 0.02f); /* NaN went as 0 */
    get_cell(client, 2, a);
    assert_true(a[0] > 0.99e30f && a[0] < 1.01e30f); /* clamped to 1e30 */
}

static void test_bad_bound_and_payloads(void **state)
{
    (void)state;
    char err[256];
    const size_t cells = 20, len = cells * CELL_BYTES;
    uint8_t raw[20 * CELL_BYTES], held[20 * CELL_BYTES], client[20 * CELL_BYTES];
    for (size_t i = 0; i < cells; ++i) {
        float v[LPVP_VALUES_PER_CELL];
        make_cell(v, 1.0);
        put_cell(raw, i, v);
    }
    uint8_t *att = NULL;
    size_t att_len = 0;
    lpvp_shq_counts sent;
    assert_int_equal(lpvp_shq_encode(raw, len, cells, NULL, 0.0005, NULL, held, &att, &att_len, &sent, err, sizeof err),
                     -1);
    assert_non_null(strstr(err, LPVP_SHQ_BOUND_KEY));
    assert_int_equal(lpvp_shq_encode(raw, len, cells, NULL, NAN, NULL, held, &att, &att_len, &sent, err, sizeof err),
                     -1);

    /* a good delta's payload, then each field broken in turn */
    round_trip(raw, len, cells, held, client, 0, 0.01);
    float v[LPVP_VALUES_PER_CELL];
    make_cell(v, 3.0);
    put_cell(raw, 3, v);
    assert_int_equal(lpvp_shq_encode(raw, len, cells, held, 0.01, NULL, held, &att, &att_len, &sent, err, sizeof err),
                     0);
    assert_int_equal(sent.sent, 1);
    uint8_t *p = NULL;
    size_t plen = 0;
    assert_int_equal(lpvp_zstd_decompress(att, att_len, 1 << 20, &p, &plen, err, sizeof err), 0);
    free(att);
    struct {
        size_t at;
        uint8_t value;
        const char *what;
    } breaks[] = {
        {0, 'X', "magic"},        {4, 2, "flags (predicted delta)"}, {4, 8, "flags"},           {8, 21, "cell count"}, {16, 2, "sent count"},
        {24, 1, "extra bytes"},  {32, 0x09, "bit map count"}, {34, 0x80, "bit past C"}, {36, 2, "mode"},
    };
    for (size_t b = 0; b < sizeof breaks / sizeof breaks[0]; ++b) {
        uint8_t *q = malloc(plen);
        memcpy(q, p, plen);
        q[breaks[b].at] = breaks[b].value;
        uint8_t *z = NULL;
        size_t zlen = 0;
        assert_int_equal(lpvp_zstd_compress(q, plen, 1, &z, &zlen, err, sizeof err), 0);
        memcpy(client + len - CELL_BYTES, held + len - CELL_BYTES, CELL_BYTES);
        err[0] = 0;
        int rc = lpvp_shq_decode(z, zlen, len, cells, client, client, NULL, err, sizeof err);
        if (rc == 0)
            print_error("accepted a payload with a broken %s\n", breaks[b].what);
        assert_int_equal(rc, -1);
        assert_true(strlen(err) > 0);
        free(z);
        free(q);
    }
    /* truncated and lengthened payloads */
    for (int d = -1; d <= 1; d += 2) {
        uint8_t *q = calloc(plen + 1, 1);
        memcpy(q, p, plen);
        uint8_t *z = NULL;
        size_t zlen = 0;
        assert_int_equal(lpvp_zstd_compress(q, plen + (size_t)d, 1, &z, &zlen, err, sizeof err), 0);
        assert_int_equal(lpvp_shq_decode(z, zlen, len, cells, client, client, NULL, err, sizeof err), -1);
        free(z);
        free(q);
    }
    /* a delta without a base, a payload for another size, and not zstd at all */
    uint8_t *z = NULL;
    size_t zlen = 0;
    assert_int_equal(lpvp_zstd_compress(p, plen, 1, &z, &zlen, err, sizeof err), 0);
    assert_int_equal(lpvp_shq_decode(z, zlen, len, cells, NULL, client, NULL, err, sizeof err), -1);
    assert_int_equal(lpvp_shq_decode(z, zlen, len - CELL_BYTES, cells - 1, client, client, NULL, err, sizeof err), -1);
    assert_int_equal(lpvp_shq_decode(p, plen, len, cells, client, client, NULL, err, sizeof err), -1);
    assert_int_equal(lpvp_shq_decode(z, zlen, len, cells, client, client, NULL, err, sizeof err), 0); /* intact */
    free(z);
    free(p);
}

/* Blocks (R5.16 bit 2): light that changes smoothly across cells is
 * carried by one change per block, so far fewer cells are re-sent and the
 * deltas are smaller than without, with the bound held on every cell,
 * zero cells left zero, the cells outside the regions untouched, and a
 * static volume still sending nothing. */
#define BLK_A 216 /* 9 x 6 x 4 */
#define BLK_GAP 3
#define BLK_B 125 /* 5 x 5 x 5 */
#define BLK_CELLS (BLK_A + BLK_GAP + BLK_B)
#define BLK_EXTRA 13

static void blocks_layout(lpvp_shq_layout *lay)
{
    memset(lay, 0, sizeof *lay);
    lay->count = 2;
    lay->region[0].first = 0;
    lay->region[0].dims[0] = 9, lay->region[0].dims[1] = 6, lay->region[0].dims[2] = 4;
    lay->region[1].first = BLK_A + BLK_GAP;
    lay->region[1].dims[0] = lay->region[1].dims[1] = lay->region[1].dims[2] = 5;
}

/* Cell i at update t: one lobe scaled by a smooth amplitude that grows by a
 * smooth amount each update; every 17th cell black. */
static void blocks_volume(uint8_t *raw, int t, const float lobe[LPVP_VALUES_PER_CELL])
{
    for (size_t i = 0; i < BLK_CELLS; ++i) {
        const size_t j = i < BLK_A ? i : i - BLK_A;
        const double x = (double)(j % 9), y = (double)(j / 9 % 6), z = (double)(j / 54);
        const double a = i % 17 == 0 ? 0.0 : (1.0 + 0.1 * x + 0.05 * y + 0.2 * z) * (1.0 + 0.03 * t * (1.0 + 0.05 * x));
        float v[LPVP_VALUES_PER_CELL];
        for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k)
            v[k] = (float)(lobe[k] * a);
        put_cell(raw, i, v);
    }
    for (size_t i = 0; i < BLK_EXTRA; ++i)
        raw[BLK_CELLS * CELL_BYTES + i] = (uint8_t)(3 * i + 1);
}

static void test_blocks_carry_smooth_change(void **state)
{
    (void)state;
    const size_t len = BLK_CELLS * CELL_BYTES + BLK_EXTRA;
    const double bound = 0.01;
    lpvp_shq_layout lay;
    blocks_layout(&lay);
    float lobe[LPVP_VALUES_PER_CELL];
    make_cell(lobe, 1.0);
    uint8_t *raw = malloc(len), *held[2] = {malloc(len), malloc(len)}, *client[2] = {malloc(len), malloc(len)};
    size_t bytes[2] = {0, 0}, resent[2] = {0, 0}, moving = 0;
    for (int with = 0; with < 2; ++with) {
        blocks_volume(raw, 0, lobe);
        round_trip_in(raw, len, BLK_CELLS, held[with], client[with], 0, bound, with ? &lay : NULL, NULL);
        for (int t = 1; t <= 10; ++t) {
            blocks_volume(raw, t, lobe);
            size_t n = 0;
            lpvp_shq_counts c =
                round_trip_in(raw, len, BLK_CELLS, held[with], client[with], 1, bound, with ? &lay : NULL, &n);
            bytes[with] += n;
            resent[with] += c.sent;
            if (with)
                moving += c.blocks;
            else
                assert_int_equal(c.blocks, 0);
            assert_true(worst_ratio(client[with], raw, BLK_CELLS) <= bound * (1.0 + 1e-6));
            for (size_t i = 0; i < BLK_CELLS; i += 17) { /* black stays exactly black */
                float v[LPVP_VALUES_PER_CELL];
                get_cell(client[with], i, v);
                for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k)
                    assert_true(v[k] == 0.0f);
            }
            assert_memory_equal(client[with] + BLK_CELLS * CELL_BYTES, raw + BLK_CELLS * CELL_BYTES, BLK_EXTRA);
        }
    }
    print_message("blocks: %zu cells re-sent, %zu bytes over 10 updates; without: %zu, %zu; %zu blocks moved\n",
                  resent[1], bytes[1], resent[0], bytes[0], moving);
    assert_true(moving > 0);
    assert_true(resent[1] * 2 < resent[0]);
    assert_true(bytes[1] < bytes[0]);
    /* nothing changed: nothing sent, blocks or not */
    lpvp_shq_counts c = round_trip_in(raw, len, BLK_CELLS, held[1], client[1], 1, bound, &lay, NULL);
    assert_int_equal(c.sent, 0);
    assert_int_equal(c.blocks, 0);
    free(raw);
    for (int w = 0; w < 2; ++w) {
        free(held[w]);
        free(client[w]);
    }
}

/* A delta with blocks, each of its block fields broken in turn, and a block
 * that would carry a value past binary32: refused, the client's volume as
 * it was. */
static void test_bad_blocks(void **state)
{
    (void)state;
    char err[256];
    const size_t len = BLK_CELLS * CELL_BYTES + BLK_EXTRA;
    lpvp_shq_layout lay;
    blocks_layout(&lay);
    float lobe[LPVP_VALUES_PER_CELL];
    make_cell(lobe, 1.0);
    uint8_t *raw = malloc(len), *held = malloc(len), *client = malloc(len), *saved = malloc(len);
    blocks_volume(raw, 0, lobe);
    round_trip_in(raw, len, BLK_CELLS, held, client, 0, 0.01, &lay, NULL);
    memcpy(saved, held, len);
    blocks_volume(raw, 1, lobe);
    uint8_t *att = NULL, *recon = malloc(len), *p = NULL;
    size_t att_len = 0, plen = 0;
    lpvp_shq_counts c;
    assert_int_equal(lpvp_shq_encode(raw, len, BLK_CELLS, held, 0.01, &lay, recon, &att, &att_len, &c, err, sizeof err),
                     0);
    assert_true(c.blocks > 0);
    assert_int_equal(lpvp_zstd_decompress(att, att_len, 1 << 20, &p, &plen, err, sizeof err), 0);
    assert_int_equal(lpvp_get_u32(p + 4), 4); /* a delta with blocks */
    assert_int_equal(lpvp_get_u32(p + 32), 2);
    assert_int_equal(lpvp_get_u32(p + 36), 3);
    const size_t blk = 32 + 8 + 2 * 20; /* the blocks' exponents */
    size_t first_moving = 0;
    while ((int8_t)p[blk + first_moving] == -128)
        first_moving++;
    struct {
        size_t at;
        uint32_t value;
        int bytes;
        const char *what;
    } breaks[] = {
        {32, 0, 4, "no regions"},
        {32, 17, 4, "too many regions"},
        {36, 0, 4, "edge 0"},
        {36, 65, 4, "edge 65"},
        {40 + 20, 10, 4, "region 1 overlapping region 0"},
        {40 + 20, BLK_CELLS - 100, 4, "region 1 past the cells"},
        {40 + 8, 0, 4, "a region 0 cells wide"},
        {40 + 8, 10, 4, "a region wider than its cells in order"},
        {blk + first_moving, 101, 1, "block exponent 101"},
        {4, 5, 4, "blocks on a keyframe"},
    };
    for (size_t b = 0; b < sizeof breaks / sizeof breaks[0]; ++b) {
        uint8_t *q = malloc(plen), *z = NULL;
        size_t zlen = 0;
        memcpy(q, p, plen);
        if (breaks[b].bytes == 4)
            lpvp_put_u32(q + breaks[b].at, breaks[b].value);
        else
            q[breaks[b].at] = (uint8_t)breaks[b].value;
        assert_int_equal(lpvp_zstd_compress(q, plen, 1, &z, &zlen, err, sizeof err), 0);
        err[0] = 0;
        int rc = lpvp_shq_decode(z, zlen, len, BLK_CELLS, client, client, NULL, err, sizeof err);
        if (rc == 0)
            print_error("accepted a payload with %s\n", breaks[b].what);
        assert_int_equal(rc, -1);
        assert_true(strlen(err) > 0);
        assert_memory_equal(client, saved, len);
        free(z);
        free(q);
    }
    /* a client cell at binary32's largest value in the first moving block, moved up by the most a block can:
     * infinity, refused */
    size_t victim = 0;
    {
        const size_t per[3] = {3, 2, 2}; /* region 0's blocks of edge 3 */
        const size_t bx = first_moving % per[0], by = first_moving / per[0] % per[1], bz = first_moving / 6;
        assert_true(first_moving < 12); /* in region 0 */
        victim = bx * 3 + 9 * (by * 3 + 6 * (bz * 3));
        if (victim % 17 == 0)
            victim += 1; /* a live cell */
    }
    float v[LPVP_VALUES_PER_CELL];
    get_cell(client, victim, v);
    v[0] = FLT_MAX;
    put_cell(client, victim, v);
    memcpy(saved, client, len);
    {
        uint8_t *q = malloc(plen), *z = NULL;
        size_t zlen = 0, nb = 12 + 8; /* region 0: 3 x 2 x 2 blocks, region 1: 2 x 2 x 2 */
        memcpy(q, p, plen);
        q[blk + first_moving] = 100;
        q[blk + nb + first_moving] = 0xFE; /* value 0's zigzag 0xFFFE: +32767 */
        q[blk + nb + 12 * nb + first_moving] = 0xFF;
        assert_int_equal(lpvp_zstd_compress(q, plen, 1, &z, &zlen, err, sizeof err), 0);
        assert_int_equal(lpvp_shq_decode(z, zlen, len, BLK_CELLS, client, client, NULL, err, sizeof err), -1);
        assert_non_null(strstr(err, "binary32"));
        assert_memory_equal(client, saved, len);
        free(z);
        free(q);
    }
    free(att);
    free(p);
    free(recon);
    free(raw);
    free(held);
    free(client);
    free(saved);
}

/* The header: "shq" needs fp32 and a bound in range; decode goes through it. */
static void test_header(void **state)
{
    (void)state;
    char err[256];
    const size_t cells = 8;
    lpvp_volume_info vi = {.revision = 1, .tick = 2, .format = LPVP_FMT_FP32, .compression = LPVP_COMP_SHQ,
                           .error_bound = 0.02, .keyframe = 1, .base_tick = -1, .dims = {2, 2, 2},
                           .cell_size = 0.5, .raw_length = cells * CELL_BYTES};
    json_t *h = lpvp_volume_header_build(&vi);
    assert_non_null(h);
    assert_string_equal(json_string_value(json_object_get(h, "compression")), "shq");
    lpvp_volume_info back;
    assert_int_equal(lpvp_volume_header_parse(h, &back, err, sizeof err), 0);
    assert_int_equal(back.compression, LPVP_COMP_SHQ);
    assert_true(back.error_bound == 0.02);

    uint8_t raw[8 * CELL_BYTES], held[8 * CELL_BYTES], out[8 * CELL_BYTES];
    for (size_t i = 0; i < cells; ++i) {
        float v[LPVP_VALUES_PER_CELL];
        make_cell(v, 1.0);
        put_cell(raw, i, v);
    }
    uint8_t *att = NULL;
    size_t att_len = 0;
    assert_int_equal(
        lpvp_shq_encode(raw, sizeof raw, cells, NULL, 0.02, NULL, held, &att, &att_len, NULL, err, sizeof err), 0);
    assert_int_equal(lpvp_volume_decode(&back, att, att_len, NULL, 0, out, err, sizeof err), 0);
    assert_memory_equal(out, held, sizeof out);
    free(att);

    json_object_set_new(h, "error_bound", json_real(0.5));
    assert_int_equal(lpvp_volume_header_parse(h, &back, err, sizeof err), -1);
    assert_non_null(strstr(err, "error_bound"));
    json_object_del(h, "error_bound");
    assert_int_equal(lpvp_volume_header_parse(h, &back, err, sizeof err), -1);
    json_object_set_new(h, "error_bound", json_real(0.02));
    json_object_set_new(h, "format", json_string("fp16"));
    json_object_set_new(h, "raw_length", json_integer((json_int_t)(cells * 24)));
    assert_int_equal(lpvp_volume_header_parse(h, &back, err, sizeof err), -1);
    assert_non_null(strstr(err, "fp32"));
    json_decref(h);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_keyframe_holds_the_bound), cmocka_unit_test(test_keyframes_are_predicted),
        cmocka_unit_test(test_deltas_hold_the_bound),
        cmocka_unit_test(test_static_volume_sends_nothing), cmocka_unit_test(test_hostile_values),
        cmocka_unit_test(test_bad_bound_and_payloads), cmocka_unit_test(test_blocks_carry_smooth_change),
        cmocka_unit_test(test_bad_blocks), cmocka_unit_test(test_header),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
