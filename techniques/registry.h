/*
 * registry.h - the techniques lpvd knows, one row each (registry.c): the
 * name clients and flags use, what it can give (core/settings.h
 * lpv_technique_cap), whether auto may choose it, and its CPU half's entry
 * points (techniques/NAME/core/NAME_rules.h). The GPU half's classes are
 * listed by techniques/classes.c, keyed by the same lpv_technique_id.
 *
 * core/settings.h declares the lookups by name and capability
 * (lpv_technique_name, lpv_technique_from_name, lpv_technique_has) so that
 * every layer asks them without knowing the modules; registry.c defines
 * them from this table.
 */
#ifndef LPV_TECHNIQUE_REGISTRY_H
#define LPV_TECHNIQUE_REGISTRY_H

#include "memory_budget.h"
#include "settings.h"
#include "tick_cost.h"

typedef struct lpv_technique_rules {
    const char *name;       /* LPV_TECHNIQUE_LPV, ...: the flag's and CONFIG's value */
    unsigned caps;          /* lpv_technique_cap bits */
    int auto_candidate;     /* technique auto may choose it (techniques/auto_choose.c, lpv_technique_choose) */
    void (*tick_cost)(const lpv_settings *s, lpv_tick_cost *out); /* NULL for auto */
    /* Optional: the technique's own rules on settings beyond each knob's
     * range (lpv_settings_validate calls it): 0, or -1 with why in err. */
    int (*validate)(const lpv_settings *s, char *err, size_t err_size);
    /* Optional: the storage its volume needs at least under s, whatever the
     * scene (lpv_memory_need_floor calls it). */
    void (*memory_floor)(const lpv_settings *s, lpv_memory_need *n);
} lpv_technique_rules;

/* The row of technique t (DEFAULT: LPV_TECHNIQUE_ID_DEFAULT_IS's), NULL for
 * an unknown value. */
const lpv_technique_rules *lpv_technique_rules_of(lpv_technique_id t);

#endif /* LPV_TECHNIQUE_REGISTRY_H */
