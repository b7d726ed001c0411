/* batch_shard.c - which items of a job one shard renders (batch_job.h,
 * lpvd_batch_shard): deterministic, balanced by expected cost, a scene's
 * items kept together unless the scene alone is worth more than a share. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "batch_job.h"
#include "error.h"

int lpvd_batch_parse_shard(const char *text, int *i, int *n, char *err, size_t err_size)
{
    char tail;
    if (sscanf(text, "%d/%d%c", i, n, &tail) != 2 || !(*n >= 1 && *n <= 100000 && *i >= 0 && *i < *n))
        return lpv_error(err, err_size, "shard \"%s\": expected I/N with 0 <= I < N <= 100000", text);
    return 0;
}

typedef struct run {
    int first, count; /* items */
    double cost;
} run;

static int by_cost(const void *a, const void *b)
{
    const run *x = a, *y = b;
    if (x->cost != y->cost)
        return x->cost > y->cost ? -1 : 1;
    return x->first - y->first; /* the same order everywhere */
}

int lpvd_batch_shard(const lpvd_batch_job *job, int i, int n, unsigned char *mine)
{
    memset(mine, 0, (size_t)job->item_count);
    if (job->item_count == 0)
        return 0;
    double total = 0.0;
    for (int k = 0; k < job->item_count; ++k)
        total += job->items[k].cost;
    const double share = total / n;
    /* runs: a scene's items, cut where a scene is worth more than a share */
    run *runs = calloc((size_t)job->item_count, sizeof *runs);
    double *load = calloc((size_t)n, sizeof *load);
    if (!runs || !load) { /* no memory: everything to shard 0 keeps every item rendered once */
        free(runs);
        free(load);
        if (i == 0)
            memset(mine, 1, (size_t)job->item_count);
        return i == 0 ? job->item_count : 0;
    }
    int nr = 0;
    for (int k = 0; k < job->item_count; ++k) {
        const lpvd_batch_item *it = &job->items[k];
        run *r = nr ? &runs[nr - 1] : NULL;
        if (!r || job->items[r->first].scene != it->scene || r->cost + it->cost > share * 1.0000001) {
            r = &runs[nr++];
            r->first = k;
        }
        r->count++;
        r->cost += it->cost;
    }
    qsort(runs, (size_t)nr, sizeof *runs, by_cost);
    int mine_count = 0;
    for (int r = 0; r < nr; ++r) {
        int best = 0;
        for (int s = 1; s < n; ++s)
            if (load[s] < load[best])
                best = s;
        load[best] += runs[r].cost;
        if (best == i) {
            memset(mine + runs[r].first, 1, (size_t)runs[r].count);
            mine_count += runs[r].count;
        }
    }
    free(runs);
    free(load);
    return mine_count;
}
