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
 * differ (predicting them cost 6 % more bytes).
 *
 * Reconstruction is q x 2^e in fp32, exact (|q| < 2^15), so the encoder's
 * copy of the client's volume is the client's bit for bit.
 */
#include "volume_codec.h"
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

int lpvp_shq_encode(const uint8_t *raw, size_t raw_len, size_t cells, const uint8_t *base, double bound,
                    uint8_t *recon, uint8_t **out, size_t *out_len, size_t *sent_out, char *err, size_t err_n)
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
    const size_t extra = raw_len - cells * cell_bytes;
    const size_t map_len = base ? (cells + 7) / 8 : 0;
    uint8_t *map = calloc(map_len ? map_len : 1, 1);
    uint8_t *exps = malloc(cells ? cells : 1), *modes = malloc(cells ? cells : 1);
    uint16_t *zz = malloc((cells ? cells : 1) * LPVP_VALUES_PER_CELL * sizeof *zz);
    uint8_t *pay = malloc(payload_len(!base, cells, cells, extra));
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
    lpvp_put_u32(p + 4, base ? 0u : SHQ_FLAG_KEY | SHQ_FLAG_PREDICTED);
    lpvp_put_u64(p + 8, cells);
    lpvp_put_u64(p + 16, sent);
    lpvp_put_u64(p + 24, extra);
    p += SHQ_HEAD;
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
    if (sent_out)
        *sent_out = sent;
    return rc;
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
    uint8_t *pay = NULL;
    size_t len = 0;
    if (lpvp_zstd_decompress(att, att_len, payload_len(0, cells, cells, extra), &pay, &len, err, err_n) != 0)
        return -1;
    int rc = -1;
    if (len < SHQ_HEAD || memcmp(pay, SHQ_MAGIC, 4) != 0) {
        lpvp_set_error(err, err_n, "shq: not an \"%s\" payload", SHQ_MAGIC);
        goto done;
    }
    const uint32_t flags = lpvp_get_u32(pay + 4);
    const int key = (flags & SHQ_FLAG_KEY) != 0, predicted = (flags & SHQ_FLAG_PREDICTED) != 0;
    const uint64_t n_cells = lpvp_get_u64(pay + 8), sent = lpvp_get_u64(pay + 16), n_extra = lpvp_get_u64(pay + 24);
    if ((flags & ~(SHQ_FLAG_KEY | SHQ_FLAG_PREDICTED)) || (predicted && !key)) {
        lpvp_set_error(err, err_n, "shq: unknown flags 0x%x%s", (unsigned)flags,
                       predicted && !key ? " (bit 1, predicted, only with bit 0, keyframe)" : "");
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
    const size_t map_len = key ? 0 : (cells + 7) / 8;
    if (len != payload_len(key, cells, (size_t)sent, extra)) {
        lpvp_set_error(err, err_n, "shq: payload of %zu bytes, its counts need %zu", len,
                       payload_len(key, cells, (size_t)sent, extra));
        goto done;
    }
    const uint8_t *map = pay + SHQ_HEAD, *exps = map + map_len, *modes = exps + sent;
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
    if (!key && raw_out != base)
        memcpy(raw_out, base, cells * cell_bytes);
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
            get_cell(raw_out, i, b); /* the base's cell, copied above */
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
    return rc;
}
