/*
 * report_html.h - the page of a batch job's report: report.html, one file
 * with its CSS and script inline, nothing fetched from the network.
 *
 * The top holds the job's totals (totals.h), the manifests read and the
 * lines skipped; then one table row per item: thumbnail (thumbs/<n>.png,
 * linked to the image), id and outputs, scene, settings as key=value, time,
 * ms, status and error. Failed rows are marked (class "failed", a red badge)
 * and a checkbox shows them alone. Every string from a manifest is escaped
 * for HTML, and paths in links are percent-encoded as well.
 *
 * After the page's load event its script checks every thumbnail <img
 * class="thumb">: loaded when complete with naturalWidth > 0. It sets on
 * <body> data-thumbs-loaded and data-thumbs-broken (counts) and
 * data-thumbs-checked="1", and marks broken ones, so a headless browser's
 * --dump-dom shows whether the page works.
 */
#ifndef LPV_BATCH_REPORT_HTML_H
#define LPV_BATCH_REPORT_HTML_H

#include <stddef.h>
#include <stdio.h>

#include "manifest.h"
#include "totals.h"

/* What became of item n's thumbnail. */
typedef struct lpv_batch_report_thumb {
    int made;          /* 1: thumbs/<n>.png was written */
    int width, height; /* its size */
    char note[400];    /* an ok item without one: why */
} lpv_batch_report_thumb;

/* Writes the page to f. title: shown as the heading (the folder's name);
 * thumbs[n] for m->items[n]; contact_tiles: the items on contact.png (0:
 * none). Returns 0, or -1 when writing to f failed. */
int lpv_batch_report_html(FILE *f, const char *title, const lpv_manifest *m, const lpv_batch_totals *t,
                          const lpv_batch_report_thumb *thumbs, size_t contact_tiles);

#endif
