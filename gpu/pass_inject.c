/*
 * pass_inject.c - VPL injection. Each VPL (from the RSMs and from emissive
 * surfaces) is one point rendered with additive blending into a 2D atlas of
 * the grid's z slices (fp32, three attachments for r, g, b): the paper's
 * point-splatting injection, portable because it needs no float atomics and
 * deterministic because blending follows primitive order. A compute pass
 * then copies the atlas into the LPV buffer layout.
 */
#include <math.h>

#include "engine_internal.h"

int lpv_atlas_create(lpv_atlas *a, const int dims[3], int attachments, char *err, size_t err_size)
{
    a->tiles_x = (int)ceil(sqrt((double)dims[2]));
    int tiles_y = (dims[2] + a->tiles_x - 1) / a->tiles_x;
    a->width = dims[0] * a->tiles_x;
    a->height = dims[1] * tiles_y;
    a->attachments = attachments;
    GLint max_size = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    if (a->width > max_size || a->height > max_size)
        return lpv_error(err, err_size, "grid needs a %dx%d injection atlas, GL allows %d", a->width, a->height,
                               max_size);
    glGenTextures(attachments, a->tex);
    glGenFramebuffers(1, &a->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, a->fbo);
    GLenum bufs[3];
    for (int i = 0; i < attachments; ++i) {
        glBindTexture(GL_TEXTURE_2D, a->tex[i]);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, a->width, a->height);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + (GLenum)i, GL_TEXTURE_2D, a->tex[i], 0);
        bufs[i] = GL_COLOR_ATTACHMENT0 + (GLenum)i;
    }
    glDrawBuffers(attachments, bufs);
    GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (status != GL_FRAMEBUFFER_COMPLETE)
        return lpv_error(err, err_size, "injection atlas framebuffer incomplete (0x%04x)", status);
    return 0;
}

void lpv_atlas_destroy(lpv_atlas *a)
{
    if (a->fbo) {
        glDeleteTextures(a->attachments, a->tex);
        glDeleteFramebuffers(1, &a->fbo);
    }
    *a = (lpv_atlas){0};
}

/* Sets the state for additive point splatting with prog into the atlas as it is. */
void lpv_atlas_begin_keep(lpv_engine *e, lpv_atlas *a, GLuint prog)
{
    glBindFramebuffer(GL_FRAMEBUFFER, a->fbo);
    glViewport(0, 0, a->width, a->height);
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glUseProgram(prog);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, e->grid_ubo);
    glUniform1i(glGetUniformLocation(prog, "u_tiles_x"), a->tiles_x);
    glUniform2f(glGetUniformLocation(prog, "u_atlas_size"), (float)a->width, (float)a->height);
    glBindVertexArray(e->empty_vao);
}

/* Draws count points reading elements [first, first + count) of buffer at
 * binding, once per cascade (instanced: gl_InstanceID is the cascade). */
void lpv_atlas_splat(lpv_engine *e, GLuint prog, GLuint binding, GLuint buffer, size_t first, size_t count)
{
    if (!count)
        return;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, buffer);
    glUniform1i(glGetUniformLocation(prog, "u_first"), (GLint)first);
    glDrawArraysInstanced(GL_POINTS, 0, (GLsizei)count, (GLsizei)e->cascades.count);
    lpv_timer_count(&e->timer, 1);
}

/* Clears the atlas and sets the state for additive point splatting with prog. */
void lpv_atlas_begin(lpv_engine *e, lpv_atlas *a, GLuint prog)
{
    glBindFramebuffer(GL_FRAMEBUFFER, a->fbo);
    static const float zero[4] = {0, 0, 0, 0};
    for (int i = 0; i < a->attachments; ++i)
        glClearBufferfv(GL_COLOR, i, zero);
    lpv_atlas_begin_keep(e, a, prog);
}

void lpv_atlas_end(void)
{
    glDisable(GL_BLEND);
    glBindVertexArray(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
}

void lpv_pass_inject_run(lpv_engine *e, int rsm_vpls, int emissive_vpls)
{
    lpv_timer_begin(&e->timer, "inject");
    lpv_atlas_begin(e, &e->lpv_atlas, e->prog_inject_vpl);
    if (rsm_vpls)
        lpv_atlas_splat(e, e->prog_inject_vpl, LPV_SSBO_VPLS, e->vpls, 0, e->rsm_texels);
    lpv_atlas_end();
    lpv_timer_end(&e->timer);
    /* Emissive surfaces are their own stage, so the plan's "emissive" pass
     * shows its cost (and its absence). */
    if (emissive_vpls) {
        lpv_timer_begin(&e->timer, "emissive");
        lpv_atlas_begin_keep(e, &e->lpv_atlas, e->prog_inject_vpl);
        lpv_atlas_splat(e, e->prog_inject_vpl, LPV_SSBO_VPLS, e->emissive_vpls, 0, e->emissive_vpl_count);
        lpv_atlas_end();
        lpv_timer_end(&e->timer);
    }

    lpv_timer_begin(&e->timer, "pack");

    glUseProgram(e->prog_pack);
    glUniform1i(glGetUniformLocation(e->prog_pack, "u_tiles_x"), e->lpv_atlas.tiles_x);
    for (int i = 0; i < 3; ++i) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glBindTexture(GL_TEXTURE_2D, e->lpv_atlas.tex[i]);
    }
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, e->grid_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_OUT, e->lpv_injected);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_ACC, e->lpv_acc);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_SIGMA_OUT, e->sigma[0]);
    glDispatchCompute(lpv_div_up((size_t)e->grid.dims[0], LPV_WG_2D), lpv_div_up((size_t)e->grid.dims[1], LPV_WG_2D),
                      (GLuint)(e->grid.dims[2] * lpv_engine_volumes(e)));
    lpv_timer_count(&e->timer, 1);
    /* propagation reads the packed grid and flux limits as buffer textures */
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
    lpv_timer_end(&e->timer);
}
