/*
 * engine_read.c - read-backs for the tests and the daemon: the technique's
 * volume (through its read function), the VPLs, and the surfels of each
 * buffer the geometry volume merges (the shared producers' layout).
 */
#include <stdlib.h>

#include "engine_internal.h"

size_t lpv_engine_read_grid(lpv_engine *e, lpv_grid_which which, lpv_cell *out, size_t max)
{
    if (!e->ticked)
        return 0;
    return e->tech->cls->read(e->tech, &e->plan, LPV_VOLUME_SUMMED, which, out, max);
}

size_t lpv_engine_read_volumes(lpv_engine *e, lpv_grid_which which, lpv_cell *out, size_t max)
{
    if (!e->ticked)
        return 0;
    return e->tech->cls->read(e->tech, &e->plan, LPV_VOLUME_STORED, which, out, max);
}

int lpv_engine_bins(const lpv_engine *e) { return e->desc.volumes_per_level; }

size_t lpv_engine_read_gv(lpv_engine *e, lpv_gv_point *out, size_t max)
{
    if (!e->ticked)
        return 0;
    return e->tech->cls->read(e->tech, &e->plan, LPV_VOLUME_GEOMETRY, LPV_GRID_ACCUMULATED, out, max);
}

size_t lpv_engine_read_transmittance(lpv_engine *e, float *out, size_t max_floats)
{
    if (!e->ticked)
        return 0;
    return e->tech->cls->read(e->tech, &e->plan, LPV_VOLUME_TRANSMIT, LPV_GRID_ACCUMULATED, out, max_floats);
}

size_t lpv_engine_read_index(lpv_engine *e, int32_t *out, size_t max)
{
    if (!e->ticked)
        return 0;
    return e->tech->cls->read(e->tech, &e->plan, LPV_VOLUME_INDEX, LPV_GRID_ACCUMULATED, out, max);
}

size_t lpv_engine_read_iv_voxels(lpv_engine *e, struct IvVoxel *out, size_t max)
{
    if (!e->ticked)
        return 0;
    return e->tech->cls->read(e->tech, &e->plan, LPV_VOLUME_IV_VOXELS, LPV_GRID_ACCUMULATED, out, max);
}

size_t lpv_engine_read_ao(lpv_engine *e, float *out, size_t max_floats)
{
    if (!e->ticked)
        return 0;
    return 4 * e->tech->cls->read(e->tech, &e->plan, LPV_VOLUME_AO, LPV_GRID_ACCUMULATED, out, max_floats / 4);
}

size_t lpv_engine_read_visibility(lpv_engine *e, float *out, size_t max_floats)
{
    if (!e->ticked)
        return 0;
    lpv_volume_desc d;
    e->tech->cls->describe(e->tech, &d);
    if (d.visibility_side <= 0)
        return 0;
    return e->tech->cls->read(e->tech, &e->plan, LPV_VOLUME_VISIBILITY, LPV_GRID_ACCUMULATED, out, max_floats);
}

size_t lpv_engine_read_vpls(lpv_engine *e, lpv_vpl *out, size_t max)
{
    if (!e->ticked)
        return 0;
    size_t n = lpv_gl_read_buffer(e->rsm.vpls, sizeof(lpv_vpl), e->rsm.vpl_count, out, max);
    if (n < max && e->plan.consumes.emissive_vpls) /* what the technique got */
        n += lpv_gl_read_buffer(e->emissive_vpls, sizeof(lpv_vpl), e->emissive_vpl_count, out + n, max - n);
    return n;
}

size_t lpv_engine_read_injected_vpls(lpv_engine *e, lpv_vpl *out, size_t max)
{
    if (!e->ticked || !e->rsm.vpls_draw)
        return 0;
    GLuint count = 0;
    lpv_gl_read_buffer(e->rsm.vpls_draw, sizeof count, 1, &count, 1);
    lpv_gl_read_buffer(e->rsm.vpls_live, sizeof(lpv_vpl), count, out, max);
    return count;
}

/* GV buffers: each punctual light, then (if any) the area light samples as
 * one (their first sample's faces; rsm.frag leaves the others' out), then the
 * camera. */
static size_t area_gv_buffers(const lpv_engine *e)
{
    return e->light_block.counts[0] > e->light_block.counts[2] ? 1 : 0;
}

size_t lpv_engine_gv_buffer_count(const lpv_engine *e)
{
    return (size_t)e->light_block.counts[2] + area_gv_buffers(e) + (e->has_view ? 1 : 0) +
           (e->scene_surfel_count ? 1 : 0);
}

void lpv_engine_gv_buffer_range(const lpv_engine *e, size_t buffer, size_t *first, size_t *count)
{
    const size_t per_layer = e->rsm.per_layer[0], per_area_layer = e->rsm.per_layer[1];
    const size_t lights = (size_t)e->light_block.counts[2];
    *first = *count = 0;
    if (buffer < lights) {
        const struct LpvLightGpu *l = &e->light_block.lights[buffer];
        *first = (size_t)l->cone_faces[2] * per_layer; /* a punctual face is a layer */
        *count = (size_t)l->cone_faces[3] * per_layer;
    } else if (buffer == lights && area_gv_buffers(e)) {
        /* only the layers holding the first sample's faces: the other
         * samples' surfels are left out of the GV anyway (rsm.frag) */
        const int layers = lpv_engine_area_gv_layers(e);
        *first = (size_t)e->rsm.punctual_faces * per_layer;
        *count = (size_t)layers * per_area_layer;
    }
}

size_t lpv_engine_read_surfels(lpv_engine *e, size_t buffer, lpv_surfel *out, size_t max)
{
    if (!e->ticked || !e->plan.consumes.surfels)
        return 0;
    size_t rsm_buffers = (size_t)e->light_block.counts[2] + area_gv_buffers(e);
    if (buffer < rsm_buffers) {
        size_t first, count;
        lpv_engine_gv_buffer_range(e, buffer, &first, &count);
        size_t n = count < max ? count : max;
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, e->rsm.surfels);
        glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, (GLintptr)(first * sizeof(lpv_surfel)),
                           (GLsizeiptr)(n * sizeof(lpv_surfel)), out);
        return n;
    }
    if (buffer == rsm_buffers && e->has_view)
        return lpv_gl_read_buffer(e->gbuf.surfels, sizeof(lpv_surfel), lpv_engine_camera_surfel_count(e), out, max);
    if (buffer == rsm_buffers + (e->has_view ? 1 : 0) && e->scene_surfel_count)
        return lpv_gl_read_buffer(e->scene_surfels, sizeof(lpv_surfel), e->scene_surfel_count, out, max);
    return 0;
}
