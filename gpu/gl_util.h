/*
 * gl_util.h - small GL helpers every part of gpu/ uses (the engine, the
 * shared producers and the techniques): storage buffers and their
 * buffer-texture views, deletes that zero the name, reads of a storage
 * buffer, and dispatch sizes. Knows no engine and no technique.
 */
#ifndef LPV_GL_UTIL_H
#define LPV_GL_UTIL_H

#include <stddef.h>

#include "gl.h"

/* A shader storage buffer of `bytes` (at least 16), left bound to
 * GL_SHADER_STORAGE_BUFFER. */
GLuint lpv_gl_new_ssbo(size_t bytes);
/* A buffer texture of the given format over buffer b. */
GLuint lpv_gl_buffer_view(GLuint b, GLenum format);
void lpv_gl_delete_buffer(GLuint *b);
/* A w x h 2D texture of one level in `format`, nearest filtering, clamped
 * to its edges, left bound to the active unit. */
GLuint lpv_gl_new_texture_2d(GLenum format, int w, int h);
/* The same as a 2D array of `layers` layers (layers >= 1). */
GLuint lpv_gl_new_texture_2d_array(GLenum format, int w, int h, int layers);
void lpv_gl_delete_texture(GLuint *t);
void lpv_gl_delete_framebuffer(GLuint *f);
/* Copies min(available, max) elements from the start of buf into out after
 * a barrier; returns the count (0 for no buffer). */
size_t lpv_gl_read_buffer(GLuint buf, size_t elem_size, size_t available, void *out, size_t max);

static inline GLuint lpv_div_up(size_t n, unsigned d)
{
    return (GLuint)((n + d - 1) / d);
}

#endif /* LPV_GL_UTIL_H */
