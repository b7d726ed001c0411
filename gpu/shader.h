/*
 * shader.h - builds GL programs from the GLSL files embedded from shaders/.
 *
 * Every stage's source is assembled as
 *   "#version 450 core\n#define LPV_GLSL 1\n" + extra defines + "#line 1 <n>\n"
 *   + lpv_shared.h + "#line 1 <m>\n" + the named file
 * so constants and struct layouts come from the one header shared with C, and
 * compiler messages name the file (the program's info log is prefixed with
 * the file name). No file is read at run time.
 */
#ifndef LPV_SHADER_H
#define LPV_SHADER_H

#include <stddef.h>
#include "gl.h"

/* Looks up an embedded source by file name; NULL if absent. */
const char *lpv_shader_text(const char *name);

/* defines may be NULL or a string of "#define ..." lines. Return 0 on failure
 * with the compile or link log, naming the file, in err. */
GLuint lpv_program_compute(const char *comp, const char *defines, char *err, size_t err_size);
GLuint lpv_program_graphics(const char *vert, const char *geom, const char *frag, const char *defines,
                            char *err, size_t err_size);

/* A program whose stages get lpv_shared.h and then the named .glsl include
 * files (a NULL-terminated list, in order) before their own text; frag NULL
 * builds a compute program from first. Returns 0 with err on failure. */
GLuint lpv_program_build(const char *first, const char *geom, const char *frag, const char *const *includes,
                         char *err, size_t err_size);
/* The same with "#define ..." lines (or NULL) ahead of everything: one source
 * compiled into variants whose unused code the compiler drops. */
GLuint lpv_program_build_defines(const char *first, const char *geom, const char *frag, const char *defines,
                                 const char *const *includes, char *err, size_t err_size);

#endif /* LPV_SHADER_H */
