/*
 * registry.c - the one table of techniques (registry.h) and the lookups
 * core/settings.h declares over it. A new technique is a row here, a class
 * in classes.c and its folder beside lpv/, octree/ and iv/.
 */
#include "registry.h"

#include <string.h>

#include "iv_rules.h"
#include "lpv_rules.h"
#include "octree_rules.h"
#include "probes_rules.h"

static const lpv_technique_rules TECHNIQUES[LPV_TECHNIQUE_ID_COUNT_] = {
    [LPV_TECHNIQUE_ID_DEFAULT] = {0}, /* not a row: resolves to LPV_TECHNIQUE_ID_DEFAULT_IS */
    [LPV_TECHNIQUE_ID_LPV] = {LPV_TECHNIQUE_LPV, 0, 1, lpv_lpv_tick_cost, NULL, lpv_lpv_memory_floor},
    [LPV_TECHNIQUE_ID_OCTREE] = {LPV_TECHNIQUE_OCTREE, 0, 0, lpv_octree_tick_cost, lpv_octree_validate,
                                 lpv_octree_memory_floor},
    [LPV_TECHNIQUE_ID_IV] = {LPV_TECHNIQUE_IV, LPV_CAP_AO, 1, lpv_iv_tick_cost, NULL, NULL},
    [LPV_TECHNIQUE_ID_AUTO] = {LPV_TECHNIQUE_AUTO, 0, 0, NULL, NULL, NULL}, /* nothing until the engine chose */
    [LPV_TECHNIQUE_ID_PROBES] = {LPV_TECHNIQUE_PROBES, 0, 1, lpv_probes_tick_cost, NULL, lpv_probes_memory_floor},
};

const lpv_technique_rules *lpv_technique_rules_of(lpv_technique_id t)
{
    if (t == LPV_TECHNIQUE_ID_DEFAULT)
        t = LPV_TECHNIQUE_ID_DEFAULT_IS;
    return (int)t > (int)LPV_TECHNIQUE_ID_DEFAULT && (int)t < (int)LPV_TECHNIQUE_ID_COUNT_ ? &TECHNIQUES[t] : NULL;
}

int lpv_technique_from_name(const char *name, lpv_technique_id *out)
{
    for (int t = LPV_TECHNIQUE_ID_DEFAULT + 1; name && t < LPV_TECHNIQUE_ID_COUNT_; ++t)
        if (strcmp(name, TECHNIQUES[t].name) == 0) {
            *out = (lpv_technique_id)t;
            return 0;
        }
    return -1;
}

const char *lpv_technique_name(lpv_technique_id t)
{
    const lpv_technique_rules *r = lpv_technique_rules_of(t);
    return r ? r->name : NULL;
}

const char *lpv_technique_names(void)
{
    return LPV_TECHNIQUE_LPV ", " LPV_TECHNIQUE_OCTREE ", " LPV_TECHNIQUE_IV ", " LPV_TECHNIQUE_AUTO ", " LPV_TECHNIQUE_PROBES; /* the table's names, in its order */
}

int lpv_technique_validate(const lpv_settings *s, char *err, size_t err_size)
{
    const lpv_technique_rules *r = lpv_technique_rules_of(s->technique);
    return r && r->validate ? r->validate(s, err, err_size) : 0;
}

void lpv_technique_memory_floor(const lpv_settings *s, lpv_memory_need *n)
{
    const lpv_technique_rules *r = lpv_technique_rules_of(s->technique);
    if (r && r->memory_floor)
        r->memory_floor(s, n);
}

int lpv_technique_has(lpv_technique_id t, lpv_technique_cap cap)
{
    const lpv_technique_rules *r = lpv_technique_rules_of(t);
    return r && (r->caps & cap) != 0;
}
