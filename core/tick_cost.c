/*
 * tick_cost.c - the upper bound of a tick's cost from its settings
 * (tick_cost.h): each technique's own (its row of techniques/registry.c),
 * the dearest of auto's candidates for auto.
 */
#include "tick_cost.h"

#include <string.h>

#include "registry.h"

void lpv_tick_cost_estimate(const lpv_settings *s, lpv_tick_cost *out)
{
    const lpv_technique_rules *r = lpv_technique_rules_of(s->technique);
    if (r && r->tick_cost) {
        r->tick_cost(s, out);
        return;
    }
    /* auto: the dearest of the techniques auto may choose (techniques/auto_choose.c) */
    memset(out, 0, sizeof *out);
    for (int t = 0; t < LPV_TECHNIQUE_ID_COUNT_; ++t) {
        r = lpv_technique_rules_of((lpv_technique_id)t);
        lpv_tick_cost c;
        if (r && r->tick_cost && r->auto_candidate) {
            r->tick_cost(s, &c);
            if (!out->terms[0] || c.cell_steps > out->cell_steps)
                *out = c;
        }
    }
}
