/*
 * atlas.c - the point-splatting atlas (see atlas.h).
 */
#include <math.h>

#include "atlas.h"

#include "error.h"
#include "lpv_shared.h"

int lpv_atlas_create(lpv_atlas *a, const int dims[3], int attachments, char *err, size_t err_size)
{
    if (attachments < 1 || attachments > LPV_ATLAS_MAX_ATTACHMENTS)
        return lpv_error(err, err_size, "an atlas holds 1..%d attachments, not %d", LPV_ATLAS_MAX_ATTACHMENTS,
                         attachments);
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
    GLenum bufs[LPV_ATLAS_MAX_ATTACHMENTS];
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
void lpv_atlas_begin_keep(const lpv_atlas *a, GLuint prog, GLuint grid_ubo, GLuint empty_vao)
{
    glBindFramebuffer(GL_FRAMEBUFFER, a->fbo);
    glViewport(0, 0, a->width, a->height);
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glUseProgram(prog);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, grid_ubo);
    glUniform1i(glGetUniformLocation(prog, "u_tiles_x"), a->tiles_x);
    glUniform2f(glGetUniformLocation(prog, "u_atlas_size"), (float)a->width, (float)a->height);
    glBindVertexArray(empty_vao);
}

/* Draws count points reading elements [first, first + count) of buffer at
 * binding, once per cascade (instanced: gl_InstanceID is the cascade). */
void lpv_atlas_splat(GLuint prog, GLuint binding, GLuint buffer, size_t first, size_t count, int instances,
                     lpv_timer *timer)
{
    if (!count)
        return;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, buffer);
    const GLint loc = glGetUniformLocation(prog, "u_first");
    for (size_t done = 0; done < count && !lpv_timer_abandoned(timer);) {
        const size_t n = count - done < LPV_ATLAS_SPLAT_CHUNK ? count - done : LPV_ATLAS_SPLAT_CHUNK;
        glUniform1i(loc, (GLint)(first + done));
        glDrawArraysInstanced(GL_POINTS, 0, (GLsizei)n, (GLsizei)instances);
        lpv_timer_count(timer, 1);
        done += n;
        if (done < count)
            lpv_timer_yield(timer);
    }
}

void lpv_atlas_splat_indirect(GLuint prog, GLuint binding, GLuint buffer, GLuint draw, int instances, lpv_timer *timer)
{
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, buffer);
    glUniform1i(glGetUniformLocation(prog, "u_first"), 0);
    const GLuint n = (GLuint)instances;
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, draw);
    glBufferSubData(GL_DRAW_INDIRECT_BUFFER, sizeof(GLuint), sizeof n, &n); /* the command's instance count */
    glDrawArraysIndirect(GL_POINTS, NULL);
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
    lpv_timer_count(timer, 1);
}

/* Clears the atlas and sets the state for additive point splatting with prog. */
void lpv_atlas_begin(const lpv_atlas *a, GLuint prog, GLuint grid_ubo, GLuint empty_vao)
{
    glBindFramebuffer(GL_FRAMEBUFFER, a->fbo);
    static const float zero[4] = {0, 0, 0, 0};
    for (int i = 0; i < a->attachments; ++i)
        glClearBufferfv(GL_COLOR, i, zero);
    lpv_atlas_begin_keep(a, prog, grid_ubo, empty_vao);
}

void lpv_atlas_end(void)
{
    glDisable(GL_BLEND);
    glBindVertexArray(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
}
