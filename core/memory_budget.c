/*
 * memory_budget.c - storage estimates and the check against the device's
 * limits (see memory_budget.h).
 */
#include "memory_budget.h"

#include "lpv_shared.h" /* LPV_LOOKUP_NORMAL_TEXELS */
#include "cascades.h"
#include "settings.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static uint64_t texels(int size, int faces)
{
    return (uint64_t)(size > 0 ? size : 0) * (uint64_t)(size > 0 ? size : 0) * (uint64_t)(faces > 0 ? faces : 0);
}

static uint64_t pixels(const lpv_memory_need *n)
{
    return (uint64_t)(n->image_w > 0 ? n->image_w : 0) * (uint64_t)(n->image_h > 0 ? n->image_h : 0);
}

uint64_t lpv_memory_block_samples(int w, int h)
{
    /* blocks of s x s pixels, min(LPV_BLOCK_SLOTS = 8, s^2) surfels each:
     * s = 1 gives w h, s = 2 at most (w / 2 + 1)(h / 2 + 1) 4, s >= 3 at
     * most ((w + s - 1) / s)((h + s - 1) / s) 8: all within (w + 2)(h + 2) */
    return (uint64_t)(w > 0 ? w + 2 : 0) * (uint64_t)(h > 0 ? h + 2 : 0);
}

/* The RSMs' VPLs (and as many surfels): at most lpv_memory_block_samples
 * per layer, whatever rsm_vpl_step down-samples them to. */
static uint64_t rsm_samples(const lpv_memory_need *n)
{
    return lpv_memory_block_samples(n->rsm_size, n->rsm_size) * (uint64_t)(n->rsm_faces > 0 ? n->rsm_faces : 0);
}

uint64_t lpv_memory_rsm_bytes(const lpv_memory_need *n)
{
    return texels(n->rsm_size, n->rsm_faces) * LPV_MEM_RSM_TEXEL + rsm_samples(n) * (LPV_MEM_VPL + LPV_MEM_VPL_LIVE + LPV_MEM_SURFEL);
}

uint64_t lpv_memory_shadow_bytes(const lpv_memory_need *n)
{
    return texels(n->shadow_size, n->shadow_faces) *
           (LPV_MEM_SHADOW_TEXEL + (n->translucent ? LPV_MEM_SHADOW_TRANSMIT_TEXEL : 0u));
}

uint64_t lpv_memory_grid_bytes(const lpv_memory_need *n)
{
    /* the lookup's normals take at most LPV_LOOKUP_NORMAL_TEXELS in all */
    const uint64_t normals = n->cells > 0 ? (uint64_t)LPV_LOOKUP_NORMAL_TEXELS * LPV_MEM_LOOKUP_NORMAL_TEXEL : 0;
    return (uint64_t)n->cells * LPV_MEM_CELL + (uint64_t)n->gv_points * LPV_MEM_GV_POINT + normals +
           n->technique_bytes;
}

uint64_t lpv_memory_image_bytes(const lpv_memory_need *n)
{
    return pixels(n) * (LPV_MEM_PIXEL + (n->translucent ? LPV_MEM_LAYER_PIXEL : 0u)) +
           lpv_memory_block_samples(n->image_w, n->image_h) * LPV_MEM_SURFEL;
}

uint64_t lpv_memory_total_bytes(const lpv_memory_need *n)
{
    return lpv_memory_rsm_bytes(n) + lpv_memory_shadow_bytes(n) + lpv_memory_grid_bytes(n) +
           lpv_memory_image_bytes(n);
}

static double gb(uint64_t bytes)
{
    return (double)bytes / 1e9;
}

static int fail(char *err, size_t err_size, const char *fmt, ...)
{
    if (err && err_size) {
        va_list ap;
        va_start(ap, fmt);
        const int k = snprintf(err, err_size, "%s", LPV_MEMORY_REFUSED);
        if (k >= 0 && (size_t)k < err_size)
            vsnprintf(err + k, err_size - (size_t)k, fmt, ap);
        va_end(ap);
    }
    return -1;
}

/* "rsm_size 2048 x 48 light faces" and the like, for part k. */
static void part_name(const lpv_memory_need *n, int k, char *buf, size_t size)
{
    switch (k) {
    case 0: snprintf(buf, size, "rsm_size %d x %d light faces", n->rsm_size, n->rsm_faces); break;
    case 1: snprintf(buf, size, "shadow_size %d x %d shadow-map faces", n->shadow_size, n->shadow_faces); break;
    case 2:
        snprintf(buf, size, "grid %dx%dx%d x %d cascade%s", n->grid_dims[0], n->grid_dims[1], n->grid_dims[2],
                 n->cascades, n->cascades == 1 ? "" : "s");
        break;
    default: snprintf(buf, size, "image size %dx%d", n->image_w, n->image_h); break;
    }
}

int lpv_memory_check(const lpv_memory_need *n, const lpv_memory_limits *lim, char *err, size_t err_size)
{
    char what[96];
    /* Texture dimensions the GL cannot make at all. */
    if (n->rsm_faces > 0 && n->rsm_size > lim->max_texture_size)
        return fail(err, err_size, "rsm_size %d is over this GL's largest texture (%d texels per side)", n->rsm_size,
                    lim->max_texture_size);
    if (n->shadow_faces > 0 && n->shadow_size > lim->max_texture_size)
        return fail(err, err_size, "shadow_size %d is over this GL's largest texture (%d texels per side)",
                    n->shadow_size, lim->max_texture_size);
    if (n->rsm_faces > lim->max_layers || n->shadow_faces > lim->max_layers)
        return fail(err, err_size, "%d RSM faces / %d shadow-map faces are over this GL's %d array layers",
                    n->rsm_faces, n->shadow_faces, lim->max_layers);

    /* Single buffers a shader must address. */
    uint64_t vpl = rsm_samples(n) * LPV_MEM_VPL;
    if (vpl > lim->max_buffer) {
        part_name(n, 0, what, sizeof what);
        return fail(err, err_size,
                    "%s needs %.2f GB for one VPL buffer (%u B per VPL); one shader storage buffer may hold "
                    "at most %.2f GB: lower rsm_size or use fewer lights",
                    what, gb(vpl), LPV_MEM_VPL, gb(lim->max_buffer));
    }
    uint64_t cell_buffer = (uint64_t)n->cells * LPV_MEM_CELL_BUFFER;
    if (cell_buffer > lim->max_buffer) {
        part_name(n, 2, what, sizeof what);
        return fail(err, err_size,
                    "%s needs %.2f GB for one LPV buffer (%u B per cell); one shader storage buffer may hold at "
                    "most %.2f GB: lower grid or cascades",
                    what, gb(cell_buffer), LPV_MEM_CELL_BUFFER, gb(lim->max_buffer));
    }
    if (n->technique_buffer > lim->max_buffer)
        return fail(err, err_size, "%s needs %.2f GB in one buffer; one shader storage buffer may hold at most "
                    "%.2f GB: lower %s",
                    n->technique_buffer_what ? n->technique_buffer_what : "the technique's largest buffer",
                    gb(n->technique_buffer), gb(lim->max_buffer),
                    n->technique_buffer_lower ? n->technique_buffer_lower : "the technique's knobs");
    uint64_t surfels = lpv_memory_block_samples(n->image_w, n->image_h) * LPV_MEM_SURFEL;
    if (surfels > lim->max_buffer) {
        part_name(n, 3, what, sizeof what);
        return fail(err, err_size,
                    "%s needs %.2f GB for its surfel buffer (%u B per pixel); one shader storage buffer may hold "
                    "at most %.2f GB",
                    what, gb(surfels), LPV_MEM_SURFEL, gb(lim->max_buffer));
    }

    /* Everything together against the budget; the largest part is named. */
    uint64_t part[4] = {lpv_memory_rsm_bytes(n), lpv_memory_shadow_bytes(n), lpv_memory_grid_bytes(n),
                        lpv_memory_image_bytes(n)};
    uint64_t total = part[0] + part[1] + part[2] + part[3];
    if (total <= lim->budget)
        return 0;
    int big = 0;
    for (int k = 1; k < 4; ++k)
        if (part[k] > part[big])
            big = k;
    static const char *const kind[4] = {"of RSM textures and VPL/surfel buffers", "of shadow maps",
                                        "of grid buffers", "of G-buffer and frame"};
    part_name(n, big, what, sizeof what);
    return fail(err, err_size,
                "%s needs %.2f GB %s; with the rest (RSMs %.2f GB, shadow maps %.2f GB, grid %.2f GB, image "
                "%.2f GB) the engine needs %.2f GB, and the limit is %.2f GB (%s)",
                what, gb(part[big]), kind[big], gb(part[0]), gb(part[1]), gb(part[2]), gb(part[3]), gb(total),
                gb(lim->budget), lim->budget_source);
}

void lpv_memory_need_grid(const struct lpv_settings *s, int levels, lpv_memory_need *n)
{
    const size_t k = (size_t)levels;
    n->cells = (size_t)s->grid_dims[0] * (size_t)s->grid_dims[1] * (size_t)s->grid_dims[2] * k;
    n->gv_points = (size_t)(s->grid_dims[0] + 1) * (size_t)(s->grid_dims[1] + 1) * (size_t)(s->grid_dims[2] + 1) * k;
    n->cascades = levels;
    memcpy(n->grid_dims, s->grid_dims, sizeof n->grid_dims);
}
