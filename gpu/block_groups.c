/*
 * block_groups.c - the uniforms of shaders/block_groups.glsl, with which the
 * camera's surfels (pass_camera.c) and the RSMs' VPLs and surfels
 * (pass_rsm.c) are down-sampled in blocks grouped by the cells and
 * geometry-volume points of the volume's cascades.
 */
#include "engine_internal.h"

void lpv_engine_bind_block_groups(const lpv_engine *e, GLuint prog)
{
    /* describe() ran at the commit before the producers of this tick */
    float grids[LPV_MAX_CASCADES][4] = {{0}};
    int levels = e->desc.kind == LPV_LEVELS_CASCADES ? e->desc.levels : 0;
    if (levels > LPV_MAX_CASCADES)
        levels = LPV_MAX_CASCADES;
    for (int k = 0; k < levels; ++k) {
        const lpv_grid *g = &e->desc.level[k];
        if (!(g->cell_size > 0.0f))
            levels = 0;
        for (int i = 0; i < 3; ++i) /* in cells, as the technique's grid block holds it */
            grids[k][i] = e->desc.origin_cells[k][i];
        grids[k][3] = g->cell_size;
    }
    glUniform4fv(glGetUniformLocation(prog, "u_group_grid"), LPV_MAX_CASCADES, &grids[0][0]);
    glUniform1i(glGetUniformLocation(prog, "u_group_levels"), levels);
}
