/* overall.c - see overall.h. */
#include "overall.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "metrics.h"

static int same_key(const int a[LPV_ACC_KEY], const int b[LPV_ACC_KEY])
{
    return memcmp(a, b, LPV_ACC_KEY * sizeof a[0]) == 0;
}

size_t lpv_acc_overall_front(const lpv_acc_row *rows, size_t n, int nscenes, lpv_acc_overall *out, size_t max)
{
    if (nscenes < 1 || nscenes > LPV_ACC_MAX_SCENES)
        return 0;
    double best[LPV_ACC_MAX_SCENES];
    for (int s = 0; s < nscenes; s++)
        best[s] = INFINITY;
    for (size_t i = 0; i < n; i++)
        if (rows[i].scene >= 0 && rows[i].scene < nscenes && isfinite(rows[i].rel_rmse) &&
            rows[i].rel_rmse < best[rows[i].scene])
            best[rows[i].scene] = rows[i].rel_rmse;

    size_t count = 0;
    for (size_t i = 0; i < n && count < max; i++) {
        int seen = 0;
        for (size_t j = 0; j < count && !seen; j++)
            seen = same_key(out[j].key, rows[i].key);
        if (seen)
            continue;
        /* gather this point's row on every scene */
        lpv_acc_overall o = {.ms = 0.0};
        memcpy(o.key, rows[i].key, sizeof o.key);
        int have = 0;
        for (int s = 0; s < nscenes; s++)
            o.rel_rmse[s] = NAN;
        for (size_t j = i; j < n; j++) {
            const lpv_acc_row *r = &rows[j];
            if (!same_key(r->key, o.key) || r->scene < 0 || r->scene >= nscenes || !isnan(o.rel_rmse[r->scene]))
                continue;
            if (!isfinite(r->rel_rmse) || !isfinite(r->ms) || !(best[r->scene] > 0.0))
                continue;
            o.rel_rmse[r->scene] = r->rel_rmse;
            o.ms += r->ms / nscenes;
            o.norm_rmse += r->rel_rmse / best[r->scene] / nscenes;
            have++;
        }
        if (have == nscenes)
            out[count++] = o;
    }
    if (count == 0)
        return 0;
    double *cost = malloc(count * sizeof *cost), *err = malloc(count * sizeof *err);
    int *front = malloc(count * sizeof *front);
    if (cost && err && front) {
        for (size_t j = 0; j < count; j++) {
            cost[j] = out[j].ms;
            err[j] = out[j].norm_rmse;
        }
        lpv_acc_pareto(cost, err, count, front);
        for (size_t j = 0; j < count; j++)
            out[j].pareto = front[j];
    }
    free(cost);
    free(err);
    free(front);
    return count;
}
