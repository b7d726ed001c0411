/*
 * block_groups.c - block_groups.h's uniforms, and the engine's cascades as
 * the groups' keys see them (lpv_engine_group_grids), with which the
 * camera's surfels (gbuffer.c) and the RSMs' VPLs and surfels (rsm_maps.c)
 * are grouped.
 */
#include <string.h>

#include "block_groups.h"
#include "engine_internal.h"

int lpv_engine_group_grids(const lpv_engine *e, lpv_group_grid g[LPV_MAX_CASCADES])
{
    /* describe() ran at the commit before the producers of this tick */
    memset(g, 0, LPV_MAX_CASCADES * sizeof *g);
    int levels = e->desc.kind == LPV_LEVELS_CASCADES ? e->desc.levels : 0;
    if (levels > LPV_MAX_CASCADES)
        levels = LPV_MAX_CASCADES;
    for (int k = 0; k < levels; ++k) {
        /* in cells, as the technique's grid block holds it */
        memcpy(g[k].origin_cells, e->desc.origin_cells[k], sizeof g[k].origin_cells);
        g[k].cell_size = e->desc.level[k].cell_size;
        g[k].vpl_spread = e->desc.vpl_spread;
        if (!(g[k].cell_size > 0.0f))
            return 0;
    }
    return levels;
}

int lpv_block_slots(int step)
{
    return step * step < LPV_BLOCK_SLOTS ? step * step : LPV_BLOCK_SLOTS;
}

void lpv_block_groups_bind(GLuint prog, const lpv_group_grid *g, int levels)
{
    float grids[LPV_MAX_CASCADES][4];
    memset(grids, 0, sizeof grids);
    for (int k = 0; k < levels && k < LPV_MAX_CASCADES; ++k) {
        memcpy(grids[k], g[k].origin_cells, sizeof g[k].origin_cells);
        grids[k][3] = g[k].cell_size;
    }
    glUniform4fv(glGetUniformLocation(prog, "u_group_grid"), LPV_MAX_CASCADES, &grids[0][0]);
    glUniform1i(glGetUniformLocation(prog, "u_group_levels"), levels);
    glUniform1i(glGetUniformLocation(prog, "u_group_spread"), levels > 0 && g[0].vpl_spread);
}
