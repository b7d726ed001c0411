/*
 * pass_gv.c - the geometry volume for fuzzy occlusion. Each buffer that saw
 * surfaces (each punctual light's RSM faces, the area light samples' faces
 * as one, the camera's G-buffer, and the surfels sampled over every triangle
 * when settings.scene_surfels is on) splats its
 * surfels into the GV atlas and is then max-merged into the total per travel
 * direction, so a surface seen by several buffers blocks once and a wall
 * seen from each side by a different buffer blocks both ways. Finally the
 * per-cell, per-direction transmittances are computed once for the whole
 * propagation. The surfel sets are the engine's inputs, in its order.
 */
#include "lpv_internal.h"

static void merge(lpv_cascaded *c, lpv_timer *timer)
{
    glUseProgram(c->prog_gv_merge);
    glUniform1i(glGetUniformLocation(c->prog_gv_merge, "u_tiles_x"), c->gv_atlas.tiles_x);
    for (int i = 0; i < 2; ++i) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glBindTexture(GL_TEXTURE_2D, c->gv_atlas.tex[i]);
    }
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, c->grid_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_GV_TOTAL, c->gv_total);
    glDispatchCompute(lpv_div_up((size_t)c->grid.dims[0] + 1, LPV_WG_2D),
                      lpv_div_up((size_t)c->grid.dims[1] + 1, LPV_WG_2D),
                      (GLuint)((c->grid.dims[2] + 1) * c->cascades.count));
    lpv_timer_count(timer, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

void lpv_pass_gv_run(lpv_cascaded *c, const lpv_technique_inputs *in, int bounce)
{
    lpv_timer *timer = in->timer;
    lpv_timer_begin(timer, "gv");
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, c->gv_total);
    glClearBufferData(GL_SHADER_STORAGE_BUFFER, GL_RGBA32F, GL_RGBA, GL_FLOAT, NULL);

    /* each punctual light's faces, then the area light samples' (one set),
     * the camera's and the scene surfels: the engine's order */
    for (size_t i = 0; i < in->surfel_set_count; ++i) {
        const lpv_surfel_set *set = &in->surfel_sets[i];
        lpv_atlas_begin(&c->gv_atlas, c->prog_inject_gv, c->grid_ubo, c->empty_vao);
        lpv_atlas_splat(c->prog_inject_gv, LPV_SSBO_SURFELS, set->buffer, set->first, set->count, c->cascades.count,
                        timer);
        lpv_atlas_end();
        merge(c, timer);
    }

    glUseProgram(c->prog_transmit);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, c->grid_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_GV_TOTAL, c->gv_total);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_TRANSMIT, c->transmit);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_REFLECT, c->reflect);
    glUniform1i(glGetUniformLocation(c->prog_transmit, "u_bounce"), bounce);
    glUniform1f(glGetUniformLocation(c->prog_transmit, "u_bounce_intensity"), in->settings->lpv.bounce_intensity);
    glDispatchCompute(lpv_div_up((size_t)c->grid.dims[0], LPV_WG_2D), lpv_div_up((size_t)c->grid.dims[1], LPV_WG_2D),
                      (GLuint)(c->grid.dims[2] * c->cascades.count));
    lpv_timer_count(timer, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
    lpv_timer_end(timer);
}
