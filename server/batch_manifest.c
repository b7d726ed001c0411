/* batch_manifest.c - see batch_manifest.h. */
#include "batch_manifest.h"

#include <dirent.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int is_manifest_name(const char *name)
{
    int i, n, end = 0;
    if (strcmp(name, "manifest.jsonl") == 0)
        return 1;
    return sscanf(name, "manifest-%d-of-%d.jsonl%n", &i, &n, &end) == 2 && end > 0 && name[end] == '\0';
}

/* manifest.jsonl (the last merge) first, then the shards' own files, which
 * may hold newer entries (a shard re-run after a merge). */
static int cmp_str(const void *a, const void *b)
{
    const char *x = *(char *const *)a, *y = *(char *const *)b;
    int mx = strcmp(x, "manifest.jsonl") == 0, my = strcmp(y, "manifest.jsonl") == 0;
    return mx != my ? my - mx : strcmp(x, y);
}

/* The lines of one file into by_id. */
static void load_file(const char *path, json_t *by_id, int *skipped)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return;
    char *line = NULL;
    size_t cap = 0;
    ssize_t len;
    while ((len = getline(&line, &cap, f)) >= 0) {
        if (len == 0 || (len == 1 && line[0] == '\n'))
            continue;
        json_t *e = json_loadb(line, (size_t)len, 0, NULL);
        const json_t *id = json_object_get(e, "id");
        if (!json_is_object(e) || !json_is_string(id)) {
            ++*skipped;
            json_decref(e);
            continue;
        }
        json_object_set_new(by_id, json_string_value(id), e);
    }
    free(line);
    fclose(f);
}

json_t *lpvd_manifest_load(const char *dir, int *skipped, char *err, size_t err_size)
{
    *skipped = 0;
    DIR *d = opendir(dir);
    if (!d) {
        if (errno == ENOENT)
            return json_object();
        snprintf(err, err_size, "%s: %s", dir, strerror(errno));
        return NULL;
    }
    char **names = NULL;
    size_t count = 0, cap = 0;
    struct dirent *de;
    while ((de = readdir(d)) != NULL) {
        if (!is_manifest_name(de->d_name))
            continue;
        if (count == cap) {
            cap = cap ? 2 * cap : 16;
            char **nn = realloc(names, cap * sizeof *nn);
            if (!nn)
                break;
            names = nn;
        }
        names[count++] = strdup(de->d_name);
    }
    closedir(d);
    qsort(names, count, sizeof *names, cmp_str);
    json_t *by_id = json_object();
    for (size_t i = 0; i < count; ++i) {
        char path[4096];
        if (names[i] && by_id) {
            snprintf(path, sizeof path, "%s/%s", dir, names[i]);
            load_file(path, by_id, skipped);
        }
        free(names[i]);
    }
    free(names);
    if (!by_id)
        snprintf(err, err_size, "out of memory");
    return by_id;
}

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

static int by_index(const void *a, const void *b)
{
    json_int_t x = json_integer_value(json_object_get(*(json_t *const *)a, "index"));
    json_int_t y = json_integer_value(json_object_get(*(json_t *const *)b, "index"));
    return x < y ? -1 : x > y;
}

int lpvd_manifest_merge(const char *dir, int *skipped, char *err, size_t err_size)
{
    json_t *by_id = lpvd_manifest_load(dir, skipped, err, err_size);
    if (!by_id)
        return -1;
    size_t n = json_object_size(by_id), k = 0;
    json_t **list = calloc(n ? n : 1, sizeof *list);
    const char *key;
    json_t *v;
    json_object_foreach(by_id, key, v) { list[k++] = v; }
    qsort(list, n, sizeof *list, by_index);
    char path[4096], tmp[4200];
    snprintf(path, sizeof path, "%s/manifest.jsonl", dir);
    snprintf(tmp, sizeof tmp, "%s.tmp-%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    int rc = -1;
    if (!f) {
        snprintf(err, err_size, "%s: %s", tmp, strerror(errno));
    } else {
        int ok = 1;
        for (size_t i = 0; i < n && ok; ++i)
            ok = lpvd_manifest_append(f, list[i]) == 0;
        if (fclose(f) != 0 || !ok || rename(tmp, path) != 0) {
            snprintf(err, err_size, "%s: could not write (%s)", path, strerror(errno));
            unlink(tmp);
        } else {
            rc = (int)n;
        }
    }
    free(list);
    json_decref(by_id);
    return rc;
}
