/*
 * volume_shq.c - "shq", the quantised SH codec of a streamed volume (SPEC
 * R5.16, issue 35). See volume_codec.h.
 *
 * Why this shape: a client does one thing with a cell's 12 values, the
 * cosine-lobe lookup E_c(n) = LOBE0 c0 + LOBE1 <c_vec, n> of each channel
 * c. So the codec bounds that, not the values: each cell is quantised with
 * a power-of-two step of its own (a shared exponent) chosen so that the
 * rounding moves no lookup by more than half the client's bound times the
 * cell's magnitude M = max_c (LOBE0 |c0| + LOBE1 |c_vec|), the largest
 * |E_c(n)| over all normals. A delta is conditional replenishment: the
 * encoder holds what the client holds (its reconstruction of the acked
 * volume) and re-sends a cell only where that is off the new volume by more
 * than the bound, so a light that moves 1 cm re-sends the few cells whose
 * light moved by more than the bound and nothing else, and a static scene
 * sends nothing. The exponents and the zigzag mantissas go in byte planes
 * (all low bytes, then all high bytes) so that zstd sees long runs. A
 * keyframe codes each cell as its change from the cell before it in the
 * buffer (the previous x, scaled to the cell's own step): neighbouring
 * cells hold similar light, and the previous cell is the one predictor
 * every decoder has without knowing the volume's layout. Measured on the
 * box's 3 x 32^3 LPV at e = 0.01 (bench/shq_codec.c), keyframes went from
 * 228 to 170 kB; the probes' from 48 to 29 kB, iv's from 31 to 27 kB. A
 * delta's re-sent cells are not predicted from each other: neighbours are
 * re-sent at different ticks, so their changes from the client's cells
 * differ (predicting them cost 6 % more bytes). What neighbours do share
 * when a lamp moves is the change itself where the light is smooth, so a
 * delta may first move the client's cells by one change per block of
 * cells of each cascade (R5.16 bit 2, SHQ_BLOCK_EDGE below), and the
 * encoder sends it when that is the smaller delta.
 *
 * Reconstruction is q x 2^e in fp32, exact (|q| < 2^15), so the encoder's
 * copy of the client's volume is the client's bit for bit.
 */
#include "volume_codec.h"
#include "volume_codec_internal.h"
#include "proto.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SHQ_MAGIC "SHQ1"
#define SHQ_HEAD 32        /* magic, flags u32, cells u64, sent u64, extra u64 */
#define SHQ_FLAG_KEY 1u
/* A keyframe's mantissas are each cell's change from its predecessor's,
 * scaled to its steps (shq_predict); set on every keyframe this encoder
 * writes, optional for a decoder's input. */
#define SHQ_FLAG_PREDICTED 2u
#define SHQ_PREDICT_SHIFT_MAX 15 /* |x' - x| beyond: no prediction */
/* A delta that first moves the client's cells by a change per block of
 * cells (R5.16 bit 2): the light of a moving lamp changes smoothly across
 * cells, so one change per 3 x 3 x 3 cells carries most of it and far fewer
 * cells leave the bound. Measured with bench/shq_codec.c on the box's
 * volumes, light 1 cm per update, e = 0.01 (re-sent cells, delta bytes):
 * the 3 x 32^3 LPV with smooth injection 19 561 -> 5 651 cells, 65 239 ->
 * 31 144 bytes; at the defaults 84 977 -> 62 208; iv 4 149 -> 2 735.
 * Edges 2, 3, 4 and 8 with a block step of 0.25, 0.35, 0.5 and 0.75 of the
 * bound were tried: 3 and 0.25 were the smallest on the three together (4:
 * 35.6 kB on the smooth LPV, 2: 32.0 kB but 3 % more on iv, 8: 52.8 kB).
 * The step is the share of the bound at the block's brightest cell. */
#define SHQ_FLAG_BLOCKS 4u
#define SHQ_BLOCK_EDGE 3
#define SHQ_BLOCK_SHARE 0.25
#define SHQ_BLOCK_MIN_SHARE 16 /* blocks are tried when a delta re-sends more than 1/16 of the cells */
#define SHQ_BLOCK_EXP_MAX 100  /* q 2^x stays a binary32 value well inside its range */
#define SHQ_BLOCK_EDGE_MAX 64
#define SHQ_REGION_BYTES 20    /* first u64, dims 3 x u32 */
#define SHQ_ZERO_EXP (-128)
#define SHQ_VALUE_LIMIT 1e30f /* |values| above are clamped (NaN is 0) */
#define SHQ_TINY 1e-30       /* a cell whose magnitude is below is sent as zero */
#define SHQ_Q_MAX 32767.0    /* |mantissa| and |a delta's residual| */
/* The share of the bound the rounding may spend; the rest is the drift a
 * delta tolerates before it re-sends a cell. Measured on a 3 x 32^3 LPV with
 * a light moving 1 cm per update (bench/shq_codec.c): the re-sent cells
 * hardly depend on it (the volume moves by more than the bound in most
 * cells anyway), the bits per cell do: 0.3 / 0.5 / 0.7 gave 0.243 / 0.219
 * / 0.206 of fp16 XOR's bytes at a bound of 0.01. */
#define SHQ_ROUND_SHARE 0.7
/* zstd's level: 3 against 1 cost 10 % more encoding time for 4 % smaller
 * deltas and 19 % smaller keyframes. */
#define SHQ_ZSTD_LEVEL 3

static const double LOBE0 = 0.88622692545275801; /* sqrt(pi) / 2, LPV_SH_LOBE0 */
static const double LOBE1 = 1.02332670794648849; /* sqrt(pi / 3), LPV_SH_LOBE1 */

static float clean(float v)
{
    if (isnan(v))
        return 0.0f;
    return v > SHQ_VALUE_LIMIT ? SHQ_VALUE_LIMIT : (v < -SHQ_VALUE_LIMIT ? -SHQ_VALUE_LIMIT : v);
}

double lpvp_shq_cell_magnitude(const float v[LPVP_VALUES_PER_CELL])
{
    double m = 0.0;
    for (int c = 0; c < 3; ++c) {
        const float *s = v + 4 * c;
        double e = LOBE0 * fabs((double)s[0]) +
                   LOBE1 * sqrt((double)s[1] * s[1] + (double)s[2] * s[2] + (double)s[3] * s[3]);
        m = e > m ? e : m;
    }
    return m;
}

double lpvp_shq_cell_error(const float a[LPVP_VALUES_PER_CELL], const float b[LPVP_VALUES_PER_CELL])
{
    double m = 0.0;
    for (int c = 0; c < 3; ++c) {
        const float *x = a + 4 * c, *y = b + 4 * c;
        double d[4];
        for (int k = 0; k < 4; ++k)
            d[k] = (double)x[k] - (double)y[k];
        double e = LOBE0 * fabs(d[0]) + LOBE1 * sqrt(d[1] * d[1] + d[2] * d[2] + d[3] * d[3]);
        m = e > m ? e : m;
    }
    return m;
}

static void get_cell(const uint8_t *raw, size_t i, float v[LPVP_VALUES_PER_CELL])
{
    const uint8_t *p = raw + i * LPVP_VALUES_PER_CELL * 4;
    if (lpvp_host_little_endian()) { /* the wire's order is the host's */
        memcpy(v, p, LPVP_VALUES_PER_CELL * 4);
        return;
    }
    for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k) {
        uint32_t u = lpvp_get_u32(p + 4 * k);
        memcpy(&v[k], &u, 4);
    }
}

static void put_cell(uint8_t *raw, size_t i, const float v[LPVP_VALUES_PER_CELL])
{
    uint8_t *p = raw + i * LPVP_VALUES_PER_CELL * 4;
    if (lpvp_host_little_endian()) {
        memcpy(p, v, LPVP_VALUES_PER_CELL * 4);
        return;
    }
    for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k) {
        uint32_t u;
        memcpy(&u, &v[k], 4);
        lpvp_put_u32(p + 4 * k, u);
    }
}

/* The base's value in steps of 2^e, as the client computes it (exact
 * scaling, ties to even). */
static double base_steps(float b, int e)
{
    return nearbyint(ldexp((double)b, -e));
}

/* One cell's values in steps of 2^e: q, and rec = q 2^e; 0 when a value
 * does not fit the mantissas' range. */
static int steps_of(const float v[LPVP_VALUES_PER_CELL], int e, int32_t q[LPVP_VALUES_PER_CELL],
                    float rec[LPVP_VALUES_PER_CELL])
{
    for (int i = 0; i < LPVP_VALUES_PER_CELL; ++i) {
        double x = nearbyint(ldexp((double)v[i], -e));
        if (!(fabs(x) <= SHQ_Q_MAX))
            return 0;
        q[i] = (int32_t)x;
        rec[i] = ldexpf((float)q[i], e);
    }
    return 1;
}

/* One cell's exponent and mantissas for bound: the coarsest power-of-two
 * step whose rounding keeps the cell within SHQ_ROUND_SHARE of the bound,
 * found from the worst case (every value off by half a step, aligned) and
 * then coarsened while the actual rounding still passes, so a typical cell
 * costs a bit or two less per value than the worst case asks. rec gets
 * what the client rebuilds. */
static int quantise(const float v[LPVP_VALUES_PER_CELL], double bound, int32_t q[LPVP_VALUES_PER_CELL],
                    float rec[LPVP_VALUES_PER_CELL])
{
    double m = lpvp_shq_cell_magnitude(v);
    const double k = LOBE0 + sqrt(3.0) * LOBE1; /* the lookup's worst gain on a per-value error */
    if (!(m >= SHQ_TINY)) {
        memset(q, 0, sizeof(int32_t) * LPVP_VALUES_PER_CELL);
        memset(rec, 0, sizeof(float) * LPVP_VALUES_PER_CELL);
        return SHQ_ZERO_EXP;
    }
    const double allowed = SHQ_ROUND_SHARE * bound * m;
    int e = (int)floor(log2(2.0 * allowed / k));
    if (e < -127) /* only reached below SHQ_TINY's magnitude at the smallest bound */
        e = -127;
    if (e > 127)
        e = 127;
    steps_of(v, e, q, rec); /* fits: |v| <= m / LOBE0 < 2^(e+1) k / (LOBE0 share bound) */
    for (int coarser = e + 1; coarser <= 127 && coarser <= e + 3; ++coarser) {
        int32_t q2[LPVP_VALUES_PER_CELL];
        float rec2[LPVP_VALUES_PER_CELL];
        if (!steps_of(v, coarser, q2, rec2) || lpvp_shq_cell_error(rec2, v) > allowed)
            break;
        memcpy(q, q2, sizeof q2);
        memcpy(rec, rec2, sizeof rec2);
        e = coarser;
    }
    return e;
}

/* The prediction of a keyframe cell's mantissa from its predecessor's q at
 * exponent prev_e: q scaled to the cell's step 2^e, rounded half to even
 * (exact: |q| < 2^15 and the shift at most 15 bits), or 0 where either
 * cell is zero, the steps are too far apart, or there is no predecessor. */
static int32_t shq_predict(int32_t prev_q, int prev_e, int e)
{
    if (prev_e == SHQ_ZERO_EXP || e == SHQ_ZERO_EXP || abs(prev_e - e) > SHQ_PREDICT_SHIFT_MAX)
        return 0;
    return (int32_t)nearbyint(ldexp((double)prev_q, prev_e - e));
}

/* v modulo 2^16 as a signed 16-bit value: a prediction's residual always
 * fits the zigzag u16, and adding it back modulo 2^16 restores q exactly
 * (|q| <= SHQ_Q_MAX). */
static int32_t wrap16(int64_t v)
{
    return (int32_t)(((v % 65536) + 65536 + 32768) % 65536) - 32768;
}

/* |v| <= 32768: 2v for v >= 0, -2v - 1 otherwise */
static uint16_t zigzag(int32_t v)
{
    return (uint16_t)(v >= 0 ? 2 * v : -2 * v - 1);
}

static int32_t unzigzag(uint16_t z)
{
    return (z & 1) ? -(int32_t)(z >> 1) - 1 : (int32_t)(z >> 1);
}

/* Bytes per sent cell: exponent, 12 mantissas; a delta's also its mode. */
#define SHQ_CELL_KEY (1 + 2 * LPVP_VALUES_PER_CELL)
#define SHQ_CELL_DELTA (SHQ_CELL_KEY + 1)
enum { SHQ_ABSOLUTE = 0, SHQ_RELATIVE = 1 };

static size_t payload_len(int key, size_t cells, size_t sent, size_t extra)
{
    return SHQ_HEAD + (key ? 0 : (cells + 7) / 8) + sent * (key ? SHQ_CELL_KEY : SHQ_CELL_DELTA) + extra;
}

/* ---- Blocks (R5.16 bit 2) ----------------------------------------------- */

/* The blocks of edge `edge` over one region: ceil(d / edge) per axis. */
static size_t region_blocks(const uint32_t dims[3], uint32_t edge, size_t per_axis[3])
{
    size_t n = 1;
    for (int a = 0; a < 3; ++a) {
        per_axis[a] = ((size_t)dims[a] + edge - 1) / edge;
        n *= per_axis[a];
    }
    return n;
}

static size_t blocks_len(int regions, size_t blocks)
{
    return 8 + (size_t)regions * SHQ_REGION_BYTES + blocks * SHQ_CELL_KEY;
}

static int cell_is_zero(const float v[LPVP_VALUES_PER_CELL])
{
    for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k)
        if (v[k] != 0.0f)
            return 0;
    return 1;
}

/* Calls visit(ctx, cell, block) for every cell of every region, block
 * counting on across regions. */
typedef void (*block_visit)(void *ctx, size_t cell, size_t block);
static void blocks_walk(const lpvp_shq_layout *lay, uint32_t edge, block_visit visit, void *ctx)
{
    size_t t0 = 0;
    for (int r = 0; r < lay->count; ++r) {
        const uint32_t *d = lay->region[r].dims;
        size_t per[3];
        const size_t n = region_blocks(d, edge, per);
        size_t i = (size_t)lay->region[r].first;
        for (uint32_t z = 0; z < d[2]; ++z)
            for (uint32_t y = 0; y < d[1]; ++y)
                for (uint32_t x = 0; x < d[0]; ++x, ++i)
                    visit(ctx, i, t0 + x / edge + per[0] * (y / edge + per[1] * (z / edge)));
        t0 += n;
    }
}

/* Adds each block's change to the cells of the block that hold anything but
 * zeros, rounding each sum to binary32 once (q 2^x is a binary32 value, so
 * this is binary32 addition in every decoder). fail is set when a sum is
 * not finite. */
typedef struct blocks_apply_ctx {
    uint8_t *vals;
    const int8_t *exps;
    const int32_t (*q)[LPVP_VALUES_PER_CELL];
    int fail;
} blocks_apply_ctx;

static void apply_visit(void *vc, size_t i, size_t t)
{
    blocks_apply_ctx *c = vc;
    if (c->exps[t] == SHQ_ZERO_EXP)
        return;
    float v[LPVP_VALUES_PER_CELL];
    get_cell(c->vals, i, v);
    if (cell_is_zero(v))
        return;
    for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k) {
        v[k] = (float)((double)v[k] + ldexp((double)c->q[t][k], c->exps[t]));
        if (!isfinite(v[k]))
            c->fail = 1;
    }
    put_cell(c->vals, i, v);
}

static int blocks_apply(uint8_t *vals, const lpvp_shq_layout *lay, uint32_t edge, const int8_t *exps,
                        const int32_t (*q)[LPVP_VALUES_PER_CELL])
{
    blocks_apply_ctx c = {vals, exps, q, 0};
    blocks_walk(lay, edge, apply_visit, &c);
    return c.fail ? -1 : 0;
}

/* The encoder's choice: per block, the mean change of its live cells (the
 * base's cells that are not zero) in steps of a share of the bound of the
 * block's brightest cell. */
typedef struct blocks_sum_ctx {
    const uint8_t *raw, *base;
    double (*sum)[LPVP_VALUES_PER_CELL];
    double *mag;
    size_t *live;
} blocks_sum_ctx;

static void sum_visit(void *vc, size_t i, size_t t)
{
    blocks_sum_ctx *c = vc;
    float v[LPVP_VALUES_PER_CELL], b[LPVP_VALUES_PER_CELL];
    get_cell(c->raw, i, v);
    for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k)
        v[k] = clean(v[k]);
    const double m = lpvp_shq_cell_magnitude(v);
    c->mag[t] = m > c->mag[t] ? m : c->mag[t];
    get_cell(c->base, i, b);
    if (cell_is_zero(b))
        return;
    c->live[t]++;
    for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k)
        c->sum[t][k] += (double)v[k] - (double)b[k];
}

/* Fills exps / q for every block; returns the blocks that move cells, or
 * (size_t)-1 when memory runs out. */
static size_t blocks_choose(const uint8_t *raw, const uint8_t *base, double bound, const lpvp_shq_layout *lay,
                            size_t count, int8_t *exps, int32_t (*q)[LPVP_VALUES_PER_CELL])
{
    blocks_sum_ctx c = {raw, base, calloc(count, sizeof *c.sum), calloc(count, sizeof *c.mag),
                        calloc(count, sizeof *c.live)};
    if (!c.sum || !c.mag || !c.live) {
        free(c.sum);
        free(c.mag);
        free(c.live);
        return (size_t)-1;
    }
    blocks_walk(lay, SHQ_BLOCK_EDGE, sum_visit, &c);
    const double k_worst = LOBE0 + sqrt(3.0) * LOBE1;
    size_t moving = 0;
    for (size_t t = 0; t < count; ++t) {
        exps[t] = SHQ_ZERO_EXP;
        memset(q[t], 0, sizeof q[t]);
        if (!c.live[t] || !(c.mag[t] >= SHQ_TINY))
            continue;
        int e = (int)floor(log2(2.0 * SHQ_BLOCK_SHARE * bound * c.mag[t] / k_worst));
        e = e < -127 ? -127 : (e > SHQ_BLOCK_EXP_MAX ? SHQ_BLOCK_EXP_MAX : e);
        int any = 0;
        for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k) {
            double x = nearbyint(ldexp(c.sum[t][k] / (double)c.live[t], -e));
            x = x > SHQ_Q_MAX ? SHQ_Q_MAX : (x < -SHQ_Q_MAX ? -SHQ_Q_MAX : x);
            q[t][k] = (int32_t)x;
            any |= q[t][k] != 0;
        }
        if (any) {
            exps[t] = (int8_t)e;
            moving++;
        } else {
            memset(q[t], 0, sizeof q[t]);
        }
    }
    free(c.sum);
    free(c.mag);
    free(c.live);
    return moving;
}

/* A layout the encoder may use: regions in order, inside the cells. */
static int layout_usable(const lpvp_shq_layout *lay, size_t cells)
{
    if (!lay || lay->count < 1 || lay->count > LPVP_SHQ_MAX_REGIONS)
        return 0;
    uint64_t end = 0;
    for (int r = 0; r < lay->count; ++r) {
        const uint32_t *d = lay->region[r].dims;
        if (!d[0] || !d[1] || !d[2] || lay->region[r].first < end)
            return 0;
        const uint64_t xy = (uint64_t)d[0] * d[1]; /* < 2^64 */
        if (xy > cells / d[2])
            return 0;
        const uint64_t n = xy * d[2];
        if (lay->region[r].first > cells - n)
            return 0;
        end = lay->region[r].first + n;
    }
    return 1;
}

/* ---- Encoding ------------------------------------------------------------ */

/* The blocks a delta carries (NULL: none). */
typedef struct shq_blocks {
    const lpvp_shq_layout *lay;
    size_t count;
    const int8_t *exps;
    const int32_t (*q)[LPVP_VALUES_PER_CELL];
} shq_blocks;

/* One payload: a keyframe (base NULL) or a delta against base, which
 * already holds the blocks' changes when blk is given. */
static int encode_one(const uint8_t *raw, size_t raw_len, size_t cells, const uint8_t *base, double bound,
                      const shq_blocks *blk, uint8_t *recon, uint8_t **out, size_t *out_len, size_t *sent_out,
                      char *err, size_t err_n)
{
    const size_t cell_bytes = LPVP_VALUES_PER_CELL * 4;
    const size_t extra = raw_len - cells * cell_bytes;
    const size_t map_len = base ? (cells + 7) / 8 : 0;
    const size_t blen = blk ? blocks_len(blk->lay->count, blk->count) : 0;
    uint8_t *map = calloc(map_len ? map_len : 1, 1);
    uint8_t *exps = malloc(cells ? cells : 1), *modes = malloc(cells ? cells : 1);
    uint16_t *zz = malloc((cells ? cells : 1) * LPVP_VALUES_PER_CELL * sizeof *zz);
    uint8_t *pay = malloc(payload_len(!base, cells, cells, extra) + blen);
    if (!map || !exps || !modes || !zz || !pay) {
        free(map);
        free(exps);
        free(modes);
        free(zz);
        free(pay);
        lpvp_set_error(err, err_n, "out of memory encoding %zu cells", cells);
        return -1;
    }
    size_t sent = 0;
    int32_t prev_q[LPVP_VALUES_PER_CELL] = {0};
    int prev_e = SHQ_ZERO_EXP; /* the first cell has no predecessor */
    for (size_t i = 0; i < cells; ++i) {
        float v[LPVP_VALUES_PER_CELL], rec[LPVP_VALUES_PER_CELL], b[LPVP_VALUES_PER_CELL];
        int32_t q[LPVP_VALUES_PER_CELL];
        get_cell(raw, i, v);
        for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k)
            v[k] = clean(v[k]);
        if (base) { /* conditional replenishment: the client's cell may stand */
            get_cell(base, i, b);
            if (lpvp_shq_cell_error(v, b) <= bound * lpvp_shq_cell_magnitude(v)) {
                if (recon != base)
                    put_cell(recon, i, b);
                continue;
            }
            map[i / 8] |= (uint8_t)(1u << (i % 8));
        }
        const int e = quantise(v, bound, q, rec);
        exps[sent] = (uint8_t)(int8_t)e;
        if (base) { /* the change from the client's cell, in the new steps: small where the light moved a little */
            int32_t r[LPVP_VALUES_PER_CELL];
            int fits = e != SHQ_ZERO_EXP;
            for (int k = 0; fits && k < LPVP_VALUES_PER_CELL; ++k) {
                double x = (double)q[k] - base_steps(b[k], e);
                fits = fabs(x) <= SHQ_Q_MAX;
                r[k] = fits ? (int32_t)x : 0;
            }
            modes[sent] = fits ? SHQ_RELATIVE : SHQ_ABSOLUTE;
            if (fits)
                memcpy(q, r, sizeof r);
        } else { /* a keyframe: the change from the previous cell's prediction */
            for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k) {
                const int32_t qk = q[k];
                q[k] = wrap16((int64_t)qk - shq_predict(prev_q[k], prev_e, e));
                prev_q[k] = qk;
            }
            prev_e = e;
        }
        for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k)
            zz[(size_t)k * cells + sent] = zigzag(q[k]);
        put_cell(recon, i, rec);
        sent++;
    }
    uint8_t *p = pay;
    memcpy(p, SHQ_MAGIC, 4);
    lpvp_put_u32(p + 4, base ? (blk ? SHQ_FLAG_BLOCKS : 0u) : SHQ_FLAG_KEY | SHQ_FLAG_PREDICTED);
    lpvp_put_u64(p + 8, cells);
    lpvp_put_u64(p + 16, sent);
    lpvp_put_u64(p + 24, extra);
    p += SHQ_HEAD;
    if (blk) { /* regions, edge, then the blocks as cells: exponents, low bytes, high bytes */
        lpvp_put_u32(p, (uint32_t)blk->lay->count);
        lpvp_put_u32(p + 4, SHQ_BLOCK_EDGE);
        p += 8;
        for (int r = 0; r < blk->lay->count; ++r, p += SHQ_REGION_BYTES) {
            lpvp_put_u64(p, blk->lay->region[r].first);
            for (int a = 0; a < 3; ++a)
                lpvp_put_u32(p + 8 + 4 * a, blk->lay->region[r].dims[a]);
        }
        for (size_t t = 0; t < blk->count; ++t)
            *p++ = (uint8_t)blk->exps[t];
        for (int half = 0; half < 2; ++half)
            for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k)
                for (size_t t = 0; t < blk->count; ++t)
                    *p++ = (uint8_t)(zigzag(blk->q[t][k]) >> (8 * half));
    }
    memcpy(p, map, map_len);
    p += map_len;
    memcpy(p, exps, sent);
    p += sent;
    if (base) {
        memcpy(p, modes, sent);
        p += sent;
    }
    for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k)
        for (size_t j = 0; j < sent; ++j)
            *p++ = (uint8_t)(zz[(size_t)k * cells + j] & 0xFF);
    for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k)
        for (size_t j = 0; j < sent; ++j)
            *p++ = (uint8_t)(zz[(size_t)k * cells + j] >> 8);
    /* what follows the values (an index, R5.12): as is, or XOR'd with the base's */
    const uint8_t *x = raw + cells * cell_bytes;
    if (base)
        lpvp_xor(p, x, base + cells * cell_bytes, extra);
    else if (extra)
        memcpy(p, x, extra);
    if (extra && recon != raw)
        memcpy(recon + cells * cell_bytes, x, extra);
    p += extra;
    free(map);
    free(exps);
    free(modes);
    free(zz);
    int rc = lpvp_zstd_compress(pay, (size_t)(p - pay), SHQ_ZSTD_LEVEL, out, out_len, err, err_n);
    free(pay);
    *sent_out = sent;
    return rc;
}

/* The delta with blocks, when it is smaller than the plain one (att / recon
 * / counts replaced). Returns 0 (either way) or -1 with err. */
static int try_blocks(const uint8_t *raw, size_t raw_len, size_t cells, const uint8_t *base, double bound,
                      const lpvp_shq_layout *lay, uint8_t *recon, uint8_t **att, size_t *att_len,
                      lpvp_shq_counts *counts, char *err, size_t err_n)
{
    size_t count = 0;
    for (int r = 0; r < lay->count; ++r) {
        size_t per[3];
        count += region_blocks(lay->region[r].dims, SHQ_BLOCK_EDGE, per);
    }
    int8_t *exps = malloc(count);
    int32_t(*q)[LPVP_VALUES_PER_CELL] = malloc(count * sizeof *q);
    uint8_t *moved = malloc(raw_len), *rec2 = malloc(raw_len), *att2 = NULL;
    size_t moving = exps && q ? blocks_choose(raw, base, bound, lay, count, exps, q) : (size_t)-1;
    int rc = 0;
    if (!moved || !rec2 || moving == (size_t)-1) {
        lpvp_set_error(err, err_n, "out of memory encoding %zu cells", cells);
        rc = -1;
        goto done;
    }
    memcpy(moved, base, raw_len);
    if (moving == 0 || blocks_apply(moved, lay, SHQ_BLOCK_EDGE, exps, (const int32_t(*)[LPVP_VALUES_PER_CELL])q) != 0)
        goto done; /* nothing to move, or a sum past binary32 (never for values within +-1e30) */
    const shq_blocks blk = {lay, count, exps, (const int32_t(*)[LPVP_VALUES_PER_CELL])q};
    size_t len2 = 0, sent2 = 0;
    if (encode_one(raw, raw_len, cells, moved, bound, &blk, rec2, &att2, &len2, &sent2, err, err_n) != 0) {
        rc = -1;
        goto done;
    }
    if (len2 < *att_len) {
        free(*att);
        *att = att2;
        *att_len = len2;
        att2 = NULL;
        memcpy(recon, rec2, raw_len);
        counts->sent = sent2;
        counts->blocks = moving;
    }
done:
    free(att2);
    free(exps);
    free(q);
    free(moved);
    free(rec2);
    return rc;
}

int lpvp_shq_encode(const uint8_t *raw, size_t raw_len, size_t cells, const uint8_t *base, double bound,
                    const lpvp_shq_layout *layout, uint8_t *recon, uint8_t **out, size_t *out_len,
                    lpvp_shq_counts *counts_out, char *err, size_t err_n)
{
    *out = NULL;
    *out_len = 0;
    if (!(bound >= LPVP_SHQ_BOUND_MIN && bound <= LPVP_SHQ_BOUND_MAX)) {
        lpvp_set_error(err, err_n, "%s %g is outside %g..%g", LPVP_SHQ_BOUND_KEY, bound, LPVP_SHQ_BOUND_MIN,
                       LPVP_SHQ_BOUND_MAX);
        return -1;
    }
    const size_t cell_bytes = LPVP_VALUES_PER_CELL * 4;
    if (cells > raw_len / cell_bytes) {
        lpvp_set_error(err, err_n, "%zu cells do not fit a %zu-byte volume", cells, raw_len);
        return -1;
    }
    lpvp_shq_counts counts = {0, 0};
    const int blocks = base && layout_usable(layout, cells);
    /* The blocks need the base and raw after the plain delta: when recon is
     * either (coding in place), the plain delta goes to a copy first. */
    uint8_t *plain = blocks && (recon == base || recon == raw) ? malloc(raw_len) : recon;
    if (!plain) {
        lpvp_set_error(err, err_n, "out of memory for a %zu-byte volume", raw_len);
        return -1;
    }
    int rc = encode_one(raw, raw_len, cells, base, bound, NULL, plain, out, out_len, &counts.sent, err, err_n);
    /* Nothing past the bound stays nothing. A delta that re-sends few cells
     * leaves the blocks little to carry: on the engine of docs/streaming.md
     * (2.8 % of the LPV's cells re-sent per update) they were never the
     * smaller and trying them tripled the encoding time. */
    if (rc == 0 && blocks && counts.sent > cells / SHQ_BLOCK_MIN_SHARE) {
        rc = try_blocks(raw, raw_len, cells, base, bound, layout, plain, out, out_len, &counts, err, err_n);
        if (rc != 0) {
            free(*out);
            *out = NULL;
            *out_len = 0;
        }
    }
    if (plain != recon) {
        if (rc == 0)
            memcpy(recon, plain, raw_len);
        free(plain);
    }
    if (counts_out)
        *counts_out = counts;
    return rc;
}

void lpvp_shq_layout_of(const struct lpvp_volume_info *vi, lpvp_shq_layout *out)
{
    memset(out, 0, sizeof *out);
    if (vi->layout.present && (vi->layout.content != LPVP_CONTENT_MERGED || vi->layout.volumes_per_level != 1 ||
                               vi->layout.values_per_cell != LPVP_VALUES_PER_CELL))
        return;
    lpvp_cascade_info c[LPVP_MAX_CASCADES];
    const int n = lpvp_cascades_of(vi, c);
    for (int k = 0; k < n && k < LPVP_SHQ_MAX_REGIONS; ++k) {
        for (int a = 0; a < 3; ++a) {
            if (c[k].dims[a] < 1 || c[k].dims[a] > UINT32_MAX) {
                out->count = 0;
                return;
            }
            out->region[k].dims[a] = (uint32_t)c[k].dims[a];
        }
        out->region[k].first = lpvp_volume_cascade_first_cell(vi, k);
        out->count = k + 1;
    }
}

/* A delta's blocks (R5.16 bit 2) at p (avail bytes): the layout, the edge,
 * the block count, and where the exponents start. Returns the section's
 * bytes, or 0 with err set. */
static size_t parse_blocks(const uint8_t *p, size_t avail, size_t cells, lpvp_shq_layout *lay, uint32_t *edge,
                           size_t *count, char *err, size_t err_n)
{
    if (avail < 8) {
        lpvp_set_error(err, err_n, "shq: the blocks' counts are cut off");
        return 0;
    }
    const uint32_t regions = lpvp_get_u32(p);
    *edge = lpvp_get_u32(p + 4);
    if (regions < 1 || regions > LPVP_SHQ_MAX_REGIONS || *edge < 1 || *edge > SHQ_BLOCK_EDGE_MAX) {
        lpvp_set_error(err, err_n, "shq: %u regions of blocks of edge %u (1..%d regions, edge 1..%d)",
                       (unsigned)regions, (unsigned)*edge, LPVP_SHQ_MAX_REGIONS, SHQ_BLOCK_EDGE_MAX);
        return 0;
    }
    if (avail < 8 + (size_t)regions * SHQ_REGION_BYTES) {
        lpvp_set_error(err, err_n, "shq: the blocks' regions are cut off");
        return 0;
    }
    memset(lay, 0, sizeof *lay);
    lay->count = (int)regions;
    *count = 0;
    for (uint32_t r = 0; r < regions; ++r) {
        const uint8_t *q = p + 8 + (size_t)r * SHQ_REGION_BYTES;
        lay->region[r].first = lpvp_get_u64(q);
        for (int a = 0; a < 3; ++a)
            lay->region[r].dims[a] = lpvp_get_u32(q + 8 + 4 * a);
    }
    if (!layout_usable(lay, cells)) {
        lpvp_set_error(err, err_n, "shq: the blocks' regions are not boxes of the %zu cells in order", cells);
        return 0;
    }
    for (uint32_t r = 0; r < regions; ++r) { /* each region fits the cells: no overflow */
        size_t per[3];
        *count += region_blocks(lay->region[r].dims, *edge, per);
    }
    return blocks_len((int)regions, *count);
}

int lpvp_shq_decode(const void *att, size_t att_len, size_t raw_len, size_t cells, const uint8_t *base,
                    uint8_t *raw_out, size_t *sent_out, char *err, size_t err_n)
{
    const size_t cell_bytes = LPVP_VALUES_PER_CELL * 4;
    if (cells > raw_len / cell_bytes) {
        lpvp_set_error(err, err_n, "%zu cells do not fit a %zu-byte volume", cells, raw_len);
        return -1;
    }
    const size_t extra = raw_len - cells * cell_bytes;
    uint8_t *pay = NULL, *moved = NULL;
    int8_t *bexps = NULL;
    int32_t(*bq)[LPVP_VALUES_PER_CELL] = NULL;
    size_t len = 0;
    /* the largest payload: a delta sending every cell, with a block per cell */
    const size_t most = payload_len(0, cells, cells, extra) + blocks_len(LPVP_SHQ_MAX_REGIONS, cells);
    if (lpvp_zstd_decompress(att, att_len, most, &pay, &len, err, err_n) != 0)
        return -1;
    int rc = -1;
    if (len < SHQ_HEAD || memcmp(pay, SHQ_MAGIC, 4) != 0) {
        lpvp_set_error(err, err_n, "shq: not an \"%s\" payload", SHQ_MAGIC);
        goto done;
    }
    const uint32_t flags = lpvp_get_u32(pay + 4);
    const int key = (flags & SHQ_FLAG_KEY) != 0, predicted = (flags & SHQ_FLAG_PREDICTED) != 0;
    const int blocks = (flags & SHQ_FLAG_BLOCKS) != 0;
    const uint64_t n_cells = lpvp_get_u64(pay + 8), sent = lpvp_get_u64(pay + 16), n_extra = lpvp_get_u64(pay + 24);
    if ((flags & ~(SHQ_FLAG_KEY | SHQ_FLAG_PREDICTED | SHQ_FLAG_BLOCKS)) || (predicted && !key) || (blocks && key)) {
        lpvp_set_error(err, err_n, "shq: unknown flags 0x%x%s", (unsigned)flags,
                       predicted && !key ? " (bit 1, predicted, only with bit 0, keyframe)"
                       : blocks && key  ? " (bit 2, blocks, only without bit 0, keyframe)"
                                        : "");
        goto done;
    }
    if (n_cells != cells || n_extra != extra || sent > cells || (key && sent != cells)) {
        lpvp_set_error(err, err_n,
                       "shq: payload of %llu cells (%llu sent) and %llu extra bytes, the header says %zu cells and %zu",
                       (unsigned long long)n_cells, (unsigned long long)sent, (unsigned long long)n_extra, cells,
                       extra);
        goto done;
    }
    if (!key && !base) {
        lpvp_set_error(err, err_n, "shq: a delta without a base volume");
        goto done;
    }
    lpvp_shq_layout lay;
    uint32_t edge = 0;
    size_t nblocks = 0, blen = 0;
    if (blocks && !(blen = parse_blocks(pay + SHQ_HEAD, len - SHQ_HEAD, cells, &lay, &edge, &nblocks, err, err_n)))
        goto done;
    const size_t map_len = key ? 0 : (cells + 7) / 8;
    if (len != payload_len(key, cells, (size_t)sent, extra) + blen) {
        lpvp_set_error(err, err_n, "shq: payload of %zu bytes, its counts need %zu", len,
                       payload_len(key, cells, (size_t)sent, extra) + blen);
        goto done;
    }
    const uint8_t *blk = pay + SHQ_HEAD + 8 + (blocks ? (size_t)lay.count * SHQ_REGION_BYTES : 0);
    const uint8_t *map = pay + SHQ_HEAD + blen, *exps = map + map_len, *modes = exps + sent;
    const uint8_t *lo = modes + (key ? 0 : sent), *hi = lo + sent * 12;
    for (size_t j = 0; !key && j < sent; ++j)
        if (modes[j] > SHQ_RELATIVE || (modes[j] == SHQ_RELATIVE && (int8_t)exps[j] == SHQ_ZERO_EXP)) {
            lpvp_set_error(err, err_n, "shq: sent cell %zu has mode %u%s", j, modes[j],
                           modes[j] > SHQ_RELATIVE ? "" : " with the zero exponent");
            goto done;
        }
    size_t count = 0;
    for (size_t i = 0; i < map_len; ++i)
        for (uint8_t b = map[i]; b; b &= (uint8_t)(b - 1))
            count++;
    if (!key && (count != sent || (cells % 8 && map_len && (map[map_len - 1] >> (cells % 8))))) {
        lpvp_set_error(err, err_n, "shq: %zu cells flagged, %llu sent", count, (unsigned long long)sent);
        goto done;
    }
    if (blocks) { /* the client's cells moved by the blocks' changes, into a copy: base stands if they fail */
        bexps = malloc(nblocks ? nblocks : 1);
        bq = malloc((nblocks ? nblocks : 1) * sizeof *bq);
        moved = malloc(cells ? cells * cell_bytes : 1);
        if (!bexps || !bq || !moved) {
            lpvp_set_error(err, err_n, "shq: out of memory for %zu blocks", nblocks);
            goto done;
        }
        for (size_t t = 0; t < nblocks; ++t) {
            bexps[t] = (int8_t)blk[t];
            if (bexps[t] != SHQ_ZERO_EXP && bexps[t] > SHQ_BLOCK_EXP_MAX) {
                lpvp_set_error(err, err_n, "shq: block %zu has exponent %d (at most %d, or -128)", t, bexps[t],
                               SHQ_BLOCK_EXP_MAX);
                goto done;
            }
            for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k) {
                const size_t at = nblocks + (size_t)k * nblocks + t;
                bq[t][k] = unzigzag((uint16_t)(blk[at] | (blk[at + 12 * nblocks] << 8)));
            }
        }
        memcpy(moved, base, cells * cell_bytes);
        if (blocks_apply(moved, &lay, edge, bexps, (const int32_t(*)[LPVP_VALUES_PER_CELL])bq) != 0) {
            lpvp_set_error(err, err_n, "shq: a block moves a value past binary32's range");
            goto done;
        }
    }
    if (!key && raw_out != (moved ? moved : base))
        memmove(raw_out, moved ? moved : base, cells * cell_bytes);
    size_t j = 0;
    int32_t prev_q[LPVP_VALUES_PER_CELL] = {0};
    int prev_e = SHQ_ZERO_EXP;
    for (size_t i = 0; i < cells; ++i) {
        if (!key && !(map[i / 8] & (1u << (i % 8))))
            continue;
        const int e = (int8_t)exps[j];
        const int relative = !key && modes[j] == SHQ_RELATIVE;
        float v[LPVP_VALUES_PER_CELL], b[LPVP_VALUES_PER_CELL];
        if (relative)
            get_cell(raw_out, i, b); /* the client's cell, copied (and moved) above */
        for (int k = 0; k < LPVP_VALUES_PER_CELL; ++k) {
            double q = unzigzag((uint16_t)(lo[(size_t)k * sent + j] | (hi[(size_t)k * sent + j] << 8)));
            if (relative)
                q += base_steps(b[k], e);
            if (predicted) {
                q = wrap16((int64_t)q + shq_predict(prev_q[k], prev_e, e));
                prev_q[k] = (int32_t)q;
            }
            v[k] = e == SHQ_ZERO_EXP ? 0.0f : (float)ldexp(q, e);
        }
        prev_e = e;
        put_cell(raw_out, i, v);
        j++;
    }
    const uint8_t *x = hi + sent * 12;
    if (key) {
        if (extra)
            memcpy(raw_out + cells * cell_bytes, x, extra);
    } else {
        lpvp_xor(raw_out + cells * cell_bytes, x, base + cells * cell_bytes, extra);
    }
    if (sent_out)
        *sent_out = (size_t)sent;
    rc = 0;
done:
    free(pay);
    free(moved);
    free(bexps);
    free(bq);
    return rc;
}
