/*
 * volume_codec.c - binary16, raw volume packing, XOR deltas, zstd and the
 * volume header (SPEC section 5). See volume_codec.h.
 */
#include "volume_codec.h"
#include "proto.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zstd.h>


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
const char *const lpvp_compression_names[2] = {[LPVP_COMP_NONE] = "none", [LPVP_COMP_ZSTD] = "zstd"};
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
    return lpvp_compression_names[c == LPVP_COMP_ZSTD ? LPVP_COMP_ZSTD : LPVP_COMP_NONE];
}

int lpvp_compression_parse(const char *s, lpvp_compression *out)
{
    int i = name_index(lpvp_compression_names, 2, s);
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

/* ---- zstd ----------------------------------------------------------------- */

size_t lpvp_zstd_bound(size_t n)
{
    return ZSTD_compressBound(n);
}

size_t lpvp_zstd_compress_into(void *dst, size_t cap, const void *src, size_t n, int level,
                               char *err, size_t err_n)
{
    size_t r;
    if (level == 0)
        level = LPVP_ZSTD_DEFAULT_LEVEL;
    /* ZSTD_compress records the content size in the frame header. */
    r = ZSTD_compress(dst, cap, n ? src : "", n, level);
    if (ZSTD_isError(r)) {
        lpvp_set_error(err, err_n, "zstd compression failed: %s", ZSTD_getErrorName(r));
        return 0;
    }
    return r;
}

int lpvp_zstd_compress(const void *src, size_t n, int level, uint8_t **out, size_t *out_len,
                       char *err, size_t err_n)
{
    size_t cap = ZSTD_compressBound(n);
    uint8_t *buf;
    size_t r;
    if (ZSTD_isError(cap) || cap == 0) {
        lpvp_set_error(err, err_n, "zstd: %zu bytes is too large to compress", n);
        return -1;
    }
    buf = malloc(cap);
    if (!buf) {
        lpvp_set_error(err, err_n, "zstd: out of memory (%zu bytes)", cap);
        return -1;
    }
    r = lpvp_zstd_compress_into(buf, cap, src, n, level, err, err_n);
    if (r == 0) {
        free(buf);
        return -1;
    }
    *out = buf;
    *out_len = r;
    return 0;
}

/* Checks that src is exactly one zstd frame with a recorded content size
 * <= max; returns that size or (unsigned long long)-1 with err set. */
static unsigned long long frame_content_size(const void *src, size_t n, size_t max, char *err,
                                             size_t err_n)
{
    unsigned long long cs;
    size_t fsize;
    if (!src || n == 0) {
        lpvp_set_error(err, err_n, "zstd: empty input");
        return (unsigned long long)-1;
    }
    cs = ZSTD_getFrameContentSize(src, n);
    if (cs == ZSTD_CONTENTSIZE_ERROR) {
        lpvp_set_error(err, err_n, "zstd: not a zstd frame");
        return (unsigned long long)-1;
    }
    if (cs == ZSTD_CONTENTSIZE_UNKNOWN) {
        lpvp_set_error(err, err_n, "zstd: frame content size is not recorded");
        return (unsigned long long)-1;
    }
    if (cs > max) {
        lpvp_set_error(err, err_n, "zstd: content size %llu exceeds the maximum %zu", cs, max);
        return (unsigned long long)-1;
    }
    fsize = ZSTD_findFrameCompressedSize(src, n);
    if (ZSTD_isError(fsize)) {
        lpvp_set_error(err, err_n, "zstd: %s", ZSTD_getErrorName(fsize));
        return (unsigned long long)-1;
    }
    if (fsize != n) {
        lpvp_set_error(err, err_n, "zstd: %zu bytes after the frame", n - fsize);
        return (unsigned long long)-1;
    }
    return cs;
}

static int decompress_to(void *dst, size_t size, const void *src, size_t n, char *err,
                         size_t err_n)
{
    size_t r = ZSTD_decompress(dst, size, src, n);
    if (ZSTD_isError(r)) {
        lpvp_set_error(err, err_n, "zstd: %s", ZSTD_getErrorName(r));
        return -1;
    }
    if (r != size) {
        lpvp_set_error(err, err_n, "zstd: frame gave %zu bytes, its header says %zu", r, size);
        return -1;
    }
    return 0;
}

int lpvp_zstd_decompress(const void *src, size_t n, size_t max_out, uint8_t **out,
                         size_t *out_len, char *err, size_t err_n)
{
    unsigned long long cs = frame_content_size(src, n, max_out, err, err_n);
    uint8_t *buf;
    if (cs == (unsigned long long)-1)
        return -1;
    buf = malloc(cs ? (size_t)cs : 1);
    if (!buf) {
        lpvp_set_error(err, err_n, "zstd: out of memory (%llu bytes)", cs);
        return -1;
    }
    if (decompress_to(buf, (size_t)cs, src, n, err, err_n) != 0) {
        free(buf);
        return -1;
    }
    *out = buf;
    *out_len = (size_t)cs;
    return 0;
}

int lpvp_zstd_decompress_exact(const void *src, size_t n, void *dst, size_t expect, char *err,
                               size_t err_n)
{
    unsigned long long cs = frame_content_size(src, n, expect, err, err_n);
    if (cs == (unsigned long long)-1)
        return -1;
    if (cs != expect) {
        lpvp_set_error(err, err_n, "zstd: content size %llu, expected %zu", cs, expect);
        return -1;
    }
    return decompress_to(dst, expect, src, n, err, err_n);
}

/* ---- Volume description (SPEC R5.9 - R5.12) ------------------------------ */

/* R5.1's order: per channel c0 (Y00), then y (Y1-1), z (Y10), x (Y11), as
 * LPVP_VOLUME_SH says. */
const char *const lpvp_sh_value_names[LPVP_VALUES_PER_CELL] = {
    "r.Y00", "r.Y1-1", "r.Y10", "r.Y11", "g.Y00", "g.Y1-1", "g.Y10", "g.Y11",
    "b.Y00", "b.Y1-1", "b.Y10", "b.Y11"};
const char *const lpvp_level_role_names[LPVP_ROLE_COUNT] = {[LPVP_ROLE_CASCADE] = "cascade",
                                                            [LPVP_ROLE_FAR_FIELD] = "far_field",
                                                            [LPVP_ROLE_OCTREE_LEVEL] = "octree_level",
                                                            [LPVP_ROLE_IV_VOXELS] = "iv_voxels"};
const char *const lpvp_volume_content_names[LPVP_CONTENT_COUNT] = {[LPVP_CONTENT_MERGED] = "merged",
                                                                   [LPVP_CONTENT_LEVELS] = "levels"};

void lpvp_volume_layout_sh(lpvp_volume_layout *l, const char *technique, int far_field, int levels)
{
    memset(l, 0, sizeof *l);
    l->present = 1;
    l->layout_version = LPVP_VOLUME_LAYOUT_VERSION;
    snprintf(l->technique, sizeof l->technique, "%s", technique ? technique : "");
    l->far_field = far_field != 0;
    for (int k = 0; k < LPVP_MAX_LEVELS; k++)
        l->role[k] = (l->far_field && k > 0 && k < levels) ? LPVP_ROLE_FAR_FIELD : LPVP_ROLE_CASCADE;
    l->volumes_per_level = 1;
    l->values_per_cell = LPVP_VALUES_PER_CELL;
    l->sh_values = 1;
}

int lpvp_octree_level_count(int64_t n)
{
    int l = 1;
    if (n < 1 || (n & (n - 1)) != 0)
        return -1;
    while ((n >> (l - 1)) > 1)
        l++;
    return l <= LPVP_MAX_LEVELS ? l : -1;
}

void lpvp_octree_level_place(const lpvp_cascade_info *level0, int i, lpvp_cascade_info *out)
{
    *out = *level0;
    out->cells = 1;
    for (int a = 0; a < 3; a++) {
        out->dims[a] = level0->dims[a] >> i;
        out->cells *= (uint64_t)(out->dims[a] > 0 ? out->dims[a] : 0);
    }
    out->cell_size = ldexp(level0->cell_size, i);
}

/* The one-value-per-cell index volume (SPEC R5.13, R5.14) over level 0. */
static void layout_index_over(lpvp_volume_layout *l, const lpvp_cascade_info *level0)
{
    l->has_index = 1;
    l->index.level = 0;
    for (int a = 0; a < 3; a++)
        l->index.dims[a] = level0->dims[a];
    l->index.cells = level0->cells;
    l->index.values_per_cell = 1;
    l->index.raw_length = level0->cells * LPVP_INDEX_VALUE_SIZE;
}

int lpvp_volume_layout_octree(lpvp_volume_layout *l, const char *technique, const lpvp_cascade_info *level0,
                              char *err, size_t err_n)
{
    int count = lpvp_octree_level_count(level0->dims[0]);
    if (count < 0 || level0->dims[1] != level0->dims[0] || level0->dims[2] != level0->dims[0]) {
        lpvp_set_error(err, err_n, "a grid of %lldx%lldx%lld cells has no octree of at most %d levels (it needs a cube "
                       "of a power of two)", (long long)level0->dims[0], (long long)level0->dims[1],
                       (long long)level0->dims[2], LPVP_MAX_LEVELS);
        return -1;
    }
    lpvp_volume_layout_sh(l, technique, 0, 1);
    l->content = LPVP_CONTENT_LEVELS;
    l->level_count = count;
    for (int i = 0; i < count; i++) {
        lpvp_octree_level_place(level0, i, &l->level[i]);
        l->role[i] = LPVP_ROLE_OCTREE_LEVEL;
    }
    layout_index_over(l, level0);
    return 0;
}

int lpvp_volume_layout_iv(lpvp_volume_layout *l, const char *technique, const lpvp_cascade_info *level0,
                          int neighbours, char *err, size_t err_n)
{
    if (neighbours < LPVP_IV_NEIGHBOURS_MIN || neighbours > LPVP_IV_NEIGHBOURS_MAX) {
        lpvp_set_error(err, err_n, "%s %d is outside %d..%d", LPVP_IV_NEIGHBOURS_KEY, neighbours,
                       LPVP_IV_NEIGHBOURS_MIN, LPVP_IV_NEIGHBOURS_MAX);
        return -1;
    }
    lpvp_volume_layout_sh(l, technique, 0, 1);
    l->role[0] = LPVP_ROLE_IV_VOXELS;
    snprintf(l->units, sizeof l->units, "%s", LPVP_VOLUME_UNITS_RADIANCE);
    layout_index_over(l, level0);
    l->iv_neighbours = neighbours;
    return 0;
}

int lpvp_volume_layout_is_iv(const lpvp_volume_layout *l)
{
    return l->present && l->content == LPVP_CONTENT_MERGED && l->role[0] == LPVP_ROLE_IV_VOXELS;
}

const char *lpvp_volume_layout_units(const lpvp_volume_layout *l)
{
    return l->units[0] ? l->units : LPVP_VOLUME_UNITS;
}

uint64_t lpvp_volume_values_bytes(const lpvp_volume_info *vi)
{
    uint64_t vpc = vi->layout.values_per_cell, vpl = vi->layout.volumes_per_level;
    if (!vi->layout.present && vpc == 0) { /* an info filled by hand before descriptions: R5.1 */
        vpc = LPVP_VALUES_PER_CELL;
        vpl = 1;
    }
    if (vpc < 1 || vpc > LPVP_MAX_VALUES_PER_CELL || vpl < 1 || vpl > LPVP_MAX_VOLUMES_PER_LEVEL)
        return 0;
    uint64_t cells = lpvp_volume_total_cells(vi);
    uint64_t per = vpc * vpl * (uint64_t)lpvp_volume_value_size(vi->format);
    if (cells > (((uint64_t)1 << 62) / per))
        return 0;
    return cells * per;
}

int lpvp_volume_layout_lookup_check(const lpvp_volume_layout *l, char *err, size_t err_n)
{
    if (lpvp_volume_layout_is_iv(l)) {
        lpvp_set_error(err, err_n,
                       "volume of technique \"%s\" is %s voxels holding radiance (%s) with an index of the voxels "
                       "that hold a surface, not R5.1's cascades R5.7's lookup reads: use R5.14's lookup",
                       l->technique, lpvp_level_role_names[LPVP_ROLE_IV_VOXELS], lpvp_volume_layout_units(l));
        return -1;
    }
    if (l->content == LPVP_CONTENT_LEVELS) {
        lpvp_set_error(err, err_n,
                       "volume of content \"%s\" (technique \"%s\": its %d levels and index volume) is not the merged "
                       "grid R5.7's lookup reads: ask GET_VOLUME with content \"%s\"",
                       lpvp_volume_content_names[LPVP_CONTENT_LEVELS], l->technique, l->level_count,
                       lpvp_volume_content_names[LPVP_CONTENT_MERGED]);
        return -1;
    }
    if ((l->sh_values || (!l->present && l->values_per_cell == 0)) && l->volumes_per_level <= 1 && !l->has_index &&
        strcmp(lpvp_volume_layout_units(l), LPVP_VOLUME_UNITS) == 0)
        return 0;
    lpvp_set_error(err, err_n,
                   "volume layout of technique \"%s\" (layout_version %d, %d values per cell%s, %d volumes per "
                   "level%s, units %s) is not R5.1's 12 SH values in one volume per level, the only layout R5.7's "
                   "lookup reads", l->technique, l->layout_version, l->values_per_cell,
                   l->sh_values ? ", the SH values" : "", l->volumes_per_level,
                   l->has_index ? ", with an index volume" : "", lpvp_volume_layout_units(l));
    return -1;
}

int lpvp_volume_layout_iv_lookup_check(const lpvp_volume_layout *l, char *err, size_t err_n)
{
    if (lpvp_volume_layout_is_iv(l) && l->sh_values && l->volumes_per_level == 1 && l->has_index &&
        l->index.level == 0 && l->index.values_per_cell == 1 && l->iv_neighbours >= LPVP_IV_NEIGHBOURS_MIN &&
        l->iv_neighbours <= LPVP_IV_NEIGHBOURS_MAX)
        return 0;
    lpvp_set_error(err, err_n,
                   "volume layout of technique \"%s\" (%s, %d values per cell, %d volumes per level%s) is not "
                   "R5.14's %s voxels, the only layout R5.14's lookup reads", l->technique[0] ? l->technique : "?",
                   l->content == LPVP_CONTENT_LEVELS ? "content \"levels\"" : "content \"merged\"",
                   l->values_per_cell, l->volumes_per_level, l->has_index ? ", with an index" : ", no index",
                   lpvp_level_role_names[LPVP_ROLE_IV_VOXELS]);
    return -1;
}

/* The description object (R5.9): levels from the cascades, values from the
 * SH names (the only values this library builds). */
static json_t *placement_json(const lpvp_cascade_info *c);
static json_t *index_json(const lpvp_volume_info *vi);

static json_t *layout_json(const lpvp_volume_info *vi, json_t *cascades)
{
    const lpvp_volume_layout *l = &vi->layout;
    json_t *levels = NULL, *values = json_array();
    if (l->content == LPVP_CONTENT_LEVELS) { /* R5.13: the octree's levels */
        levels = json_array();
        for (int k = 0; levels && k < l->level_count && k < LPVP_MAX_LEVELS; k++) {
            if (json_array_append_new(levels, placement_json(&l->level[k])) != 0) {
                json_decref(levels);
                levels = NULL;
            }
        }
    } else {
        levels = json_deep_copy(cascades);
    }
    json_t *o = json_object();
    int bad = !levels || !values || !o || !l->sh_values || l->values_per_cell != LPVP_VALUES_PER_CELL;
    for (size_t k = 0; !bad && k < json_array_size(levels); k++) {
        int r = l->role[k] >= 0 && l->role[k] < LPVP_ROLE_COUNT ? (int)l->role[k] : LPVP_ROLE_CASCADE;
        bad |= json_object_set_new(json_array_get(levels, k), "role", json_string(lpvp_level_role_names[r])) != 0;
    }
    for (int i = 0; !bad && i < LPVP_VALUES_PER_CELL; i++)
        bad |= json_array_append_new(values, json_string(lpvp_sh_value_names[i])) != 0;
    if (!bad) {
        bad |= json_object_set_new(o, "layout_version", json_integer(l->layout_version)) != 0;
        bad |= json_object_set_new(o, "technique", json_string(l->technique)) != 0;
        bad |= json_object_set_new(o, "levels", levels) != 0;
        levels = NULL;
        bad |= json_object_set_new(o, "far_field", json_boolean(l->far_field)) != 0;
        bad |= json_object_set_new(o, "volumes_per_level", json_integer(l->volumes_per_level)) != 0;
        bad |= json_object_set_new(o, "values_per_cell", json_integer(l->values_per_cell)) != 0;
        bad |= json_object_set_new(o, "values", values) != 0;
        values = NULL;
        bad |= json_object_set_new(o, "units", json_string(lpvp_volume_layout_units(l))) != 0;
        bad |= json_object_set_new(o, "index", l->has_index ? index_json(vi) : json_null()) != 0;
        if (lpvp_volume_layout_is_iv(l)) /* R5.14 */
            bad |= json_object_set_new(o, LPVP_IV_NEIGHBOURS_KEY, json_integer(l->iv_neighbours)) != 0;
    }
    json_decref(levels);
    json_decref(values);
    if (bad) {
        json_decref(o);
        return NULL;
    }
    return o;
}

/* ---- Volume header -------------------------------------------------------- */

static json_t *vec_json(const double *v, size_t n)
{
    json_t *a = json_array();
    for (size_t i = 0; a && i < n; i++) {
        if (json_array_append_new(a, json_real(isfinite(v[i]) ? v[i] : 0.0)) != 0) {
            json_decref(a);
            return NULL;
        }
    }
    return a;
}

/* The cascades build and the totals use: vi's own, or one from the grid. */
static int cascades_of(const lpvp_volume_info *vi, lpvp_cascade_info *out)
{
    if (vi->cascade_count == 0) {
        memset(out, 0, sizeof *out);
        out->cells = 1;
        for (int i = 0; i < 3; i++) {
            out->dims[i] = vi->dims[i];
            out->origin[i] = vi->origin[i];
            out->cells *= (uint64_t)(vi->dims[i] > 0 ? vi->dims[i] : 0);
        }
        out->cell_size = vi->cell_size;
        return 1;
    }
    if (vi->cascade_count < 0 || vi->cascade_count > LPVP_MAX_CASCADES)
        return -1;
    for (int k = 0; k < vi->cascade_count; k++)
        out[k] = vi->cascades[k];
    return vi->cascade_count;
}

/* The levels the raw volume holds: the octree's (R5.13) or the cascades. */
static int levels_of(const lpvp_volume_info *vi, lpvp_cascade_info *out)
{
    if (vi->layout.content != LPVP_CONTENT_LEVELS)
        return cascades_of(vi, out);
    if (vi->layout.level_count < 1 || vi->layout.level_count > LPVP_MAX_LEVELS)
        return -1;
    for (int k = 0; k < vi->layout.level_count; k++)
        out[k] = vi->layout.level[k];
    return vi->layout.level_count;
}

uint64_t lpvp_volume_total_cells(const lpvp_volume_info *vi)
{
    lpvp_cascade_info c[LPVP_MAX_LEVELS];
    int n = levels_of(vi, c);
    uint64_t total = 0;
    for (int k = 0; k < n; k++)
        total += c[k].cells;
    return n < 0 ? 0 : total;
}

uint64_t lpvp_volume_cascade_first_cell(const lpvp_volume_info *vi, int k)
{
    lpvp_cascade_info c[LPVP_MAX_LEVELS];
    int n = levels_of(vi, c);
    uint64_t first = 0;
    for (int i = 0; i < k && i < n; i++)
        first += c[i].cells;
    return first;
}

/* One level's (cascade's) placement: dims, origin, cell_size, cells. */
static json_t *placement_json(const lpvp_cascade_info *c)
{
    return json_pack("{s:[I,I,I], s:o, s:f, s:I}", "dims", (json_int_t)c->dims[0], (json_int_t)c->dims[1],
                     (json_int_t)c->dims[2], "origin", vec_json(c->origin, 3), "cell_size",
                     isfinite(c->cell_size) ? c->cell_size : 0.0, "cells", (json_int_t)c->cells);
}

/* The index object (R5.12), right after the levels' values. */
static json_t *index_json(const lpvp_volume_info *vi)
{
    const lpvp_index_info *ix = &vi->layout.index;
    uint64_t length = ix->cells * (uint64_t)ix->values_per_cell * LPVP_INDEX_VALUE_SIZE;
    return json_pack("{s:i, s:[I,I,I], s:i, s:s, s:I, s:I}", "level", ix->level, "dims", (json_int_t)ix->dims[0],
                     (json_int_t)ix->dims[1], (json_int_t)ix->dims[2], "values_per_cell", ix->values_per_cell,
                     "value_type", LPVP_INDEX_VALUE_TYPE, "raw_offset", (json_int_t)lpvp_volume_values_bytes(vi),
                     "raw_length", (json_int_t)length);
}

static json_t *cascades_json(const lpvp_volume_info *vi)
{
    lpvp_cascade_info c[LPVP_MAX_CASCADES];
    int n = cascades_of(vi, c);
    json_t *a = json_array();
    if (!a || n < 0) {
        json_decref(a);
        return NULL;
    }
    for (int k = 0; k < n; k++) {
        json_t *e = placement_json(&c[k]);
        if (!e || json_array_append_new(a, e) != 0) {
            json_decref(a);
            return NULL;
        }
    }
    return a;
}

json_t *lpvp_volume_header_build(const lpvp_volume_info *vi)
{
    json_t *o = json_object();
    json_t *grid = json_object();
    json_t *dims = json_array();
    int bad = !o || !grid || !dims;
    for (int i = 0; !bad && i < 3; i++)
        bad |= json_array_append_new(dims, json_integer(vi->dims[i])) != 0;
    if (!bad) {
        bad |= json_object_set_new(grid, "dims", dims) != 0;
        dims = NULL;
        bad |= json_object_set_new(grid, "origin", vec_json(vi->origin, 3)) != 0;
        bad |= json_object_set_new(grid, "cell_size",
                                   json_real(isfinite(vi->cell_size) ? vi->cell_size : 0.0)) != 0;
    }
    if (!bad) {
        bad |= json_object_set_new(o, "revision", json_integer(vi->revision)) != 0;
        bad |= json_object_set_new(o, "tick", json_integer(vi->tick)) != 0;
        bad |= json_object_set_new(o, "format",
                                   json_string(lpvp_volume_format_name(vi->format))) != 0;
        bad |= json_object_set_new(o, "compression",
                                   json_string(lpvp_compression_name(vi->compression))) != 0;
        bad |= json_object_set_new(o, "keyframe", json_boolean(vi->keyframe)) != 0;
        if (!vi->keyframe)
            bad |= json_object_set_new(o, "base_tick", json_integer(vi->base_tick)) != 0;
        bad |= json_object_set_new(o, "grid", grid) != 0;
        grid = NULL;
        json_t *cascades = cascades_json(vi);
        bad |= json_object_set_new(o, "cascades", cascades) != 0;
        bad |= json_object_set_new(o, "units", json_string(lpvp_volume_layout_units(&vi->layout))) != 0;
        bad |= json_object_set_new(o, "layout", json_string(LPVP_VOLUME_LAYOUT)) != 0;
        bad |= json_object_set_new(o, "sh", json_string(LPVP_VOLUME_SH)) != 0;
        bad |= json_object_set_new(o, "raw_length", json_integer((json_int_t)vi->raw_length)) != 0;
        if (!bad && vi->layout.present)
            bad |= json_object_set_new(o, LPVP_VOLUME_DESC_KEY, layout_json(vi, cascades)) != 0;
    }
    json_decref(dims);
    json_decref(grid);
    if (bad) {
        json_decref(o);
        return NULL;
    }
    return o;
}

/* Local getters (volume_codec does not depend on proto.c's). */
static int need_int(const json_t *o, const char *key, long long min, long long *out, char *err,
                    size_t err_n)
{
    json_t *v = json_object_get(o, key);
    if (!json_is_integer(v)) {
        lpvp_set_error(err, err_n, "%s: expected an integer", key);
        return -1;
    }
    if (json_integer_value(v) < min) {
        lpvp_set_error(err, err_n, "%s: %lld is less than %lld", key, (long long)json_integer_value(v),
                min);
        return -1;
    }
    *out = (long long)json_integer_value(v);
    return 0;
}

static int same_real(double a, double b)
{
    return fabs(a - b) <= 1e-9 * (fabs(a) > fabs(b) ? fabs(a) : fabs(b)) + 1e-12;
}

/* "cascades" (R5.6) into vi->lpv.cascades; the grid fields are already read.
 * Absent: one cascade equal to the grid (a server before cascades). */
static int parse_cascades(const json_t *obj, lpvp_volume_info *vi, char *err, size_t err_n)
{
    const json_t *a = json_object_get(obj, "cascades");
    uint64_t total = 0;
    if (!a) {
        vi->cascade_count = 0;
        cascades_of(vi, &vi->cascades[0]);
        vi->cascade_count = 1;
        return 0;
    }
    if (!json_is_array(a) || json_array_size(a) < 1 || json_array_size(a) > LPVP_MAX_CASCADES) {
        lpvp_set_error(err, err_n, "cascades: expected an array of 1 to %d cascades", LPVP_MAX_CASCADES);
        return -1;
    }
    vi->cascade_count = (int)json_array_size(a);
    for (int k = 0; k < vi->cascade_count; k++) {
        const json_t *c = json_array_get(a, (size_t)k), *d, *v;
        lpvp_cascade_info *ci = &vi->cascades[k];
        uint64_t cells = 1;
        if (!json_is_object(c)) {
            lpvp_set_error(err, err_n, "cascades[%d]: expected an object", k);
            return -1;
        }
        d = json_object_get(c, "dims");
        if (!json_is_array(d) || json_array_size(d) != 3) {
            lpvp_set_error(err, err_n, "cascades[%d].dims: expected an array of 3 integers", k);
            return -1;
        }
        for (size_t i = 0; i < 3; i++) {
            v = json_array_get(d, i);
            if (!json_is_integer(v) || json_integer_value(v) < 1 ||
                json_integer_value(v) > (1 << 20)) {
                lpvp_set_error(err, err_n, "cascades[%d].dims[%zu]: expected an integer in [1, 1048576]",
                               k, i);
                return -1;
            }
            ci->dims[i] = json_integer_value(v);
            if (cells > ((uint64_t)1 << 62) / (uint64_t)ci->dims[i]) {
                lpvp_set_error(err, err_n, "cascades[%d].dims: too many cells", k);
                return -1;
            }
            cells *= (uint64_t)ci->dims[i];
        }
        d = json_object_get(c, "origin");
        if (!json_is_array(d) || json_array_size(d) != 3) {
            lpvp_set_error(err, err_n, "cascades[%d].origin: expected an array of 3 numbers", k);
            return -1;
        }
        for (size_t i = 0; i < 3; i++) {
            v = json_array_get(d, i);
            if (!json_is_number(v) || !isfinite(json_number_value(v))) {
                lpvp_set_error(err, err_n, "cascades[%d].origin[%zu]: expected a number", k, i);
                return -1;
            }
            ci->origin[i] = json_number_value(v);
        }
        v = json_object_get(c, "cell_size");
        if (!json_is_number(v) || !(json_number_value(v) > 0.0) || !isfinite(json_number_value(v))) {
            lpvp_set_error(err, err_n, "cascades[%d].cell_size: expected a positive number", k);
            return -1;
        }
        ci->cell_size = json_number_value(v);
        v = json_object_get(c, "cells");
        if (!json_is_integer(v) || json_integer_value(v) < 0 ||
            (uint64_t)json_integer_value(v) != cells) {
            lpvp_set_error(err, err_n, "cascades[%d].cells: expected %llu (the product of its dims)", k,
                           (unsigned long long)cells);
            return -1;
        }
        ci->cells = cells;
        if (total > ((uint64_t)1 << 62) - cells) {
            lpvp_set_error(err, err_n, "cascades: too many cells");
            return -1;
        }
        total += cells;
    }
    for (int i = 0; i < 3; i++) {
        if (vi->cascades[0].dims[i] != vi->dims[i]) {
            lpvp_set_error(err, err_n, "grid.dims: differs from cascades[0].dims");
            return -1;
        }
        if (!same_real(vi->cascades[0].origin[i], vi->origin[i])) {
            lpvp_set_error(err, err_n, "grid.origin: differs from cascades[0].origin");
            return -1;
        }
    }
    if (!same_real(vi->cascades[0].cell_size, vi->cell_size)) {
        lpvp_set_error(err, err_n, "grid.cell_size: differs from cascades[0].cell_size");
        return -1;
    }
    if ((uint64_t)(size_t)total != total) {
        lpvp_set_error(err, err_n, "cascades: too many cells");
        return -1;
    }
    return 0;
}

/* 1 when a level object e has ci's dims, origin, cell_size and cells. */
static int level_matches(const json_t *e, const lpvp_cascade_info *ci)
{
    const json_t *dims = json_object_get(e, "dims"), *org = json_object_get(e, "origin"), *v;
    int same = json_is_array(dims) && json_array_size(dims) == 3 && json_is_array(org) && json_array_size(org) == 3;
    for (size_t i = 0; same && i < 3; i++) {
        same = json_is_integer(json_array_get(dims, i)) && json_integer_value(json_array_get(dims, i)) == ci->dims[i] &&
               json_is_number(json_array_get(org, i)) &&
               same_real(json_number_value(json_array_get(org, i)), ci->origin[i]);
    }
    v = json_object_get(e, "cell_size");
    same = same && json_is_number(v) && same_real(json_number_value(v), ci->cell_size);
    v = json_object_get(e, "cells");
    return same && json_is_integer(v) && (uint64_t)json_integer_value(v) == ci->cells;
}

/* 1 when levels[0] has the role `role` ("octree_level": R5.13, "iv_voxels": R5.14). */
static int levels_have_role(const json_t *levels, int role)
{
    const json_t *r = json_object_get(json_array_get(levels, 0), "role");
    return json_is_array(levels) && json_is_string(r) && strcmp(json_string_value(r), lpvp_level_role_names[role]) == 0;
}

/* R5.13: an octree's levels over cascades[0] (the only cascade), every one
 * placed as lpvp_octree_level_place says, far_field false. */
static int parse_octree_levels(const json_t *d, lpvp_volume_info *vi, char *err, size_t err_n)
{
    lpvp_volume_layout *l = &vi->layout;
    const char *K = LPVP_VOLUME_DESC_KEY, *OL = lpvp_level_role_names[LPVP_ROLE_OCTREE_LEVEL];
    const json_t *a = json_object_get(d, "levels");
    const lpvp_cascade_info *c0 = &vi->cascades[0];
    if (vi->cascade_count != 1) {
        lpvp_set_error(err, err_n, "cascades: %d entries, but \"%s\" levels need exactly one, level 0", vi->cascade_count,
                       OL);
        return -1;
    }
    int count = lpvp_octree_level_count(c0->dims[0]);
    if (count < 0 || c0->dims[1] != c0->dims[0] || c0->dims[2] != c0->dims[0]) {
        lpvp_set_error(err, err_n, "%s.levels: \"%s\" levels over a %lldx%lldx%lld level 0, which has no octree of at "
                       "most %d levels (a cube of a power of two)", K, OL, (long long)c0->dims[0], (long long)c0->dims[1],
                       (long long)c0->dims[2], LPVP_MAX_LEVELS);
        return -1;
    }
    if (json_array_size(a) != (size_t)count) {
        lpvp_set_error(err, err_n, "%s.levels: %zu \"%s\" levels, but an octree over %lld^3 cells has %d (log2(n) + 1)",
                       K, json_array_size(a), OL, (long long)c0->dims[0], count);
        return -1;
    }
    if (l->far_field) {
        lpvp_set_error(err, err_n, "%s.far_field: true with \"%s\" levels (an octree has no far field)", K, OL);
        return -1;
    }
    for (int k = 0; k < count; k++) {
        const json_t *e = json_array_get(a, (size_t)k), *r = json_object_get(e, "role");
        lpvp_cascade_info want;
        lpvp_octree_level_place(c0, k, &want);
        if (!json_is_object(e) || !level_matches(e, &want)) {
            lpvp_set_error(err, err_n, "%s.levels[%d]: dims, origin, cell_size and cells differ from octree level %d "
                           "(level 0's origin, dims n >> %d, cell size 2^%d x level 0's)", K, k, k, k, k);
            return -1;
        }
        if (!json_is_string(r) || strcmp(json_string_value(r), OL) != 0) {
            lpvp_set_error(err, err_n, "%s.levels[%d].role: expected \"%s\" (level 0's role)", K, k, OL);
            return -1;
        }
        l->level[k] = want;
        l->role[k] = LPVP_ROLE_OCTREE_LEVEL;
    }
    l->content = LPVP_CONTENT_LEVELS;
    l->level_count = count;
    return 0;
}

/* R5.14: technique iv's one level of voxels, equal to cascades[0] (the only
 * cascade), far_field false, and its lookup's iv_neighbours. The cells, units
 * and index are checked after parse_cells (iv_checks). */
static int parse_iv_levels(const json_t *d, lpvp_volume_info *vi, char *err, size_t err_n)
{
    lpvp_volume_layout *l = &vi->layout;
    const char *K = LPVP_VOLUME_DESC_KEY, *IV = lpvp_level_role_names[LPVP_ROLE_IV_VOXELS];
    const json_t *a = json_object_get(d, "levels"), *v;
    if (vi->cascade_count != 1 || json_array_size(a) != 1) {
        lpvp_set_error(err, err_n, "%s.levels: %zu levels over %d cascades, but \"%s\" is exactly one level over "
                       "one cascade (R5.14)", K, json_array_size(a), vi->cascade_count, IV);
        return -1;
    }
    if (!json_is_object(json_array_get(a, 0)) || !level_matches(json_array_get(a, 0), &vi->cascades[0])) {
        lpvp_set_error(err, err_n, "%s.levels[0]: dims, origin, cell_size and cells differ from cascades[0]", K);
        return -1;
    }
    if (l->far_field) {
        lpvp_set_error(err, err_n, "%s.far_field: true with \"%s\" levels (an iv volume has no far field)", K, IV);
        return -1;
    }
    v = json_object_get(d, LPVP_IV_NEIGHBOURS_KEY);
    if (!json_is_integer(v) || json_integer_value(v) < LPVP_IV_NEIGHBOURS_MIN ||
        json_integer_value(v) > LPVP_IV_NEIGHBOURS_MAX) {
        lpvp_set_error(err, err_n, "%s.%s: expected an integer in [%d, %d] with \"%s\" levels (R5.14)", K,
                       LPVP_IV_NEIGHBOURS_KEY, LPVP_IV_NEIGHBOURS_MIN, LPVP_IV_NEIGHBOURS_MAX, IV);
        return -1;
    }
    l->iv_neighbours = (int)json_integer_value(v);
    l->role[0] = LPVP_ROLE_IV_VOXELS;
    return 0;
}

/* R5.14 after parse_cells: the 12 SH values in one volume, radiance units,
 * the index over level 0 with one value per voxel. */
static int iv_checks(lpvp_volume_info *vi, char *err, size_t err_n)
{
    const lpvp_volume_layout *l = &vi->layout;
    const lpvp_cascade_info *c0 = &vi->cascades[0];
    const char *K = LPVP_VOLUME_DESC_KEY, *IV = lpvp_level_role_names[LPVP_ROLE_IV_VOXELS];
    if (!l->sh_values || l->volumes_per_level != 1) {
        lpvp_set_error(err, err_n, "%s.values: \"%s\" levels hold R5.1's 12 SH values in one volume per level "
                       "(got %d values, %d volumes; R5.14)", K, IV, l->values_per_cell, l->volumes_per_level);
        return -1;
    }
    if (strcmp(lpvp_volume_layout_units(l), LPVP_VOLUME_UNITS_RADIANCE) != 0) {
        lpvp_set_error(err, err_n, "%s.units: \"%s\" with \"%s\" levels, expected \"%s\" (radiance; R5.14)", K,
                       lpvp_volume_layout_units(l), IV, LPVP_VOLUME_UNITS_RADIANCE);
        return -1;
    }
    if (!l->has_index || l->index.level != 0 || l->index.values_per_cell != 1 || l->index.dims[0] != c0->dims[0] ||
        l->index.dims[1] != c0->dims[1] || l->index.dims[2] != c0->dims[2]) {
        lpvp_set_error(err, err_n, "%s.index: \"%s\" levels need the index over level 0 (level 0, dims [%lld, "
                       "%lld, %lld], values_per_cell 1: which voxels hold a surface; R5.14)", K, IV,
                       (long long)c0->dims[0], (long long)c0->dims[1], (long long)c0->dims[2]);
        return -1;
    }
    return 0;
}

static int parse_cells(const json_t *obj, const json_t *d, lpvp_volume_info *vi, char *err, size_t err_n);

/* The description (R5.9 - R5.12) into vi->layout; the cascades are already
 * read. Absent: R5.1's 12 values (layout.present 0). Each MUST-reject rule of
 * R5.9 - R5.12 is one check here, its message naming the field. */
static int parse_layout(const json_t *obj, lpvp_volume_info *vi, char *err, size_t err_n)
{
    lpvp_volume_layout *l = &vi->layout;
    const json_t *d = json_object_get(obj, LPVP_VOLUME_DESC_KEY), *v, *a;
    const char *K = LPVP_VOLUME_DESC_KEY;
    char key[96];
    if (!d) {
        lpvp_volume_layout_sh(l, "", 0, vi->cascade_count);
        l->present = 0;
        l->layout_version = 0;
        return 0;
    }
    memset(l, 0, sizeof *l);
    l->present = 1;
    if (!json_is_object(d)) {
        lpvp_set_error(err, err_n, "%s: expected an object", K);
        return -1;
    }
    snprintf(key, sizeof key, "%s.layout_version", K);
    v = json_object_get(d, "layout_version");
    if (!json_is_integer(v)) {
        lpvp_set_error(err, err_n, "%s: expected an integer", key);
        return -1;
    }
    if (json_integer_value(v) != LPVP_VOLUME_LAYOUT_VERSION) {
        lpvp_set_error(err, err_n, "%s: %lld is not a layout this client reads (it reads %d)", key,
                       (long long)json_integer_value(v), LPVP_VOLUME_LAYOUT_VERSION);
        return -1;
    }
    l->layout_version = (int)json_integer_value(v);
    v = json_object_get(d, "technique");
    if (!json_is_string(v) || json_string_length(v) == 0 || json_string_length(v) >= sizeof l->technique) {
        lpvp_set_error(err, err_n, "%s.technique: expected a name of 1 to %zu characters", K,
                       sizeof l->technique - 1);
        return -1;
    }
    snprintf(l->technique, sizeof l->technique, "%s", json_string_value(v));
    v = json_object_get(d, "far_field");
    if (!json_is_boolean(v)) {
        lpvp_set_error(err, err_n, "%s.lpv.far_field: expected true or false", K);
        return -1;
    }
    l->far_field = json_is_true(v);

    a = json_object_get(d, "levels");
    if (levels_have_role(a, LPVP_ROLE_OCTREE_LEVEL))
        return parse_octree_levels(d, vi, err, err_n) != 0 ? -1 : parse_cells(obj, d, vi, err, err_n);
    if (levels_have_role(a, LPVP_ROLE_IV_VOXELS))
        return parse_iv_levels(d, vi, err, err_n) != 0 || parse_cells(obj, d, vi, err, err_n) != 0
                   ? -1
                   : iv_checks(vi, err, err_n);
    /* R5.10: the levels are the cascades, each with a role agreeing with far_field */
    if (!json_is_array(a) || json_array_size(a) != (size_t)vi->cascade_count) {
        lpvp_set_error(err, err_n, "%s.levels: expected an array of %d levels (one per cascade)", K,
                       vi->cascade_count);
        return -1;
    }
    for (int k = 0; k < vi->cascade_count; k++) {
        const json_t *e = json_array_get(a, (size_t)k);
        const lpvp_cascade_info *ci = &vi->cascades[k];
        if (!json_is_object(e)) {
            lpvp_set_error(err, err_n, "%s.levels[%d]: expected an object", K, k);
            return -1;
        }
        if (!level_matches(e, ci)) {
            lpvp_set_error(err, err_n, "%s.levels[%d]: dims, origin, cell_size and cells differ from cascades[%d]", K,
                           k, k);
            return -1;
        }
        v = json_object_get(e, "role");
        int role = -1;
        for (int r = 0; json_is_string(v) && r < LPVP_ROLE_COUNT; r++)
            if (strcmp(json_string_value(v), lpvp_level_role_names[r]) == 0)
                role = r;
        if (role < 0) {
            lpvp_set_error(err, err_n, "%s.levels[%d].role: expected \"%s\", \"%s\", \"%s\" or \"%s\"", K, k,
                           lpvp_level_role_names[LPVP_ROLE_CASCADE], lpvp_level_role_names[LPVP_ROLE_FAR_FIELD],
                           lpvp_level_role_names[LPVP_ROLE_OCTREE_LEVEL], lpvp_level_role_names[LPVP_ROLE_IV_VOXELS]);
            return -1;
        }
        int want = (l->far_field && k > 0) ? LPVP_ROLE_FAR_FIELD : LPVP_ROLE_CASCADE;
        if (role != want) {
            lpvp_set_error(err, err_n, "%s.levels[%d].role: \"%s\" with far_field %s (level 0 is a \"%s\"; levels "
                           "1.. are \"%s\" exactly when far_field is true)", K, k, lpvp_level_role_names[role],
                           l->far_field ? "true" : "false", lpvp_level_role_names[LPVP_ROLE_CASCADE],
                           lpvp_level_role_names[LPVP_ROLE_FAR_FIELD]);
            return -1;
        }
        l->role[k] = (lpvp_level_role)role;
    }
    return parse_cells(obj, d, vi, err, err_n);
}

/* R5.11, R5.12: what a cell holds, units, the index. */
static int parse_cells(const json_t *obj, const json_t *d, lpvp_volume_info *vi, char *err, size_t err_n)
{
    lpvp_volume_layout *l = &vi->layout;
    const json_t *v, *a;
    const char *K = LPVP_VOLUME_DESC_KEY;
    long long x;
    char key[96];

    /* R5.11: what a cell holds */
    snprintf(key, sizeof key, "%s.volumes_per_level", K);
    if (need_int(d, "volumes_per_level", 1, &x, err, err_n) != 0 || x > LPVP_MAX_VOLUMES_PER_LEVEL) {
        lpvp_set_error(err, err_n, "%s: expected an integer in [1, %d]", key, LPVP_MAX_VOLUMES_PER_LEVEL);
        return -1;
    }
    l->volumes_per_level = (int)x;
    snprintf(key, sizeof key, "%s.values_per_cell", K);
    if (need_int(d, "values_per_cell", 1, &x, err, err_n) != 0 || x > LPVP_MAX_VALUES_PER_CELL) {
        lpvp_set_error(err, err_n, "%s: expected an integer in [1, %d]", key, LPVP_MAX_VALUES_PER_CELL);
        return -1;
    }
    l->values_per_cell = (int)x;
    a = json_object_get(d, "values");
    if (!json_is_array(a) || json_array_size(a) != (size_t)l->values_per_cell) {
        lpvp_set_error(err, err_n, "%s.values: expected an array of values_per_cell (%d) names", K,
                       l->values_per_cell);
        return -1;
    }
    l->sh_values = l->values_per_cell == LPVP_VALUES_PER_CELL;
    for (size_t i = 0; i < json_array_size(a); i++) {
        v = json_array_get(a, i);
        if (!json_is_string(v) || json_string_length(v) == 0) {
            lpvp_set_error(err, err_n, "%s.values[%zu]: expected a non-empty name", K, i);
            return -1;
        }
        for (size_t j = 0; j < i; j++) {
            if (strcmp(json_string_value(v), json_string_value(json_array_get(a, j))) == 0) {
                lpvp_set_error(err, err_n, "%s.values[%zu]: \"%s\" is named twice (also values[%zu])", K, i,
                               json_string_value(v), j);
                return -1;
            }
        }
        if (l->sh_values && strcmp(json_string_value(v), lpvp_sh_value_names[i]) != 0)
            l->sh_values = 0;
    }
    v = json_object_get(d, "units");
    const json_t *top_units = json_object_get(obj, "units");
    if (!json_is_string(v) || (json_is_string(top_units) && !json_equal(v, top_units))) {
        lpvp_set_error(err, err_n, "%s.units: expected a string equal to the header's \"units\"", K);
        return -1;
    }
    if (json_string_length(v) >= sizeof l->units) {
        lpvp_set_error(err, err_n, "%s.units: \"%s\" is longer than the units this client knows", K,
                       json_string_value(v));
        return -1;
    }
    snprintf(l->units, sizeof l->units, "%s", json_string_value(v));

    /* R5.12: an index volume after the levels' values */
    v = json_object_get(d, "index");
    if (v && !json_is_null(v)) {
        lpvp_index_info *ix = &l->index;
        if (!json_is_object(v)) {
            lpvp_set_error(err, err_n, "%s.index: expected null or an object", K);
            return -1;
        }
        snprintf(key, sizeof key, "%s.index.level", K);
        int level_count = l->content == LPVP_CONTENT_LEVELS ? l->level_count : vi->cascade_count;
        if (need_int(v, "level", 0, &x, err, err_n) != 0 || x >= level_count) {
            lpvp_set_error(err, err_n, "%s: expected a level in [0, %d]", key, level_count - 1);
            return -1;
        }
        ix->level = (int)x;
        const json_t *dims = json_object_get(v, "dims");
        if (!json_is_array(dims) || json_array_size(dims) != 3) {
            lpvp_set_error(err, err_n, "%s.index.dims: expected an array of 3 integers", K);
            return -1;
        }
        ix->cells = 1;
        for (size_t i = 0; i < 3; i++) {
            const json_t *e = json_array_get(dims, i);
            if (!json_is_integer(e) || json_integer_value(e) < 1 || json_integer_value(e) > (1 << 20)) {
                lpvp_set_error(err, err_n, "%s.index.dims[%zu]: expected an integer in [1, 1048576]", K, i);
                return -1;
            }
            ix->dims[i] = json_integer_value(e);
            ix->cells *= (uint64_t)ix->dims[i];
        }
        snprintf(key, sizeof key, "%s.index.values_per_cell", K);
        if (need_int(v, "values_per_cell", 1, &x, err, err_n) != 0 || x > LPVP_MAX_VALUES_PER_CELL) {
            lpvp_set_error(err, err_n, "%s: expected an integer in [1, %d]", key, LPVP_MAX_VALUES_PER_CELL);
            return -1;
        }
        ix->values_per_cell = (int)x;
        const json_t *vt = json_object_get(v, "value_type");
        if (!json_is_string(vt) || strcmp(json_string_value(vt), LPVP_INDEX_VALUE_TYPE) != 0) {
            lpvp_set_error(err, err_n, "%s.index.value_type: expected \"%s\"", K, LPVP_INDEX_VALUE_TYPE);
            return -1;
        }
        uint64_t values = lpvp_volume_values_bytes(vi);
        snprintf(key, sizeof key, "%s.index.raw_offset", K);
        if (need_int(v, "raw_offset", 0, &x, err, err_n) != 0 || (uint64_t)x != values) {
            lpvp_set_error(err, err_n, "%s: expected %llu (right after the levels' values)", key,
                           (unsigned long long)values);
            return -1;
        }
        ix->raw_offset = (uint64_t)x;
        uint64_t want = ix->cells * (uint64_t)ix->values_per_cell * LPVP_INDEX_VALUE_SIZE;
        snprintf(key, sizeof key, "%s.index.raw_length", K);
        if (need_int(v, "raw_length", 0, &x, err, err_n) != 0 || (uint64_t)x != want) {
            lpvp_set_error(err, err_n, "%s: expected %llu (dims' product x values_per_cell x %d bytes)", key,
                           (unsigned long long)want, LPVP_INDEX_VALUE_SIZE);
            return -1;
        }
        ix->raw_length = want;
        l->has_index = 1;
    }
    if (l->content == LPVP_CONTENT_LEVELS &&
        (!l->has_index || l->index.level != 0 || l->index.values_per_cell != 1 ||
         l->index.dims[0] != vi->cascades[0].dims[0] || l->index.dims[1] != vi->cascades[0].dims[1] ||
         l->index.dims[2] != vi->cascades[0].dims[2])) {
        lpvp_set_error(err, err_n, "%s.index: \"%s\" levels need the index volume over level 0 (level 0, dims [%lld, "
                       "%lld, %lld], values_per_cell 1)", K, lpvp_level_role_names[LPVP_ROLE_OCTREE_LEVEL],
                       (long long)vi->cascades[0].dims[0], (long long)vi->cascades[0].dims[1],
                       (long long)vi->cascades[0].dims[2]);
        return -1;
    }
    return 0;
}

int lpvp_volume_header_parse(const json_t *obj, lpvp_volume_info *vi, char *err, size_t err_n)
{
    long long x;
    json_t *v, *grid, *a;
    size_t cells = 1;
    memset(vi, 0, sizeof *vi);
    vi->base_tick = -1;
    if (!json_is_object(obj)) {
        lpvp_set_error(err, err_n, "volume header: not an object");
        return -1;
    }
    if (need_int(obj, "revision", 0, &x, err, err_n))
        return -1;
    vi->revision = x;
    if (need_int(obj, "tick", 0, &x, err, err_n))
        return -1;
    vi->tick = x;
    if (lpvp_volume_format_parse(json_string_value(json_object_get(obj, "format")),
                                 &vi->format) != 0) {
        lpvp_set_error(err, err_n, "format: expected \"fp16\" or \"fp32\"");
        return -1;
    }
    if (lpvp_compression_parse(json_string_value(json_object_get(obj, "compression")),
                               &vi->compression) != 0) {
        lpvp_set_error(err, err_n, "compression: expected \"zstd\" or \"none\"");
        return -1;
    }
    v = json_object_get(obj, "keyframe");
    if (!json_is_boolean(v)) {
        lpvp_set_error(err, err_n, "keyframe: expected true or false");
        return -1;
    }
    vi->keyframe = json_is_true(v);
    if (!vi->keyframe) {
        if (need_int(obj, "base_tick", 0, &x, err, err_n))
            return -1;
        vi->base_tick = x;
    }
    grid = json_object_get(obj, "grid");
    if (!json_is_object(grid)) {
        lpvp_set_error(err, err_n, "grid: expected an object");
        return -1;
    }
    a = json_object_get(grid, "dims");
    if (!json_is_array(a) || json_array_size(a) != 3) {
        lpvp_set_error(err, err_n, "grid.dims: expected an array of 3 integers");
        return -1;
    }
    for (size_t i = 0; i < 3; i++) {
        json_t *d = json_array_get(a, i);
        if (!json_is_integer(d) || json_integer_value(d) < 1 ||
            json_integer_value(d) > (1 << 20)) {
            lpvp_set_error(err, err_n, "grid.dims[%zu]: expected an integer in [1, 1048576]", i);
            return -1;
        }
        vi->dims[i] = json_integer_value(d);
        if (cells > ((size_t)-1) / (size_t)vi->dims[i]) {
            lpvp_set_error(err, err_n, "grid.dims: too many cells");
            return -1;
        }
        cells *= (size_t)vi->dims[i];
    }
    a = json_object_get(grid, "origin");
    if (!json_is_array(a) || json_array_size(a) != 3) {
        lpvp_set_error(err, err_n, "grid.origin: expected an array of 3 numbers");
        return -1;
    }
    for (size_t i = 0; i < 3; i++) {
        json_t *d = json_array_get(a, i);
        if (!json_is_number(d)) {
            lpvp_set_error(err, err_n, "grid.origin[%zu]: expected a number", i);
            return -1;
        }
        vi->origin[i] = json_number_value(d);
    }
    v = json_object_get(grid, "cell_size");
    if (!json_is_number(v) || !(json_number_value(v) > 0.0) || !isfinite(json_number_value(v))) {
        lpvp_set_error(err, err_n, "grid.cell_size: expected a positive number");
        return -1;
    }
    vi->cell_size = json_number_value(v);
    if (parse_cascades(obj, vi, err, err_n) != 0 || parse_layout(obj, vi, err, err_n) != 0)
        return -1;
    cells = (size_t)lpvp_volume_total_cells(vi);
    if (need_int(obj, "raw_length", 0, &x, err, err_n))
        return -1;
    vi->raw_length = (uint64_t)x;
    {
        /* R5.6 / R5.11: the levels' values as described, then the index (R5.12) */
        uint64_t values = lpvp_volume_values_bytes(vi);
        uint64_t index = vi->layout.has_index ? vi->layout.index.raw_length : 0;
        uint64_t expect = values + index;
        if (values == 0 || (uint64_t)(size_t)expect != expect || expect != vi->raw_length) {
            lpvp_set_error(err, err_n,
                           "raw_length: %llu, but %zu cells x %d volumes x %d values of %s%s need %llu bytes", x,
                           cells, vi->layout.volumes_per_level, vi->layout.values_per_cell,
                           lpvp_volume_format_name(vi->format), index ? " + the index" : "",
                           (unsigned long long)expect);
            return -1;
        }
    }
    return 0;
}

int lpvp_volume_decode(const lpvp_volume_info *vi, const void *attachment, size_t att_len,
                       const uint8_t *base_raw, size_t base_len, uint8_t *raw_out, char *err,
                       size_t err_n)
{
    size_t raw_len = (size_t)vi->raw_length;
    if ((uint64_t)raw_len != vi->raw_length) {
        lpvp_set_error(err, err_n, "raw_length %llu does not fit in memory",
                (unsigned long long)vi->raw_length);
        return -1;
    }
    if (!vi->keyframe && (!base_raw || base_len != raw_len)) {
        lpvp_set_error(err, err_n, "delta against tick %lld without a base volume of %zu bytes",
                (long long)vi->base_tick, raw_len);
        return -1;
    }
    if (vi->compression == LPVP_COMP_ZSTD) {
        if (!vi->keyframe && raw_out == base_raw) {
            /* In place: decompress aside, then XOR into the base. */
            uint8_t *tmp = malloc(raw_len ? raw_len : 1);
            if (!tmp) {
                lpvp_set_error(err, err_n, "out of memory (%zu bytes)", raw_len);
                return -1;
            }
            if (lpvp_zstd_decompress_exact(attachment, att_len, tmp, raw_len, err, err_n) != 0) {
                free(tmp);
                return -1;
            }
            lpvp_xor(raw_out, tmp, base_raw, raw_len);
            free(tmp);
            return 0;
        }
        if (lpvp_zstd_decompress_exact(attachment, att_len, raw_out, raw_len, err, err_n) != 0)
            return -1;
    } else {
        if (att_len != raw_len) {
            lpvp_set_error(err, err_n, "attachment of %zu bytes, raw_length is %zu", att_len, raw_len);
            return -1;
        }
        if (vi->keyframe) {
            if (raw_len)
                memmove(raw_out, attachment, raw_len);
            return 0;
        }
        lpvp_xor(raw_out, attachment, base_raw, raw_len);
        return 0;
    }
    if (!vi->keyframe)
        lpvp_xor(raw_out, raw_out, base_raw, raw_len);
    return 0;
}
