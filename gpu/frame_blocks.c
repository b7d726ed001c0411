/*
 * frame_blocks.c - the frame's passes per block of pixels, each run before
 * the frame (pass_camera.c) that spreads its blocks over the pixels along
 * their planes (shading.glsl, blocks_upsampled):
 *   - the lookup step (settings.lookup_step > 1, lookup_blocks.comp): the
 *     technique's irradiance once per block;
 *   - the area shadow step (settings.area_shadow_step > 1,
 *     area_shadow_blocks.comp): the area light samples' visibility once per
 *     block, as the ratio of their shadowed to unshadowed irradiance, which
 *     the frame multiplies by each pixel's own unshadowed irradiance. On
 *     llvmpipe every sample's shadow filter costs the frame about 5 ms at
 *     512 x 512 (docs/area-lights.md, "The area shadow step").
 */
#include "engine_internal.h"

/* Runs the current program (its uniforms set) over the blocks of `step`
 * pixels into b, through image units img_value and img_plane, then binds
 * the blocks for the frame at texture units tex_value and tex_plane. b's
 * textures are (re)made when the step or the frame's size changed, at unit
 * tex_value (making a texture binds it to the active unit, and the units
 * below hold the G-buffer). */
static void run_blocks(lpv_engine *e, lpv_frame_blocks *b, int step, GLuint img_value, GLuint img_plane,
                       GLenum tex_value, GLenum tex_plane)
{
    const int w = (e->gbuf.w + step - 1) / step, h = (e->gbuf.h + step - 1) / step;
    if (b->step != step || b->w != w || b->h != h) {
        glActiveTexture(GL_TEXTURE0 + tex_value);
        for (int i = 0; i < 2; ++i) {
            lpv_gl_delete_texture(&b->tex[i]);
            b->tex[i] = lpv_gl_new_texture_2d(GL_RGBA32F, w, h);
        }
        b->w = w;
        b->h = h;
        b->step = step;
    }
    glBindImageTexture(img_value, b->tex[0], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glBindImageTexture(img_plane, b->tex[1], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glDispatchCompute(lpv_div_up((size_t)w, LPV_WG_2D), lpv_div_up((size_t)h, LPV_WG_2D), 1);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    glActiveTexture(GL_TEXTURE0 + tex_value);
    glBindTexture(GL_TEXTURE_2D, b->tex[0]);
    glActiveTexture(GL_TEXTURE0 + tex_plane);
    glBindTexture(GL_TEXTURE_2D, b->tex[1]);
}

void lpv_frame_lookup_blocks_run(lpv_engine *e)
{
    const int step = e->settings.lookup_step;
    const float damping = e->settings.lpv.damping;
    const GLuint prog = damping > 0.0f ? e->prog_lookup_blocks_damped : e->prog_lookup_blocks;
    glUseProgram(prog);
    lpv_engine_bind_lookup(e, prog, damping);
    glUniform1i(glGetUniformLocation(prog, "u_lookup_step"), step);
    run_blocks(e, &e->frame.lookup_blocks, step, LPV_IMG_BLOCK_IRRADIANCE, LPV_IMG_BLOCK_PLANE, LPV_TEX_BLOCK_IRRADIANCE,
               LPV_TEX_BLOCK_PLANE);
}

void lpv_frame_area_shadow_blocks_run(lpv_engine *e)
{
    lpv_timer_begin(&e->timer, "area_shadow");
    const int step = e->settings.area_shadow_step;
    const GLuint prog = e->prog_area_shadow_blocks;
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "u_area_shadow_step"), step);
    run_blocks(e, &e->frame.area_shadow_blocks, step, LPV_IMG_AREA_SHADOW, LPV_IMG_AREA_SHADOW_PLANE, LPV_TEX_AREA_SHADOW,
               LPV_TEX_AREA_SHADOW_PLANE);
    lpv_timer_count(&e->timer, 1);
    lpv_timer_end(&e->timer);
}

void lpv_frame_blocks_free(lpv_engine *e)
{
    lpv_frame_blocks *all[] = {&e->frame.lookup_blocks, &e->frame.area_shadow_blocks};
    for (size_t k = 0; k < sizeof all / sizeof all[0]; ++k) {
        for (int i = 0; i < 2; ++i)
            lpv_gl_delete_texture(&all[k]->tex[i]);
        all[k]->w = all[k]->h = all[k]->step = 0;
    }
}
