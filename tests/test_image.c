/* test_image.c - image_io.h through OpenImageIO: PNG (8-bit) and EXR (float)
 * round trips, channel conversion on read, resizing, and clean failures. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image_io.h"
#include "test_util.h"

/* Sanitizer build only (the runtime calls these hooks when it is linked in;
 * otherwise they are unused). OpenImageIO 2.4 leaks a std::string when libpng
 * longjmps out of its read callback on the truncated PNG read below; the
 * frames that name it lie beyond libstdc++, which has no frame pointers, so
 * this (small, fast) test unwinds allocations the slow way. The same
 * suppression is in tests/lsan.supp. */
const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "fast_unwind_on_malloc=0";
}
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void)
{
    return "leak:OpenImageIO_v2_4::PNGInput::PngReadCallback\n";
}

static const char *tmp_path(const char *name)
{
    static char slots[4][512];
    static int next;
    char *p = slots[next++ & 3];
    snprintf(p, 512, "%s/%s", lpvt_tmpdir(), name);
    return p;
}

static void test_png_roundtrip(void **state)
{
    (void)state;
    enum { W = 7, H = 5 };
    uint8_t px[W * H * 4];
    for (int i = 0; i < W * H * 4; i++)
        px[i] = (uint8_t)((i * 37 + 11) & 0xff);
    px[0] = 0;
    px[1] = 255;
    const char *path = tmp_path("rgba8.png");
    char err[1024] = "";
    if (lpv_image_write_u8(path, W, H, 4, px, err, sizeof err) != 0)
        fail_msg("%s", err);

    int w = 0, h = 0;
    float *rd = NULL;
    if (lpv_image_read_f32(path, 4, &w, &h, &rd, err, sizeof err) != 0)
        fail_msg("%s", err);
    assert_int_equal(w, W);
    assert_int_equal(h, H);
    for (int i = 0; i < W * H * 4; i++) {
        /* 8-bit values come back as k/255: exact after rescaling. */
        long k = lroundf(rd[i] * 255.0f);
        assert_int_equal(k, px[i]);
        assert_true(fabsf(rd[i] - (float)px[i] / 255.0f) < 1e-6f);
    }
    free(rd);

    /* Reading RGBA as RGB drops alpha; as one channel keeps the first. */
    rd = NULL;
    assert_int_equal(lpv_image_read_f32(path, 3, &w, &h, &rd, err, sizeof err), 0);
    for (int i = 0; i < W * H; i++)
        for (int c = 0; c < 3; c++)
            assert_int_equal(lroundf(rd[i * 3 + c] * 255.0f), px[i * 4 + c]);
    free(rd);
    rd = NULL;
    assert_int_equal(lpv_image_read_f32(path, 1, &w, &h, &rd, err, sizeof err), 0);
    for (int i = 0; i < W * H; i++)
        assert_int_equal(lroundf(rd[i] * 255.0f), px[i * 4]);
    free(rd);
}

static void test_png_rgb_read_rgba(void **state)
{
    (void)state;
    enum { W = 3, H = 2 };
    uint8_t px[W * H * 3] = {0, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100, 110, 120, 130, 140, 250, 251, 255};
    const char *path = tmp_path("rgb8.png");
    char err[1024] = "";
    if (lpv_image_write_u8(path, W, H, 3, px, err, sizeof err) != 0)
        fail_msg("%s", err);
    int w = 0, h = 0;
    float *rd = NULL;
    assert_int_equal(lpv_image_read_f32(path, 4, &w, &h, &rd, err, sizeof err), 0);
    for (int i = 0; i < W * H; i++) {
        for (int c = 0; c < 3; c++)
            assert_int_equal(lroundf(rd[i * 4 + c] * 255.0f), px[i * 3 + c]);
        assert_true(rd[i * 4 + 3] == 1.0f); /* missing alpha is 1 */
    }
    free(rd);

    /* A grey file fills every colour channel. */
    uint8_t grey[W * H] = {0, 1, 2, 128, 254, 255};
    path = tmp_path("grey8.png");
    if (lpv_image_write_u8(path, W, H, 1, grey, err, sizeof err) != 0)
        fail_msg("%s", err);
    rd = NULL;
    assert_int_equal(lpv_image_read_f32(path, 4, &w, &h, &rd, err, sizeof err), 0);
    for (int i = 0; i < W * H; i++) {
        for (int c = 0; c < 3; c++)
            assert_int_equal(lroundf(rd[i * 4 + c] * 255.0f), grey[i]);
        assert_true(rd[i * 4 + 3] == 1.0f);
    }
    free(rd);
}

static void test_exr_roundtrip(void **state)
{
    (void)state;
    enum { W = 4, H = 3, C = 4 };
    float px[W * H * C];
    for (int i = 0; i < W * H * C; i++)
        px[i] = (float)i * 0.37f - 3.0f;
    px[0] = 1234.5f;
    px[1] = 1e-6f;
    px[2] = 0.0f;
    px[5] = 65504.0f * 4.0f; /* beyond half: must survive as float */
    px[6] = 1.0f / 3.0f;
    const char *path = tmp_path("linear.exr");
    char err[1024] = "";
    assert_int_equal(lpv_image_is_float_format(path), 1);
    if (lpv_image_write_f32(path, W, H, C, px, err, sizeof err) != 0)
        fail_msg("%s", err);
    int w = 0, h = 0;
    float *rd = NULL;
    if (lpv_image_read_f32(path, C, &w, &h, &rd, err, sizeof err) != 0)
        fail_msg("%s", err);
    assert_int_equal(w, W);
    assert_int_equal(h, H);
    for (int i = 0; i < W * H * C; i++) {
        if (rd[i] != px[i])
            fail_msg("sample %d: wrote %.9g, read %.9g", i, (double)px[i], (double)rd[i]);
    }
    assert_true(rd[0] == 1234.5f);
    assert_true(rd[1] == 1e-6f);
    free(rd);

    /* Three-channel EXR read as RGBA: alpha 1. */
    path = tmp_path("rgb.exr");
    if (lpv_image_write_f32(path, W, H, 3, px, err, sizeof err) != 0)
        fail_msg("%s", err);
    rd = NULL;
    assert_int_equal(lpv_image_read_f32(path, 4, &w, &h, &rd, err, sizeof err), 0);
    for (int i = 0; i < W * H; i++) {
        for (int c = 0; c < 3; c++)
            assert_true(rd[i * 4 + c] == px[i * 3 + c]);
        assert_true(rd[i * 4 + 3] == 1.0f);
    }
    free(rd);
}

static void test_float_format(void **state)
{
    (void)state;
    assert_int_equal(lpv_image_is_float_format("a.exr"), 1);
    assert_int_equal(lpv_image_is_float_format("/x/y/A.EXR"), 1);
    assert_int_equal(lpv_image_is_float_format("a.png"), 0);
    assert_int_equal(lpv_image_is_float_format("exr"), 0);
    assert_int_equal(lpv_image_is_float_format("dir.exr/file"), 0);
    assert_int_equal(lpv_image_is_float_format(NULL), 0);
}

static void test_write_errors(void **state)
{
    (void)state;
    uint8_t px[4] = {1, 2, 3, 4};
    float fpx[4] = {1, 2, 3, 4};
    char err[1024] = "";
    const char *path = tmp_path("no/such/folder/out.png");
    assert_int_equal(lpv_image_write_u8(path, 1, 1, 4, px, err, sizeof err), -1);
    assert_non_null(strstr(err, path));
    fprintf(stderr, "[ image    ] expected failure: %s\n", err);

    err[0] = '\0';
    path = tmp_path("no/such/folder/out.exr");
    assert_int_equal(lpv_image_write_f32(path, 1, 1, 4, fpx, err, sizeof err), -1);
    assert_non_null(strstr(err, path));

    err[0] = '\0';
    path = tmp_path("unknown.format-xyz");
    assert_int_equal(lpv_image_write_u8(path, 1, 1, 4, px, err, sizeof err), -1);
    assert_non_null(strstr(err, path));

    err[0] = '\0';
    path = tmp_path("bad.png");
    assert_int_equal(lpv_image_write_u8(path, 0, 1, 4, px, err, sizeof err), -1);
    assert_non_null(strstr(err, path));
    assert_int_equal(lpv_image_write_u8(path, 1, 1, 5, px, err, sizeof err), -1);
    assert_int_equal(lpv_image_write_u8(path, 1, 1, 4, NULL, err, sizeof err), -1);
    assert_int_equal(lpv_image_write_u8(NULL, 1, 1, 4, px, err, sizeof err), -1);
}

static void test_read_errors(void **state)
{
    (void)state;
    char err[1024] = "";
    int w = -1, h = -1;
    float *rd = (float *)&w; /* must be reset to NULL */

    const char *missing = tmp_path("does-not-exist.png");
    assert_int_equal(lpv_image_read_f32(missing, 4, &w, &h, &rd, err, sizeof err), -1);
    assert_null(rd);
    assert_non_null(strstr(err, missing));

    static const char garbage[] = "this is not an image at all\n\x01\x02\x03";
    const char *g = lpvt_write_file(lpvt_tmpdir(), "garbage.png", garbage, sizeof garbage);
    err[0] = '\0';
    rd = (float *)&w;
    assert_int_equal(lpv_image_read_f32(g, 4, &w, &h, &rd, err, sizeof err), -1);
    assert_null(rd);
    assert_non_null(strstr(err, g));
    fprintf(stderr, "[ image    ] expected failure: %s\n", err);

    g = lpvt_write_file(lpvt_tmpdir(), "garbage.exr", garbage, sizeof garbage);
    err[0] = '\0';
    assert_int_equal(lpv_image_read_f32(g, 4, &w, &h, &rd, err, sizeof err), -1);
    assert_null(rd);
    assert_non_null(strstr(err, g));

    /* A truncated PNG: a valid header, then nothing. */
    uint8_t px[16 * 16 * 4];
    memset(px, 200, sizeof px);
    const char *good = tmp_path("truncated.png");
    assert_int_equal(lpv_image_write_u8(good, 16, 16, 4, px, err, sizeof err), 0);
    FILE *f = fopen(good, "rb");
    assert_non_null(f);
    uint8_t head[40];
    assert_int_equal(fread(head, 1, sizeof head, f), sizeof head);
    fclose(f);
    g = lpvt_write_file(lpvt_tmpdir(), "truncated.png", head, sizeof head);
    err[0] = '\0';
    assert_int_equal(lpv_image_read_f32(g, 4, &w, &h, &rd, err, sizeof err), -1);
    assert_null(rd);
    assert_non_null(strstr(err, g));

    /* Bad arguments. */
    assert_int_equal(lpv_image_read_f32(good, 0, &w, &h, &rd, err, sizeof err), -1);
    assert_int_equal(lpv_image_read_f32(good, 4, NULL, &h, &rd, err, sizeof err), -1);
    assert_int_equal(lpv_image_read_f32(NULL, 4, &w, &h, &rd, err, sizeof err), -1);
}

/* Resizing is an area average: a 1-pixel checkerboard halved in each
 * direction is flat grey, a ramp shrunk by 3 gives the means of its thirds,
 * and HDR values next to black never ring below 0. */
static void test_resize(void **state)
{
    (void)state;
    enum { W = 12, H = 8 };
    float src[W * H * 2];
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            src[(y * W + x) * 2] = (float)((x + y) & 1);         /* checkerboard */
            src[(y * W + x) * 2 + 1] = x < W / 2 ? 0.0f : 1000.0f; /* a hard HDR edge */
        }
    char err[512] = "";
    float *out = NULL;
    if (lpv_image_resize_f32(src, W, H, 2, W / 2, H / 2, &out, err, sizeof err) != 0)
        fail_msg("%s", err);
    for (int i = 0; i < (W / 2) * (H / 2); i++) {
        assert_true(fabsf(out[2 * i] - 0.5f) < 1e-5f);
        assert_true(out[2 * i + 1] >= 0.0f && out[2 * i + 1] <= 1000.0f);
    }
    free(out);

    float ramp[9];
    for (int x = 0; x < 9; x++)
        ramp[x] = (float)x;
    out = NULL;
    assert_int_equal(lpv_image_resize_f32(ramp, 9, 1, 1, 3, 1, &out, err, sizeof err), 0);
    assert_true(fabsf(out[0] - 1.0f) < 1e-5f);
    assert_true(fabsf(out[1] - 4.0f) < 1e-5f);
    assert_true(fabsf(out[2] - 7.0f) < 1e-5f);
    free(out);

    out = NULL;
    assert_int_equal(lpv_image_resize_f32(ramp, 9, 1, 1, 0, 1, &out, err, sizeof err), -1);
    assert_null(out);
    assert_int_equal(lpv_image_resize_f32(ramp, 9, 1, 5, 3, 1, &out, err, sizeof err), -1);
    assert_int_equal(lpv_image_resize_f32(NULL, 9, 1, 1, 3, 1, &out, err, sizeof err), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_png_roundtrip),  cmocka_unit_test(test_png_rgb_read_rgba),
        cmocka_unit_test(test_exr_roundtrip),  cmocka_unit_test(test_float_format),
        cmocka_unit_test(test_write_errors),   cmocka_unit_test(test_read_errors),
        cmocka_unit_test(test_resize),
    };
    return cmocka_run_group_tests_name("image", tests, NULL, NULL);
}
