/*
 * context.h - a headless OpenGL 4.5 core context, no X, no window.
 *
 * Backends, tried in this order by LPV_BACKEND_AUTO:
 *   1. EGL on a real GPU through EGL_EXT_platform_device (devices that
 *      advertise EGL_MESA_device_software are skipped);
 *   2. EGL with Mesa's surfaceless platform (llvmpipe when there is no GPU);
 *   3. OSMesa, opened at run time with dlopen, as the last fallback.
 * The choice can be forced with lpv_gl_context_desc.backend, or with the
 * environment variable LPVD_GL_BACKEND (auto | egl-device | egl-surfaceless |
 * osmesa); the descriptor wins over the environment when it is not AUTO.
 * All rendering goes to framebuffer objects the passes create.
 */
#ifndef LPV_CONTEXT_H
#define LPV_CONTEXT_H

#include <stddef.h>

typedef enum lpv_backend {
    LPV_BACKEND_AUTO = 0,
    LPV_BACKEND_EGL_DEVICE,
    LPV_BACKEND_EGL_SURFACELESS,
    LPV_BACKEND_OSMESA,
} lpv_backend;

typedef struct lpv_gl_context_desc {
    lpv_backend backend; /* AUTO (0): LPVD_GL_BACKEND, else the order above */
    int debug;           /* non-zero: debug context, GL messages to stderr */
} lpv_gl_context_desc;

typedef struct lpv_gl_context lpv_gl_context;

/* Creates a context, makes it current on the calling thread and loads the GL
 * function table (gl.h). On failure returns NULL and writes, into err, every
 * backend tried and why it failed. */
lpv_gl_context *lpv_gl_context_create(const lpv_gl_context_desc *desc, char *err, size_t err_size);
void lpv_gl_context_destroy(lpv_gl_context *ctx);

/* Makes the context current on the calling thread (for the daemon's GL
 * thread). Returns 0 on success. */
int lpv_gl_context_make_current(lpv_gl_context *ctx);

lpv_backend lpv_gl_context_backend(const lpv_gl_context *ctx);
const char *lpv_gl_context_renderer(const lpv_gl_context *ctx); /* GL_RENDERER */
const char *lpv_gl_context_version(const lpv_gl_context *ctx);  /* GL_VERSION */

const char *lpv_backend_name(lpv_backend b); /* "egl-device", ... */
/* Parses a backend name; returns 0 on success, -1 for an unknown name. */
int lpv_backend_parse(const char *name, lpv_backend *out);

#endif /* LPV_CONTEXT_H */
