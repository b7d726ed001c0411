/* totals.c - a batch job's figures (totals.h). */
#include "totals.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int ms_value(json_t *v, double *ms)
{
    if (!json_is_number(v))
        return 0;
    double x = json_number_value(v);
    if (!isfinite(x) || x < 0.0)
        return 0;
    *ms = x;
    return 1;
}

/* Adds ms to the sum named `name` in *sums, appending it when new. */
static int add_sum(lpv_batch_sum **sums, size_t *n, const char *name, double ms)
{
    for (size_t i = 0; i < *n; i++)
        if (strcmp((*sums)[i].name, name) == 0) {
            (*sums)[i].ms += ms;
            return 0;
        }
    lpv_batch_sum *ns = realloc(*sums, (*n + 1) * sizeof *ns);
    if (!ns)
        return -1;
    *sums = ns;
    ns[*n].name = strdup(name);
    if (!ns[*n].name)
        return -1;
    ns[*n].ms = ms;
    (*n)++;
    return 0;
}

int lpv_batch_totals_compute(const lpv_manifest *m, lpv_batch_totals *t)
{
    memset(t, 0, sizeof *t);
    t->span_s = NAN;
    t->images_per_hour = NAN;
    t->mean_ms = NAN;
    for (size_t i = 0; i < m->count; i++) {
        const lpv_manifest_item *it = &m->items[i];
        t->items++;
        if (lpv_manifest_item_ok(it))
            t->ok++;
        else
            t->failed++;
        double ms;
        json_t *times = json_object_get(it->line, "ms");
        const char *key;
        json_t *v;
        json_object_foreach(times, key, v)
        {
            if (!ms_value(v, &ms))
                continue;
            if (strcmp(key, "total") == 0) {
                t->item_ms += ms;
                t->item_ms_count++;
            } else {
                if (add_sum(&t->phases, &t->nphases, key, ms) != 0)
                    return -1;
                t->phases_ms += ms;
            }
        }
        json_object_foreach(json_object_get(it->line, "stages"), key, v)
        {
            if (!ms_value(v, &ms))
                continue;
            if (add_sum(&t->stages, &t->nstages, key, ms) != 0)
                return -1;
            t->stages_ms += ms;
        }
    }
    if (t->item_ms_count > 0)
        t->mean_ms = t->item_ms / (double)t->item_ms_count;
    if (!isnan(m->first_started) && !isnan(m->last_finished) && m->last_finished >= m->first_started) {
        t->span_s = m->last_finished - m->first_started;
        if (t->span_s > 0.0)
            t->images_per_hour = (double)t->ok * 3600.0 / t->span_s;
    }
    return 0;
}

void lpv_batch_totals_free(lpv_batch_totals *t)
{
    if (!t)
        return;
    for (size_t i = 0; i < t->nstages; i++)
        free(t->stages[i].name);
    free(t->stages);
    for (size_t i = 0; i < t->nphases; i++)
        free(t->phases[i].name);
    free(t->phases);
    memset(t, 0, sizeof *t);
}
