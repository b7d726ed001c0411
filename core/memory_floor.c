/*
 * memory_floor.c - the least storage settings need whatever the scene: the
 * shared producers' maps and the technique's own volume (its row of
 * techniques/registry.c). Apart from memory_budget.c, whose sums the
 * techniques' rules call, so that file stays below the registry.
 */
#include "memory_budget.h"

#include <string.h>

#include "registry.h"

void lpv_memory_need_floor(const lpv_settings *s, int light_faces, lpv_memory_need *n)
{
    memset(n, 0, sizeof *n);
    const int faces = light_faces > 1 ? light_faces : 1;
    n->rsm_size = s->rsm_size;
    n->rsm_faces = faces;
    n->shadow_size = s->shadow_size;
    n->shadow_faces = faces;
    lpv_technique_memory_floor(s, n);
}
