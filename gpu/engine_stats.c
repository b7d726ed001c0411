/*
 * engine_stats.c - a technique's own counts in the tick's stats, by name
 * (engine.h, lpv_stats_put and lpv_stats_get): the engine and the stats'
 * readers handle every technique's the same way.
 */
#include <string.h>

#include "engine.h"

void lpv_stats_put(lpv_engine_stats *s, const char *name, lpv_stat_kind kind, double a, double b, double c)
{
    int i = 0;
    while (i < s->technique_stat_count && strcmp(s->technique_stats[i].name, name) != 0)
        ++i;
    if (i >= LPV_TECHNIQUE_STATS_MAX)
        return;
    if (i == s->technique_stat_count)
        s->technique_stat_count++;
    s->technique_stats[i] = (lpv_stat){name, kind, {a, b, c}};
}

const lpv_stat *lpv_stats_get(const lpv_engine_stats *s, const char *name)
{
    for (int i = 0; i < s->technique_stat_count; ++i)
        if (strcmp(s->technique_stats[i].name, name) == 0)
            return &s->technique_stats[i];
    return NULL;
}
