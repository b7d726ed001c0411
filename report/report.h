/*
 * report.h - the report of an `lpvd batch` job (docs/batch.md, "Report").
 *
 * Reads the manifests in the job's output folder DIR (manifest.h: the merged
 * DIR/manifest.jsonl, else every DIR/manifest-I-of-N.jsonl; the last line of
 * each id counts) and writes, in DIR:
 *   thumbs/<n>.png  the thumbnail of item n (n: the item's row in the report,
 *                   from 0, items ordered by "index"), for every ok item with
 *                   a PNG or EXR image output (thumbs.h);
 *   contact.png     every item as a tile of a grid (contact.h);
 *   report.html     one self-contained page: the job's totals, then a row per
 *                   item (report_html.h).
 * Used by `lpvd batch --report` and by lpvd-report.
 */
#ifndef LPV_BATCH_REPORT_H
#define LPV_BATCH_REPORT_H

#include <stddef.h>
#include <stdio.h>

typedef struct lpv_batch_report_summary {
    long items, ok, failed;             /* distinct ids; failed: every status but "ok" */
    long lines, skipped, superseded;    /* manifest lines read, skipped (not JSON objects with an id),
                                           superseded by a later line of the same id */
    long thumbs, thumbs_missing;        /* ok items with a thumbnail, and without one */
    size_t contact_tiles;               /* items on contact.png (0: none written) */
    int contact_width, contact_height;  /* its size in pixels */
} lpv_batch_report_summary;

/* Writes DIR's report. Warnings (skipped manifest lines, ok items without a
 * thumbnail: one line each) go to `warnings` when it is not NULL; they do not
 * fail the report. summary may be NULL. With no item at all the page says so
 * and no contact.png is left. Returns 0, or -1 with a message in err: no
 * manifest in DIR, a manifest that cannot be read, a file that cannot be
 * written, out of memory. */
int lpv_batch_report(const char *dir, lpv_batch_report_summary *summary, FILE *warnings, char *err,
                     size_t err_size);

#endif
