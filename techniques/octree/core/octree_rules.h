/*
 * octree_rules.h - the octree LPV's CPU half beside its oracle
 * (oracle_octree.h): it plans as the cascaded LPV does (lpv_rules.h) and
 * bounds its tick cost here; techniques/registry.c lists them.
 */
#ifndef LPV_OCTREE_RULES_H
#define LPV_OCTREE_RULES_H

#include "lpv_rules.h"

/* Every level propagates: level 0's cells x 8/7 x iterations. */
void lpv_octree_tick_cost(const lpv_settings *s, lpv_tick_cost *out);

#endif /* LPV_OCTREE_RULES_H */
