/*
 * pass_gv.c - the geometry volume for fuzzy occlusion. Each buffer that saw
 * surfaces (each punctual light's RSM faces, the area light samples' faces
 * as one, the camera's G-buffer, and the surfels sampled over every triangle
 * when settings.scene_surfels is on) splats its
 * surfels into the GV atlas and is then max-merged into the total per travel
 * direction, so a surface seen by several buffers blocks once and a wall
 * seen from each side by a different buffer blocks both ways. Finally the
 * per-cell, per-direction transmittances are computed once for the whole
 * propagation.
 */
#include "engine_internal.h"

static void merge(lpv_engine *e)
{
    glUseProgram(e->prog_gv_merge);
    glUniform1i(glGetUniformLocation(e->prog_gv_merge, "u_tiles_x"), e->gv_atlas.tiles_x);
    for (int i = 0; i < 2; ++i) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glBindTexture(GL_TEXTURE_2D, e->gv_atlas.tex[i]);
    }
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, e->grid_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_GV_TOTAL, e->gv_total);
    glDispatchCompute(lpv_div_up((size_t)e->grid.dims[0] + 1, LPV_WG_2D),
                      lpv_div_up((size_t)e->grid.dims[1] + 1, LPV_WG_2D),
                      (GLuint)((e->grid.dims[2] + 1) * e->cascades.count));
    lpv_timer_count(&e->timer, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

void lpv_pass_gv_run(lpv_engine *e, int bounce, int camera)
{
    lpv_timer_begin(&e->timer, "gv");
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, e->gv_total);
    glClearBufferData(GL_SHADER_STORAGE_BUFFER, GL_RGBA32F, GL_RGBA, GL_FLOAT, NULL);

    /* each punctual light's faces, then the area light samples' (one buffer) */
    for (size_t b = 0, first, count; lpv_engine_gv_buffer_range(e, b, &first, &count), count > 0; ++b) {
        lpv_atlas_begin(e, &e->gv_atlas, e->prog_inject_gv);
        lpv_atlas_splat(e, e->prog_inject_gv, LPV_SSBO_SURFELS, e->surfels, first, count);
        lpv_atlas_end();
        merge(e);
    }
    if (camera) {
        lpv_atlas_begin(e, &e->gv_atlas, e->prog_inject_gv);
        lpv_atlas_splat(e, e->prog_inject_gv, LPV_SSBO_SURFELS, e->camera_surfels, 0,
                        (size_t)e->gbuf_w * (size_t)e->gbuf_h);
        lpv_atlas_end();
        merge(e);
    }
    if (e->scene_surfel_count) { /* the geometry itself, seen or not */
        lpv_atlas_begin(e, &e->gv_atlas, e->prog_inject_gv);
        lpv_atlas_splat(e, e->prog_inject_gv, LPV_SSBO_SURFELS, e->scene_surfels, 0, e->scene_surfel_count);
        lpv_atlas_end();
        merge(e);
    }

    glUseProgram(e->prog_transmit);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, e->grid_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_GV_TOTAL, e->gv_total);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_TRANSMIT, e->transmit);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_REFLECT, e->reflect);
    glUniform1i(glGetUniformLocation(e->prog_transmit, "u_bounce"), bounce);
    glUniform1f(glGetUniformLocation(e->prog_transmit, "u_bounce_intensity"), e->settings.bounce_intensity);
    glDispatchCompute(lpv_div_up((size_t)e->grid.dims[0], LPV_WG_2D), lpv_div_up((size_t)e->grid.dims[1], LPV_WG_2D),
                      (GLuint)(e->grid.dims[2] * e->cascades.count));
    lpv_timer_count(&e->timer, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
    lpv_timer_end(&e->timer);
}
