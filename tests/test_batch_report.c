/* test_batch_report.c - the report of a batch job (report/report.h): manifests
 * with a superseded and a torn line, escaping, totals, thumbnails and the
 * contact sheet; the merged manifest first; one id in two shards; items
 * without a thumbnail; no items; clean failures; the manifests' times. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "contact.h"
#include "image_io.h"
#include "report.h"
#include "report_fixture.h"
#include "test_util.h"
#include "timestamp.h"
#include "tonemap.h"

/* A new folder under the test's temporary folder. */
static const char *job_dir(const char *name)
{
    static char slots[4][512];
    static int next;
    char *p = slots[next++ & 3];
    snprintf(p, 512, "%s/%s", lpvt_tmpdir(), name);
    assert_int_equal(mkdir(p, 0777), 0);
    return p;
}

static char *read_text(const char *dir, const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "rb");
    if (!f)
        fail_msg("%s: cannot open", path);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    assert_non_null(s);
    assert_int_equal(fread(s, 1, (size_t)n, f), (size_t)n);
    s[n] = '\0';
    fclose(f);
    return s;
}

static int count(const char *hay, const char *needle)
{
    int n = 0;
    for (const char *p = hay; (p = strstr(p, needle)) != NULL; p += strlen(needle))
        n++;
    return n;
}

static int exists(const char *dir, const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return access(path, F_OK) == 0;
}

/* The image dir/name as RGBA float (k/255 for PNG); fails the test if it
 * cannot be read. */
static float *read_image(const char *dir, const char *name, int *w, int *h)
{
    char path[1024], err[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    float *px = NULL;
    if (lpv_image_read_f32(path, 4, w, h, &px, err, sizeof err) != 0)
        fail_msg("%s", err);
    return px;
}

static void write_manifest(const char *dir, const char *name, const char *text)
{
    lpvt_write_file(dir, name, text, strlen(text));
}

static void assert_contains(const char *html, const char *s)
{
    if (!strstr(html, s))
        fail_msg("report.html lacks: %s", s);
}

static void test_fixture(void **state)
{
    (void)state;
    const char *dir = job_dir("fixture");
    char err[1024] = "";
    if (lpvt_report_fixture(dir, err, sizeof err) != 0)
        fail_msg("%s", err);
    FILE *warnings = tmpfile();
    assert_non_null(warnings);
    lpv_batch_report_summary s;
    if (lpv_batch_report(dir, &s, warnings, err, sizeof err) != 0)
        fail_msg("%s", err);

    assert_int_equal(s.items, 3);
    assert_int_equal(s.ok, 2);
    assert_int_equal(s.failed, 1);
    assert_int_equal(s.lines, 5);
    assert_int_equal(s.skipped, 1);
    assert_int_equal(s.superseded, 1);
    assert_int_equal(s.thumbs, 2);
    assert_int_equal(s.thumbs_missing, 0);

    /* The torn line is named in one warning, and nothing else is. */
    char text[4096] = "";
    rewind(warnings);
    size_t n = fread(text, 1, sizeof text - 1, warnings);
    text[n] = '\0';
    fclose(warnings);
    assert_int_equal(count(text, "\n"), 1);
    assert_non_null(strstr(text, "manifest-1-of-2.jsonl:2: skipped"));

    char *html = read_text(dir, "report.html");
    /* Every id, escaped; none raw. */
    assert_contains(html, "<code>cornell/cam0/a&amp;b&lt;1&gt;</code>");
    assert_contains(html, "<code>blinds/&quot;cam1&quot;</code>");
    assert_contains(html, "<code>courtyard/cam0/fast</code>");
    assert_null(strstr(html, "a&b<1>"));
    assert_null(strstr(html, "blinds/\"cam1\""));
    /* The error, escaped: the page's only <script> is its own. */
    assert_contains(html, "shader &lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt; &amp; &quot;quoted&quot;");
    assert_null(strstr(html, "<script>alert"));
    assert_null(strstr(html, "<script>&"));
    assert_int_equal(count(html, "<script"), 1);
    /* The superseded attempt's error is gone; the failed item is marked. */
    assert_null(strstr(html, "timeout"));
    assert_int_equal(count(html, "<tr class=\"item failed\""), 1);
    assert_contains(html, "<tr class=\"item failed\" id=\"item-2\">");
    assert_int_equal(count(html, "<span class=\"badge failed\">failed</span>"), 1);
    assert_int_equal(count(html, "<tr class=\"item ok\""), 2);
    /* Totals. */
    assert_contains(html, "2 ok");
    assert_contains(html, "1 failed");
    assert_contains(html, "3 items");
    assert_contains(html, "<th>images per hour</th><td>200.0</td>");
    assert_contains(html, "<th>wall time</th><td>36.0 s</td>");
    assert_contains(html, "<th>mean time per item</th><td>150.0 ms</td>");
    assert_contains(html, "<th>inject</th><td class=\"num\">5.0</td><td class=\"num\">25.0 %</td>");
    assert_contains(html, "<th>propagate</th><td class=\"num\">15.0</td><td class=\"num\">75.0 %</td>");
    assert_contains(html, "<th>tick</th><td class=\"num\">260.0</td>");
    assert_contains(html, "1 line skipped");
    assert_contains(html, "1 line superseded");
    /* Settings as key=value, outputs linked (percent-encoded). */
    assert_contains(html,
                    "<code>grid=16</code> <code>technique=iv</code> <code>bounces=2</code> <code>exposure=0.1</code>");
    assert_contains(html, "<code>cascades=[1,2]</code>");
    assert_contains(html, "<a href=\"images/b.exr\">images/b.exr</a>");
    /* A thumbnail per ok item. */
    assert_int_equal(count(html, "<img class=\"thumb\""), 2);
    assert_contains(html, "src=\"thumbs/0.png\" width=\"256\" height=\"128\"");
    assert_contains(html, "src=\"thumbs/1.png\" width=\"40\" height=\"30\"");
    free(html);

    /* Thumbnails: within 256 x 256, aspect kept, no thumbnail for the failed item. */
    int w, h;
    float *t0 = read_image(dir, "thumbs/0.png", &w, &h);
    assert_int_equal(w, 256);
    assert_int_equal(h, 128);
    assert_true(t0[0] < 0.05f);                        /* red ramps from 0 at the left */
    assert_true(t0[(size_t)(w - 1) * 4] > 0.95f);      /* ... to 1 at the right */
    free(t0);
    float *t1 = read_image(dir, "thumbs/1.png", &w, &h);
    assert_int_equal(w, 40);
    assert_int_equal(h, 30);
    /* The EXR's uncovered quarter gets the tone map's background, opaque. */
    const float *bg = t1 + ((size_t)15 * 40 + 2) * 4;
    for (int c = 0; c < 3; c++)
        assert_true(fabsf(bg[c] - LPV_BACKGROUND_SRGB) < 0.01f);
    assert_true(bg[3] == 1.0f);
    /* The covered part is exposed to show something. */
    const float *lit = t1 + ((size_t)15 * 40 + 30) * 4;
    assert_true(lit[0] + lit[1] + lit[2] > 0.2f);
    free(t1);
    assert_false(exists(dir, "thumbs/2.png"));

    /* Contact sheet: 3 tiles in a row; the failed item's tile dark red. */
    size_t tiles;
    int cw, ch;
    lpv_batch_contact_size(3, &tiles, &cw, &ch);
    assert_int_equal(tiles, 3);
    assert_int_equal(cw, 3 * 256 + 4 * 4);
    assert_int_equal(ch, 256 + 2 * 4);
    assert_int_equal(s.contact_tiles, 3);
    assert_int_equal(s.contact_width, cw);
    assert_int_equal(s.contact_height, ch);
    float *sheet = read_image(dir, "contact.png", &w, &h);
    assert_int_equal(w, cw);
    assert_int_equal(h, ch);
    const float *red = sheet + ((size_t)(4 + 128) * (size_t)w + (size_t)(4 + 2 * 260 + 128)) * 4;
    assert_int_equal(lroundf(red[0] * 255.0f), 110);
    assert_int_equal(lroundf(red[1] * 255.0f), 20);
    assert_int_equal(lroundf(red[2] * 255.0f), 20);
    /* Tile 1 holds a 40x30 thumbnail centred: its corner is plain tile grey. */
    const float *grey = sheet + ((size_t)(4 + 5) * (size_t)w + (size_t)(4 + 260 + 5)) * 4;
    assert_int_equal(lroundf(grey[0] * 255.0f), 40);
    free(sheet);
}

/* manifest.jsonl (a merge) is read first and the shards' files after it,
 * so lines a shard appended after the merge count too. */
static void test_merged_first(void **state)
{
    (void)state;
    const char *dir = job_dir("merged");
    char err[1024] = "";
    if (lpvt_report_fixture(dir, err, sizeof err) != 0)
        fail_msg("%s", err);
    write_manifest(dir, "manifest.jsonl",
                   "{\"id\": \"merged/only\", \"index\": 0, \"status\": \"ok\", "
                   "\"outputs\": [{\"kind\": \"image\", \"path\": \"images/a.png\"}]}\n");
    lpv_batch_report_summary s;
    if (lpv_batch_report(dir, &s, NULL, err, sizeof err) != 0)
        fail_msg("%s", err);
    assert_int_equal(s.items, 4); /* the merged line and the fixture's three shard items */
    assert_int_equal(s.ok, 3);
    char *html = read_text(dir, "report.html");
    assert_contains(html, "merged/only");
    assert_contains(html, "courtyard");
    free(html);
}

/* The same id in two shard files: the line that finished later counts,
 * whichever file is read first. */
static void test_across_shards(void **state)
{
    (void)state;
    const char *dir = job_dir("across");
    write_manifest(dir, "manifest-0-of-2.jsonl",
                   "{\"id\": \"x\", \"status\": \"ok\", \"finished\": \"2026-11-25T10:00:05Z\"}\n"
                   "{\"id\": \"y\", \"status\": \"ok\", \"finished\": \"2026-11-25T10:00:01Z\"}\n");
    write_manifest(dir, "manifest-1-of-2.jsonl",
                   "{\"id\": \"x\", \"status\": \"failed\", \"error\": \"older-x\", "
                   "\"finished\": \"2026-11-25T10:00:01Z\"}\n"
                   "{\"id\": \"y\", \"status\": \"failed\", \"error\": \"newer-y\", "
                   "\"finished\": \"2026-11-25T10:00:09Z\"}\n");
    char err[1024] = "";
    lpv_batch_report_summary s;
    if (lpv_batch_report(dir, &s, NULL, err, sizeof err) != 0)
        fail_msg("%s", err);
    assert_int_equal(s.items, 2);
    assert_int_equal(s.superseded, 2);
    assert_int_equal(s.ok, 1);
    assert_int_equal(s.failed, 1);
    char *html = read_text(dir, "report.html");
    assert_null(strstr(html, "older-x"));
    assert_contains(html, "newer-y");
    free(html);
}

/* An ok item whose image is missing or that has none: the report is still
 * written, the row says why, and each gets a warning. */
static void test_missing_image(void **state)
{
    (void)state;
    const char *dir = job_dir("missing");
    write_manifest(dir, "manifest.jsonl",
                   "{\"id\": \"gone\", \"index\": 0, \"status\": \"ok\", "
                   "\"outputs\": [{\"kind\": \"image\", \"path\": \"images/gone.png\"}]}\n"
                   "{\"id\": \"volume-only\", \"index\": 1, \"status\": \"ok\", "
                   "\"outputs\": [{\"kind\": \"volume\", \"path\": \"v.lpvv\"}]}\n");
    FILE *warnings = tmpfile();
    assert_non_null(warnings);
    char err[1024] = "";
    lpv_batch_report_summary s;
    if (lpv_batch_report(dir, &s, warnings, err, sizeof err) != 0)
        fail_msg("%s", err);
    assert_int_equal(s.ok, 2);
    assert_int_equal(s.thumbs, 0);
    assert_int_equal(s.thumbs_missing, 2);
    char text[4096] = "";
    rewind(warnings);
    size_t n = fread(text, 1, sizeof text - 1, warnings);
    text[n] = '\0';
    fclose(warnings);
    assert_int_equal(count(text, "no thumbnail"), 2);
    assert_non_null(strstr(text, "gone.png"));
    char *html = read_text(dir, "report.html");
    assert_int_equal(count(html, "<img class=\"thumb\""), 0);
    assert_contains(html, "no PNG or EXR image output");
    assert_contains(html, "gone.png");
    assert_contains(html, "2 ok items have no thumbnail");
    free(html);
    assert_true(exists(dir, "contact.png"));
}

/* Nothing but a torn line: a page saying so, and no contact sheet (an old
 * one is removed). */
static void test_no_items(void **state)
{
    (void)state;
    const char *dir = job_dir("empty");
    write_manifest(dir, "manifest-0-of-1.jsonl", "\n{\"id\": \"torn");
    write_manifest(dir, "contact.png", "stale");
    char err[1024] = "";
    lpv_batch_report_summary s;
    if (lpv_batch_report(dir, &s, NULL, err, sizeof err) != 0)
        fail_msg("%s", err);
    assert_int_equal(s.items, 0);
    assert_int_equal(s.lines, 1);
    assert_int_equal(s.skipped, 1);
    assert_int_equal(s.contact_tiles, 0);
    assert_false(exists(dir, "contact.png"));
    char *html = read_text(dir, "report.html");
    assert_contains(html, "0 ok");
    assert_contains(html, "No items");
    free(html);
}

static void test_errors(void **state)
{
    (void)state;
    char err[1024] = "";
    char missing[600];
    snprintf(missing, sizeof missing, "%s/does-not-exist", lpvt_tmpdir());
    assert_int_equal(lpv_batch_report(missing, NULL, NULL, err, sizeof err), -1);
    assert_non_null(strstr(err, missing));

    const char *dir = job_dir("no-manifest");
    write_manifest(dir, "manifest-x-of-2.jsonl", "{}\n"); /* not a shard name */
    err[0] = '\0';
    assert_int_equal(lpv_batch_report(dir, NULL, NULL, err, sizeof err), -1);
    assert_non_null(strstr(err, "no manifest"));
    assert_false(exists(dir, "report.html"));
}

static void test_times(void **state)
{
    (void)state;
    double a = -1, b = -1;
    assert_int_equal(lpv_batch_time_parse("1970-01-01T00:00:00Z", &a), 0);
    assert_true(a == 0.0);
    assert_int_equal(lpv_batch_time_parse("2000-01-01T00:00:00Z", &a), 0);
    assert_true(a == 946684800.0);
    assert_int_equal(lpv_batch_time_parse("2026-11-25T15:20:00.123Z", &a), 0);
    assert_int_equal(lpv_batch_time_parse("2026-11-25T16:50:00.123+01:30", &b), 0);
    assert_true(fabs(a - b) < 1e-6);
    assert_int_equal(lpv_batch_time_parse("2026-11-25T14:20:00.123-01:00", &b), 0);
    assert_true(fabs(a - b) < 1e-6);
    assert_true(fabs(a - floor(a) - 0.123) < 1e-4);
    const char *bad[] = {"", "2026-11-25", "2026-11-25T15:20:00", "2026-11-25 15:20:00Z", "2026-13-01T00:00:00Z",
                         "2026-11-25T15:20:00.Z", "2026-11-25T15:20:00Zjunk", "2026-11-25T15:20:00+0100"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        b = 42.0;
        assert_int_equal(lpv_batch_time_parse(bad[i], &b), -1);
        assert_true(b == 42.0);
    }
    assert_int_equal(lpv_batch_time_parse(NULL, &b), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fixture),       cmocka_unit_test(test_merged_first), cmocka_unit_test(test_across_shards),
        cmocka_unit_test(test_missing_image), cmocka_unit_test(test_no_items),     cmocka_unit_test(test_errors),
        cmocka_unit_test(test_times),
    };
    return cmocka_run_group_tests_name("batch_report", tests, NULL, NULL);
}
