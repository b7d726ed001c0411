/* lpvd_report.c - `lpvd-report DIR`: the report of an `lpvd batch` job's
 * output folder (report/report.h, docs/batch.md "Report"). */
#include "report.h"

#include <stdio.h>
#include <string.h>

int main(int argc, char **argv)
{
    if (argc != 2 || argv[1][0] == '-') {
        FILE *f = argc == 2 && (strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "--help") == 0) ? stdout : stderr;
        fprintf(f, "usage: lpvd-report DIR\n"
                   "Writes DIR/report.html, DIR/contact.png and DIR/thumbs/ from the manifests of the\n"
                   "batch job in DIR (DIR/manifest.jsonl, then every DIR/manifest-I-of-N.jsonl).\n");
        return f == stdout ? 0 : 2;
    }
    char err[1024] = "";
    lpv_batch_report_summary s;
    if (lpv_batch_report(argv[1], &s, stderr, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd-report: %s\n", err);
        return 1;
    }
    fprintf(stderr, "lpvd-report: %s/report.html: %ld items, %ld ok, %ld failed", argv[1], s.items, s.ok, s.failed);
    if (s.skipped)
        fprintf(stderr, ", %ld manifest %s skipped", s.skipped, s.skipped == 1 ? "line" : "lines");
    if (s.thumbs_missing)
        fprintf(stderr, ", %ld ok %s without a thumbnail", s.thumbs_missing, s.thumbs_missing == 1 ? "item" : "items");
    fprintf(stderr, "\n");
    return 0;
}
