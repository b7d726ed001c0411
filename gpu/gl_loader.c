/* gl_loader.c - the GL function table declared in gl.h, and its loader. The
 * list of functions is generated (gl_api.h, from gpu/gl_api.txt). */
#include "gl.h"

#include <stdio.h>

/* One definition per entry point: PFN... lpv_gl_glName = NULL. */
#define LPV_GL_DEFINE_(type, name) type lpv_gl_##name = NULL;
LPV_GL_FUNCTIONS(LPV_GL_DEFINE_)
#undef LPV_GL_DEFINE_

static unsigned g_generation;

unsigned lpv_gl_table_generation(void)
{
    return g_generation;
}

#define LPV_GL_COUNT_(type, name) +1
const size_t lpv_gl_function_count = 0 LPV_GL_FUNCTIONS(LPV_GL_COUNT_);
#undef LPV_GL_COUNT_

void lpv_gl_unload(void)
{
    /* `name` (not lpv_gl_##name) goes through gl_api.h's #define, so an
     * entry of the list without its #define does not compile. */
#define LPV_GL_CLEAR_(type, name) name = NULL;
    LPV_GL_FUNCTIONS(LPV_GL_CLEAR_)
#undef LPV_GL_CLEAR_
    g_generation++;
}

int lpv_gl_load(void *(*get_proc)(const char *name), char *err, size_t err_size)
{
    void *p;
    if (!get_proc) {
        if (err && err_size)
            snprintf(err, err_size, "no GL get-proc-address function");
        lpv_gl_unload();
        return -1;
    }
    /* Converting void * to a function pointer is what every GL loader does;
     * POSIX (dlsym) guarantees it works. */
#define LPV_GL_LOAD_(type, name)                                                      \
    p = get_proc(#name);                                                              \
    if (!p) {                                                                         \
        if (err && err_size)                                                          \
            snprintf(err, err_size, "missing GL function %s", #name);                 \
        lpv_gl_unload();                                                              \
        return -1;                                                                    \
    }                                                                                 \
    name = (type)p;
    LPV_GL_FUNCTIONS(LPV_GL_LOAD_)
#undef LPV_GL_LOAD_
    g_generation++;
    return 0;
}

const char *lpv_gl_error_name(GLenum error)
{
    switch (error) {
    case GL_NO_ERROR: return "GL_NO_ERROR";
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_STACK_OVERFLOW: return "GL_STACK_OVERFLOW";
    case GL_STACK_UNDERFLOW: return "GL_STACK_UNDERFLOW";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_CONTEXT_LOST: return "GL_CONTEXT_LOST";
    default: return "unknown GL error";
    }
}
