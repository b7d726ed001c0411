/* batch_manifest.c - see batch_manifest.h. */
#include "batch_manifest.h"

#include "manifest.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

FILE *lpvd_manifest_open(const char *dir, int shard, int shards, char *err, size_t err_size)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/manifest-%d-of-%d.jsonl", dir, shard, shards);
    FILE *f = fopen(path, "a+");
    if (!f) {
        snprintf(err, err_size, "%s: %s", path, strerror(errno));
        return NULL;
    }
    /* a line torn by a crash has no newline: the next entry starts its own line */
    if (fseek(f, -1, SEEK_END) == 0 && fgetc(f) != '\n' && (fputc('\n', f) == EOF || fflush(f) != 0)) {
        snprintf(err, err_size, "%s: %s", path, strerror(errno));
        fclose(f);
        return NULL;
    }
    return f;
}

int lpvd_manifest_append(FILE *f, const json_t *entry)
{
    char *s = json_dumps(entry, JSON_COMPACT | JSON_SORT_KEYS);
    if (!s)
        return -1;
    int rc = fprintf(f, "%s\n", s) < 0 || fflush(f) != 0 || fsync(fileno(f)) != 0 ? -1 : 0;
    free(s);
    return rc;
}

int lpvd_manifest_merge(const char *dir, int *skipped, char *err, size_t err_size)
{
    lpv_manifest m;
    if (lpv_manifest_read(dir, &m, stderr, err, err_size) != 0) {
        lpv_manifest_free(&m);
        return -1;
    }
    *skipped = (int)m.skipped;
    char path[4096], tmp[4200];
    snprintf(path, sizeof path, "%s/manifest.jsonl", dir);
    snprintf(tmp, sizeof tmp, "%s.tmp-%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    int rc = -1;
    if (!f) {
        snprintf(err, err_size, "%s: %s", tmp, strerror(errno));
    } else {
        int ok = 1;
        for (size_t i = 0; i < m.count && ok; ++i) /* by index: the job's order */
            ok = lpvd_manifest_append(f, m.items[i].line) == 0;
        if (fclose(f) != 0 || !ok || rename(tmp, path) != 0) {
            snprintf(err, err_size, "%s: could not write (%s)", path, strerror(errno));
            unlink(tmp);
        } else {
            rc = (int)m.count;
        }
    }
    lpv_manifest_free(&m);
    return rc;
}
