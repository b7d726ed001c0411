/*
 * totals.h - a batch job's figures for the top of its report: items ok and
 * failed, throughput, wall time, and where the time went.
 */
#ifndef LPV_BATCH_TOTALS_H
#define LPV_BATCH_TOTALS_H

#include <stddef.h>

#include "manifest.h"

/* One named time summed over the items. */
typedef struct lpv_batch_sum {
    char *name;
    double ms;
} lpv_batch_sum;

typedef struct lpv_batch_totals {
    long items, ok, failed;  /* failed: every status but "ok" */
    double span_s;           /* earliest "started" to latest "finished" of any line read; NAN if unknown */
    double images_per_hour;  /* ok items per hour of span_s; NAN if unknown */
    double item_ms;          /* "ms"."total" summed over the items that have it */
    long item_ms_count;      /* how many items have it */
    double mean_ms;          /* item_ms / item_ms_count; NAN if none */
    lpv_batch_sum *stages;   /* "stages" (GPU ms per engine stage), in order of first appearance */
    size_t nstages;
    double stages_ms;        /* their sum: the base of each stage's share */
    lpv_batch_sum *phases;   /* "ms" without "total" (wall-clock ms of load, tick, render, write...) */
    size_t nphases;
    double phases_ms;
} lpv_batch_totals;

/* The totals over m's kept lines (a superseded line counts nowhere but in the
 * span). Values that are not finite non-negative numbers are left out.
 * Returns 0, or -1 when out of memory. lpv_batch_totals_free(t) in both cases. */
int lpv_batch_totals_compute(const lpv_manifest *m, lpv_batch_totals *t);
void lpv_batch_totals_free(lpv_batch_totals *t);

#endif
