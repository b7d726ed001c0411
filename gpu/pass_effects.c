/*
 * pass_effects.c - the paper's section 7 render-time effects (docs/effects.md):
 * glossy reflections marched through the cascades, and single scattering in
 * a participating medium, each its own full-screen pass over the shaded frame
 * (so each has its own timer stage, and a skipped one costs nothing). Also
 * the medium's GPU state (coefficients, box, 3D density texture), which the
 * propagation uses too, to attenuate the light the medium scatters away.
 */
#include <math.h>
#include <string.h>

#include "engine_internal.h"

int lpv_medium_upload(lpv_engine *e, const lpv_scene *scene, char *err, size_t err_size)
{
    if (e->medium_density)
        glDeleteTextures(1, &e->medium_density);
    e->medium_density = 0;
    memset(&e->medium, 0, sizeof e->medium);
    const lpv_medium *m = &scene->medium;
    if (!m->present)
        return 0;
    e->medium = *m;
    e->medium.density = NULL; /* the texture holds it */
    size_t n = (size_t)m->dims[0] * (size_t)m->dims[1] * (size_t)m->dims[2];
    if (!m->has_box || !m->density || n == 0)
        return 0;
    glGenTextures(1, &e->medium_density);
    glBindTexture(GL_TEXTURE_3D, e->medium_density);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexImage3D(GL_TEXTURE_3D, 0, GL_R32F, m->dims[0], m->dims[1], m->dims[2], 0, GL_RED, GL_FLOAT, m->density);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    GLenum wrap[] = {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R};
    for (int i = 0; i < 3; ++i)
        glTexParameteri(GL_TEXTURE_3D, wrap[i], GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_3D, 0);
    if (glGetError() != GL_NO_ERROR)
        return lpv_error(err, err_size, "could not upload a %dx%dx%d medium density texture", m->dims[0], m->dims[1],
                         m->dims[2]);
    return 0;
}

void lpv_medium_bind(lpv_engine *e, GLuint prog, int on)
{
    const lpv_settings *s = &e->settings;
    int flags = 0;
    float sigma_s[3] = {0, 0, 0}, sigma_a[3] = {0, 0, 0}, lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    if (on && (s->fog_sigma_s > 0.0f || s->fog_sigma_a > 0.0f)) { /* the fog settings win */
        flags = 1;
        for (int i = 0; i < 3; ++i) {
            sigma_s[i] = s->fog_sigma_s;
            sigma_a[i] = s->fog_sigma_a;
        }
    } else if (on && e->medium.present) {
        const lpv_medium *m = &e->medium;
        flags = 1 | (m->has_box ? 2 : 0) | (e->medium_density ? 4 : 0);
        memcpy(sigma_s, m->sigma_s, sizeof sigma_s);
        memcpy(sigma_a, m->sigma_a, sizeof sigma_a);
        if (m->has_box) {
            memcpy(lo, m->box_min, sizeof lo);
            memcpy(hi, m->box_max, sizeof hi);
        }
    }
    glUniform1i(glGetUniformLocation(prog, "u_medium"), flags);
    glUniform3fv(glGetUniformLocation(prog, "u_medium_sigma_s"), 1, sigma_s);
    glUniform3fv(glGetUniformLocation(prog, "u_medium_sigma_a"), 1, sigma_a);
    glUniform3fv(glGetUniformLocation(prog, "u_medium_box_min"), 1, lo);
    glUniform3fv(glGetUniformLocation(prog, "u_medium_box_max"), 1, hi);
    glActiveTexture(GL_TEXTURE0 + LPV_TEX_DENSITY);
    glBindTexture(GL_TEXTURE_3D, (flags & 4) ? e->medium_density : 0);
}

/* Binds the G-buffer to units 0..3 and the blocks the full-screen passes read. */
static void bind_frame_inputs(lpv_engine *e)
{
    for (int i = 0; i < 4; ++i) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glBindTexture(GL_TEXTURE_2D, e->gbuf_tex[i]);
    }
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, e->grid_ubo);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_LIGHT, e->light_ubo);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_VIEW, e->view_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_ACC, e->lpv_acc);
    glBindFramebuffer(GL_FRAMEBUFFER, e->frame_fbo);
    glViewport(0, 0, e->gbuf_w, e->gbuf_h);
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
    glUseProgram(e->prog_glossy);
    glUniform1f(glGetUniformLocation(e->prog_glossy, "u_glossy_roughness"), e->settings.glossy_roughness);
    glUniform1f(glGetUniformLocation(e->prog_glossy, "u_damping"), e->settings.damping);
    draw_fullscreen(e);
    lpv_timer_end(&e->timer);
}

void lpv_pass_media_run(lpv_engine *e)
{
    lpv_timer_begin(&e->timer, "media");
    bind_frame_inputs(e);
    /* frame = scattered + transmittance x frame, per channel; alpha kept */
    glBlendFuncSeparate(GL_ONE, GL_SRC1_COLOR, GL_ZERO, GL_ONE);
    GLuint p = e->prog_media;
    glUseProgram(p);
    glActiveTexture(GL_TEXTURE4);
    glBindTexture(GL_TEXTURE_2D_ARRAY, e->shadow_tex);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_SHADOW, e->shadow_ubo);
    lpv_medium_bind(e, p, 1);
    glUniform1f(glGetUniformLocation(p, "u_media_step"), e->settings.media_step);
    glUniform1f(glGetUniformLocation(p, "u_damping"), 0.0f);
    /* March over the medium's box, or over the scene and the coarsest cascade. */
    float lo[3], hi[3];
    const lpv_grid *g = &e->cascades.grid[e->cascades.count - 1];
    for (int i = 0; i < 3; ++i) {
        lo[i] = fminf(e->scene_min[i], g->origin[i]);
        hi[i] = fmaxf(e->scene_max[i], g->origin[i] + g->cell_size * (float)g->dims[i]);
    }
    const int fog = e->settings.fog_sigma_s > 0.0f || e->settings.fog_sigma_a > 0.0f;
    if (!fog && e->medium.present && e->medium.has_box) {
        memcpy(lo, e->medium.box_min, sizeof lo);
        memcpy(hi, e->medium.box_max, sizeof hi);
    }
    glUniform3fv(glGetUniformLocation(p, "u_march_min"), 1, lo);
    glUniform3fv(glGetUniformLocation(p, "u_march_max"), 1, hi);
    draw_fullscreen(e);
    lpv_timer_end(&e->timer);
}
