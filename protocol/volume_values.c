/*
 * volume_values.c - the values of a raw volume (SPEC R5.1 - R5.3):
 * binary16 conversion, the names of formats and compressions, packing and
 * unpacking cells as fp16 or fp32, and XOR deltas. See volume_codec.h.
 */
#include "volume_codec.h"
#include "proto.h"

#include <math.h>
#include <string.h>

/* ---- binary16 ------------------------------------------------------------- */

static uint32_t f32_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    return u;
}

static float bits_f32(uint32_t u)
{
    float f;
    memcpy(&f, &u, 4);
    return f;
}

uint16_t lpvp_f32_to_f16(float f)
{
    uint32_t x = f32_bits(f);
    uint16_t sign = (uint16_t)((x >> 16) & 0x8000u);
    uint32_t a = x & 0x7FFFFFFFu;

    if (a > 0x7F800000u) /* NaN -> +0 (R5.4: NaN is never sent) */
        return 0;
    if (a >= 0x477FE000u) /* >= 65504 (and Inf): clamp, never Inf (R5.4) */
        return (uint16_t)(sign | 0x7BFFu);
    if (a >= 0x38800000u) { /* normal half: 2^-14 <= |f| < 65504 */
        uint32_t h = (a >> 13) - ((uint32_t)(127 - 15) << 10);
        uint32_t rem = a & 0x1FFFu;
        if (rem > 0x1000u || (rem == 0x1000u && (h & 1u)))
            h++; /* cannot pass 0x7BFF: a < 65504 */
        return (uint16_t)(sign | h);
    }
    if (a <= 0x33000000u) /* <= 2^-25: half of the smallest subnormal ties to 0 */
        return sign;
    {
        /* Subnormal half: value / 2^-24 = m * 2^(e - 126), shift 14..24. */
        uint32_t e = a >> 23;
        uint32_t m = (a & 0x7FFFFFu) | 0x800000u;
        uint32_t shift = 126u - e;
        uint32_t r = m >> shift;
        uint32_t rem = m & ((1u << shift) - 1u);
        uint32_t half = 1u << (shift - 1u);
        if (rem > half || (rem == half && (r & 1u)))
            r++; /* may become 0x400, the smallest normal: still correct */
        return (uint16_t)(sign | r);
    }
}

float lpvp_f16_to_f32(uint16_t h)
{
    uint32_t sign = (uint32_t)(h & 0x8000u) << 16;
    uint32_t e = (h >> 10) & 0x1Fu;
    uint32_t m = h & 0x3FFu;
    if (e == 0) {
        uint32_t e32 = 113;
        if (m == 0)
            return bits_f32(sign);
        while (!(m & 0x400u)) {
            m <<= 1;
            e32--;
        }
        m &= 0x3FFu;
        return bits_f32(sign | (e32 << 23) | (m << 13));
    }
    if (e == 31) {
        if (m == 0)
            return bits_f32(sign | 0x7F800000u);
        return bits_f32(sign | 0x7FC00000u | (m << 13));
    }
    return bits_f32(sign | ((e + 112u) << 23) | (m << 13));
}

/* ---- Names ---------------------------------------------------------------- */

const char *const lpvp_volume_format_names[2] = {[LPVP_FMT_FP16] = "fp16", [LPVP_FMT_FP32] = "fp32"};
const char *const lpvp_compression_names[3] = {[LPVP_COMP_NONE] = "none", [LPVP_COMP_ZSTD] = "zstd",
                                               [LPVP_COMP_SHQ] = "shq"};
const char *const lpvp_frame_terms_names[LPVP_TERMS_COUNT] = {
    [LPVP_TERMS_FULL] = "full", [LPVP_TERMS_INDIRECT] = "indirect", [LPVP_TERMS_DIRECT] = "direct",
    [LPVP_TERMS_AO] = "ao"};
const char *const lpvp_frame_format_names[LPVP_FRAME_FORMAT_COUNT] = {
    [LPVP_FRAME_RGBA8] = "rgba8", [LPVP_FRAME_PNG] = "png", [LPVP_FRAME_EXR] = "exr"};
const char *const lpvp_stream_names[LPVP_STREAM_COUNT] = {[LPVP_STREAM_VOLUME] = "volume",
                                                          [LPVP_STREAM_FRAME] = "frame"};

/* Index of s in names[0..n), or -1. */
static int name_index(const char *const *names, int n, const char *s)
{
    for (int i = 0; s && i < n; ++i)
        if (strcmp(s, names[i]) == 0)
            return i;
    return -1;
}

const char *lpvp_volume_format_name(lpvp_volume_format fmt)
{
    return lpvp_volume_format_names[fmt == LPVP_FMT_FP32 ? LPVP_FMT_FP32 : LPVP_FMT_FP16];
}

int lpvp_volume_format_parse(const char *s, lpvp_volume_format *out)
{
    int i = name_index(lpvp_volume_format_names, 2, s);
    if (i < 0)
        return -1;
    *out = (lpvp_volume_format)i;
    return 0;
}

const char *lpvp_compression_name(lpvp_compression c)
{
    return lpvp_compression_names[c == LPVP_COMP_ZSTD || c == LPVP_COMP_SHQ ? c : LPVP_COMP_NONE];
}

int lpvp_compression_parse(const char *s, lpvp_compression *out)
{
    int i = name_index(lpvp_compression_names, 3, s);
    if (i < 0)
        return -1;
    *out = (lpvp_compression)i;
    return 0;
}

/* ---- Raw volumes ---------------------------------------------------------- */

size_t lpvp_volume_value_size(lpvp_volume_format fmt)
{
    return fmt == LPVP_FMT_FP32 ? 4 : 2;
}

size_t lpvp_volume_raw_size(size_t cells, lpvp_volume_format fmt)
{
    size_t per = LPVP_VALUES_PER_CELL * lpvp_volume_value_size(fmt);
    if (cells > ((size_t)-1) / per)
        return 0;
    return cells * per;
}

void lpvp_volume_pack(const float *cells12, size_t cells, lpvp_volume_format fmt, uint8_t *out)
{
    size_t n = cells * LPVP_VALUES_PER_CELL;
    if (fmt == LPVP_FMT_FP16) {
        for (size_t i = 0; i < n; i++) {
            uint16_t h = lpvp_f32_to_f16(cells12[i]);
            out[2 * i] = (uint8_t)h;
            out[2 * i + 1] = (uint8_t)(h >> 8);
        }
    } else {
        for (size_t i = 0; i < n; i++) {
            uint32_t u = f32_bits(cells12[i]);
            if ((u & 0x7FFFFFFFu) > 0x7F800000u)
                u = 0; /* NaN is never sent */
            out[4 * i] = (uint8_t)u;
            out[4 * i + 1] = (uint8_t)(u >> 8);
            out[4 * i + 2] = (uint8_t)(u >> 16);
            out[4 * i + 3] = (uint8_t)(u >> 24);
        }
    }
}

void lpvp_values_unpack(const uint8_t *raw, size_t n, lpvp_volume_format fmt, float *out)
{
    if (fmt == LPVP_FMT_FP16) {
        for (size_t i = 0; i < n; i++)
            out[i] = lpvp_f16_to_f32((uint16_t)(raw[2 * i] | (raw[2 * i + 1] << 8)));
    } else {
        for (size_t i = 0; i < n; i++) {
            uint32_t u = (uint32_t)raw[4 * i] | ((uint32_t)raw[4 * i + 1] << 8) |
                         ((uint32_t)raw[4 * i + 2] << 16) | ((uint32_t)raw[4 * i + 3] << 24);
            out[i] = bits_f32(u);
        }
    }
}

void lpvp_volume_unpack(const uint8_t *raw, size_t cells, lpvp_volume_format fmt, float *out)
{
    lpvp_values_unpack(raw, cells * LPVP_VALUES_PER_CELL, fmt, out);
}

/* ---- XOR ------------------------------------------------------------------ */

void lpvp_xor(uint8_t *dst, const uint8_t *a, const uint8_t *b, size_t n)
{
    size_t i = 0;
    /* Word at a time through memcpy (alias- and alignment-safe). */
    for (; i + 8 <= n; i += 8) {
        uint64_t x, y;
        memcpy(&x, a + i, 8);
        memcpy(&y, b + i, 8);
        x ^= y;
        memcpy(dst + i, &x, 8);
    }
    for (; i < n; i++)
        dst[i] = (uint8_t)(a[i] ^ b[i]);
}
