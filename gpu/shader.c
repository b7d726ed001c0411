/*
 * shader.c - GL programs from the embedded GLSL sources (see shader.h).
 *
 * Each stage is compiled from the concatenation
 *   "#version 450 core\n#define LPV_GLSL 1\n"   source string 0
 *   + defines (if any) + "\n"                   still source string 0
 *   + "#line 1 1\n" + lpv_shared.h              source string 1
 *   + "#line 1 2\n" + the stage's file          source string 2
 * so a compiler message "2:17(5): error ..." (Mesa's form) means line 17 of
 * the stage's file and "1:..." a line of lpv_shared.h. The logs handed back
 * start with the file name and spell out that mapping. Line numbers are
 * reliable; the source number is not always: Mesa 22 reports syntax errors
 * with the right source but some semantic ones ("no function with name")
 * with source 0.
 */
#include "shader.h"
#include "error.h"

#include "shader_sources.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LPV_SHARED_HEADER "lpv_shared.h"


const char *lpv_shader_text(const char *name)
{
    if (!name)
        return NULL;
    for (const lpv_shader_source *s = lpv_shader_sources; s->name; s++) {
        if (strcmp(s->name, name) == 0)
            return s->text;
    }
    return NULL;
}

static const char *stage_name(GLenum stage)
{
    switch (stage) {
    case GL_VERTEX_SHADER: return "vertex";
    case GL_GEOMETRY_SHADER: return "geometry";
    case GL_FRAGMENT_SHADER: return "fragment";
    case GL_COMPUTE_SHADER: return "compute";
    default: return "shader";
    }
}

/* Returns a malloc'd info log of a shader (is_program 0) or program, or NULL. */
static char *info_log(GLuint obj, int is_program)
{
    GLint len = 0;
    if (is_program)
        glGetProgramiv(obj, GL_INFO_LOG_LENGTH, &len);
    else
        glGetShaderiv(obj, GL_INFO_LOG_LENGTH, &len);
    if (len <= 0)
        return NULL;
    char *log = malloc((size_t)len + 1);
    if (!log)
        return NULL;
    GLsizei got = 0;
    if (is_program)
        glGetProgramInfoLog(obj, len, &got, log);
    else
        glGetShaderInfoLog(obj, len, &got, log);
    log[got > 0 ? (got < len ? got : len - 1) : 0] = '\0';
    /* drop trailing newlines, the caller's message decides the layout */
    size_t n = strlen(log);
    while (n && (log[n - 1] == '\n' || log[n - 1] == '\r'))
        log[--n] = '\0';
    return log;
}

/* Compiles one stage of file `name`. Returns the shader, or 0 with err set. */
static GLuint compile_stage(GLenum stage, const char *name, const char *defines, char *err, size_t err_size)
{
    const char *text = lpv_shader_text(name);
    if (!text) {
        lpv_error(err, err_size, "%s: no such embedded shader (files of shaders/ are embedded at build time)", name);
        return 0;
    }
    const char *shared = lpv_shader_text(LPV_SHARED_HEADER);
    if (!shared) {
        lpv_error(err, err_size, "%s: %s is not embedded", name, LPV_SHARED_HEADER);
        return 0;
    }
    /* LPV_STAGE_* lets an include shared by several stages keep
     * stage-specific functions (dFdx only exists in fragment shaders). */
    const char *version = stage == GL_COMPUTE_SHADER    ? "#version 450 core\n#define LPV_GLSL 1\n#define LPV_STAGE_COMPUTE 1\n"
                          : stage == GL_VERTEX_SHADER   ? "#version 450 core\n#define LPV_GLSL 1\n#define LPV_STAGE_VERTEX 1\n"
                          : stage == GL_GEOMETRY_SHADER ? "#version 450 core\n#define LPV_GLSL 1\n#define LPV_STAGE_GEOMETRY 1\n"
                                                        : "#version 450 core\n#define LPV_GLSL 1\n#define LPV_STAGE_FRAGMENT 1\n";
    const char *parts[7] = {
        version,
        defines ? defines : "",
        "\n#line 1 1\n",
        shared,
        "\n#line 1 2\n",
        text,
        "\n",
    };
    GLuint sh = glCreateShader(stage);
    if (!sh) {
        lpv_error(err, err_size, "%s: glCreateShader(%s) failed (%s)", name, stage_name(stage),
                lpv_gl_error_name(glGetError()));
        return 0;
    }
    glShaderSource(sh, (GLsizei)(sizeof parts / sizeof parts[0]), parts, NULL);
    glCompileShader(sh);
    GLint ok = GL_FALSE;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char *log = info_log(sh, 0);
        lpv_error(err, err_size,
                "%s: %s shader compile failed (source 2 = %s, source 1 = " LPV_SHARED_HEADER
                ", source 0 = prelude/defines):\n%s",
                name, stage_name(stage), name, log ? log : "(no log)");
        free(log);
        glDeleteShader(sh);
        return 0;
    }
    return sh;
}

/* Links the given shaders (0 entries skipped) and deletes them. `label` names
 * the files for messages. Returns the program or 0 with err set. */
static GLuint link_program(const GLuint *shaders, int count, const char *label, char *err, size_t err_size)
{
    GLuint prog = glCreateProgram();
    if (!prog) {
        lpv_error(err, err_size, "%s: glCreateProgram failed (%s)", label, lpv_gl_error_name(glGetError()));
        for (int i = 0; i < count; i++)
            if (shaders[i])
                glDeleteShader(shaders[i]);
        return 0;
    }
    for (int i = 0; i < count; i++)
        if (shaders[i])
            glAttachShader(prog, shaders[i]);
    glLinkProgram(prog);
    for (int i = 0; i < count; i++) {
        if (shaders[i]) {
            glDetachShader(prog, shaders[i]);
            glDeleteShader(shaders[i]);
        }
    }
    GLint ok = GL_FALSE;
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    if (!ok) {
        char *log = info_log(prog, 1);
        lpv_error(err, err_size, "%s: link failed:\n%s", label, log ? log : "(no log)");
        free(log);
        glDeleteProgram(prog);
        return 0;
    }
    return prog;
}

GLuint lpv_program_compute(const char *comp, const char *defines, char *err, size_t err_size)
{
    if (!comp) {
        lpv_error(err, err_size, "lpv_program_compute: no compute shader named");
        return 0;
    }
    GLuint cs = compile_stage(GL_COMPUTE_SHADER, comp, defines, err, err_size);
    if (!cs)
        return 0;
    GLuint prog = link_program(&cs, 1, comp, err, err_size);
    if (prog && err && err_size)
        err[0] = '\0';
    return prog;
}

GLuint lpv_program_graphics(const char *vert, const char *geom, const char *frag, const char *defines,
                            char *err, size_t err_size)
{
    if (!vert) {
        lpv_error(err, err_size, "lpv_program_graphics: no vertex shader named");
        return 0;
    }
    /* geom may be NULL; frag may be NULL for depth-only passes. */
    char label[256];
    snprintf(label, sizeof label, "%s%s%s%s%s", vert, geom ? " + " : "", geom ? geom : "", frag ? " + " : "",
             frag ? frag : "");
    GLuint sh[3] = {0, 0, 0};
    sh[0] = compile_stage(GL_VERTEX_SHADER, vert, defines, err, err_size);
    if (!sh[0])
        return 0;
    if (geom) {
        sh[1] = compile_stage(GL_GEOMETRY_SHADER, geom, defines, err, err_size);
        if (!sh[1]) {
            glDeleteShader(sh[0]);
            return 0;
        }
    }
    if (frag) {
        sh[2] = compile_stage(GL_FRAGMENT_SHADER, frag, defines, err, err_size);
        if (!sh[2]) {
            glDeleteShader(sh[0]);
            if (sh[1])
                glDeleteShader(sh[1]);
            return 0;
        }
    }
    GLuint prog = link_program(sh, 3, label, err, err_size);
    if (prog && err && err_size)
        err[0] = '\0';
    return prog;
}

GLuint lpv_program_build(const char *first, const char *geom, const char *frag, const char *const *includes,
                         char *err, size_t err_size)
{
    return lpv_program_build_defines(first, geom, frag, NULL, includes, err, err_size);
}

GLuint lpv_program_build_defines(const char *first, const char *geom, const char *frag, const char *defines,
                                 const char *const *includes, char *err, size_t err_size)
{
    /* The includes use the shared header's types, so it goes first; its
     * include guard makes the copy shader.c adds afterwards a no-op. */
    const char *shared = lpv_shader_text("lpv_shared.h");
    size_t len = strlen(shared) + 2 + (defines ? strlen(defines) + 1 : 0);
    for (const char *const *i = includes; i && *i; ++i) {
        const char *t = lpv_shader_text(*i);
        if (!t) {
            lpv_error(err, err_size, "shader include %s is not embedded", *i);
            return 0;
        }
        len += strlen(t) + 64;
    }
    char *prelude = malloc(len);
    if (!prelude) {
        lpv_error(err, err_size, "out of memory building %s", first);
        return 0;
    }
    prelude[0] = '\0';
    if (defines) {
        strcat(prelude, defines);
        strcat(prelude, "\n");
    }
    strcat(prelude, shared);
    strcat(prelude, "\n");
    for (const char *const *i = includes; i && *i; ++i) {
        strcat(prelude, lpv_shader_text(*i));
        strcat(prelude, "\n");
    }
    GLuint p = frag ? lpv_program_graphics(first, geom, frag, prelude, err, err_size)
                    : lpv_program_compute(first, prelude, err, err_size);
    free(prelude);
    return p;
}
