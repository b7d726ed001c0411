/*
 * test_protocol.c - the wire protocol library (protocol/proto.h,
 * protocol/volume_codec.h) against protocol/SPEC.md: header codec and every
 * header error, the incremental parser (byte by byte, random chunks, several
 * frames per buffer, hostile lengths), bodies and field getters, ERROR
 * frames, binary16 exhaustively, volume packing, XOR deltas, zstd.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zstd.h>

#include "oracle_iv.h"
#include "proto.h"
#include "volume_codec.h"
#include "volume_lookup.h"

/* ---- helpers -------------------------------------------------------------- */

static void make_header(uint8_t out[24], const char *magic, uint16_t version, uint16_t type,
                        uint32_t rid, uint32_t flags, uint32_t jl, uint32_t al)
{
    memcpy(out, magic, 4);
    lpvp_put_u16(out + 4, version);
    lpvp_put_u16(out + 6, type);
    lpvp_put_u32(out + 8, rid);
    lpvp_put_u32(out + 12, flags);
    lpvp_put_u32(out + 16, jl);
    lpvp_put_u32(out + 20, al);
}

static uint32_t rng_state = 12345;
static uint32_t rng(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 17;
    rng_state ^= rng_state << 5;
    return rng_state;
}

/* ---- names and the error table (R3.4) ------------------------------------- */

static void test_names(void **state)
{
    (void)state;
    static const struct {
        int code;
        const char *name;
        int closes;
    } table[] = {
        {1, "BAD_MAGIC", 1},      {2, "BAD_VERSION", 1},    {3, "BAD_FRAME", 1},
        {4, "TOO_LARGE", 1},      {5, "BAD_JSON", 0},       {6, "UNKNOWN_TYPE", 0},
        {7, "BAD_FIELD", 0},      {8, "UNAUTHORIZED", 1},   {9, "HELLO_REQUIRED", 0},
        {10, "NOT_READY", 0},     {11, "SCENE_INVALID", 0}, {12, "PATH_REFUSED", 0},
        {13, "LIMIT", 0},         {14, "INTERNAL", 0},      {15, "SHUTTING_DOWN", 1},
    };
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++) {
        assert_string_equal(lpvp_error_name(table[i].code), table[i].name);
        assert_int_equal(lpvp_error_closes(table[i].code), table[i].closes);
    }
    assert_int_equal(LPVP_E_BAD_MAGIC, 1);
    assert_int_equal(LPVP_E_SHUTTING_DOWN, 15);
    assert_string_equal(lpvp_error_name(0), "UNKNOWN");
    assert_string_equal(lpvp_error_name(16), "UNKNOWN");
    assert_string_equal(lpvp_error_name(-3), "UNKNOWN");
    assert_int_equal(lpvp_error_closes(0), 0);

    assert_string_equal(lpvp_type_name(LPVP_HELLO), "HELLO");
    assert_string_equal(lpvp_type_name(LPVP_QUERY_IRRADIANCE), "QUERY_IRRADIANCE");
    assert_string_equal(lpvp_type_name(LPVP_ACK), "ACK");
    assert_string_equal(lpvp_type_name(LPVP_REPLY(LPVP_HELLO)), "HELLO_REPLY");
    assert_string_equal(lpvp_type_name(LPVP_BYE_REPLY), "BYE_REPLY");
    assert_int_equal(LPVP_BYE_REPLY, 0x800F);
    assert_string_equal(lpvp_type_name(LPVP_VOLUME), "VOLUME");
    assert_string_equal(lpvp_type_name(LPVP_FRAME), "FRAME");
    assert_string_equal(lpvp_type_name(LPVP_ERROR), "ERROR");
    assert_string_equal(lpvp_type_name(0), "UNKNOWN");
    assert_string_equal(lpvp_type_name(0x0011), "UNKNOWN");
    assert_string_equal(lpvp_type_name(0x8010), "UNKNOWN"); /* ACK has no reply */
    assert_string_equal(lpvp_type_name(0x8000), "UNKNOWN");
    for (unsigned t = 0; t < 0x10000; t++) {
        int req = t >= 1 && t <= 0x10;
        assert_int_equal(lpvp_type_is_request((uint16_t)t), req);
        assert_int_equal(lpvp_type_has_reply((uint16_t)t), req && t != 0x10);
        assert_non_null(lpvp_type_name((uint16_t)t));
    }
}

/* ---- header (R2.1-R2.5) --------------------------------------------------- */

static void test_header_roundtrip(void **state)
{
    (void)state;
    lpvp_header h = {1, LPVP_GET_VOLUME, 0xA1B2C3D4u, 0, 1234, 0x01020304u}, d;
    uint8_t b[24];
    int code = -1;
    lpvp_header_encode(&h, b);
    /* Byte layout (R1.3, section 2). */
    static const uint8_t expect[24] = {'L',  'P',  'V',  'D',  1,    0,    0x0B, 0,
                                       0xD4, 0xC3, 0xB2, 0xA1, 0,    0,    0,    0,
                                       0xD2, 0x04, 0,    0,    0x04, 0x03, 0x02, 0x01};
    assert_memory_equal(b, expect, 24);
    assert_int_equal(lpvp_header_decode(b, NULL, &d, &code), 0);
    assert_int_equal(code, LPVP_E_NONE);
    assert_int_equal(d.version, 1);
    assert_int_equal(d.type, LPVP_GET_VOLUME);
    assert_int_equal(d.request_id, 0xA1B2C3D4u);
    assert_int_equal(d.flags, 0);
    assert_int_equal(d.json_length, 1234);
    assert_int_equal(d.attachment_length, 0x01020304u);

    /* The HELLO example of docs/protocol.md. */
    static const char hello[] = "{\"version\":1,\"client\":\"demo\"}";
    size_t n = 0;
    uint8_t *f = lpvp_frame_build(LPVP_HELLO, 1, hello, strlen(hello), NULL, 0, &n);
    static const uint8_t hello_head[24] = {0x4C, 0x50, 0x56, 0x44, 0x01, 0x00, 0x01, 0x00,
                                           0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                                           0x1D, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};
    assert_non_null(f);
    assert_int_equal(n, 24 + 29);
    assert_memory_equal(f, hello_head, 24);
    assert_memory_equal(f + 24, hello, 29);
    free(f);
}

static void expect_header_error(const uint8_t b[24], const lpvp_limits *lim, int want_code,
                                uint32_t want_rid)
{
    lpvp_header h;
    int code = 0;
    char msg[256];
    assert_int_equal(lpvp_header_decode(b, lim, &h, &code), -1);
    assert_int_equal(code, want_code);
    assert_int_equal(h.request_id, want_rid);
    assert_int_equal(lpvp_header_check(b, lim, &h, msg, sizeof msg), want_code);
    assert_true(strlen(msg) > 0);
    assert_true(lpvp_error_closes(code)); /* every header error closes */
}

static void test_header_errors(void **state)
{
    (void)state;
    uint8_t b[24];
    lpvp_header h;
    int code = -1;
    lpvp_limits lim = {100, 1000, 0};

    make_header(b, "LPVX", 1, 1, 7, 0, 2, 0);
    expect_header_error(b, NULL, LPVP_E_BAD_MAGIC, 0); /* R2.2: request_id 0 */
    make_header(b, "lpvd", 1, 1, 7, 0, 2, 0);
    expect_header_error(b, NULL, LPVP_E_BAD_MAGIC, 0);
    make_header(b, "LPVX", 9, 1, 7, 5, 0, 0); /* magic is checked first */
    expect_header_error(b, NULL, LPVP_E_BAD_MAGIC, 0);
    make_header(b, "LPVD", 2, 1, 7, 0, 2, 0);
    expect_header_error(b, NULL, LPVP_E_BAD_VERSION, 7); /* R2.3 */
    make_header(b, "LPVD", 0, 1, 7, 0, 2, 0);
    expect_header_error(b, NULL, LPVP_E_BAD_VERSION, 7);
    make_header(b, "LPVD", 0xFFFF, 1, 7, 1, 0, 0); /* version before flags */
    expect_header_error(b, NULL, LPVP_E_BAD_VERSION, 7);
    make_header(b, "LPVD", 1, 1, 8, 1, 2, 0);
    expect_header_error(b, NULL, LPVP_E_BAD_FRAME, 8); /* R2.4 */
    make_header(b, "LPVD", 1, 1, 8, 0x80000000u, 2, 0);
    expect_header_error(b, NULL, LPVP_E_BAD_FRAME, 8);
    make_header(b, "LPVD", 1, 1, 9, 0, 0, 0);
    expect_header_error(b, NULL, LPVP_E_BAD_FRAME, 9); /* R2.1 */
    make_header(b, "LPVD", 1, 1, 9, 0, 1, 5);
    expect_header_error(b, NULL, LPVP_E_BAD_FRAME, 9);
    make_header(b, "LPVD", 1, 1, 10, 0, (1u << 20) + 1, 0);
    expect_header_error(b, NULL, LPVP_E_TOO_LARGE, 10); /* R2.5, default 1 MiB */
    make_header(b, "LPVD", 1, 1, 10, 0, 0xFFFFFFFFu, 0xFFFFFFFFu);
    expect_header_error(b, NULL, LPVP_E_TOO_LARGE, 10);
    make_header(b, "LPVD", 1, 1, 11, 0, 2, (256u << 20) - 1);
    expect_header_error(b, NULL, LPVP_E_TOO_LARGE, 11); /* 256 MiB + 1 */
    make_header(b, "LPVD", 1, 1, 11, 0, 2, 0xFFFFFFFFu);
    expect_header_error(b, NULL, LPVP_E_TOO_LARGE, 11);

    /* Exactly at the limits is fine. */
    make_header(b, "LPVD", 1, 1, 12, 0, 1u << 20, (256u << 20) - (1u << 20));
    assert_int_equal(lpvp_header_decode(b, NULL, &h, &code), 0);
    assert_int_equal(code, 0);
    make_header(b, "LPVD", 1, 0x7777, 12, 0, 2, 0); /* unknown type: not a header error (R2.8) */
    assert_int_equal(lpvp_header_decode(b, NULL, &h, &code), 0);

    /* Custom limits. */
    make_header(b, "LPVD", 1, 1, 13, 0, 100, 900);
    assert_int_equal(lpvp_header_decode(b, &lim, &h, &code), 0);
    make_header(b, "LPVD", 1, 1, 13, 0, 101, 0);
    expect_header_error(b, &lim, LPVP_E_TOO_LARGE, 13);
    make_header(b, "LPVD", 1, 1, 13, 0, 100, 901);
    expect_header_error(b, &lim, LPVP_E_TOO_LARGE, 13);
    assert_int_equal(lpvp_header_decode(b, &lim, &h, NULL), -1); /* NULL error_code ok */
}

/* ---- parser --------------------------------------------------------------- */

typedef struct {
    lpvp_header h;
    uint8_t *payload;
    size_t len;
} got_frame;

typedef struct {
    got_frame f[64];
    size_t n;
    int status; /* last non-NEED_MORE status, or 0 */
} got_list;

static void got_free(got_list *g)
{
    for (size_t i = 0; i < g->n; i++)
        free(g->f[i].payload);
    g->n = 0;
}

/* Feeds data in chunks of sizes given by chunk(), collecting frames. */
static void feed_all(lpvp_parser *p, const uint8_t *data, size_t len, size_t (*chunk)(size_t),
                     got_list *g)
{
    size_t off = 0;
    while (off < len) {
        size_t c = chunk(len - off);
        size_t in_chunk = 0;
        while (in_chunk < c) {
            size_t used = 0;
            lpvp_frame f;
            int st = lpvp_parser_feed(p, data + off + in_chunk, c - in_chunk, &used, &f);
            assert_true(used <= c - in_chunk);
            in_chunk += used;
            if (st == LPVP_PARSE_FRAME) {
                assert_true(g->n < 64);
                got_frame *gf = &g->f[g->n++];
                gf->h = f.header;
                assert_int_equal(f.body_len, f.header.json_length);
                assert_int_equal(f.attachment_len, f.header.attachment_length);
                gf->len = f.body_len + f.attachment_len;
                gf->payload = malloc(gf->len);
                memcpy(gf->payload, f.body, f.body_len);
                if (f.attachment_len)
                    memcpy(gf->payload + f.body_len, f.attachment, f.attachment_len);
                else
                    assert_null(f.attachment);
            } else if (st == LPVP_PARSE_ERROR) {
                g->status = st;
                return;
            } else {
                assert_int_equal(st, LPVP_PARSE_NEED_MORE);
                assert_int_equal(in_chunk, c);
            }
        }
        off += c;
    }
}

static size_t chunk_all(size_t left) { return left; }
static size_t chunk_one(size_t left) { (void)left; return 1; }
static size_t chunk_random(size_t left)
{
    size_t c = 1 + rng() % ((rng() & 1) ? 7 : 70000);
    return c < left ? c : left;
}

static uint8_t *build_stream(size_t *len, size_t *nframes)
{
    uint8_t *att = malloc(150000);
    uint8_t *stream = NULL;
    size_t total = 0, n = 0;
    for (size_t i = 0; i < 150000; i++)
        att[i] = (uint8_t)(i * 31 + 7);
    for (int k = 0; k < 12; k++) {
        char json[128];
        size_t att_len = (k % 3 == 0) ? 0 : (k % 3 == 1 ? (size_t)k * 5 : 150000 - (size_t)k);
        size_t fl;
        snprintf(json, sizeof json, "{\"k\":%d,\"pad\":\"%.*s\"}", k, k * 4,
                 "xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx");
        uint8_t *f = lpvp_frame_build((uint16_t)(1 + k), (uint32_t)(100 + k), json,
                                      strlen(json), att, att_len, &fl);
        assert_non_null(f);
        stream = realloc(stream, total + fl);
        memcpy(stream + total, f, fl);
        total += fl;
        n++;
        free(f);
    }
    /* The smallest frame: "{}" and nothing else. */
    {
        size_t fl;
        uint8_t *f = lpvp_frame_build(LPVP_TICK, 999, NULL, 0, NULL, 0, &fl);
        assert_int_equal(fl, 26);
        stream = realloc(stream, total + fl);
        memcpy(stream + total, f, fl);
        total += fl;
        n++;
        free(f);
    }
    free(att);
    *len = total;
    *nframes = n;
    return stream;
}

static void compare_got(const got_list *a, const got_list *b)
{
    assert_int_equal(a->n, b->n);
    for (size_t i = 0; i < a->n; i++) {
        assert_memory_equal(&a->f[i].h, &b->f[i].h, sizeof(lpvp_header));
        assert_int_equal(a->f[i].len, b->f[i].len);
        assert_memory_equal(a->f[i].payload, b->f[i].payload, a->f[i].len);
    }
}

static void test_parser_chunks(void **state)
{
    (void)state;
    size_t len, nframes;
    uint8_t *stream = build_stream(&len, &nframes);
    got_list whole = {0}, bytes = {0};
    lpvp_parser p;

    lpvp_parser_init(&p, NULL);
    feed_all(&p, stream, len, chunk_all, &whole);
    assert_int_equal(whole.status, 0);
    assert_int_equal(whole.n, nframes);
    assert_int_equal(p.frames, nframes);
    assert_int_equal(p.bytes, len);
    assert_false(lpvp_parser_mid_frame(&p));
    for (size_t i = 0; i + 1 < nframes; i++) {
        char expect[32];
        assert_int_equal(whole.f[i].h.type, 1 + i);
        assert_int_equal(whole.f[i].h.request_id, 100 + i);
        snprintf(expect, sizeof expect, "{\"k\":%zu,", i);
        assert_memory_equal(whole.f[i].payload, expect, strlen(expect));
    }
    assert_int_equal(whole.f[nframes - 1].h.request_id, 999);
    assert_memory_equal(whole.f[nframes - 1].payload, "{}", 2);
    lpvp_parser_free(&p);

    lpvp_parser_init(&p, NULL);
    feed_all(&p, stream, len, chunk_one, &bytes);
    compare_got(&whole, &bytes);
    got_free(&bytes);
    lpvp_parser_free(&p);

    for (int trial = 0; trial < 40; trial++) {
        got_list r = {0};
        lpvp_parser_init(&p, NULL);
        feed_all(&p, stream, len, chunk_random, &r);
        compare_got(&whole, &r);
        got_free(&r);
        lpvp_parser_free(&p);
    }

    /* Every split point of the first two frames into two feeds. */
    {
        size_t l2 = 0;
        got_list ref = {0};
        for (size_t i = 0; i < 2; i++)
            l2 += 24 + whole.f[i].len;
        lpvp_parser_init(&p, NULL);
        feed_all(&p, stream, l2, chunk_all, &ref);
        lpvp_parser_free(&p);
        assert_int_equal(ref.n, 2);
        for (size_t cut = 0; cut <= l2; cut++) {
            got_list r = {0};
            lpvp_parser_init(&p, NULL);
            feed_all(&p, stream, cut, chunk_all, &r);
            assert_int_equal(lpvp_parser_mid_frame(&p),
                             cut != 0 && cut != 24 + whole.f[0].len && cut != l2);
            feed_all(&p, stream + cut, l2 - cut, chunk_all, &r);
            compare_got(&ref, &r);
            got_free(&r);
            lpvp_parser_free(&p);
        }
        got_free(&ref);
    }
    got_free(&whole);
    free(stream);
}

static void test_parser_several_in_one_buffer(void **state)
{
    (void)state;
    size_t l1, l2, l3;
    uint8_t *a = lpvp_frame_build(LPVP_HELLO, 1, "{\"version\":1}", 13, NULL, 0, &l1);
    uint8_t *b = lpvp_frame_build(LPVP_QUERY_IRRADIANCE, 2, "{\"count\":1}", 11, "012345678901234567890123", 24, &l2);
    uint8_t *c = lpvp_frame_build(LPVP_BYE, 3, NULL, 0, NULL, 0, &l3);
    uint8_t buf[512];
    size_t used;
    lpvp_frame f;
    lpvp_parser p;
    memcpy(buf, a, l1);
    memcpy(buf + l1, b, l2);
    memcpy(buf + l1 + l2, c, l3);
    lpvp_parser_init(&p, NULL);
    assert_int_equal(lpvp_parser_feed(&p, buf, l1 + l2 + l3, &used, &f), LPVP_PARSE_FRAME);
    assert_int_equal(used, l1);
    assert_int_equal(f.header.type, LPVP_HELLO);
    assert_true(f.body == (const char *)buf + 24); /* zero copy */
    assert_null(f.attachment);
    assert_int_equal(lpvp_parser_feed(&p, buf + l1, l2 + l3, &used, &f), LPVP_PARSE_FRAME);
    assert_int_equal(used, l2);
    assert_int_equal(f.header.request_id, 2);
    assert_int_equal(f.attachment_len, 24);
    assert_memory_equal(f.attachment, "012345678901234567890123", 24);
    assert_int_equal(lpvp_parser_feed(&p, buf + l1 + l2, l3, &used, &f), LPVP_PARSE_FRAME);
    assert_int_equal(used, l3);
    assert_int_equal(f.header.type, LPVP_BYE);
    assert_int_equal(lpvp_parser_feed(&p, buf, 0, &used, &f), LPVP_PARSE_NEED_MORE);
    assert_int_equal(used, 0);
    /* Header in one feed, the whole payload in the next: also zero copy. */
    assert_int_equal(lpvp_parser_feed(&p, buf + l1, 24, &used, &f), LPVP_PARSE_NEED_MORE);
    assert_int_equal(lpvp_parser_feed(&p, buf + l1 + 24, l2 - 24 + l3, &used, &f),
                     LPVP_PARSE_FRAME);
    assert_int_equal(used, l2 - 24);
    assert_true(f.body == (const char *)buf + l1 + 24);
    assert_true(f.attachment == buf + l1 + 24 + 11);
    assert_null(p.buf);
    lpvp_parser_free(&p);
    free(a);
    free(b);
    free(c);
}

static void test_parser_hostile(void **state)
{
    (void)state;
    uint8_t b[64];
    size_t used;
    lpvp_frame f;
    lpvp_parser p;

    /* 0xFFFFFFFF lengths: TOO_LARGE from the header alone, nothing allocated. */
    make_header(b, "LPVD", 1, 1, 42, 0, 0xFFFFFFFFu, 0xFFFFFFFFu);
    memset(b + 24, 'x', 40);
    lpvp_parser_init(&p, NULL);
    assert_int_equal(lpvp_parser_feed(&p, b, 64, &used, &f), LPVP_PARSE_ERROR);
    assert_int_equal(used, 24); /* the body is not read (R2.5) */
    assert_int_equal(p.error_code, LPVP_E_TOO_LARGE);
    assert_int_equal(p.error_request_id, 42);
    assert_true(strstr(p.error_message, "4294967295") != NULL);
    assert_null(p.buf);
    assert_int_equal(p.buf_cap, 0);
    /* Stays failed. */
    assert_int_equal(lpvp_parser_feed(&p, b, 64, &used, &f), LPVP_PARSE_ERROR);
    assert_int_equal(used, 0);
    lpvp_parser_free(&p);

    make_header(b, "LPVD", 1, 1, 43, 0, 2, 0xFFFFFFFFu);
    lpvp_parser_init(&p, NULL);
    assert_int_equal(lpvp_parser_feed(&p, b, 24, &used, &f), LPVP_PARSE_ERROR);
    assert_int_equal(p.error_code, LPVP_E_TOO_LARGE);
    assert_null(p.buf);
    lpvp_parser_free(&p);

    /* A promise within the limits followed by a trickle: memory follows the
     * bytes received, not the promise. */
    make_header(b, "LPVD", 1, 1, 44, 0, 1u << 20, (200u << 20));
    lpvp_parser_init(&p, NULL);
    assert_int_equal(lpvp_parser_feed(&p, b, 24 + 40, &used, &f), LPVP_PARSE_NEED_MORE);
    assert_int_equal(used, 64);
    assert_true(p.buf_cap <= 4096);
    assert_true(lpvp_parser_mid_frame(&p));
    {
        static uint8_t junk[100000];
        for (int i = 0; i < 10; i++)
            assert_int_equal(lpvp_parser_feed(&p, junk, sizeof junk, &used, &f),
                             LPVP_PARSE_NEED_MORE);
        assert_true(p.buf_cap <= 2 * (40 + 10 * sizeof junk));
    }
    lpvp_parser_free(&p);

    /* Bad magic is caught at the first wrong byte (R2.2). */
    lpvp_parser_init(&p, NULL);
    assert_int_equal(lpvp_parser_feed(&p, "GET / HTTP/1.1\r\n", 16, &used, &f), LPVP_PARSE_ERROR);
    assert_int_equal(used, 1);
    assert_int_equal(p.error_code, LPVP_E_BAD_MAGIC);
    assert_int_equal(p.error_request_id, 0);
    lpvp_parser_free(&p);
    lpvp_parser_init(&p, NULL);
    assert_int_equal(lpvp_parser_feed(&p, "LP", 2, &used, &f), LPVP_PARSE_NEED_MORE);
    assert_int_equal(lpvp_parser_feed(&p, "VX", 2, &used, &f), LPVP_PARSE_ERROR);
    assert_int_equal(used, 2);
    assert_int_equal(p.error_code, LPVP_E_BAD_MAGIC);
    lpvp_parser_free(&p);

    /* Header errors through the parser carry the frame's request_id. */
    struct {
        uint16_t version;
        uint32_t flags, jl;
        int code;
    } cases[] = {{2, 0, 2, LPVP_E_BAD_VERSION}, {1, 4, 2, LPVP_E_BAD_FRAME},
                 {1, 0, 1, LPVP_E_BAD_FRAME}, {1, 0, (1u << 20) + 1, LPVP_E_TOO_LARGE}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        make_header(b, "LPVD", cases[i].version, 3, 77, cases[i].flags, cases[i].jl, 0);
        lpvp_parser_init(&p, NULL);
        for (size_t k = 0; k < 23; k++)
            assert_int_equal(lpvp_parser_feed(&p, b + k, 1, &used, &f), LPVP_PARSE_NEED_MORE);
        assert_int_equal(lpvp_parser_feed(&p, b + 23, 1, &used, &f), LPVP_PARSE_ERROR);
        assert_int_equal(p.error_code, cases[i].code);
        assert_int_equal(p.error_request_id, 77);
        assert_true(strlen(p.error_message) > 0);
        lpvp_parser_free(&p);
    }

    /* Custom limits reach the parser. */
    {
        lpvp_limits lim = {16, 64, 0};
        make_header(b, "LPVD", 1, 3, 5, 0, 17, 0);
        lpvp_parser_init(&p, &lim);
        assert_int_equal(lpvp_parser_feed(&p, b, 24, &used, &f), LPVP_PARSE_ERROR);
        assert_int_equal(p.error_code, LPVP_E_TOO_LARGE);
        lpvp_parser_free(&p);
    }

    /* R2.5a: with no_attachment (a server before HELLO) any attachment is
     * refused from the header alone, however small; a frame without one
     * passes. */
    {
        lpvp_limits lim = {4096, 4096, 1};
        make_header(b, "LPVD", 1, 1, 6, 0, 2, 1);
        lpvp_parser_init(&p, &lim);
        assert_int_equal(lpvp_parser_feed(&p, b, 24, &used, &f), LPVP_PARSE_ERROR);
        assert_int_equal(used, 24);
        assert_int_equal(p.error_code, LPVP_E_TOO_LARGE);
        assert_int_equal(p.error_request_id, 6);
        assert_non_null(strstr(p.error_message, "attachment_length 1"));
        lpvp_parser_free(&p);
        uint8_t fr[26];
        make_header(fr, "LPVD", 1, 1, 7, 0, 2, 0);
        memcpy(fr + 24, "{}", 2);
        lpvp_parser_init(&p, &lim);
        assert_int_equal(lpvp_parser_feed(&p, fr, sizeof fr, &used, &f), LPVP_PARSE_FRAME);
        lpvp_parser_free(&p);
    }

    /* Random garbage never crashes and always ends in an error or waits. */
    for (int trial = 0; trial < 2000; trial++) {
        uint8_t g[200];
        size_t n = rng() % sizeof g, off = 0;
        for (size_t i = 0; i < n; i++)
            g[i] = (uint8_t)rng();
        if (trial & 1)
            memcpy(g, "LPVD\x01\x00", n < 6 ? n : 6);
        lpvp_parser_init(&p, NULL);
        while (off < n) {
            int st = lpvp_parser_feed(&p, g + off, n - off, &used, &f);
            off += used;
            if (st == LPVP_PARSE_ERROR) {
                assert_true(p.error_code >= 1 && p.error_code <= 4);
                break;
            }
        }
        lpvp_parser_free(&p);
    }
}

/* ---- bodies and fields (R2.7, R2.9) --------------------------------------- */

static void expect_bad_body(const char *body, size_t len)
{
    char err[256] = "";
    json_t *j = lpvp_body_parse(body, len, err, sizeof err);
    assert_null(j);
    assert_true(strlen(err) > 0);
}

static void test_body_parse(void **state)
{
    (void)state;
    char err[256];
    json_t *j = lpvp_body_parse("{}", 2, err, sizeof err);
    assert_non_null(j);
    assert_true(json_is_object(j));
    json_decref(j);
    j = lpvp_body_parse("{\"a\":[1,2,{\"b\":\"\xc3\xa9\"}]}xxx", 22, err, sizeof err);
    assert_non_null(j); /* length-bounded: bytes after len are not read */
    json_decref(j);

    expect_bad_body("{", 1);
    expect_bad_body("", 0);
    expect_bad_body("{\"a\":}", 6);
    expect_bad_body("[1,2]", 5);
    expect_bad_body("\"str\"", 5);
    expect_bad_body("42", 2);
    expect_bad_body("null", 4);
    expect_bad_body("{} {}", 5);                    /* trailing data */
    expect_bad_body("{\"a\":\"\xff\"}", 9);          /* invalid UTF-8 */
    expect_bad_body("{\"a\":\"\xc3\"}", 9);          /* truncated UTF-8 */
    expect_bad_body("{\"\xed\xa0\x80\":1}", 9);      /* surrogate in UTF-8 */
    expect_bad_body("{\"a\":\"\\u0000\"}", 14);      /* NUL */
    expect_bad_body("{\"a\":1,\"a\":2}", 13);        /* duplicate key */
    expect_bad_body("{\"a\":NaN}", 9);              /* no NaN in JSON */
    expect_bad_body("{\"a\":Infinity}", 14);
    expect_bad_body("{\"a\":1e400}", 11);           /* overflows double */
    expect_bad_body("{\"a\":\0}", 7);
    lpvp_body_parse("[]", 2, err, sizeof err);
    assert_true(strstr(err, "object") != NULL);
    {
        /* Deep nesting is refused, not a stack overflow. */
        size_t n = 100000;
        char *deep = malloc(n);
        deep[0] = '{';
        deep[1] = '"';
        deep[2] = 'a';
        deep[3] = '"';
        deep[4] = ':';
        for (size_t i = 5; i < n; i++)
            deep[i] = '[';
        expect_bad_body(deep, n);
        free(deep);
    }
}

static void test_field_getters(void **state)
{
    (void)state;
    char err[256];
    const char *body =
        "{\"i\": 42, \"neg\": -5, \"r\": 512.0, \"half\": 1.5, \"big\": 1e300, \"s\": \"hello\","
        " \"t\": true, \"f\": false, \"z\": null, \"eye\": [1, 2.5, -3], \"bad3\": [1, \"x\", 3],"
        " \"two\": [1, 2], \"grid\": [32, 32, 16], \"o\": {\"x\": 1}, \"arr\": [1,2,3,4],"
        " \"fmt\": \"fp32\", \"huge\": 1e39, \"tiny\": 1e-300, \"zero\": 0.0, \"mat\": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}";
    json_t *j = lpvp_body_parse(body, strlen(body), err, sizeof err);
    assert_non_null(j);

    int64_t i = -1;
    assert_int_equal(lpvp_get_int(j, "i", 1, 0, 100, &i, err, sizeof err), LPVP_FIELD_OK);
    assert_int_equal(i, 42);
    assert_int_equal(lpvp_get_int(j, "i", 1, 0, 10, &i, err, sizeof err), LPVP_FIELD_BAD);
    assert_true(strstr(err, "i:") == err && strstr(err, "range"));
    assert_int_equal(i, 42); /* untouched on BAD */
    assert_int_equal(lpvp_get_int(j, "neg", 1, 0, 10, &i, err, sizeof err), LPVP_FIELD_BAD);
    /* 512.0 is a JSON number, not a JSON integer (R4.11; issue 14): refused, naming the key */
    assert_int_equal(lpvp_get_int(j, "r", 1, 0, 1000, &i, err, sizeof err), LPVP_FIELD_BAD);
    assert_true(strstr(err, "r: expected an integer") == err && strstr(err, "512"));
    assert_int_equal(i, 42); /* untouched on BAD */
    assert_int_equal(lpvp_get_int(j, "half", 1, 0, 1000, &i, err, sizeof err), LPVP_FIELD_BAD);
    assert_true(strstr(err, "half") && strstr(err, "integer"));
    assert_int_equal(lpvp_get_int(j, "big", 1, 0, 1000, &i, err, sizeof err), LPVP_FIELD_BAD);
    assert_int_equal(lpvp_get_int(j, "s", 1, 0, 1000, &i, err, sizeof err), LPVP_FIELD_BAD);
    assert_true(strstr(err, "s: expected an integer, got a string") != NULL);
    assert_int_equal(lpvp_get_int(j, "z", 0, 0, 1000, &i, err, sizeof err), LPVP_FIELD_BAD);
    assert_true(strstr(err, "null") != NULL);
    i = 7;
    assert_int_equal(lpvp_get_int(j, "missing", 0, 0, 1000, &i, err, sizeof err),
                     LPVP_FIELD_ABSENT);
    assert_int_equal(i, 7);
    assert_int_equal(lpvp_get_int(j, "missing", 1, 0, 1000, &i, err, sizeof err),
                     LPVP_FIELD_BAD);
    assert_true(strstr(err, "missing") && strstr(err, "required"));

    double d = 0;
    assert_int_equal(lpvp_get_number(j, "half", 1, 0, 2, &d, err, sizeof err), LPVP_FIELD_OK);
    assert_true(d == 1.5);
    assert_int_equal(lpvp_get_number(j, "i", 1, 0, 100, &d, err, sizeof err), LPVP_FIELD_OK);
    assert_true(d == 42.0);
    assert_int_equal(lpvp_get_number(j, "big", 1, 0, 1e10, &d, err, sizeof err),
                     LPVP_FIELD_BAD);
    assert_int_equal(lpvp_get_number(j, "t", 1, 0, 1, &d, err, sizeof err), LPVP_FIELD_BAD);
    assert_true(strstr(err, "t: expected a number, got a boolean") != NULL);
    float fl = 0;
    assert_int_equal(lpvp_get_float(j, "half", 1, 0, 2, &fl, err, sizeof err), LPVP_FIELD_OK);
    assert_true(fl == 1.5f);
    assert_int_equal(lpvp_get_float(j, "huge", 1, -1e300, 1e300, &fl, err, sizeof err),
                     LPVP_FIELD_BAD);
    /* a light's range 1e-300 became 0, "unlimited" (issue 31, item 12) */
    assert_int_equal(lpvp_get_float(j, "tiny", 1, 0, 1e9, &fl, err, sizeof err), LPVP_FIELD_BAD);
    assert_non_null(strstr(err, "tiny: 1e-300 is too small"));
    assert_int_equal(lpvp_get_float(j, "zero", 1, 0, 1e9, &fl, err, sizeof err), LPVP_FIELD_OK);
    assert_true(fl == 0.0f);

    int b = -1;
    assert_int_equal(lpvp_get_bool(j, "t", 1, &b, err, sizeof err), LPVP_FIELD_OK);
    assert_int_equal(b, 1);
    assert_int_equal(lpvp_get_bool(j, "f", 1, &b, err, sizeof err), LPVP_FIELD_OK);
    assert_int_equal(b, 0);
    assert_int_equal(lpvp_get_bool(j, "i", 1, &b, err, sizeof err), LPVP_FIELD_BAD);
    assert_true(strstr(err, "i:") == err);

    const char *s = NULL;
    size_t sl = 0;
    assert_int_equal(lpvp_get_string(j, "s", 1, 5, &s, &sl, err, sizeof err), LPVP_FIELD_OK);
    assert_string_equal(s, "hello");
    assert_int_equal(sl, 5);
    assert_int_equal(lpvp_get_string(j, "s", 1, 4, &s, NULL, err, sizeof err), LPVP_FIELD_BAD);
    assert_true(strstr(err, "longer") != NULL);
    assert_int_equal(lpvp_get_string(j, "i", 1, 4, &s, NULL, err, sizeof err), LPVP_FIELD_BAD);

    static const char *const fmts[] = {"fp16", "fp32"};
    int e = -1;
    assert_int_equal(lpvp_get_enum(j, "fmt", 1, fmts, 2, &e, err, sizeof err), LPVP_FIELD_OK);
    assert_int_equal(e, 1);
    assert_int_equal(lpvp_get_enum(j, "s", 1, fmts, 2, &e, err, sizeof err), LPVP_FIELD_BAD);
    assert_string_equal(err, "s: expected one of \"fp16\", \"fp32\"");
    assert_int_equal(lpvp_get_enum(j, "i", 1, fmts, 2, &e, err, sizeof err), LPVP_FIELD_BAD);

    double v3[3];
    float f3[3], m16[16];
    assert_int_equal(lpvp_get_numbers(j, "eye", 1, 3, -10, 10, v3, err, sizeof err),
                     LPVP_FIELD_OK);
    assert_true(v3[0] == 1 && v3[1] == 2.5 && v3[2] == -3);
    assert_int_equal(lpvp_get_floats(j, "eye", 1, 3, -10, 10, f3, err, sizeof err),
                     LPVP_FIELD_OK);
    assert_true(f3[1] == 2.5f);
    assert_int_equal(lpvp_get_numbers(j, "eye", 1, 3, 0, 10, v3, err, sizeof err),
                     LPVP_FIELD_BAD);
    assert_true(strstr(err, "eye[2]") == err);
    assert_int_equal(lpvp_get_floats(j, "bad3", 1, 3, -10, 10, f3, err, sizeof err),
                     LPVP_FIELD_BAD);
    assert_true(strstr(err, "bad3[1]: expected a number, got a string") != NULL);
    assert_int_equal(lpvp_get_floats(j, "two", 1, 3, -10, 10, f3, err, sizeof err),
                     LPVP_FIELD_BAD);
    assert_true(strstr(err, "two") && strstr(err, "3"));
    assert_int_equal(lpvp_get_floats(j, "i", 1, 3, -10, 10, f3, err, sizeof err),
                     LPVP_FIELD_BAD);
    assert_int_equal(lpvp_get_floats(j, "nope", 0, 3, -10, 10, f3, err, sizeof err),
                     LPVP_FIELD_ABSENT);
    assert_int_equal(lpvp_get_floats(j, "nope", 1, 3, -10, 10, f3, err, sizeof err),
                     LPVP_FIELD_BAD);
    assert_int_equal(lpvp_get_floats(j, "mat", 1, 16, -1e30, 1e30, m16, err, sizeof err),
                     LPVP_FIELD_OK);
    assert_true(m16[0] == 1 && m16[5] == 1 && m16[15] == 1 && m16[1] == 0);
    assert_int_equal(lpvp_get_floats(j, "arr", 1, 4, -1e30, 1e30, m16, err, sizeof err),
                     LPVP_FIELD_OK);

    int64_t g3[3];
    assert_int_equal(lpvp_get_ints(j, "grid", 1, 3, 1, 256, g3, err, sizeof err), LPVP_FIELD_OK);
    assert_true(g3[0] == 32 && g3[2] == 16);
    assert_int_equal(lpvp_get_ints(j, "grid", 1, 3, 1, 16, g3, err, sizeof err), LPVP_FIELD_BAD);
    assert_true(strstr(err, "grid[0]") == err);
    assert_int_equal(lpvp_get_ints(j, "eye", 1, 3, -10, 10, g3, err, sizeof err),
                     LPVP_FIELD_BAD);
    assert_true(strstr(err, "eye[1]") == err);

    const json_t *o = NULL, *a = NULL;
    assert_int_equal(lpvp_get_object(j, "o", 1, &o, err, sizeof err), LPVP_FIELD_OK);
    assert_int_equal(lpvp_get_int(o, "x", 1, 0, 5, &i, err, sizeof err), LPVP_FIELD_OK);
    assert_int_equal(lpvp_get_int(o, "y", 1, 0, 5, &i, err, sizeof err), LPVP_FIELD_BAD);
    lpvp_err_prefix(err, sizeof err, "nodes[%d].", 3);
    assert_string_equal(err, "nodes[3].y: missing required field");
    assert_int_equal(lpvp_get_object(j, "arr", 1, &o, err, sizeof err), LPVP_FIELD_BAD);
    assert_int_equal(lpvp_get_array(j, "arr", 1, 4, &a, err, sizeof err), LPVP_FIELD_OK);
    assert_int_equal(json_array_size(a), 4);
    assert_int_equal(lpvp_get_array(j, "arr", 1, 3, &a, err, sizeof err), LPVP_FIELD_BAD);
    assert_int_equal(lpvp_get_array(j, "o", 1, 3, &a, err, sizeof err), LPVP_FIELD_BAD);

    /* A non-object "obj" is treated as absent. */
    assert_int_equal(lpvp_get_int(a, "x", 0, 0, 5, &i, err, sizeof err), LPVP_FIELD_ABSENT);
    /* Tiny and NULL error buffers are safe. */
    assert_int_equal(lpvp_get_int(j, "s", 1, 0, 5, &i, err, 4), LPVP_FIELD_BAD);
    assert_int_equal(strlen(err), 3);
    assert_int_equal(lpvp_get_int(j, "s", 1, 0, 5, &i, NULL, 0), LPVP_FIELD_BAD);
    {
        char small[8] = "abc";
        lpvp_err_prefix(small, sizeof small, "0123456789");
        assert_string_equal(small, "0123456");
        strcpy(small, "abcdef");
        lpvp_err_prefix(small, sizeof small, "xy");
        assert_string_equal(small, "xyabcde");
    }
    json_decref(j);
}

/* ---- building and ERROR frames (R3.4) ------------------------------------- */

static void test_error_frame(void **state)
{
    (void)state;
    size_t n, used;
    lpvp_parser p;
    lpvp_frame f;
    char err[128];
    uint8_t *e = lpvp_error_build(17, LPVP_E_BAD_FIELD, &n, "eye: expected %d numbers", 3);
    assert_non_null(e);
    lpvp_parser_init(&p, NULL);
    assert_int_equal(lpvp_parser_feed(&p, e, n, &used, &f), LPVP_PARSE_FRAME);
    assert_int_equal(used, n);
    assert_int_equal(f.header.type, LPVP_ERROR);
    assert_int_equal(f.header.type, 0xFFFF);
    assert_int_equal(f.header.request_id, 17);
    assert_int_equal(f.attachment_len, 0);
    json_t *j = lpvp_body_parse(f.body, f.body_len, err, sizeof err);
    assert_non_null(j);
    assert_int_equal(json_integer_value(json_object_get(j, "code")), 7);
    assert_string_equal(json_string_value(json_object_get(j, "name")), "BAD_FIELD");
    assert_string_equal(json_string_value(json_object_get(j, "message")),
                        "eye: expected 3 numbers");
    assert_null(json_object_get(j, "versions"));
    json_decref(j);
    free(e);

    e = lpvp_error_build(5, LPVP_E_BAD_VERSION, &n, "version %d not spoken", 9);
    assert_int_equal(lpvp_parser_feed(&p, e, n, &used, &f), LPVP_PARSE_FRAME);
    j = lpvp_body_parse(f.body, f.body_len, err, sizeof err);
    assert_non_null(j);
    assert_int_equal(json_integer_value(json_object_get(j, "code")), 2);
    json_t *v = json_object_get(j, "versions");
    assert_true(json_is_array(v) && json_array_size(v) == 1);
    assert_int_equal(json_integer_value(json_array_get(v, 0)), 1);
    json_decref(j);
    free(e);

    /* Invalid UTF-8 in a message never breaks the frame. */
    e = lpvp_error_build(0, LPVP_E_SCENE_INVALID, &n, "bad name %s", "\xff\xfe");
    assert_non_null(e);
    assert_int_equal(lpvp_parser_feed(&p, e, n, &used, &f), LPVP_PARSE_FRAME);
    j = lpvp_body_parse(f.body, f.body_len, err, sizeof err);
    assert_non_null(j);
    assert_string_equal(json_string_value(json_object_get(j, "name")), "SCENE_INVALID");
    json_decref(j);
    free(e);

    /* lpvp_error_body + extra fields, lpvp_frame_build_json. */
    j = lpvp_error_body(LPVP_E_LIMIT, "grid %d > %d", 512, 256);
    json_object_set_new(j, "limit", json_integer(256));
    e = lpvp_frame_build_json(LPVP_ERROR, 9, j, NULL, 0, &n);
    json_decref(j);
    assert_int_equal(lpvp_parser_feed(&p, e, n, &used, &f), LPVP_PARSE_FRAME);
    j = lpvp_body_parse(f.body, f.body_len, err, sizeof err);
    assert_int_equal(json_integer_value(json_object_get(j, "limit")), 256);
    assert_string_equal(json_string_value(json_object_get(j, "message")), "grid 512 > 256");
    json_decref(j);
    free(e);

    /* build_json refuses a non-object; NULL body is {}. */
    j = json_array();
    assert_null(lpvp_frame_build_json(LPVP_TICK, 1, j, NULL, 0, &n));
    json_decref(j);
    e = lpvp_frame_build_json(LPVP_TICK, 1, NULL, "ab", 2, &n);
    assert_int_equal(n, 28);
    assert_memory_equal(e + 24, "{}ab", 4);
    free(e);

    /* build_head: header + json with attachment_length for writev. */
    e = lpvp_frame_build_head(LPVP_REPLY(LPVP_GET_VOLUME), 3, "{\"a\":1}", 7, 1000, &n);
    assert_int_equal(n, 31);
    assert_int_equal(lpvp_get_u32(e + 20), 1000);
    assert_int_equal(lpvp_get_u16(e + 6), 0x800B);
    free(e);
    lpvp_parser_free(&p);
}

/* ---- binary16 (R5.4), exhaustively ---------------------------------------- */

/* Reference decoding through ldexp. */
static double ref_half_value(uint16_t h)
{
    int e = (h >> 10) & 31, m = h & 1023;
    double s = (h & 0x8000) ? -1.0 : 1.0;
    if (e == 0)
        return s * ldexp(m, -24);
    if (e == 31)
        return m ? NAN : s * INFINITY;
    return s * ldexp(1024 + m, e - 25);
}

/* Reference encoding: round to nearest even with nearbyint in double, then
 * clamp, then find the bits by decoding candidates. */
static double ref_round_to_half(float f)
{
    double a = fabs((double)f), r;
    if (isnan(f))
        return 0.0;
    if (a >= 65504.0)
        r = 65504.0;
    else if (a < ldexp(1, -14))
        r = ldexp(nearbyint(ldexp(a, 24)), -24);
    else {
        int e;
        frexp(a, &e); /* a = x * 2^e, x in [0.5, 1) */
        r = ldexp(nearbyint(ldexp(a, 11 - e)), e - 11);
        if (r > 65504.0)
            r = 65504.0;
    }
    return signbit(f) ? -r : r;
}

static void check_f32(float f)
{
    uint16_t h = lpvp_f32_to_f16(f);
    double want = ref_round_to_half(f);
    double got = ref_half_value(h);
    if (got != want || (want == 0.0 && !isnan(f) && signbit(got) != signbit(want)) ||
        (isnan(f) && h != 0)) {
        uint32_t u;
        memcpy(&u, &f, 4);
        fail_msg("f32 0x%08x (%.9g) -> half 0x%04x (%.9g), want %.9g", u, (double)f, h, got,
                 want);
    }
    assert_true(((h >> 10) & 31) != 31); /* never Inf or NaN */
}

static void test_fp16_decode_all(void **state)
{
    (void)state;
    for (uint32_t h = 0; h < 65536; h++) {
        float f = lpvp_f16_to_f32((uint16_t)h);
        double want = ref_half_value((uint16_t)h);
        if (isnan(want)) {
            assert_true(isnan(f));
            continue;
        }
        assert_true((double)f == want);
        assert_int_equal(signbit(f) != 0, (h & 0x8000) != 0);
        /* Round trip: every finite half survives; Inf clamps to 65504. */
        uint16_t back = lpvp_f32_to_f16(f);
        if (((h >> 10) & 31) == 31)
            assert_int_equal(back, (h & 0x8000) | 0x7BFF);
        else
            assert_int_equal(back, h);
    }
}

static float next_up(float f) { return nextafterf(f, INFINITY); }
static float next_down(float f) { return nextafterf(f, -INFINITY); }

static void test_fp16_rounding(void **state)
{
    (void)state;
    /* Ties and neighbours: between every pair of adjacent positive halves
     * (including subnormals and zero) the midpoint rounds to the even one,
     * one float ulp either side to the nearer. */
    for (uint16_t h = 0; h < 0x7BFF; h++) {
        double lo = ref_half_value(h), hi = ref_half_value((uint16_t)(h + 1));
        float mid = (float)((lo + hi) / 2); /* exact in float */
        assert_true((double)mid == (lo + hi) / 2);
        uint16_t even = (h & 1) ? (uint16_t)(h + 1) : h;
        assert_int_equal(lpvp_f32_to_f16(mid), even);
        assert_int_equal(lpvp_f32_to_f16(-mid), even | 0x8000);
        assert_int_equal(lpvp_f32_to_f16(next_down(mid)), h);
        assert_int_equal(lpvp_f32_to_f16(next_up(mid)), h + 1);
        check_f32(mid);
        check_f32(next_down(mid));
        check_f32(next_up(mid));
        check_f32(-next_up(mid));
    }
    /* Overflow: clamped, never Inf (R5.4). */
    assert_int_equal(lpvp_f32_to_f16(65504.0f), 0x7BFF);
    assert_int_equal(lpvp_f32_to_f16(65519.996f), 0x7BFF);
    assert_int_equal(lpvp_f32_to_f16(65520.0f), 0x7BFF); /* would be Inf in plain RNE */
    assert_int_equal(lpvp_f32_to_f16(1e30f), 0x7BFF);
    assert_int_equal(lpvp_f32_to_f16(-1e30f), 0xFBFF);
    assert_int_equal(lpvp_f32_to_f16(INFINITY), 0x7BFF);
    assert_int_equal(lpvp_f32_to_f16(-INFINITY), 0xFBFF);
    assert_int_equal(lpvp_f32_to_f16(NAN), 0);
    assert_int_equal(lpvp_f32_to_f16(-NAN), 0);
    /* Subnormals and underflow. */
    assert_int_equal(lpvp_f32_to_f16(ldexpf(1, -24)), 0x0001);
    assert_int_equal(lpvp_f32_to_f16(ldexpf(1, -25)), 0x0000); /* tie to even: 0 */
    assert_int_equal(lpvp_f32_to_f16(next_up(ldexpf(1, -25))), 0x0001);
    assert_int_equal(lpvp_f32_to_f16(ldexpf(3, -25)), 0x0002); /* 1.5 ulp: tie to even 2 */
    assert_int_equal(lpvp_f32_to_f16(-ldexpf(1, -26)), 0x8000);
    assert_int_equal(lpvp_f32_to_f16(ldexpf(1, -14)), 0x0400);
    assert_int_equal(lpvp_f32_to_f16(ldexpf(1023, -24)), 0x03FF);
    assert_int_equal(lpvp_f32_to_f16(1e-30f), 0);
    assert_int_equal(lpvp_f32_to_f16(-0.0f), 0x8000);
    assert_int_equal(lpvp_f32_to_f16(1.0f), 0x3C00);
    assert_int_equal(lpvp_f32_to_f16(-2.0f), 0xC000);
    assert_int_equal(lpvp_f32_to_f16(0.1f), 0x2E66);
    assert_int_equal(lpvp_f32_to_f16(1.0f + ldexpf(1, -11)), 0x3C00); /* tie down to even */
    assert_int_equal(lpvp_f32_to_f16(1.0f + 3 * ldexpf(1, -11)), 0x3C02); /* tie up to even */
}

static void test_fp16_many_floats(void **state)
{
    (void)state;
    /* Every 61st float bit pattern (~70 M), both signs, NaNs and Infs
     * included, against the reference. */
    for (uint64_t u = 0; u <= 0xFFFFFFFFu; u += 61) {
        uint32_t b32 = (uint32_t)u;
        float f;
        memcpy(&f, &b32, 4);
        check_f32(f);
    }
    /* And every float in the binades that matter most (2^-26 .. 2^-13 and
     * 2^15 .. 2^17), exhaustively. */
    for (uint32_t b32 = 0x32800000u; b32 < 0x39000000u; b32 += 3) {
        float f;
        memcpy(&f, &b32, 4);
        check_f32(f);
    }
    for (uint32_t b32 = 0x47000000u; b32 < 0x48000000u; b32++) {
        float f;
        memcpy(&f, &b32, 4);
        check_f32(f);
    }
}

/* ---- volumes (R5.1, R5.3) ------------------------------------------------- */

static void test_volume_pack(void **state)
{
    (void)state;
    const size_t cells = 1000;
    float *v = malloc(cells * 12 * sizeof(float));
    float *back = malloc(cells * 12 * sizeof(float));
    uint8_t *raw16 = malloc(lpvp_volume_raw_size(cells, LPVP_FMT_FP16));
    uint8_t *raw32 = malloc(lpvp_volume_raw_size(cells, LPVP_FMT_FP32));
    assert_int_equal(lpvp_volume_raw_size(cells, LPVP_FMT_FP16), cells * 24);
    assert_int_equal(lpvp_volume_raw_size(cells, LPVP_FMT_FP32), cells * 48);
    assert_int_equal(lpvp_volume_raw_size((size_t)-1 / 4, LPVP_FMT_FP32), 0);
    for (size_t i = 0; i < cells * 12; i++) {
        uint32_t r = rng();
        v[i] = ldexpf((float)(r & 0xFFFFF) / 1048576.0f, (int)(r >> 26) - 40) *
               ((r & 0x100000) ? -1.0f : 1.0f);
    }
    v[0] = 1.0f;  /* r0 of cell 0 */
    v[1] = -2.0f; /* r1 (y) */
    v[4] = 0.5f;  /* g0 */
    v[5] = NAN;
    v[6] = INFINITY;
    v[7] = 1e9f;

    lpvp_volume_pack(v, cells, LPVP_FMT_FP32, raw32);
    assert_memory_equal(raw32, "\x00\x00\x80\x3f\x00\x00\x00\xc0", 8); /* LE binary32 */
    lpvp_volume_unpack(raw32, cells, LPVP_FMT_FP32, back);
    assert_true(back[5] == 0.0f); /* NaN never sent */
    assert_true(back[6] == INFINITY);
    for (size_t i = 0; i < cells * 12; i++)
        if (i != 5)
            assert_true(memcmp(&back[i], &v[i], 4) == 0);

    lpvp_volume_pack(v, cells, LPVP_FMT_FP16, raw16);
    assert_memory_equal(raw16, "\x00\x3c\x00\xc0", 4); /* 1.0 = 0x3C00, -2.0 = 0xC000 LE */
    assert_memory_equal(raw16 + 8, "\x00\x38", 2);     /* g0 = 0.5 at value 4 */
    lpvp_volume_unpack(raw16, cells, LPVP_FMT_FP16, back);
    assert_true(back[5] == 0.0f);
    assert_true(back[6] == 65504.0f);
    assert_true(back[7] == 65504.0f);
    for (size_t i = 0; i < cells * 12; i++)
        assert_true(back[i] == lpvp_f16_to_f32(lpvp_f32_to_f16(v[i])));

    /* fp16 re-pack of unpacked data is the identity. */
    {
        uint8_t *again = malloc(cells * 24);
        lpvp_volume_pack(back, cells, LPVP_FMT_FP16, again);
        assert_memory_equal(again, raw16, cells * 24);
        free(again);
    }
    assert_string_equal(lpvp_volume_format_name(LPVP_FMT_FP16), "fp16");
    assert_string_equal(lpvp_volume_format_name(LPVP_FMT_FP32), "fp32");
    lpvp_volume_format fmt;
    lpvp_compression comp;
    assert_int_equal(lpvp_volume_format_parse("fp32", &fmt), 0);
    assert_int_equal(fmt, LPVP_FMT_FP32);
    assert_int_equal(lpvp_volume_format_parse("fp64", &fmt), -1);
    assert_int_equal(lpvp_compression_parse("zstd", &comp), 0);
    assert_int_equal(comp, LPVP_COMP_ZSTD);
    assert_int_equal(lpvp_compression_parse("gzip", &comp), -1);
    free(v);
    free(back);
    free(raw16);
    free(raw32);
}

static void test_xor_delta(void **state)
{
    (void)state;
    for (size_t n = 0; n < 70; n++) {
        uint8_t a[70] = {0}, b[70] = {0}, d[70] = {0}, r[70] = {0};
        for (size_t i = 0; i < n; i++) {
            a[i] = (uint8_t)rng();
            b[i] = (i % 3) ? a[i] : (uint8_t)rng(); /* mostly equal, like ticks */
        }
        lpvp_xor(d, a, b, n);
        for (size_t i = 0; i < n; i++)
            assert_int_equal(d[i], a[i] ^ b[i]);
        lpvp_xor(r, d, b, n); /* rebuild */
        assert_memory_equal(r, a, n);
        memcpy(r, b, n);
        lpvp_xor(r, d, r, n); /* in place */
        assert_memory_equal(r, a, n);
        memcpy(r, d, n);
        lpvp_xor(r, r, b, n);
        assert_memory_equal(r, a, n);
    }
}

/* ---- zstd (R5.2) ---------------------------------------------------------- */

static void test_zstd(void **state)
{
    (void)state;
    char err[256];
    size_t n = 300000, cn = 0, dn = 0;
    uint8_t *src = malloc(n), *c = NULL, *d = NULL;
    for (size_t i = 0; i < n; i++)
        src[i] = (uint8_t)((i / 100) ^ (i % 7));
    assert_int_equal(lpvp_zstd_compress(src, n, 0, &c, &cn, err, sizeof err), 0);
    assert_true(cn < n / 4);
    assert_int_equal(lpvp_zstd_decompress(c, cn, n, &d, &dn, err, sizeof err), 0);
    assert_int_equal(dn, n);
    assert_memory_equal(d, src, n);
    free(d);
    d = malloc(n);
    assert_int_equal(lpvp_zstd_decompress_exact(c, cn, d, n, err, sizeof err), 0);
    assert_memory_equal(d, src, n);
    /* exact: wrong expected size */
    assert_int_equal(lpvp_zstd_decompress_exact(c, cn, d, n - 1, err, sizeof err), -1);
    assert_int_equal(lpvp_zstd_decompress_exact(c, cn, d, n + 1 > n ? n : n, err, sizeof err), 0);
    free(d);
    d = NULL;

    /* Over the maximum: refused before allocating. */
    assert_int_equal(lpvp_zstd_decompress(c, cn, n - 1, &d, &dn, err, sizeof err), -1);
    assert_null(d);
    assert_true(strstr(err, "exceeds") != NULL);
    /* Truncated, trailing bytes, garbage, empty. */
    assert_int_equal(lpvp_zstd_decompress(c, cn - 1, n, &d, &dn, err, sizeof err), -1);
    assert_int_equal(lpvp_zstd_decompress(c, 3, n, &d, &dn, err, sizeof err), -1);
    {
        uint8_t *t = malloc(cn + 1);
        memcpy(t, c, cn);
        t[cn] = 0;
        assert_int_equal(lpvp_zstd_decompress(t, cn + 1, n, &d, &dn, err, sizeof err), -1);
        /* Corrupted content: decoder error or checksum-less garbage, never a crash. */
        memcpy(t, c, cn);
        for (size_t i = 20; i < cn; i += 37)
            t[i] ^= 0x5A;
        if (lpvp_zstd_decompress(t, cn, n, &d, &dn, err, sizeof err) == 0) {
            assert_int_equal(dn, n);
            free(d);
            d = NULL;
        }
        free(t);
    }
    assert_int_equal(lpvp_zstd_decompress("garbage garbage", 15, n, &d, &dn, err, sizeof err),
                     -1);
    assert_int_equal(lpvp_zstd_decompress(NULL, 0, n, &d, &dn, err, sizeof err), -1);
    assert_null(d);

    /* A frame without a recorded content size is refused. */
    {
        ZSTD_CCtx *cc = ZSTD_createCCtx();
        uint8_t *buf = malloc(ZSTD_compressBound(n));
        ZSTD_inBuffer in = {src, n, 0};
        ZSTD_outBuffer out = {buf, ZSTD_compressBound(n), 0};
        ZSTD_CCtx_setParameter(cc, ZSTD_c_contentSizeFlag, 0);
        size_t r;
        do {
            r = ZSTD_compressStream2(cc, &out, &in, ZSTD_e_end);
            assert_false(ZSTD_isError(r));
        } while (r != 0);
        assert_true(ZSTD_getFrameContentSize(buf, out.pos) == ZSTD_CONTENTSIZE_UNKNOWN);
        assert_int_equal(lpvp_zstd_decompress(buf, out.pos, n, &d, &dn, err, sizeof err), -1);
        assert_true(strstr(err, "content size") != NULL);
        ZSTD_freeCCtx(cc);
        free(buf);
    }
    /* Empty input round trip. */
    free(c);
    c = NULL;
    assert_int_equal(lpvp_zstd_compress(src, 0, 3, &c, &cn, err, sizeof err), 0);
    assert_int_equal(lpvp_zstd_decompress(c, cn, 10, &d, &dn, err, sizeof err), 0);
    assert_int_equal(dn, 0);
    free(d);
    free(c);
    /* Into a caller buffer. */
    {
        size_t cap = lpvp_zstd_bound(n);
        uint8_t *buf = malloc(cap);
        size_t r = lpvp_zstd_compress_into(buf, cap, src, n, 1, err, sizeof err);
        assert_true(r > 0);
        assert_int_equal(lpvp_zstd_compress_into(buf, 4, src, n, 1, err, sizeof err), 0);
        free(buf);
    }
    free(src);
}

/* ---- volume header and client decoding (section 5) ------------------------ */

static void expect_cascade_error(json_t *h, const char *field)
{
    char err[256];
    lpvp_volume_info back;
    assert_int_equal(lpvp_volume_header_parse(h, &back, err, sizeof err), -1);
    if (strstr(err, field) != err)
        fail_msg("expected an error on %s, got \"%s\"", field, err);
    json_decref(h);
}

/* R5.6: several cascades, finest first, the grid equal to cascade 0. */
static void test_volume_cascades(void **state)
{
    (void)state;
    char err[256];
    lpvp_volume_info vi;
    memset(&vi, 0, sizeof vi);
    vi.revision = 3;
    vi.tick = 9;
    vi.format = LPVP_FMT_FP32;
    vi.keyframe = 1;
    vi.base_tick = -1;
    vi.cascade_count = 3;
    for (int k = 0; k < 3; k++) {
        lpvp_cascade_info *c = &vi.cascades[k];
        c->dims[0] = 4;
        c->dims[1] = 3;
        c->dims[2] = 2;
        c->cells = 24;
        c->cell_size = 0.25 * (double)(1 << k);
        for (int i = 0; i < 3; i++)
            c->origin[i] = -0.5 * c->cell_size * (double)c->dims[i] + 0.125;
    }
    for (int i = 0; i < 3; i++) {
        vi.dims[i] = vi.cascades[0].dims[i];
        vi.origin[i] = vi.cascades[0].origin[i];
    }
    vi.cell_size = vi.cascades[0].cell_size;
    assert_int_equal(lpvp_volume_total_cells(&vi), 72);
    assert_int_equal(lpvp_volume_cascade_first_cell(&vi, 0), 0);
    assert_int_equal(lpvp_volume_cascade_first_cell(&vi, 2), 48);
    vi.raw_length = 72 * 12 * 4;

    json_t *h = lpvp_volume_header_build(&vi);
    assert_non_null(h);
    json_t *a = json_object_get(h, "cascades");
    assert_true(json_is_array(a) && json_array_size(a) == 3);
    assert_int_equal(json_integer_value(json_object_get(json_array_get(a, 1), "cells")), 24);
    lpvp_volume_info back;
    assert_int_equal(lpvp_volume_header_parse(h, &back, err, sizeof err), 0);
    assert_int_equal(back.cascade_count, 3);
    assert_true(back.cascades[2].cell_size == 1.0);
    assert_true(back.cascades[1].origin[1] == vi.cascades[1].origin[1]);
    assert_int_equal(back.cascades[2].dims[2], 2);
    assert_int_equal(back.raw_length, 72 * 48);
    assert_int_equal(lpvp_volume_total_cells(&back), 72);

    /* Inconsistencies, each with "<field>: <what>". */
    json_t *c;
    c = json_deep_copy(h);
    json_object_set_new(c, "raw_length", json_integer(24 * 48)); /* one cascade's worth */
    expect_cascade_error(c, "raw_length");
    c = json_deep_copy(h);
    json_object_set_new(c, "cascades", json_array());
    expect_cascade_error(c, "cascades");
    c = json_deep_copy(h);
    for (int k = 0; k < 2; k++)
        json_array_append(json_object_get(c, "cascades"), json_array_get(json_object_get(c, "cascades"), 0));
    expect_cascade_error(c, "cascades"); /* 5 > LPVP_MAX_CASCADES */
    c = json_deep_copy(h);
    json_object_set_new(c, "cascades", json_string("no"));
    expect_cascade_error(c, "cascades");
    c = json_deep_copy(h);
    json_array_set_new(json_object_get(json_array_get(json_object_get(c, "cascades"), 1), "dims"), 0,
                       json_integer(0));
    expect_cascade_error(c, "cascades[1].dims[0]");
    c = json_deep_copy(h);
    json_object_set_new(json_array_get(json_object_get(c, "cascades"), 2), "cell_size", json_real(0.0));
    expect_cascade_error(c, "cascades[2].cell_size");
    c = json_deep_copy(h);
    json_object_set_new(json_array_get(json_object_get(c, "cascades"), 2), "cell_size", json_real(-1.0));
    expect_cascade_error(c, "cascades[2].cell_size");
    c = json_deep_copy(h);
    json_object_set_new(json_array_get(json_object_get(c, "cascades"), 1), "cells", json_integer(23));
    expect_cascade_error(c, "cascades[1].cells");
    c = json_deep_copy(h);
    json_object_del(json_array_get(json_object_get(c, "cascades"), 0), "origin");
    expect_cascade_error(c, "cascades[0].origin");
    c = json_deep_copy(h);
    json_object_set_new(json_object_get(c, "grid"), "cell_size", json_real(0.5));
    expect_cascade_error(c, "grid.cell_size");
    c = json_deep_copy(h);
    json_array_set_new(json_object_get(json_object_get(c, "grid"), "origin"), 1, json_real(7.0));
    expect_cascade_error(c, "grid.origin");
    c = json_deep_copy(h);
    json_array_set_new(json_object_get(json_object_get(c, "grid"), "dims"), 0, json_integer(5));
    json_array_set_new(json_object_get(json_array_get(json_object_get(c, "cascades"), 0), "dims"), 0,
                       json_integer(5));
    json_object_set_new(json_array_get(json_object_get(c, "cascades"), 0), "cells", json_integer(30));
    json_object_set_new(c, "raw_length", json_integer(78 * 48));
    assert_int_equal(lpvp_volume_header_parse(c, &back, err, sizeof err), 0); /* consistent again */
    json_array_set_new(json_object_get(json_object_get(c, "grid"), "dims"), 0, json_integer(4));
    json_object_set_new(c, "raw_length", json_integer(78 * 48));
    expect_cascade_error(c, "grid.dims");
    json_decref(h);

    /* A header without "cascades" (an older server) reads as one cascade. */
    vi.cascade_count = 0;
    vi.raw_length = 24 * 48;
    h = lpvp_volume_header_build(&vi);
    assert_int_equal(json_array_size(json_object_get(h, "cascades")), 1);
    json_object_del(h, "cascades");
    assert_int_equal(lpvp_volume_header_parse(h, &back, err, sizeof err), 0);
    assert_int_equal(back.cascade_count, 1);
    assert_int_equal(back.cascades[0].cells, 24);
    assert_true(back.cascades[0].cell_size == 0.25);
    json_decref(h);
}

static void test_volume_header_and_decode(void **state)
{
    (void)state;
    char err[256];
    const size_t cells = 4 * 3 * 2;
    lpvp_volume_info vi = {.revision = 7, .tick = 12, .format = LPVP_FMT_FP16,
                           .compression = LPVP_COMP_ZSTD, .keyframe = 1, .base_tick = -1,
                           .dims = {4, 3, 2}, .origin = {-1, 0, 0.5}, .cell_size = 0.25,
                           .raw_length = cells * 24};
    json_t *h = lpvp_volume_header_build(&vi);
    assert_non_null(h);
    assert_string_equal(json_string_value(json_object_get(h, "layout")), LPVP_VOLUME_LAYOUT);
    assert_string_equal(json_string_value(json_object_get(h, "units")), "W/sr");
    assert_null(json_object_get(h, "base_tick"));
    lpvp_volume_info back;
    assert_int_equal(lpvp_volume_header_parse(h, &back, err, sizeof err), 0);
    assert_int_equal(back.revision, 7);
    assert_int_equal(back.tick, 12);
    assert_int_equal(back.format, LPVP_FMT_FP16);
    assert_int_equal(back.compression, LPVP_COMP_ZSTD);
    assert_true(back.keyframe);
    assert_int_equal(back.dims[0], 4);
    assert_true(back.origin[2] == 0.5 && back.cell_size == 0.25);
    assert_int_equal(back.raw_length, cells * 24);
    /* A wrong raw_length is caught. */
    json_object_set_new(h, "raw_length", json_integer(cells * 24 + 1));
    assert_int_equal(lpvp_volume_header_parse(h, &back, err, sizeof err), -1);
    assert_true(strstr(err, "raw_length") == err);
    json_decref(h);

    /* Server side: two ticks, keyframe then zstd'd XOR delta; client side decode. */
    float v1[24 * 12], v2[24 * 12], out[24 * 12];
    uint8_t raw1[24 * 24], raw2[24 * 24], delta[24 * 24], client[24 * 24];
    for (size_t i = 0; i < cells * 12; i++) {
        v1[i] = (float)i * 0.5f;
        v2[i] = (i % 5) ? v1[i] : v1[i] + 1.0f;
    }
    lpvp_volume_pack(v1, cells, LPVP_FMT_FP16, raw1);
    lpvp_volume_pack(v2, cells, LPVP_FMT_FP16, raw2);
    uint8_t *att;
    size_t att_len;
    assert_int_equal(lpvp_zstd_compress(raw1, sizeof raw1, 1, &att, &att_len, err, sizeof err),
                     0);
    assert_int_equal(lpvp_volume_decode(&vi, att, att_len, NULL, 0, client, err, sizeof err), 0);
    assert_memory_equal(client, raw1, sizeof raw1);
    free(att);

    lpvp_xor(delta, raw2, raw1, sizeof raw1);
    assert_int_equal(lpvp_zstd_compress(delta, sizeof delta, 1, &att, &att_len, err, sizeof err),
                     0);
    vi.keyframe = 0;
    vi.base_tick = 12;
    vi.tick = 13;
    h = lpvp_volume_header_build(&vi);
    assert_int_equal(json_integer_value(json_object_get(h, "base_tick")), 12);
    assert_int_equal(lpvp_volume_header_parse(h, &back, err, sizeof err), 0);
    assert_int_equal(back.base_tick, 12);
    json_decref(h);
    assert_int_equal(lpvp_volume_decode(&back, att, att_len, NULL, 0, client, err, sizeof err),
                     -1); /* delta without base */
    assert_int_equal(
        lpvp_volume_decode(&back, att, att_len, client, sizeof client, client, err, sizeof err),
        0); /* in place */
    assert_memory_equal(client, raw2, sizeof raw2);
    lpvp_volume_unpack(client, cells, LPVP_FMT_FP16, out);
    for (size_t i = 0; i < cells * 12; i++)
        assert_true(out[i] == lpvp_f16_to_f32(lpvp_f32_to_f16(v2[i])));
    free(att);

    /* Uncompressed delta, not in place; wrong attachment size refused. */
    vi.compression = LPVP_COMP_NONE;
    uint8_t client2[24 * 24];
    assert_int_equal(
        lpvp_volume_decode(&vi, delta, sizeof delta, raw1, sizeof raw1, client2, err, sizeof err),
        0);
    assert_memory_equal(client2, raw2, sizeof raw2);
    assert_int_equal(lpvp_volume_decode(&vi, delta, sizeof delta - 1, raw1, sizeof raw1, client2,
                                        err, sizeof err),
                     -1);
}

/* R1.1: host/port splitting and the default socket rule shared by the
 * daemon and the clients. */
/* A two-level far-field volume with its description (R5.9 - R5.11). */
static void described_volume(lpvp_volume_info *vi)
{
    memset(vi, 0, sizeof *vi);
    vi->revision = 1;
    vi->tick = 4;
    vi->format = LPVP_FMT_FP16;
    vi->keyframe = 1;
    vi->base_tick = -1;
    vi->cascade_count = 2;
    for (int k = 0; k < 2; k++) {
        lpvp_cascade_info *c = &vi->cascades[k];
        c->dims[0] = c->dims[1] = c->dims[2] = 2;
        c->cells = 8;
        c->cell_size = 0.5 * (double)(1 << k);
        for (int i = 0; i < 3; i++)
            c->origin[i] = -c->cell_size;
    }
    for (int i = 0; i < 3; i++) {
        vi->dims[i] = vi->cascades[0].dims[i];
        vi->origin[i] = vi->cascades[0].origin[i];
    }
    vi->cell_size = vi->cascades[0].cell_size;
    vi->raw_length = 16 * 12 * 2;
    lpvp_volume_layout_sh(&vi->layout, "cascaded_lpv", 1, 2);
}

/* Parses h (taking it) and expects a refusal whose message contains what. */
static void expect_refused(json_t *h, const char *what)
{
    char err[256] = "";
    lpvp_volume_info back;
    int rc = lpvp_volume_header_parse(h, &back, err, sizeof err);
    if (rc == 0 || !strstr(err, what))
        fail_msg("expected a refusal naming '%s', got rc %d: '%s'", what, rc, err);
    json_decref(h);
}

/* R5.13: an octree's levels and index volume (GET_VOLUME content "levels"):
 * built, read back, and every inconsistent placement refused naming it. */
static void test_volume_octree_levels(void **state)
{
    (void)state;
    char err[256];
    lpvp_volume_info vi, back;
    assert_int_equal(lpvp_octree_level_count(1), 1);
    assert_int_equal(lpvp_octree_level_count(16), 5);
    assert_int_equal(lpvp_octree_level_count(256), 9);
    assert_int_equal(lpvp_octree_level_count(512), -1);
    assert_int_equal(lpvp_octree_level_count(12), -1);
    assert_int_equal(lpvp_octree_level_count(0), -1);

    memset(&vi, 0, sizeof vi);
    vi.revision = 3;
    vi.tick = 7;
    vi.format = LPVP_FMT_FP16;
    vi.keyframe = 1;
    vi.base_tick = -1;
    vi.cascade_count = 1;
    lpvp_cascade_info *c0 = &vi.cascades[0];
    for (int a = 0; a < 3; a++) {
        vi.dims[a] = c0->dims[a] = 4;
        vi.origin[a] = c0->origin[a] = -1.0 + 0.25 * a;
    }
    vi.cell_size = c0->cell_size = 0.5;
    c0->cells = 64;
    lpvp_cascade_info skew = *c0;
    skew.dims[2] = 2;
    assert_int_equal(lpvp_volume_layout_octree(&vi.layout, "octree", &skew, err, sizeof err), -1);
    assert_non_null(strstr(err, "4x4x2"));
    assert_int_equal(lpvp_volume_layout_octree(&vi.layout, "octree", c0, err, sizeof err), 0);
    assert_int_equal(vi.layout.content, LPVP_CONTENT_LEVELS);
    assert_int_equal(vi.layout.level_count, 3);
    /* levels 4^3 + 2^3 + 1^3 = 73 cells x 12 fp16 values, then 64 u32 */
    assert_int_equal(lpvp_volume_total_cells(&vi), 73);
    assert_int_equal(lpvp_volume_values_bytes(&vi), 73 * 12 * 2);
    assert_int_equal(lpvp_volume_cascade_first_cell(&vi, 2), 72);
    vi.raw_length = 73 * 12 * 2 + 64 * 4;
    json_t *h = lpvp_volume_header_build(&vi);
    assert_non_null(h);
    json_t *d = json_object_get(h, LPVP_VOLUME_DESC_KEY), *lv = json_object_get(d, "levels");
    assert_int_equal(json_array_size(lv), 3);
    assert_int_equal(json_array_size(json_object_get(h, "cascades")), 1);
    assert_string_equal(json_string_value(json_object_get(json_array_get(lv, 2), "role")), "octree_level");
    assert_true(json_number_value(json_object_get(json_array_get(lv, 2), "cell_size")) == 2.0);
    assert_int_equal(json_integer_value(json_object_get(json_array_get(lv, 1), "cells")), 8);
    json_t *ix = json_object_get(d, "index");
    assert_int_equal(json_integer_value(json_object_get(ix, "raw_offset")), 73 * 12 * 2);
    assert_int_equal(json_integer_value(json_object_get(ix, "raw_length")), 64 * 4);
    assert_string_equal(json_string_value(json_object_get(ix, "value_type")), LPVP_INDEX_VALUE_TYPE);

    assert_int_equal(lpvp_volume_header_parse(h, &back, err, sizeof err), 0);
    assert_int_equal(back.layout.content, LPVP_CONTENT_LEVELS);
    assert_int_equal(back.layout.level_count, 3);
    assert_int_equal(back.cascade_count, 1);
    assert_int_equal(back.layout.level[1].dims[0], 2);
    assert_true(back.layout.level[2].cell_size == 2.0);
    assert_true(back.layout.level[2].origin[1] == -0.75);
    assert_int_equal(back.layout.role[2], LPVP_ROLE_OCTREE_LEVEL);
    assert_true(back.layout.has_index && back.layout.index.level == 0 && back.layout.index.cells == 64);
    assert_int_equal(lpvp_volume_total_cells(&back), 73);
    assert_int_equal(back.raw_length, 73 * 12 * 2 + 64 * 4);
    assert_int_equal(lpvp_volume_layout_lookup_check(&back.layout, err, sizeof err), -1);
    assert_non_null(strstr(err, "\"levels\""));

#define BAD(edit, what)                                                                                       \
    do {                                                                                                      \
        json_t *b = json_deep_copy(h), *bd = json_object_get(b, LPVP_VOLUME_DESC_KEY);                        \
        json_t *bl = json_object_get(bd, "levels");                                                           \
        (void)bl;                                                                                             \
        edit;                                                                                                 \
        expect_refused(b, what);                                                                              \
    } while (0)
    /* placement: count, dims, origin, cell size, cells, role of every level */
    BAD(json_array_remove(bl, 2), "levels: 2");
    BAD(json_array_append(bl, json_array_get(bl, 2)), "levels: 4");
    BAD(json_object_set_new(json_array_get(bl, 1), "dims", json_pack("[i,i,i]", 2, 2, 1)), "levels[1]");
    BAD(json_object_set_new(json_array_get(bl, 1), "cells", json_integer(9)), "levels[1]");
    BAD(json_object_set_new(json_array_get(bl, 2), "cell_size", json_real(1.0)), "levels[2]");
    BAD(json_object_set_new(json_array_get(bl, 2), "origin", json_pack("[f,f,f]", 0.0, 0.0, 0.0)), "levels[2]");
    BAD(json_object_set_new(json_array_get(bl, 0), "cell_size", json_real(0.25)), "levels[0]");
    BAD(json_object_set_new(json_array_get(bl, 1), "role", json_string("cascade")), "levels[1].role");
    BAD(json_object_set_new(bd, "far_field", json_true()), "far_field");
    /* the legacy keys describe level 0 alone */
    BAD(json_array_append(json_object_get(b, "cascades"), json_array_get(json_object_get(b, "cascades"), 0)),
        "cascades");
    /* the index: over level 0, one u32 per cell */
    BAD(json_object_set_new(bd, "index", json_null()), "need the index volume over level 0");
    BAD((json_object_set_new(json_object_get(bd, "index"), "values_per_cell", json_integer(2)),
         json_object_set_new(json_object_get(bd, "index"), "raw_length", json_integer(64 * 2 * 4))),
        "need the index volume over level 0");
    BAD((json_object_set_new(json_object_get(bd, "index"), "dims", json_pack("[i,i,i]", 4, 4, 2)),
         json_object_set_new(json_object_get(bd, "index"), "raw_length", json_integer(32 * 4))),
        "need the index volume over level 0");
    BAD(json_object_set_new(json_object_get(bd, "index"), "raw_offset", json_integer(0)), "index.raw_offset");
    BAD(json_object_set_new(b, "raw_length", json_integer(73 * 12 * 2)), "raw_length");
    /* a grid with no octree */
    {
        json_t *b = json_deep_copy(h);
        json_t *g = json_object_get(b, "grid"), *c = json_array_get(json_object_get(b, "cascades"), 0);
        json_object_set_new(g, "dims", json_pack("[i,i,i]", 3, 3, 3));
        json_object_set_new(c, "dims", json_pack("[i,i,i]", 3, 3, 3));
        json_object_set_new(c, "cells", json_integer(27));
        expect_refused(b, "3x3x3");
    }
#undef BAD
    json_decref(h);
}

/* R5.14: technique iv's volume (one level of voxels, radiance, the index of
 * the voxels holding a surface, iv_neighbours): built, read back, refused for
 * R5.7's lookup, and every inconsistent variant refused naming the field. */
static void test_volume_iv(void **state)
{
    (void)state;
    char err[256];
    lpvp_volume_info vi, back;
    memset(&vi, 0, sizeof vi);
    vi.revision = 2;
    vi.tick = 5;
    vi.format = LPVP_FMT_FP32;
    vi.keyframe = 1;
    vi.base_tick = -1;
    vi.cascade_count = 1;
    lpvp_cascade_info *c0 = &vi.cascades[0];
    const int dims[3] = {4, 3, 2};
    for (int a = 0; a < 3; a++) {
        vi.dims[a] = c0->dims[a] = dims[a];
        vi.origin[a] = c0->origin[a] = -1.0 + 0.5 * a;
    }
    vi.cell_size = c0->cell_size = 0.5;
    c0->cells = 24;
    assert_int_equal(lpvp_volume_layout_iv(&vi.layout, "iv", c0, 0, err, sizeof err), -1);
    assert_non_null(strstr(err, LPVP_IV_NEIGHBOURS_KEY));
    assert_int_equal(lpvp_volume_layout_iv(&vi.layout, "iv", c0, 9, err, sizeof err), -1);
    assert_int_equal(lpvp_volume_layout_iv(&vi.layout, "iv", c0, 6, err, sizeof err), 0);
    assert_true(lpvp_volume_layout_is_iv(&vi.layout));
    assert_string_equal(lpvp_volume_layout_units(&vi.layout), LPVP_VOLUME_UNITS_RADIANCE);
    /* 24 voxels x 12 fp32 values, then 24 u32 */
    assert_int_equal(lpvp_volume_values_bytes(&vi), 24 * 12 * 4);
    vi.raw_length = 24 * 12 * 4 + 24 * 4;
    json_t *h = lpvp_volume_header_build(&vi);
    assert_non_null(h);
    assert_string_equal(json_string_value(json_object_get(h, "units")), "W/(m^2 sr)");
    json_t *d = json_object_get(h, LPVP_VOLUME_DESC_KEY), *lv = json_object_get(d, "levels");
    assert_string_equal(json_string_value(json_object_get(d, "units")), "W/(m^2 sr)");
    assert_string_equal(json_string_value(json_object_get(d, "technique")), "iv");
    assert_int_equal(json_array_size(lv), 1);
    assert_string_equal(json_string_value(json_object_get(json_array_get(lv, 0), "role")), "iv_voxels");
    assert_true(json_is_false(json_object_get(d, "far_field")));
    assert_int_equal(json_integer_value(json_object_get(d, LPVP_IV_NEIGHBOURS_KEY)), 6);
    json_t *ix = json_object_get(d, "index");
    assert_int_equal(json_integer_value(json_object_get(ix, "level")), 0);
    assert_int_equal(json_integer_value(json_array_get(json_object_get(ix, "dims"), 0)), 4);
    assert_int_equal(json_integer_value(json_object_get(ix, "values_per_cell")), 1);
    assert_int_equal(json_integer_value(json_object_get(ix, "raw_offset")), 24 * 12 * 4);
    assert_int_equal(json_integer_value(json_object_get(ix, "raw_length")), 24 * 4);

    assert_int_equal(lpvp_volume_header_parse(h, &back, err, sizeof err), 0);
    assert_true(lpvp_volume_layout_is_iv(&back.layout));
    assert_int_equal(back.layout.role[0], LPVP_ROLE_IV_VOXELS);
    assert_int_equal(back.layout.iv_neighbours, 6);
    assert_string_equal(back.layout.units, "W/(m^2 sr)");
    assert_true(back.layout.sh_values && back.layout.has_index && back.layout.index.cells == 24);
    assert_int_equal(back.raw_length, 24 * 12 * 4 + 24 * 4);
    /* R5.7's lookup refuses it, R5.14's reads it; and the other way round */
    assert_int_equal(lpvp_volume_layout_lookup_check(&back.layout, err, sizeof err), -1);
    assert_non_null(strstr(err, "R5.14"));
    assert_int_equal(lpvp_volume_layout_iv_lookup_check(&back.layout, err, sizeof err), 0);
    lpvp_volume_layout sh;
    lpvp_volume_layout_sh(&sh, "lpv", 0, 1);
    assert_int_equal(lpvp_volume_layout_iv_lookup_check(&sh, err, sizeof err), -1);
    assert_non_null(strstr(err, "iv_voxels"));
    /* W/(m^2 sr) in an LPV's layout is not what R5.7 reads either */
    snprintf(sh.units, sizeof sh.units, "%s", LPVP_VOLUME_UNITS_RADIANCE);
    assert_int_equal(lpvp_volume_layout_lookup_check(&sh, err, sizeof err), -1);
    assert_non_null(strstr(err, "units W/(m^2 sr)"));

#define BAD(edit, what)                                                                                       \
    do {                                                                                                      \
        json_t *b = json_deep_copy(h), *bd = json_object_get(b, LPVP_VOLUME_DESC_KEY);                        \
        json_t *bl = json_object_get(bd, "levels"), *bi = json_object_get(bd, "index");                       \
        (void)bl;                                                                                             \
        (void)bi;                                                                                             \
        edit;                                                                                                 \
        expect_refused(b, what);                                                                              \
    } while (0)
    /* the role and placement: one level equal to the one cascade */
    {
        /* as a "cascade" the same header is an LPV-like volume with an index in other units: R5.9 - R5.12
         * read it, but it is not R5.14's and R5.7's lookup refuses it */
        json_t *b = json_deep_copy(h);
        json_object_set_new(json_array_get(json_object_get(json_object_get(b, LPVP_VOLUME_DESC_KEY), "levels"), 0),
                            "role", json_string("cascade"));
        assert_int_equal(lpvp_volume_header_parse(b, &back, err, sizeof err), 0);
        assert_false(lpvp_volume_layout_is_iv(&back.layout));
        assert_int_equal(lpvp_volume_layout_lookup_check(&back.layout, err, sizeof err), -1);
        assert_int_equal(lpvp_volume_layout_iv_lookup_check(&back.layout, err, sizeof err), -1);
        json_decref(b);
    }
    BAD(json_object_set_new(json_array_get(bl, 0), "role", json_string("voxels")), "levels[0].role");
    BAD(json_array_append(bl, json_array_get(bl, 0)), "exactly one level");
    BAD(json_array_append(json_object_get(b, "cascades"), json_array_get(json_object_get(b, "cascades"), 0)),
        "cascades");
    BAD(json_object_set_new(json_array_get(bl, 0), "cell_size", json_real(0.25)), "levels[0]");
    BAD(json_object_set_new(bd, "far_field", json_true()), "far_field");
    /* the units: radiance, in the description and the header alike */
    BAD((json_object_set_new(bd, "units", json_string("W/sr")), json_object_set_new(b, "units", json_string("W/sr"))),
        "units");
    BAD(json_object_set_new(bd, "units", json_string("W/sr")), "units");
    /* the values: the 12 SH values in one volume */
    BAD(json_array_set_new(json_object_get(bd, "values"), 3, json_string("r.Y2")), "values");
    BAD((json_object_set_new(bd, "volumes_per_level", json_integer(2)),
         json_object_set_new(bi, "raw_offset", json_integer(24 * 12 * 4 * 2)),
         json_object_set_new(b, "raw_length", json_integer(24 * 12 * 4 * 2 + 24 * 4))),
        "values");
    /* the index: over level 0, level 0's dims, one u32 per voxel */
    BAD(json_object_set_new(bd, "index", json_null()), "index");
    BAD(json_object_del(bd, "index"), "index");
    BAD((json_object_set_new(bi, "dims", json_pack("[i,i,i]", 4, 3, 1)),
         json_object_set_new(bi, "raw_length", json_integer(12 * 4)),
         json_object_set_new(b, "raw_length", json_integer(24 * 12 * 4 + 12 * 4))),
        "index over level 0");
    BAD((json_object_set_new(bi, "dims", json_pack("[i,i,i]", 2, 3, 4)))
        , "index over level 0");
    BAD((json_object_set_new(bi, "values_per_cell", json_integer(2)),
         json_object_set_new(bi, "raw_length", json_integer(24 * 2 * 4)),
         json_object_set_new(b, "raw_length", json_integer(24 * 12 * 4 + 24 * 2 * 4))),
        "index over level 0");
    BAD(json_object_set_new(bi, "value_type", json_string("u16")), "index.value_type");
    BAD(json_object_set_new(bi, "raw_length", json_integer(24 * 2)), "index.raw_length");
    BAD(json_object_set_new(b, "raw_length", json_integer(24 * 12 * 4)), "raw_length");
    /* the lookup's parameter */
    BAD(json_object_del(bd, LPVP_IV_NEIGHBOURS_KEY), LPVP_IV_NEIGHBOURS_KEY);
    BAD(json_object_set_new(bd, LPVP_IV_NEIGHBOURS_KEY, json_integer(0)), LPVP_IV_NEIGHBOURS_KEY);
    BAD(json_object_set_new(bd, LPVP_IV_NEIGHBOURS_KEY, json_integer(9)), LPVP_IV_NEIGHBOURS_KEY);
    BAD(json_object_set_new(bd, LPVP_IV_NEIGHBOURS_KEY, json_real(4.0)), LPVP_IV_NEIGHBOURS_KEY);
#undef BAD
    json_decref(h);
}

/* R5.15: a probes' volume with its visibility (GET_VOLUME content
 * "visibility"): built, read back (still R5.7's SH), and every inconsistent
 * variant refused naming the field. */
static void test_volume_visibility(void **state)
{
    (void)state;
    char err[256];
    lpvp_volume_info vi, back;
    memset(&vi, 0, sizeof vi);
    vi.revision = 3;
    vi.tick = 4;
    vi.format = LPVP_FMT_FP16;
    vi.keyframe = 1;
    vi.base_tick = -1;
    vi.cascade_count = 2;
    for (int k = 0; k < 2; k++) {
        lpvp_cascade_info *c = &vi.cascades[k];
        for (int a = 0; a < 3; a++) {
            c->dims[a] = 2;
            c->origin[a] = -1.0 * (k + 1);
        }
        c->cell_size = k + 1.0;
        c->cells = 8;
    }
    for (int a = 0; a < 3; a++) {
        vi.dims[a] = 2;
        vi.origin[a] = -1.0;
    }
    vi.cell_size = 1.0;
    assert_int_equal(lpvp_volume_layout_visibility(&vi.layout, "probes", 2, 0, 8, 0.25, err, sizeof err), -1);
    assert_int_equal(lpvp_volume_layout_visibility(&vi.layout, "probes", 2, 6, 33, 0.25, err, sizeof err), -1);
    assert_int_equal(lpvp_volume_layout_visibility(&vi.layout, "probes", 2, 6, 8, -1.0, err, sizeof err), -1);
    assert_int_equal(lpvp_volume_layout_visibility(&vi.layout, "probes", 2, 6, 8, 0.25, err, sizeof err), 0);
    assert_int_equal(vi.layout.visibility.values_per_probe, 240);
    /* 16 probes x 12 fp16 values, then 16 x 240 f32 */
    assert_int_equal(lpvp_volume_values_bytes(&vi), 16 * 12 * 2);
    assert_int_equal(lpvp_volume_extra_bytes(&vi), 16 * 240 * 4);
    vi.raw_length = 16 * 12 * 2 + 16 * 240 * 4;
    json_t *h = lpvp_volume_header_build(&vi);
    assert_non_null(h);
    json_t *d = json_object_get(h, LPVP_VOLUME_DESC_KEY), *v = json_object_get(d, LPVP_VISIBILITY_KEY);
    assert_non_null(v);
    assert_int_equal(json_integer_value(json_object_get(v, "probes")), 16);
    assert_int_equal(json_integer_value(json_object_get(v, "irradiance_side")), 6);
    assert_int_equal(json_integer_value(json_object_get(v, "distance_side")), 8);
    assert_int_equal(json_integer_value(json_object_get(v, "values_per_probe")), 240);
    assert_string_equal(json_string_value(json_object_get(v, "value_type")), "f32");
    assert_true(json_real_value(json_object_get(v, "bias_cells")) == 0.25);
    assert_int_equal(json_integer_value(json_object_get(v, "raw_offset")), 16 * 12 * 2);
    assert_int_equal(json_integer_value(json_object_get(v, "raw_length")), 16 * 240 * 4);
    assert_true(json_is_null(json_object_get(d, "index")));
    assert_true(json_is_false(json_object_get(d, "far_field")));
    assert_int_equal(lpvp_volume_header_parse(h, &back, err, sizeof err), 0);
    assert_int_equal(back.layout.content, LPVP_CONTENT_VISIBILITY);
    assert_true(back.layout.has_visibility);
    assert_int_equal(back.layout.visibility.probes, 16);
    assert_int_equal(back.layout.visibility.values_per_probe, 240);
    assert_int_equal(back.layout.visibility.raw_offset, 16 * 12 * 2);
    assert_int_equal(back.layout.visibility.raw_length, 16 * 240 * 4);
    assert_true(back.layout.visibility.bias_cells == 0.25);
    assert_int_equal(lpvp_volume_layout_lookup_check(&back.layout, err, sizeof err), 0); /* R5.7 reads its SH */

#define BAD(edit, what)                                                                                       \
    do {                                                                                                      \
        json_t *b = json_deep_copy(h), *bd = json_object_get(b, LPVP_VOLUME_DESC_KEY);                        \
        json_t *bv = json_object_get(bd, LPVP_VISIBILITY_KEY);                                                \
        (void)bv;                                                                                             \
        edit;                                                                                                 \
        expect_refused(b, what);                                                                              \
    } while (0)
    BAD(json_object_set_new(bd, LPVP_VISIBILITY_KEY, json_integer(1)), "visibility: expected an object");
    BAD(json_object_set_new(bv, "irradiance_side", json_integer(0)), "visibility.irradiance_side");
    BAD(json_object_set_new(bv, "irradiance_side", json_integer(17)), "visibility.irradiance_side");
    BAD(json_object_set_new(bv, "distance_side", json_integer(33)), "visibility.distance_side");
    BAD(json_object_set_new(bv, "distance_side", json_integer(7)), "visibility.values_per_probe");
    BAD(json_object_set_new(bv, "values_per_probe", json_integer(239)), "visibility.values_per_probe");
    BAD(json_object_set_new(bv, "probes", json_integer(8)), "visibility.probes");
    BAD(json_object_set_new(bv, "value_type", json_string("f16")), "visibility.value_type");
    BAD(json_object_set_new(bv, "bias_cells", json_real(-0.5)), "visibility.bias_cells");
    BAD(json_object_set_new(bv, "bias_cells", json_string("0.25")), "visibility.bias_cells");
    BAD(json_object_set_new(bv, "raw_offset", json_integer(0)), "visibility.raw_offset");
    BAD(json_object_set_new(bv, "raw_length", json_integer(16 * 240 * 2)), "visibility.raw_length");
    BAD(json_object_set_new(b, "raw_length", json_integer(16 * 12 * 2)), "raw_length");
    /* only with cascades of the SH in one volume, no far field, no index */
    BAD((json_object_set_new(bd, "far_field", json_true()),
         json_object_set_new(json_array_get(json_object_get(bd, "levels"), 1), "role", json_string("far_field"))),
        "visibility");
    BAD(json_object_set_new(bd, "index", json_pack("{s:i, s:[i,i,i], s:i, s:s, s:I, s:I}", "level", 0, "dims", 2, 2,
                                                  2, "values_per_cell", 1, "value_type", "u32", "raw_offset",
                                                  (json_int_t)(16 * 12 * 2), "raw_length", (json_int_t)32)),
        "visibility");
#undef BAD
    json_decref(h);

    /* on an iv volume it is refused too */
    lpvp_volume_info iv = vi;
    iv.cascade_count = 1;
    assert_int_equal(lpvp_volume_layout_iv(&iv.layout, "iv", &iv.cascades[0], 6, err, sizeof err), 0);
    iv.raw_length = 8 * 12 * 2 + 8 * 4;
    json_t *hi = lpvp_volume_header_build(&iv);
    json_object_set_new(json_object_get(hi, LPVP_VOLUME_DESC_KEY), LPVP_VISIBILITY_KEY, json_object());
    expect_refused(hi, "only a probes' volume");
}

/* R5.15's lookup on hand-made records: probes that all hold the same
 * irradiance give it wherever the point is; a probe whose distance map says
 * a wall stands between it and the point counts (almost) nothing; off probes
 * count nothing. */
static void test_probes_lookup(void **state)
{
    (void)state;
    enum { I = 2, D = 2, PER = 4 + 3 * I * I + 2 * D * D };
    float rec[8 * PER];
    memset(rec, 0, sizeof rec);
    for (int p = 0; p < 8; p++) {
        float *r = rec + p * PER;
        r[3] = 1.0f;
        for (int t = 0; t < I * I; t++) {
            r[4 + 3 * t] = 3.0f, r[5 + 3 * t] = 2.0f, r[6 + 3 * t] = 1.0f;
        }
        for (int t = 0; t < D * D; t++) {
            r[4 + 3 * I * I + 2 * t] = 10.0f; /* far walls: every probe sees every point */
            r[5 + 3 * I * I + 2 * t] = 100.0f;
        }
    }
    lpvp_lookup_probes pr = {.count = 1, .records = rec, .irradiance_side = I, .distance_side = D, .bias_cells = 0.25f};
    pr.levels[0] = (lpvp_lookup_cascade){.dims = {2, 2, 2}, .origin = {0, 0, 0}, .cell_size = 1.0f};
    const float pts[3][3] = {{1.0f, 1.0f, 1.0f}, {0.6f, 1.3f, 0.9f}, {5.0f, -3.0f, 1.0f}};
    const float n[3] = {0.0f, 0.0f, 2.0f};
    for (int i = 0; i < 3; i++) {
        float e[3];
        assert_int_equal(lpvp_probes_irradiance(&pr, pts[i], n, e), 0);
        assert_float_equal(e[0], 3.0f, 1e-5f);
        assert_float_equal(e[1], 2.0f, 1e-5f);
        assert_float_equal(e[2], 1.0f, 1e-5f);
    }
    /* the x = 1 probes (odd indices) light 6 times as bright; at x = 0.5 the two halves weigh the same */
    for (int p = 1; p < 8; p += 2)
        for (int t = 0; t < I * I; t++)
            rec[p * PER + 4 + 3 * t] = 18.0f;
    const float mid[3] = {1.0f, 1.0f, 1.0f}, up[3] = {0.0f, 0.0f, 1.0f};
    float e[3];
    assert_int_equal(lpvp_probes_irradiance(&pr, mid, up, e), 0);
    assert_float_equal(e[0], 10.5f, 1e-4f);
    /* the bright probes see a wall 0.1 m away in every direction: the point (0.5 m off) is hidden from them */
    for (int p = 1; p < 8; p += 2)
        for (int t = 0; t < D * D; t++) {
            rec[p * PER + 4 + 3 * I * I + 2 * t] = 0.1f;
            rec[p * PER + 5 + 3 * I * I + 2 * t] = 0.0101f;
        }
    assert_int_equal(lpvp_probes_irradiance(&pr, mid, up, e), 0);
    assert_true(e[0] > 3.0f && e[0] < 3.01f);
    /* off, the dim probes count nothing: only the hidden bright ones are left, by the floor of their weights */
    for (int p = 0; p < 8; p += 2)
        rec[p * PER + 3] = 0.0f;
    assert_int_equal(lpvp_probes_irradiance(&pr, mid, up, e), 0);
    assert_float_equal(e[0], 18.0f, 1e-3f);
    /* no normal, no light; a field that is not usable refuses */
    const float zero[3] = {0, 0, 0};
    assert_int_equal(lpvp_probes_irradiance(&pr, mid, zero, e), 0);
    assert_true(e[0] == 0.0f && e[1] == 0.0f && e[2] == 0.0f);
    pr.count = 0;
    assert_int_equal(lpvp_probes_irradiance(&pr, mid, up, e), -1);
}

/* R5.14's lookup (volume_lookup.h) is core's reconstruction on the flags:
 * bit for bit what lpv_iv_irradiance gives from the voxels the flags come
 * from, at random points and normals (inside, on faces, outside the grid). */
static void test_iv_lookup(void **state)
{
    (void)state;
    const lpv_grid g = {.dims = {5, 4, 6}, .origin = {-1.0f, 0.25f, -0.5f}, .cell_size = 0.4f};
    const size_t cells = lpv_grid_cell_count(&g);
    lpv_cell *vol = aligned_alloc(16, cells * sizeof *vol);
    lpv_iv_voxel *vox = calloc(cells, sizeof *vox);
    uint32_t *held = calloc(cells, sizeof *held);
    assert_non_null(vol);
    assert_non_null(vox);
    assert_non_null(held);
    rng_state = 777;
    for (size_t i = 0; i < cells; i++) {
        float *c = (float *)&vol[i];
        for (int k = 0; k < 12; k++)
            c[k] = (float)(rng() % 2001) / 1000.0f - (k % 4 ? 1.0f : 0.0f);
        if (rng() % 3 == 0) {
            vox[i].normal[3] = 1.0f + (float)(rng() % 4);
            held[i] = 1;
        }
    }
    lpvp_lookup_iv v = {.dims = {g.dims[0], g.dims[1], g.dims[2]},
                        .origin = {g.origin[0], g.origin[1], g.origin[2]},
                        .cell_size = g.cell_size,
                        .cells = (const float *)vol,
                        .held = held};
    float rgb[3], want[3];
    const float p0[3] = {0.0f, 1.0f, 0.5f}, n0[3] = {0.0f, 1.0f, 0.0f};
    assert_int_equal(lpvp_iv_irradiance(&v, p0, n0, rgb), -1); /* neighbours 0 */
    v.neighbours = 9;
    assert_int_equal(lpvp_iv_irradiance(&v, p0, n0, rgb), -1);
    int nonzero = 0;
    for (int nb = 1; nb <= 8; nb++) {
        v.neighbours = nb;
        for (int t = 0; t < 400; t++) {
            float p[3], n[3];
            for (int a = 0; a < 3; a++) {
                float u = (float)(rng() % 1300) / 1000.0f - 0.15f; /* a little outside too */
                if (t % 5 == 0)
                    u = (float)(rng() % 7) / 6.0f; /* on voxel faces and centres */
                p[a] = g.origin[a] + u * (float)g.dims[a] * g.cell_size;
                n[a] = (float)(rng() % 2001) / 1000.0f - 1.0f;
            }
            if (t % 7 == 0) {
                n[0] = n[1] = n[2] = 0.0f;
                n[t % 3] = t % 2 ? 1.0f : -1.0f;
            }
            assert_int_equal(lpvp_iv_irradiance(&v, p, n, rgb), 0);
            lpv_iv_irradiance(&g, vox, vol, p, n, nb, want);
            assert_memory_equal(rgb, want, sizeof rgb);
            nonzero += rgb[0] != 0.0f || rgb[1] != 0.0f || rgb[2] != 0.0f;
        }
    }
    assert_true(nonzero > 400);
    /* flags NULL: refused (a volume without its index is not R5.14's) */
    v.held = NULL;
    assert_int_equal(lpvp_iv_irradiance(&v, p0, n0, rgb), -1);
    assert_true(rgb[0] == 0.0f && rgb[1] == 0.0f && rgb[2] == 0.0f);
    free(vol);
    free(vox);
    free(held);
}

/* R5.9 - R5.12: the description is built, read back, and every
 * inconsistent variant is refused naming the field. */
static void test_volume_description(void **state)
{
    (void)state;
    char err[256];
    lpvp_volume_info vi, back;
    described_volume(&vi);
    json_t *h = lpvp_volume_header_build(&vi);
    assert_non_null(h);
    json_t *d = json_object_get(h, LPVP_VOLUME_DESC_KEY);
    assert_true(json_is_object(d));
    assert_int_equal(json_integer_value(json_object_get(d, "layout_version")), LPVP_VOLUME_LAYOUT_VERSION);
    assert_string_equal(json_string_value(json_object_get(d, "technique")), "cascaded_lpv");
    assert_true(json_is_true(json_object_get(d, "far_field")));
    assert_int_equal(json_integer_value(json_object_get(d, "values_per_cell")), LPVP_VALUES_PER_CELL);
    assert_int_equal(json_array_size(json_object_get(d, "values")), LPVP_VALUES_PER_CELL);
    assert_string_equal(json_string_value(json_array_get(json_object_get(d, "values"), 1)), "r.Y1-1");
    assert_true(json_is_null(json_object_get(d, "index")));
    json_t *lv = json_object_get(d, "levels");
    assert_int_equal(json_array_size(lv), 2);
    assert_string_equal(json_string_value(json_object_get(json_array_get(lv, 0), "role")), "cascade");
    assert_string_equal(json_string_value(json_object_get(json_array_get(lv, 1), "role")), "far_field");

    assert_int_equal(lpvp_volume_header_parse(h, &back, err, sizeof err), 0);
    assert_true(back.layout.present);
    assert_string_equal(back.layout.technique, "cascaded_lpv");
    assert_true(back.layout.far_field && back.layout.sh_values && !back.layout.has_index);
    assert_int_equal(back.layout.role[1], LPVP_ROLE_FAR_FIELD);
    assert_int_equal(back.layout.volumes_per_level, 1);
    assert_int_equal(lpvp_volume_layout_lookup_check(&back.layout, err, sizeof err), 0);

    /* an older server: no description, R5.1's layout */
    json_t *old = json_deep_copy(h);
    json_object_del(old, LPVP_VOLUME_DESC_KEY);
    assert_int_equal(lpvp_volume_header_parse(old, &back, err, sizeof err), 0);
    assert_false(back.layout.present);
    assert_int_equal(back.layout.values_per_cell, LPVP_VALUES_PER_CELL);
    assert_int_equal(lpvp_volume_layout_lookup_check(&back.layout, err, sizeof err), 0);
    json_decref(old);

#define BAD(edit, what)                                                                                       \
    do {                                                                                                      \
        json_t *b = json_deep_copy(h), *bd = json_object_get(b, LPVP_VOLUME_DESC_KEY);                        \
        (void)bd;                                                                                             \
        edit;                                                                                                 \
        expect_refused(b, what);                                                                              \
    } while (0)
    BAD(json_object_set_new(bd, "layout_version", json_integer(2)), "layout_version");
    BAD(json_object_del(bd, "layout_version"), "layout_version");
    BAD(json_object_set_new(bd, "technique", json_string("")), "technique");
    BAD(json_object_set_new(b, LPVP_VOLUME_DESC_KEY, json_string("x")), LPVP_VOLUME_DESC_KEY);
    BAD(json_array_remove(json_object_get(bd, "levels"), 1), "levels");
    BAD(json_object_set_new(json_array_get(json_object_get(bd, "levels"), 1), "cell_size", json_real(2.0)),
        "levels[1]");
    BAD(json_object_set_new(json_array_get(json_object_get(bd, "levels"), 0), "cells", json_integer(9)),
        "levels[0]");
    BAD(json_object_set_new(json_array_get(json_object_get(bd, "levels"), 1), "role", json_string("cascade")),
        "levels[1].role");
    BAD(json_object_set_new(json_array_get(json_object_get(bd, "levels"), 0), "role", json_string("far_field")),
        "levels[0].role");
    BAD(json_object_set_new(bd, "far_field", json_false()), "levels[1].role");
    BAD(json_object_set_new(json_array_get(json_object_get(bd, "levels"), 1), "role", json_string("octree")),
        "levels[1].role");
    BAD(json_array_remove(json_object_get(bd, "values"), 11), "values");
    BAD(json_object_set_new(bd, "values_per_cell", json_integer(0)), "values_per_cell");
    BAD(json_array_set_new(json_object_get(bd, "values"), 3, json_string("r.Y00")), "values[3]");
    BAD(json_object_set_new(bd, "volumes_per_level", json_integer(0)), "volumes_per_level");
    BAD(json_object_set_new(bd, "volumes_per_level", json_integer(6)), "raw_length");
    BAD(json_object_set_new(bd, "units", json_string("W/m^2")), "units");
    BAD(json_object_set_new(bd, "index", json_integer(1)), "index");

    /* A layout the lookup does not read: 4 values per cell, then an index
     * volume after them (R5.12), as an octree technique would send. */
    json_t *o = json_deep_copy(h);
    json_t *od = json_object_get(o, LPVP_VOLUME_DESC_KEY);
    json_object_set_new(od, "technique", json_string("octree_lpv"));
    json_object_set_new(od, "values_per_cell", json_integer(4));
    json_object_set_new(od, "values", json_pack("[s,s,s,s]", "a", "b", "c", "d"));
    json_object_set_new(od, "index", json_pack("{s:i, s:[i,i,i], s:i, s:s, s:I, s:I}", "level", 0, "dims", 1, 1, 2,
                                               "values_per_cell", 1, "value_type", LPVP_INDEX_VALUE_TYPE,
                                               "raw_offset", (json_int_t)(16 * 4 * 2), "raw_length",
                                               (json_int_t)(2 * 4)));
    json_object_set_new(o, "raw_length", json_integer(16 * 4 * 2 + 2 * 4));
    assert_int_equal(lpvp_volume_header_parse(o, &back, err, sizeof err), 0);
    assert_int_equal(back.layout.values_per_cell, 4);
    assert_false(back.layout.sh_values);
    assert_true(back.layout.has_index);
    assert_int_equal(back.layout.index.raw_offset, 128);
    assert_int_equal(lpvp_volume_values_bytes(&back), 128);
    assert_int_equal(lpvp_volume_layout_lookup_check(&back.layout, err, sizeof err), -1);
    assert_non_null(strstr(err, "octree_lpv"));
    assert_non_null(strstr(err, "4 values per cell"));
    {
        json_t *b = json_deep_copy(o);
        json_object_set_new(json_object_get(json_object_get(b, LPVP_VOLUME_DESC_KEY), "index"), "raw_offset",
                            json_integer(0));
        expect_refused(b, "index.raw_offset");
        b = json_deep_copy(o);
        json_object_set_new(json_object_get(json_object_get(b, LPVP_VOLUME_DESC_KEY), "index"), "raw_length",
                            json_integer(4));
        expect_refused(b, "index.raw_length");
        b = json_deep_copy(o);
        json_object_set_new(json_object_get(json_object_get(b, LPVP_VOLUME_DESC_KEY), "index"), "level",
                            json_integer(2));
        expect_refused(b, "index.level");
        b = json_deep_copy(o);
        json_object_set_new(b, "raw_length", json_integer(16 * 4 * 2));
        expect_refused(b, "raw_length");
    }
    json_decref(o);
#undef BAD
    json_decref(h);
}

static void test_addresses(void **state)
{
    (void)state;
    char host[64], err[128];
    unsigned port = 1;
    assert_int_equal(lpvp_split_host_port("127.0.0.1:7070", host, sizeof host, &port, err, sizeof err), 0);
    assert_string_equal(host, "127.0.0.1");
    assert_int_equal(port, 7070);
    assert_int_equal(lpvp_split_host_port("[::1]:80", host, sizeof host, &port, err, sizeof err), 0);
    assert_string_equal(host, "::1");
    assert_int_equal(port, 80);
    assert_int_equal(lpvp_split_host_port("9000", host, sizeof host, &port, err, sizeof err), 0);
    assert_string_equal(host, "127.0.0.1");
    assert_int_equal(port, 9000);
    assert_int_equal(lpvp_split_host_port(":0", host, sizeof host, &port, err, sizeof err), 0);
    assert_int_equal(port, 0);
    const char *bad[] = {"host:", "host:65536", "host:-1", "host:12ab", "abc", ""};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        err[0] = '\0';
        assert_int_equal(lpvp_split_host_port(bad[i], host, sizeof host, &port, err, sizeof err), -1);
        assert_non_null(strstr(err, bad[i]));
    }
    char path[256];
    setenv("XDG_RUNTIME_DIR", "/nonexistent-lpvd-dir", 1);
    lpvp_default_socket_path(path, sizeof path);
    assert_int_equal(strncmp(path, "/tmp/lpvd-", 10), 0);
    setenv("XDG_RUNTIME_DIR", "/tmp", 1);
    lpvp_default_socket_path(path, sizeof path);
    assert_string_equal(path, "/tmp/lpvd.sock");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_names),
        cmocka_unit_test(test_header_roundtrip),
        cmocka_unit_test(test_header_errors),
        cmocka_unit_test(test_parser_chunks),
        cmocka_unit_test(test_parser_several_in_one_buffer),
        cmocka_unit_test(test_parser_hostile),
        cmocka_unit_test(test_body_parse),
        cmocka_unit_test(test_field_getters),
        cmocka_unit_test(test_error_frame),
        cmocka_unit_test(test_fp16_decode_all),
        cmocka_unit_test(test_fp16_rounding),
        cmocka_unit_test(test_fp16_many_floats),
        cmocka_unit_test(test_volume_pack),
        cmocka_unit_test(test_xor_delta),
        cmocka_unit_test(test_zstd),
        cmocka_unit_test(test_volume_header_and_decode),
        cmocka_unit_test(test_volume_cascades),
        cmocka_unit_test(test_volume_description),
        cmocka_unit_test(test_volume_octree_levels),
        cmocka_unit_test(test_volume_iv),
        cmocka_unit_test(test_iv_lookup),
        cmocka_unit_test(test_volume_visibility),
        cmocka_unit_test(test_probes_lookup),
        cmocka_unit_test(test_addresses),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
