/*
 * manifest.h - the lines an `lpvd batch` job appended to its output folder,
 * one per finished work item, reduced to the last line of every id.
 *
 * Files: DIR/manifest.jsonl when it exists (the merged manifest, `lpvd batch
 * --merge`), then every DIR/manifest-I-of-N.jsonl (one per shard, appended
 * by `lpvd batch`), read in order of N then I.
 * Within a file a later line with the same id supersedes an earlier one (a
 * failed item retried); between two files the line with the later
 * "finished" time wins (the later file when either time is missing). Lines
 * that are not JSON objects with a non-empty string "id" (a torn last line
 * after a crash) are skipped and counted, with a warning; blank lines are
 * ignored.
 */
#ifndef LPV_BATCH_MANIFEST_H
#define LPV_BATCH_MANIFEST_H

#include <stddef.h>
#include <stdio.h>

#include <jansson.h>

typedef struct lpv_manifest_item {
    const char *id; /* the line's "id" (owned by line) */
    json_t *line;   /* the kept line, a JSON object (a reference the manifest owns) */
    long index;     /* the line's integer "index", or LONG_MAX without one */
    long seq;       /* order of the id's first appearance */
    int file;       /* which of files[] the kept line came from */
} lpv_manifest_item;

typedef struct lpv_manifest {
    lpv_manifest_item *items; /* one per id, by index then first appearance */
    size_t count;
    size_t capacity; /* of items */
    char **files; /* the file names read (without DIR), in reading order */
    size_t nfiles;
    long lines;           /* non-blank lines read */
    long skipped;         /* lines skipped: not a JSON object with a string id */
    long superseded;      /* lines replaced by a later line of the same id */
    double first_started; /* earliest "started" of any line read (retries included), NAN if none */
    double last_finished; /* latest "finished" of any line read, NAN if none */
} lpv_manifest;

/* Reads DIR's manifests into m (zeroed first). Warnings, one line each (the
 * first 20 skipped lines, then a count), go to `warnings` when not NULL.
 * Returns 0, or -1 with a message in err: no manifest in DIR, a file that
 * cannot be read, out of memory. lpv_manifest_free(m) in both cases. */
int lpv_manifest_read(const char *dir, lpv_manifest *m, FILE *warnings, char *err, size_t err_size);
/* The same, but a folder with no manifest (or no folder) is no error: 0 and
 * no items (a job's first run). */
int lpv_manifest_read_any(const char *dir, lpv_manifest *m, FILE *warnings, char *err, size_t err_size);
void lpv_manifest_free(lpv_manifest *m);

/* 1 when the item's "status" is "ok"; anything else counts as failed. */
int lpv_manifest_item_ok(const lpv_manifest_item *item);

#endif
