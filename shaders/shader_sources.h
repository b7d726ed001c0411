/* shader_sources.h - the GLSL files of shaders/, embedded at build time by
 * cmake/embed.cmake. Looked up by file name (e.g. "propagate.comp"). */
#ifndef LPV_SHADER_SOURCES_H
#define LPV_SHADER_SOURCES_H

#include <stddef.h>

typedef struct lpv_shader_source {
    const char *name;
    const char *text;
    size_t length;
} lpv_shader_source;

/* Terminated by an entry with name == NULL. */
extern const lpv_shader_source lpv_shader_sources[];

#endif
