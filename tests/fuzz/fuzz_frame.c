/*
 * fuzz_frame.c - libFuzzer target for the protocol library (proto.h,
 * volume_codec.h). The input's first bytes choose the chunk sizes; the rest
 * is a byte stream fed to the incremental parser in those chunks (SPEC R2.x
 * hostile input). Each frame's body goes through lpvp_body_parse and every
 * field getter, its attachment through zstd decompression with a small
 * maximum and, if it looks like one, the volume header parser. Must never
 * crash, leak, or trip ASan/UBSan.
 *
 * Build: cmake -S . -B build-fuzz -DCMAKE_C_COMPILER=clang -DLPVD_FUZZ=ON
 *        cmake --build build-fuzz --target fuzz_frame
 * Run:   ./build-fuzz/fuzz/fuzz_frame -max_total_time=60 tests/fuzz/corpus
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "proto.h"
#include "volume_codec.h"

static void exercise_body(const json_t *j)
{
    char err[160];
    int64_t i = 0, i3[3];
    double d = 0, d6[6];
    float f = 0, f3[3], f4[4], f16[16];
    int b = 0, e = 0;
    const char *s = NULL;
    size_t sl = 0;
    const json_t *o = NULL, *a = NULL;
    static const char *const streams[] = {"volume", "frame"};

    lpvp_get_int(j, "version", 1, 1, 1, &i, err, sizeof err);
    lpvp_get_int(j, "count", 0, 0, 1 << 20, &i, err, sizeof err);
    lpvp_get_number(j, "intensity", 0, 0, 1e30, &d, err, sizeof err);
    lpvp_get_float(j, "fov_deg", 0, 1e-3, 179, &f, err, sizeof err);
    lpvp_get_bool(j, "delta", 0, &b, err, sizeof err);
    lpvp_get_string(j, "path", 0, 4096, &s, &sl, err, sizeof err);
    lpvp_get_enum(j, "stream", 0, streams, 2, &e, err, sizeof err);
    lpvp_get_floats(j, "eye", 0, 3, -1e6, 1e6, f3, err, sizeof err);
    lpvp_get_floats(j, "rotation", 0, 4, -1, 1, f4, err, sizeof err);
    lpvp_get_floats(j, "matrix", 0, 16, -1e30, 1e30, f16, err, sizeof err);
    lpvp_get_numbers(j, "bounds", 0, 6, -1e6, 1e6, d6, err, sizeof err);
    lpvp_get_ints(j, "grid", 0, 3, 1, 256, i3, err, sizeof err);
    lpvp_get_object(j, "limits", 0, &o, err, sizeof err);
    if (lpvp_get_array(j, "nodes", 0, 1024, &a, err, sizeof err) == LPVP_FIELD_OK) {
        for (size_t k = 0; k < json_array_size(a); k++) {
            const json_t *n = json_array_get(a, k);
            if (lpvp_get_floats(n, "translation", 1, 3, -1e6, 1e6, f3, err, sizeof err) !=
                LPVP_FIELD_OK)
                lpvp_err_prefix(err, sizeof err, "nodes[%zu].", k);
        }
    }
}

static void exercise_frame(const lpvp_frame *fr)
{
    char err[160];
    json_t *j = lpvp_body_parse(fr->body, fr->body_len, err, sizeof err);
    if (j) {
        lpvp_volume_info vi;
        exercise_body(j);
        if (lpvp_volume_header_parse(j, &vi, err, sizeof err) == 0 && vi.raw_length <= 4096) {
            uint8_t raw[4096], base[4096];
            memset(base, 0x5A, sizeof base);
            lpvp_volume_decode(&vi, fr->attachment, fr->attachment_len, base,
                               (size_t)vi.raw_length, raw, err, sizeof err);
        }
        json_decref(j);
    }
    if (fr->attachment_len) {
        uint8_t *out = NULL;
        size_t out_len = 0;
        if (lpvp_zstd_decompress(fr->attachment, fr->attachment_len, 1 << 16, &out, &out_len,
                                 err, sizeof err) == 0)
            free(out);
    }
    /* Re-encode: an ERROR reply naming the frame. */
    {
        size_t n = 0;
        uint8_t *e = lpvp_error_build(fr->header.request_id, LPVP_E_UNKNOWN_TYPE, &n,
                                      "no such message type 0x%04x (%s)", fr->header.type,
                                      lpvp_type_name(fr->header.type));
        free(e);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    uint8_t chunks[8] = {0};
    size_t nc = size < 8 ? size : 8, off, k = 0;
    lpvp_parser p;
    lpvp_limits lim = {4096, 1 << 16, 0}; /* small limits to reach TOO_LARGE too */

    memcpy(chunks, data, nc);
    data += nc;
    size -= nc;
    lpvp_parser_init(&p, (nc && (chunks[0] & 1)) ? &lim : NULL);
    for (off = 0; off < size;) {
        size_t c = 1 + chunks[k++ % 8];
        if (c > size - off)
            c = size - off;
        size_t in_chunk = 0;
        while (in_chunk < c) {
            size_t used = 0;
            lpvp_frame fr;
            int st = lpvp_parser_feed(&p, data + off + in_chunk, c - in_chunk, &used, &fr);
            in_chunk += used;
            if (st == LPVP_PARSE_FRAME) {
                exercise_frame(&fr);
            } else if (st == LPVP_PARSE_ERROR) {
                size_t n = 0;
                uint8_t *e = lpvp_error_build(p.error_request_id, p.error_code, &n, "%s",
                                              p.error_message);
                free(e);
                lpvp_parser_free(&p);
                return 0;
            } else if (used == 0) {
                break; /* cannot happen; guards against a loop */
            }
        }
        off += c;
    }
    (void)lpvp_parser_mid_frame(&p);
    lpvp_parser_free(&p);
    return 0;
}
