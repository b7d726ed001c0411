/*
 * gl.h - the OpenGL function table of lpvd.
 *
 * Include this instead of any other GL header. The declarations come from
 * gl_api.h, which the build generates (cmake/gen_gl_api.py) from the Khronos
 * registry (gl.xml, Debian's khronos-api) for exactly the names listed in
 * gpu/gl_api.txt: the GL types those names need, the enums, a PFN...PROC
 * typedef per command, LPV_GL_FUNCTIONS(X) and
 *     #define glClear lpv_gl_glClear
 * per command, so the rest of the code calls GL by its usual names through
 * one function pointer each (nothing links against libGL).
 *
 * Why our own table and not a loader library: the context (context.c) comes
 * from EGL (pointers from eglGetProcAddress) or from OSMesa opened with dlopen
 * (pointers from OSMesaGetProcAddress), both in one process, and the same call
 * sites serve both. libepoxy resolves through the current EGL or GLX context
 * only (with an OSMesa context current it asserts), so it could not serve the
 * OSMesa backend. lpv_gl_load() fills the table from whichever backend made
 * the context current; context.c calls it, nobody else needs to.
 *
 * Every listed command is required: loading fails, naming the first missing
 * function, if one is absent. The table is process-wide. Pointers from EGL
 * are valid for every EGL context; pointers from OSMesa for every OSMesa
 * context; context.c reloads the table when a context of another backend is
 * made current.
 */
#ifndef LPV_GL_H
#define LPV_GL_H

#include <stddef.h>

#include "gl_api.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LPV_GL_DECLARE_(type, name) extern type lpv_gl_##name;
LPV_GL_FUNCTIONS(LPV_GL_DECLARE_)
#undef LPV_GL_DECLARE_

/* Number of entry points (LPV_GL_FUNCTIONS). */
extern const size_t lpv_gl_function_count;

/* Fills the table with get_proc(name) for every function. Returns 0, or -1
 * with "missing GL function glXyz" (the first absent one) in err; on failure
 * the table is left cleared (all NULL). The pointers stay valid as long as
 * the library they came from is loaded (context.c keeps libOSMesa mapped for
 * the life of the process). */
int lpv_gl_load(void *(*get_proc)(const char *name), char *err, size_t err_size);

/* Clears the table (all NULL). */
void lpv_gl_unload(void);

/* Incremented by every lpv_gl_load and lpv_gl_unload: context.c reloads the
 * table on make-current when it changed since the context loaded it. */
unsigned lpv_gl_table_generation(void);

/* Name of a GL error code ("GL_INVALID_OPERATION", ...), "GL_NO_ERROR" for 0,
 * "unknown GL error" otherwise. */
const char *lpv_gl_error_name(GLenum error);

#ifdef __cplusplus
}
#endif

#endif /* LPV_GL_H */
