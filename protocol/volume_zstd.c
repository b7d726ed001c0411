/*
 * volume_zstd.c - zstd frames of volume payloads (SPEC R5.2): compression,
 * and decompression that checks the frame's declared size against what the
 * header allows before allocating. See volume_codec.h.
 */
#include "volume_codec.h"
#include "proto.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zstd.h>

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
