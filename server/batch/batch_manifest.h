/*
 * batch_manifest.h - writing lpvd batch's manifests (docs/batch.md): JSON
 * Lines, one object per finished item, appended by each shard to
 * OUT/manifest-I-of-N.jsonl and combined by --merge into OUT/manifest.jsonl.
 * Reading them (which line of an id counts, torn lines) is report/manifest.h's,
 * shared with the report.
 */
#ifndef LPVD_BATCH_MANIFEST_H
#define LPVD_BATCH_MANIFEST_H

#include <stddef.h>
#include <stdio.h>

#include <jansson.h>

/* Opens (creates) OUT/manifest-I-of-N.jsonl for appending. */
FILE *lpvd_manifest_open(const char *dir, int shard, int shards, char *err, size_t err_size);

/* Appends entry as one line and makes it durable (fflush + fsync) before
 * returning, so an item is recorded only once its outputs are in place.
 * Returns 0 or -1. */
int lpvd_manifest_append(FILE *f, const json_t *entry);

/* --merge: every entry of the folder (lpv_manifest_read) written to
 * OUT/manifest.jsonl in the items' "index" order, replacing it atomically.
 * Returns the number of entries, or -1 with a message in err. */
int lpvd_manifest_merge(const char *dir, int *skipped, char *err, size_t err_size);

#endif
