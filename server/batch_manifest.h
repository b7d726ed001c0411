/*
 * batch_manifest.h - lpvd batch's manifests (docs/batch.md): JSON Lines,
 * one object per finished item, appended by each shard to
 * OUT/manifest-I-of-N.jsonl and combined by --merge into OUT/manifest.jsonl.
 * A later line of the same id supersedes an earlier one; a line that is not
 * a JSON object with a string "id" (a torn last line after a crash) is
 * skipped and counted.
 */
#ifndef LPVD_BATCH_MANIFEST_H
#define LPVD_BATCH_MANIFEST_H

#include <stddef.h>
#include <stdio.h>

#include <jansson.h>

/* Every entry of the folder's manifests (manifest.jsonl and each
 * manifest-*-of-*.jsonl, in name order, lines in file order), the last per
 * id kept: a JSON object mapping id -> entry. *skipped gets the number of
 * unreadable lines. NULL with a message in err if the folder cannot be
 * read (no manifest at all is an empty object). */
json_t *lpvd_manifest_load(const char *dir, int *skipped, char *err, size_t err_size);

/* Opens (creates) OUT/manifest-I-of-N.jsonl for appending. */
FILE *lpvd_manifest_open(const char *dir, int shard, int shards, char *err, size_t err_size);

/* Appends entry as one line and makes it durable (fflush + fsync) before
 * returning, so an item is recorded only once its outputs are in place.
 * Returns 0 or -1. */
int lpvd_manifest_append(FILE *f, const json_t *entry);

/* --merge: every entry of the folder (lpvd_manifest_load) written to
 * OUT/manifest.jsonl in the items' "index" order, replacing it atomically.
 * Returns the number of entries, or -1 with a message in err. */
int lpvd_manifest_merge(const char *dir, int *skipped, char *err, size_t err_size);

#endif
