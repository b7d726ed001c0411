/* batch_manifest.c - see batch_manifest.h. */
#include "batch_manifest.h"

#include "manifest.h"
#include "write_beneath.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

FILE *lpvd_manifest_open(const char *dir, int shard, int shards, char *err, size_t err_size)
{
    char name[128];
    snprintf(name, sizeof name, "manifest-%d-of-%d.jsonl", shard, shards);
    /* beneath --out and never through a link: a linked manifest would have
     * had the lines appended to its target (issue 31, item 7) */
    const int dfd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    const int fd = dfd < 0 ? -1 : lpv_open_append_beneath(dfd, name);
    const int e = errno;
    if (dfd >= 0)
        close(dfd);
    FILE *f = fd < 0 ? NULL : fdopen(fd, "a+");
    if (!f) {
        snprintf(err, err_size, "%s/%s: %s", dir, name,
                 e == ELOOP ? "a symbolic link (outputs are never written through one)"
                 : e == EINVAL ? "not a regular file"
                               : strerror(e));
        if (fd >= 0)
            close(fd);
        return NULL;
    }
    /* a line torn by a crash has no newline: the next entry starts its own line */
    if (fseek(f, -1, SEEK_END) == 0 && fgetc(f) != '\n' && (fputc('\n', f) == EOF || fflush(f) != 0)) {
        snprintf(err, err_size, "%s/%s: %s", dir, name, strerror(errno));
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

/* The merged manifest's lines, by index: the job's order. */
static int write_lines(const char *path, void *arg, char *err, size_t err_size)
{
    const lpv_manifest *m = arg;
    FILE *f = fopen(path, "w");
    if (!f) {
        snprintf(err, err_size, "manifest.jsonl: %s", strerror(errno));
        return -1;
    }
    int ok = 1;
    for (size_t i = 0; i < m->count && ok; ++i)
        ok = lpvd_manifest_append(f, m->items[i].line) == 0;
    if (fclose(f) != 0 || !ok) {
        snprintf(err, err_size, "manifest.jsonl: could not write (%s)", strerror(errno));
        return -1;
    }
    return 0;
}

int lpvd_manifest_merge(const char *dir, int *skipped, char *err, size_t err_size)
{
    lpv_manifest m;
    if (lpv_manifest_read(dir, &m, stderr, err, err_size) != 0) {
        lpv_manifest_free(&m);
        return -1;
    }
    *skipped = (int)m.skipped;
    const int dfd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    int rc = -1;
    if (dfd < 0)
        snprintf(err, err_size, "%s: %s", dir, strerror(errno));
    else if (lpv_write_beneath(dfd, "manifest.jsonl", write_lines, &m, err, err_size) == 0)
        rc = (int)m.count;
    if (dfd >= 0)
        close(dfd);
    lpv_manifest_free(&m);
    return rc;
}
