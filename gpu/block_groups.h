/*
 * block_groups.h - the uniforms of shaders/block_groups.glsl: blocks of
 * texels (the camera's G-buffer, the lights' RSMs) down-sampled into a few
 * samples each, grouped by the cells and geometry-volume points of the
 * volume's cascades (core/surfel_groups.h holds the CPU side of the same
 * keys). Knows no engine: the engine gives the cascades
 * (lpv_engine_group_grids).
 */
#ifndef LPV_BLOCK_GROUPS_H
#define LPV_BLOCK_GROUPS_H

#include "gl.h"
#include "surfel_groups.h"

/* Samples a block of step x step keeps: min(step^2, LPV_BLOCK_SLOTS). */
int lpv_block_slots(int step);

/* Sets prog's (in use) block_groups.glsl uniforms from `levels` cascades
 * (0: one group per block). */
void lpv_block_groups_bind(GLuint prog, const lpv_group_grid *grids, int levels);

#endif
