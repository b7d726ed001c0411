/* manifest.c - reading a batch job's manifests, last line per id (manifest.h). */
#include "manifest.h"

#include "timestamp.h"

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define MAX_WARNINGS 20 /* skipped lines named one by one; the rest are counted */

static int set_err(char *err, size_t n, const char *fmt, const char *a, const char *b)
{
    if (err && n)
        snprintf(err, n, fmt, a, b);
    return -1;
}

/* "manifest-I-of-N.jsonl" with I and N decimal: 1 and *shard, *of. */
static int shard_name(const char *name, unsigned long *shard, unsigned long *of)
{
    static const char prefix[] = "manifest-", mid[] = "-of-", suffix[] = ".jsonl";
    const char *p = name;
    if (strncmp(p, prefix, sizeof prefix - 1) != 0)
        return 0;
    p += sizeof prefix - 1;
    unsigned long v[2];
    for (int k = 0; k < 2; k++) {
        if (*p < '0' || *p > '9')
            return 0;
        char *end;
        errno = 0;
        v[k] = strtoul(p, &end, 10);
        if (errno || end - p > 9)
            return 0;
        p = end;
        const char *want = k == 0 ? mid : suffix;
        if (strncmp(p, want, strlen(want)) != 0)
            return 0;
        p += strlen(want);
    }
    if (*p != '\0')
        return 0;
    *shard = v[0];
    *of = v[1];
    return 1;
}

typedef struct shard_file {
    char *name;
    unsigned long shard, of;
} shard_file;

static int shard_cmp(const void *a, const void *b)
{
    const shard_file *x = a, *y = b;
    if (x->of != y->of)
        return x->of < y->of ? -1 : 1;
    if (x->shard != y->shard)
        return x->shard < y->shard ? -1 : 1;
    return strcmp(x->name, y->name);
}

#define NO_MANIFEST (-2)

/* The file names to read into m->files: the merged manifest first (when
 * there is one), then the shards' own, which may hold newer lines (a shard
 * run again after a merge). */
static int find_files(const char *dir, lpv_manifest *m, char *err, size_t err_size)
{
    char path[4096];
    struct stat st;
    snprintf(path, sizeof path, "%s/manifest.jsonl", dir);
    const int merged = stat(path, &st) == 0 && S_ISREG(st.st_mode);
    DIR *d = opendir(dir);
    if (!d) {
        set_err(err, err_size, "%s: %s", dir, strerror(errno));
        return errno == ENOENT ? NO_MANIFEST : -1;
    }
    shard_file *list = NULL;
    size_t n = 0, cap = 0;
    int rc = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        unsigned long shard, of;
        if (!shard_name(e->d_name, &shard, &of))
            continue;
        if (n == cap) {
            size_t ncap = cap ? cap * 2 : 16;
            shard_file *nl = realloc(list, ncap * sizeof *nl);
            if (!nl) {
                rc = -1;
                break;
            }
            list = nl;
            cap = ncap;
        }
        list[n].name = strdup(e->d_name);
        if (!list[n].name) {
            rc = -1;
            break;
        }
        list[n].shard = shard;
        list[n].of = of;
        n++;
    }
    closedir(d);
    if (rc == 0 && n + merged > 0) {
        if (n > 1)
            qsort(list, n, sizeof *list, shard_cmp);
        m->files = calloc(n + (size_t)merged, sizeof *m->files);
        if (!m->files || (merged && !(m->files[0] = strdup("manifest.jsonl"))))
            rc = -1;
    }
    for (size_t i = 0; i < n; i++) {
        if (rc == 0)
            m->files[i + (size_t)merged] = list[i].name;
        else
            free(list[i].name);
    }
    free(list);
    if (rc != 0)
        return set_err(err, err_size, "%s%s: out of memory", dir, "");
    m->nfiles = n + (size_t)merged;
    if (m->nfiles == 0) {
        set_err(err, err_size, "%s: no manifest (manifest.jsonl or manifest-I-of-N.jsonl)%s", dir, "");
        return NO_MANIFEST;
    }
    return 0;
}

static int blank(const char *s)
{
    for (; *s; s++)
        if (*s != ' ' && *s != '\t' && *s != '\r' && *s != '\n')
            return 0;
    return 1;
}

static double line_time(json_t *line, const char *key)
{
    double t;
    if (lpv_batch_time_parse(json_string_value(json_object_get(line, key)), &t) == 0)
        return t;
    return NAN;
}

/* Keeps `line` (a reference handed over) for its id. */
static int keep(lpv_manifest *m, json_t *by_id, json_t *line, const char *id, int file)
{
    json_t *pos = json_object_get(by_id, id);
    json_t *idx = json_object_get(line, "index");
    long index = json_is_integer(idx) && json_integer_value(idx) >= 0 && json_integer_value(idx) < LONG_MAX
                     ? (long)json_integer_value(idx)
                     : LONG_MAX;
    if (pos) {
        lpv_manifest_item *it = &m->items[json_integer_value(pos)];
        int replace = 1;
        if (it->file != file) {
            double old_t = line_time(it->line, "finished"), new_t = line_time(line, "finished");
            if (!isnan(old_t) && !isnan(new_t) && new_t < old_t)
                replace = 0;
        }
        m->superseded++;
        if (!replace) {
            json_decref(line);
            return 0;
        }
        json_decref(it->line);
        it->line = line;
        it->id = json_string_value(json_object_get(line, "id"));
        it->index = index;
        it->file = file;
        return 0;
    }
    if (m->count == m->capacity) {
        size_t ncap = m->capacity ? m->capacity * 2 : 64;
        lpv_manifest_item *ni = realloc(m->items, ncap * sizeof *ni);
        if (!ni)
            return -1;
        m->items = ni;
        m->capacity = ncap;
    }
    if (json_object_set_new(by_id, id, json_integer((json_int_t)m->count)) != 0)
        return -1;
    lpv_manifest_item *it = &m->items[m->count];
    it->line = line;
    it->id = id;
    it->index = index;
    it->seq = (long)m->count;
    it->file = file;
    m->count++;
    return 0;
}

static int read_file(const char *dir, lpv_manifest *m, json_t *by_id, int file, FILE *warnings, char *err,
                     size_t err_size)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, m->files[file]);
    FILE *f = fopen(path, "r");
    if (!f)
        return set_err(err, err_size, "%s: %s", path, strerror(errno));
    char *buf = NULL;
    size_t cap = 0;
    ssize_t len;
    long lineno = 0;
    int rc = 0;
    while ((len = getline(&buf, &cap, f)) >= 0) {
        lineno++;
        if (blank(buf))
            continue;
        m->lines++;
        json_error_t jerr;
        json_t *line = json_loads(buf, 0, &jerr);
        const char *why = NULL;
        if (!line)
            why = jerr.text;
        else if (!json_is_object(line))
            why = "not a JSON object";
        else if (!json_string_value(json_object_get(line, "id")) || !json_string_value(json_object_get(line, "id"))[0])
            why = "no string \"id\"";
        if (why) {
            if (warnings && m->skipped < MAX_WARNINGS)
                fprintf(warnings, "%s:%ld: skipped: %s\n", path, lineno, why);
            m->skipped++;
            json_decref(line);
            continue;
        }
        double t = line_time(line, "started");
        if (!isnan(t) && (isnan(m->first_started) || t < m->first_started))
            m->first_started = t;
        t = line_time(line, "finished");
        if (!isnan(t) && (isnan(m->last_finished) || t > m->last_finished))
            m->last_finished = t;
        if (keep(m, by_id, line, json_string_value(json_object_get(line, "id")), file) != 0) {
            json_decref(line);
            rc = set_err(err, err_size, "%s%s: out of memory", path, "");
            break;
        }
    }
    if (rc == 0 && ferror(f))
        rc = set_err(err, err_size, "%s: %s", path, strerror(errno));
    free(buf);
    fclose(f);
    return rc;
}

static int item_cmp(const void *a, const void *b)
{
    const lpv_manifest_item *x = a, *y = b;
    if (x->index != y->index)
        return x->index < y->index ? -1 : 1;
    return x->seq < y->seq ? -1 : x->seq > y->seq;
}

static int read_manifests(const char *dir, lpv_manifest *m, int none_ok, FILE *warnings, char *err,
                          size_t err_size);

int lpv_manifest_read(const char *dir, lpv_manifest *m, FILE *warnings, char *err, size_t err_size)
{
    return read_manifests(dir, m, 0, warnings, err, err_size);
}

int lpv_manifest_read_any(const char *dir, lpv_manifest *m, FILE *warnings, char *err, size_t err_size)
{
    return read_manifests(dir, m, 1, warnings, err, err_size);
}

static int read_manifests(const char *dir, lpv_manifest *m, int none_ok, FILE *warnings, char *err, size_t err_size)
{
    memset(m, 0, sizeof *m);
    m->first_started = NAN;
    m->last_finished = NAN;
    if (!dir || !dir[0])
        return set_err(err, err_size, "no folder given%s%s", "", "");
    int found = find_files(dir, m, err, err_size);
    if (found == NO_MANIFEST && none_ok)
        return 0;
    if (found != 0)
        return -1;
    json_t *by_id = json_object();
    if (!by_id)
        return set_err(err, err_size, "%s%s: out of memory", dir, "");
    int rc = 0;
    for (size_t i = 0; i < m->nfiles && rc == 0; i++)
        rc = read_file(dir, m, by_id, (int)i, warnings, err, err_size);
    json_decref(by_id);
    if (rc != 0)
        return -1;
    if (warnings && m->skipped > MAX_WARNINGS)
        fprintf(warnings, "%s: %ld more lines skipped\n", dir, m->skipped - MAX_WARNINGS);
    if (m->count > 1)
        qsort(m->items, m->count, sizeof *m->items, item_cmp);
    return 0;
}

void lpv_manifest_free(lpv_manifest *m)
{
    if (!m)
        return;
    for (size_t i = 0; i < m->count; i++)
        json_decref(m->items[i].line);
    free(m->items);
    for (size_t i = 0; i < m->nfiles; i++)
        free(m->files[i]);
    free(m->files);
    memset(m, 0, sizeof *m);
}

int lpv_manifest_item_ok(const lpv_manifest_item *item)
{
    const char *s = json_string_value(json_object_get(item->line, "status"));
    return s && strcmp(s, "ok") == 0;
}
