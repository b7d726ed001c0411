/*
 * report_fixture.h - a batch job's output folder for the report's tests
 * (test_batch_report.c, report_browser.py through report_fixture_main.c).
 *
 * Two shard manifests, manifest-0-of-2.jsonl and manifest-1-of-2.jsonl, with
 * three items in index order:
 *   0 "cornell/cam0/a&b<1>"   ok, images/a.png (600x300 PNG)
 *   1 "blinds/\"cam1\""        failed ("timeout"), then retried ok in a later
 *                              line: a volume output, then images/b.exr
 *                              (40x30 radiance, alpha 0 in its left quarter)
 *   2 "courtyard/cam0/fast"   failed, an error holding <script>, & and quotes
 * and a torn last line in shard 1. So: 5 lines, 1 skipped, 1 superseded;
 * started 15:20:00.000Z at the earliest, finished 15:20:36.000Z at the
 * latest (36 s, 200 ok items per hour); ms.total 100, 300 and 50 (mean
 * 150.0); stages inject 1 + 2 + 2 and propagate 5 + 10 (25 % and 75 %).
 */
#ifndef LPVT_REPORT_FIXTURE_H
#define LPVT_REPORT_FIXTURE_H

#include <stddef.h>

#define LPVT_REPORT_ERROR "shader <script>alert(\"x\")</script> & \"quoted\""

/* Writes the folder's files into dir (which must exist). Returns 0, or -1
 * with a message in err. */
int lpvt_report_fixture(const char *dir, char *err, size_t err_size);

#endif
