/*
 * compact.c - the dispatches of shaders/compact.comp (compact.h).
 */
#include "compact.h"

#include "lpv_shared.h"

static size_t chunks_of(size_t count)
{
    return (count + LPV_COMPACT_CHUNK - 1) / LPV_COMPACT_CHUNK;
}

size_t lpv_compact_head_bytes(size_t count)
{
    return (4 + 2 * chunks_of(count)) * sizeof(GLuint);
}

void lpv_compact_clear(GLuint head)
{
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, head);
    glClearBufferData(GL_SHADER_STORAGE_BUFFER, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}

void lpv_compact_bind(GLuint head)
{
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_COMPACT_HEAD, head);
}

void lpv_compact_run(const GLuint progs[2], GLuint src, size_t count, GLuint dst, GLuint head)
{
    const size_t chunks = chunks_of(count);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_VPLS, src);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_COMPACT_DST, dst);
    lpv_compact_bind(head);
    for (int phase = 0; phase < 2; ++phase) {
        glUseProgram(progs[phase]);
        glUniform1i(glGetUniformLocation(progs[phase], "u_chunks"), (GLint)chunks);
        const GLuint groups = phase == 0 ? 1u : (GLuint)((chunks + LPV_COMPACT_WG - 1) / LPV_COMPACT_WG);
        if (groups > 0)
            glDispatchCompute(groups, 1, 1);
        /* the copy reads the first places; the copy feeds a vertex stage
         * and an indirect draw */
        glMemoryBarrier(phase == 0 ? GL_SHADER_STORAGE_BARRIER_BIT
                                   : GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
    }
}
