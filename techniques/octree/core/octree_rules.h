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

/* Its least storage whatever the scene: level 0's grid. */
void lpv_octree_memory_floor(const lpv_settings *s, lpv_memory_need *n);

/* A full octree halves one cube down to one cell: a cubic grid of a power
 * of two cells per axis. 0, or -1 with why in err. */
int lpv_octree_validate(const lpv_settings *s, char *err, size_t err_size);

#endif /* LPV_OCTREE_RULES_H */
