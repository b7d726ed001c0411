/*
 * pass_effects.c - the paper's section 7 render-time effects (docs/effects.md):
 * glossy reflections marched through the cascades, and single scattering in
 * a participating medium, each its own full-screen pass over the shaded frame
 * (so each has its own timer stage, and a skipped one costs nothing), both
 * reading the technique's volume through its lookup. The medium's GPU state
 * is medium.c's.
 */
#include <math.h>
#include <string.h>

#include "engine_internal.h"

/* Binds the G-buffer to units 0..3 and the blocks the full-screen passes read. */
static void bind_frame_inputs(lpv_engine *e)
{
    for (int i = 0; i < 4; ++i) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glBindTexture(GL_TEXTURE_2D, e->gbuf.tex[i]);
    }
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_LIGHT, e->light_ubo);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_VIEW, e->view_ubo);
    glBindFramebuffer(GL_FRAMEBUFFER, e->frame.fbo);
    glViewport(0, 0, e->gbuf.w, e->gbuf.h);
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
}

static void draw_fullscreen(lpv_engine *e)
{
    glBindVertexArray(e->empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    lpv_timer_count(&e->timer, 1);
    glBindVertexArray(0);
    glDisable(GL_BLEND);
    /* Mesa refuses draws into several attachments while a dual-source factor
     * is set, even with blending off: leave the default behind. */
    glBlendFunc(GL_ONE, GL_ZERO);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void lpv_pass_glossy_run(lpv_engine *e)
{
    lpv_timer_begin(&e->timer, "glossy");
    bind_frame_inputs(e);
    glBlendFunc(GL_ONE, GL_ONE);
    glUseProgram(e->progs.glossy);
    glUniform1f(glGetUniformLocation(e->progs.glossy, "u_glossy_roughness"), e->settings.glossy_roughness);
    lpv_engine_bind_lookup(e, e->progs.glossy, e->settings.lpv.damping);
    draw_fullscreen(e);
    lpv_timer_end(&e->timer);
}

void lpv_pass_media_run(lpv_engine *e)
{
    lpv_timer_begin(&e->timer, "media");
    bind_frame_inputs(e);
    /* frame = scattered + transmittance x frame, per channel; alpha kept */
    glBlendFuncSeparate(GL_ONE, GL_SRC1_COLOR, GL_ZERO, GL_ONE);
    GLuint p = e->progs.media;
    glUseProgram(p);
    lpv_shadow_maps_bind(&e->shadows);
    lpv_medium_bind(&e->medium, &e->settings, p, 1);
    glUniform1f(glGetUniformLocation(p, "u_media_step"), e->settings.media_step);
    lpv_engine_bind_lookup(e, p, 0.0f);
    /* March over the medium's box, or over the scene and the coarsest cascade. */
    float lo[3], hi[3];
    const lpv_grid *g = &e->desc.level[e->desc.levels - 1];
    for (int i = 0; i < 3; ++i) {
        lo[i] = fminf(e->scene_min[i], g->origin[i]);
        hi[i] = fmaxf(e->scene_max[i], g->origin[i] + g->cell_size * (float)g->dims[i]);
    }
    const int fog = e->settings.fog_sigma_s > 0.0f || e->settings.fog_sigma_a > 0.0f;
    if (!fog && e->medium.medium.present && e->medium.medium.has_box) {
        memcpy(lo, e->medium.medium.box_min, sizeof lo);
        memcpy(hi, e->medium.medium.box_max, sizeof hi);
    }
    glUniform3fv(glGetUniformLocation(p, "u_march_min"), 1, lo);
    glUniform3fv(glGetUniformLocation(p, "u_march_max"), 1, hi);
    draw_fullscreen(e);
    lpv_timer_end(&e->timer);
}
