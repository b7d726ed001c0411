/*
 * gl_util.c - see gl_util.h.
 */
#include "gl_util.h"

GLuint lpv_gl_new_ssbo(size_t bytes)
{
    GLuint b;
    glGenBuffers(1, &b);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, b);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(bytes ? bytes : 16), NULL, GL_DYNAMIC_COPY);
    return b;
}

GLuint lpv_gl_buffer_view(GLuint b, GLenum format)
{
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_BUFFER, t);
    glTexBuffer(GL_TEXTURE_BUFFER, format, b);
    glBindTexture(GL_TEXTURE_BUFFER, 0);
    return t;
}

void lpv_gl_delete_buffer(GLuint *b)
{
    if (*b)
        glDeleteBuffers(1, b);
    *b = 0;
}

/* A texture of one level, nearest filtering, clamped: a 2D texture
 * (layers 0) or a 2D array of `layers` layers. */
static GLuint new_texture(GLenum format, int w, int h, int layers)
{
    const GLenum target = layers > 0 ? GL_TEXTURE_2D_ARRAY : GL_TEXTURE_2D;
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(target, t);
    if (layers > 0)
        glTexStorage3D(target, 1, format, w, h, layers);
    else
        glTexStorage2D(target, 1, format, w, h);
    glTexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return t;
}

GLuint lpv_gl_new_texture_2d(GLenum format, int w, int h)
{
    return new_texture(format, w, h, 0);
}

GLuint lpv_gl_new_texture_2d_array(GLenum format, int w, int h, int layers)
{
    return new_texture(format, w, h, layers);
}

void lpv_gl_delete_texture(GLuint *t)
{
    if (*t)
        glDeleteTextures(1, t);
    *t = 0;
}

void lpv_gl_delete_framebuffer(GLuint *f)
{
    if (*f)
        glDeleteFramebuffers(1, f);
    *f = 0;
}

size_t lpv_gl_read_buffer(GLuint buf, size_t elem_size, size_t available, void *out, size_t max)
{
    size_t n = available < max ? available : max;
    if (!buf || !n)
        return 0;
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, buf);
    glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(n * elem_size), out);
    return n;
}
