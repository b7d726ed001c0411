/*
 * memory_limits.c - see memory_limits.h.
 */
#include "memory_limits.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "engine_internal.h"

#define GPU_MEMORY_INFO_DEDICATED_VIDMEM_NVX 0x9047 /* GL_NVX_gpu_memory_info, kB */
#define TEXTURE_FREE_MEMORY_ATI 0x87FC              /* GL_ATI_meminfo, 4 x kB */

static int has_extension(const char *name)
{
    GLint n = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &n);
    for (GLint i = 0; i < n; ++i) {
        const char *e = (const char *)glGetStringi(GL_EXTENSIONS, (GLuint)i);
        if (e && strcmp(e, name) == 0)
            return 1;
    }
    return 0;
}

void lpv_memory_limits_query(lpv_memory_limits *out)
{
    memset(out, 0, sizeof *out);
    uint64_t memory = 0;
    const char *source = "RAM";
    GLint kb[4] = {0, 0, 0, 0};
    if (has_extension("GL_NVX_gpu_memory_info")) {
        glGetIntegerv(GPU_MEMORY_INFO_DEDICATED_VIDMEM_NVX, kb);
        memory = (uint64_t)(kb[0] > 0 ? kb[0] : 0) * 1024u;
        source = "video memory (GL_NVX_gpu_memory_info)";
    } else if (has_extension("GL_ATI_meminfo")) {
        glGetIntegerv(TEXTURE_FREE_MEMORY_ATI, kb);
        memory = (uint64_t)(kb[0] > 0 ? kb[0] : 0) * 1024u;
        source = "free texture memory (GL_ATI_meminfo)";
    }
    if (memory == 0) {
        long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
        memory = (pages > 0 && page > 0) ? (uint64_t)pages * (uint64_t)page : (uint64_t)4 << 30;
        source = "RAM (the driver reports no video memory)";
    }
    glGetError(); /* an unknown enum on a driver that lied about its extension */
    out->budget = memory / 2;
    snprintf(out->budget_source, sizeof out->budget_source, "half of the %.2f GB of %s", (double)memory / 1e9,
             source);
    /* LPVD_MEMORY_BUDGET_MB can only lower it (a GPU shared with others). */
    const char *cap = getenv("LPVD_MEMORY_BUDGET_MB");
    if (cap && *cap) {
        char *end;
        errno = 0;
        unsigned long long mb = strtoull(cap, &end, 10);
        if (end != cap && !*end && errno == 0 && mb > 0 && mb * 1000000ull < out->budget) {
            out->budget = mb * 1000000ull;
            snprintf(out->budget_source, sizeof out->budget_source, "LPVD_MEMORY_BUDGET_MB=%llu", mb);
        }
    }

    /* GLSL addresses shader storage with 32-bit offsets (llvmpipe faults
     * past 2 GiB), and the grids are also read as buffer textures. */
    GLint tbo = 0, tex = 0, layers = 0;
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &tbo);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &tex);
    glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &layers);
    uint64_t max_buffer = (uint64_t)INT32_MAX;
    if (tbo > 0 && (uint64_t)tbo * 16u < max_buffer)
        max_buffer = (uint64_t)tbo * 16u;
    out->max_buffer = max_buffer;
    out->max_texture_size = tex > 0 ? tex : 16384;
    out->max_layers = layers > 0 ? layers : 256;
}

void lpv_engine_memory_need(const lpv_engine *e, lpv_memory_need *n)
{
    memset(n, 0, sizeof *n);
    lpv_light_face_counts(e, &n->rsm_faces, &n->shadow_faces);
    n->rsm_size = e->settings.rsm_size;
    n->shadow_size = e->settings.shadow_size;
    n->translucent = e->geo.blend_draws > 0;
    if (e->has_view) {
        n->image_w = e->view.width;
        n->image_h = e->view.height;
    }
}

void lpv_engine_set_memory_cap(lpv_engine *e, uint64_t bytes, const char *source)
{
    if (bytes >= e->mem_device_budget) {
        e->mem_limits.budget = e->mem_device_budget;
        snprintf(e->mem_limits.budget_source, sizeof e->mem_limits.budget_source, "%s", e->mem_device_source);
        return;
    }
    e->mem_limits.budget = bytes;
    snprintf(e->mem_limits.budget_source, sizeof e->mem_limits.budget_source, "%s", source);
}

uint64_t lpv_engine_memory_bytes(const lpv_engine *e)
{
    lpv_memory_need need;
    lpv_engine_memory_need(e, &need);
    e->tech->cls->memory_need(e->tech, &need);
    return lpv_memory_total_bytes(&need);
}

int lpv_engine_memory_check(const lpv_engine *e, char *err, size_t err_size)
{
    lpv_memory_need need;
    lpv_engine_memory_need(e, &need);
    e->tech->cls->memory_need(e->tech, &need);
    return lpv_memory_check(&need, &e->mem_limits, err, err_size);
}
