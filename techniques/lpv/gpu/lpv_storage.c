/*
 * lpv_storage.c - where the cascades go (core/cascades.c places them from the
 * settings, the scene's bounds and the camera) and the buffers that hold
 * them: the injected grid, the ping-pong pair, the accumulation, the flux
 * limits, the geometry volume, the transmittances and reflectances, their
 * buffer-texture views, and both atlases. Storage is made anew only when the
 * dims, the cascade count or the normal bins change, after checking it
 * against the memory budget together with the engine's own storage.
 */
#include <math.h>
#include <string.h>

#include "error.h"
#include "lpv_internal.h"

int lpv_cascaded_place(lpv_cascaded *c, const lpv_technique_where *w, int *moved, char *err, size_t err_size)
{
    char why[LPV_PLAN_REASON_MAX];
    const int count = lpv_plan_cascades(w->settings, w->facts, why, sizeof why);
    const float *fwd = w->forward;
    float f[3];
    if (fwd) {
        float len = sqrtf(fwd[0] * fwd[0] + fwd[1] * fwd[1] + fwd[2] * fwd[2]);
        for (int i = 0; i < 3; ++i)
            f[i] = len > 0.0f ? fwd[i] / len : 0.0f;
        fwd = f;
    }
    if (lpv_cascades_place(w->settings, count, w->bounds_min, w->bounds_max, w->eye, fwd, w->facts->view_chord,
                           &c->pending) != 0)
        return lpv_error(err, err_size, "%d cascades of %dx%dx%d cells cannot be placed", count,
                         w->settings->grid_dims[0], w->settings->grid_dims[1], w->settings->grid_dims[2]);
    if (moved)
        *moved = !lpv_cascades_equal(&c->pending, &c->cascades);
    return 0;
}

void lpv_cascaded_place_grid(lpv_cascaded *c, const lpv_grid *g, int *moved)
{
    memset(&c->pending, 0, sizeof c->pending);
    c->pending.count = 1;
    c->pending.grid[0] = *g;
    for (int i = 0; i < 3; ++i)
        c->pending.origin_cells[0][i] = g->origin[i] / g->cell_size;
    if (moved)
        *moved = !lpv_cascades_equal(&c->pending, &c->cascades);
}

void lpv_cascaded_free_storage(lpv_cascaded *c)
{
    lpv_atlas_destroy(&c->lpv_atlas);
    lpv_atlas_destroy(&c->gv_atlas);
    lpv_lookup_volume_free(&c->lookup);
    GLuint *bufs[] = {&c->lpv_injected, &c->lpv_ping, &c->lpv_pong, &c->lpv_acc,  &c->gv_total,
                      &c->transmit,     &c->reflect,  &c->sent[0], &c->sent[1]};
    for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; ++i)
        lpv_gl_delete_buffer(bufs[i]);
    GLuint *views[] = {&c->tbo_injected, &c->tbo_ping, &c->tbo_pong, &c->tbo_sent[0], &c->tbo_sent[1],
                       &c->tbo_acc, &c->tbo_transmit, &c->tbo_reflect};
    for (size_t i = 0; i < sizeof views / sizeof views[0]; ++i)
        lpv_gl_delete_texture(views[i]);
    c->grid_alloc_cells = 0;
    c->grid_alloc_cascades = 0;
}

/* The grid part of the budget for the cascades `set`. */
static void grid_need(const lpv_cascade_set *set, const lpv_grid *fallback, lpv_memory_need *n)
{
    const lpv_grid *g = set->count > 0 ? &set->grid[0] : fallback;
    const size_t k = (size_t)(set->count > 0 ? set->count : 1);
    n->cells = lpv_grid_cell_count(g) * k;
    n->gv_points = lpv_grid_gv_count(g) * k;
    n->cascades = (int)k;
    memcpy(n->grid_dims, g->dims, sizeof n->grid_dims);
}

void lpv_cascaded_memory_need(const lpv_cascaded *c, lpv_memory_need *n)
{
    grid_need(&c->cascades, &c->grid, n);
}

int lpv_cascaded_commit(lpv_cascaded *c, const lpv_technique_where *w, int *reset, char *err, size_t err_size)
{
    const lpv_cascade_set *set = &c->pending;
    const lpv_grid *g = &set->grid[0];
    *reset = 0;
    c->cascades = *set;
    c->grid = *g;
    c->bins = c->settings.lpv.normal_bins == LPV_SWITCH_ON ? LPV_NORMAL_BINS : 1;
    struct LpvGridParams params;
    lpv_cascades_grid_params(set, &params);
    params.info[1] = set->count > 1 && !set->handoff ? 1.0f : 0.0f;
    params.info[2] = (float)c->bins;
    params.info[3] = c->settings.lpv.central_transport == LPV_SWITCH_ON ? (float)LPV_TRANSPORT_CENTRAL
                                                                       : (float)LPV_TRANSPORT_PAPER;
    params.mode[0] = set->handoff ? 1.0f : 0.0f;
    glBindBuffer(GL_UNIFORM_BUFFER, c->grid_ubo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof params, &params);
    if (c->grid_alloc_cells && memcmp(g->dims, c->grid_alloc_dims, sizeof g->dims) == 0 &&
        c->grid_alloc_cascades == set->count && c->grid_alloc_bins == c->bins)
        return 0;

    lpv_memory_need need = w->others;
    grid_need(set, &c->grid, &need);
    if (lpv_memory_check(&need, w->limits, err, err_size) != 0)
        return -1;
    lpv_cascaded_free_storage(c);
    *reset = 1;
    const size_t K = (size_t)set->count;
    size_t cells = lpv_grid_cell_count(g) * K, gv = lpv_grid_gv_count(g) * K;
    size_t vcells = cells * (size_t)c->bins; /* LPV volumes: cascades x bins */
    int lpv_dims[3] = {g->dims[0], g->dims[1], g->dims[2] * set->count * c->bins};
    int gv_dims[3] = {g->dims[0] + 1, g->dims[1] + 1, (g->dims[2] + 1) * set->count};
    if (lpv_atlas_create(&c->lpv_atlas, lpv_dims, 3, err, err_size) != 0 ||
        lpv_atlas_create(&c->gv_atlas, gv_dims, 2, err, err_size) != 0)
        return -1;
    c->lpv_injected = lpv_gl_new_ssbo(vcells * sizeof(lpv_cell));
    c->lpv_ping = lpv_gl_new_ssbo(vcells * sizeof(lpv_cell));
    c->lpv_pong = lpv_gl_new_ssbo(vcells * sizeof(lpv_cell));
    c->lpv_acc = lpv_gl_new_ssbo(vcells * sizeof(lpv_cell));
    c->gv_total = lpv_gl_new_ssbo(gv * sizeof(lpv_gv_point));
    c->transmit = lpv_gl_new_ssbo(cells * LPV_DIR_COUNT * sizeof(float));
    c->reflect = lpv_gl_new_ssbo(cells * LPV_DIR_COUNT * 4 * sizeof(float));
    c->sent[0] = lpv_gl_new_ssbo(vcells * sizeof(lpv_cell));
    c->sent[1] = lpv_gl_new_ssbo(vcells * sizeof(lpv_cell));
    c->tbo_injected = lpv_gl_buffer_view(c->lpv_injected, GL_RGBA32F);
    c->tbo_ping = lpv_gl_buffer_view(c->lpv_ping, GL_RGBA32F);
    c->tbo_pong = lpv_gl_buffer_view(c->lpv_pong, GL_RGBA32F);
    c->tbo_sent[0] = lpv_gl_buffer_view(c->sent[0], GL_RGBA32F);
    c->tbo_sent[1] = lpv_gl_buffer_view(c->sent[1], GL_RGBA32F);
    c->tbo_acc = lpv_gl_buffer_view(c->lpv_acc, GL_RGBA32F);
    c->tbo_transmit = lpv_gl_buffer_view(c->transmit, GL_RG32F); /* a face pair per texel */
    c->tbo_reflect = lpv_gl_buffer_view(c->reflect, GL_RGBA32F);
    if (c->lookup_wanted &&
        lpv_lookup_volume_alloc(&c->lookup, g->dims, c->cascades.count, lpv_cascade_volumes(c), err, err_size) != 0)
        return -1;
    c->grid_alloc_cells = cells;
    memcpy(c->grid_alloc_dims, g->dims, sizeof g->dims);
    c->grid_alloc_cascades = set->count;
    c->grid_alloc_bins = c->bins;
    if (glGetError() != GL_NO_ERROR)
        return lpv_error(err, err_size, "could not allocate %d cascades of %dx%dx%d cells", set->count, g->dims[0],
                         g->dims[1], g->dims[2]);
    return 0;
}
