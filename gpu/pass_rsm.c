/*
 * pass_rsm.c - reflective shadow maps as the engine's producer: lays out
 * the light faces (light_faces.c), checks the memory budget before the maps
 * (rsm_maps.c: every light face renders the scene's position/area, normal
 * and reflected flux into one layer, or an area light's tile, of array
 * textures; direct light has its own shadow maps, shadow_maps.c) allocate,
 * and has rsm_maps.c turn every texel block into VPLs and surfels grouped
 * by the cascades' cells (a compute pass) at the step each kind of layer
 * takes, for the technique.
 */
#include <math.h>

#include "compact.h"
#include "engine_internal.h"

int lpv_pass_rsm_prepare(lpv_engine *e, char *err, size_t err_size)
{
    lpv_light_faces_build(e);
    glBindBuffer(GL_UNIFORM_BUFFER, e->light_ubo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof e->light_block, &e->light_block);

    const int size = e->settings.rsm_size;
    const int layers = e->rsm.layers > 0 ? e->rsm.layers : 1;
    if (lpv_rsms_fit(&e->rsm, size, layers)) {
        e->rsm.size = size;
        return 0;
    }
    e->rsm.size = 0;
    e->rsm.vpl_count = 0;
    /* Estimate before allocating: past what the device holds, drivers fail
     * in ways that crash (llvmpipe segfaults on shader storage past 2 GiB). */
    lpv_memory_need need;
    lpv_engine_memory_need(e, &need);
    if (lpv_engine_memory_check(e, err, err_size) != 0 ||
        lpv_rsms_allocate(&e->rsm, size, layers, lpv_memory_rsm_bytes(&need), err, err_size) != 0)
        return -1;
    e->rsm.size = size;
    e->rsm.vpl_count = 0;
    return 0;
}

/* Layers [first, first + count) of the RSMs, whose faces are `side` texels
 * (a whole layer, or an area light's tile), into VPLs and surfels from
 * element `base` on (rsm_maps.c), at the step of the settings for that
 * side; surfels: whether the geometry volume takes these layers' surfels
 * (the step depends on it, lpv_settings_rsm_vpl_step). Returns the elements
 * per layer. */
static size_t extract_layers(lpv_engine *e, int first, int count, int side, size_t base, int surfels)
{
    const int step = lpv_settings_rsm_vpl_step(&e->settings, side, surfels);
    /* step 1: a VPL per texel (a program without the grouping: llvmpipe
     * would run its code for every texel even where it is not needed);
     * step 2: four slots (block_groups.glsl), as many as texels; larger: 8,
     * without the surfels' grouping where the GV leaves them out (their
     * slots are then not written) */
    const GLuint prog = step == 1   ? e->progs.vpl_extract
                        : step == 2 ? e->progs.vpl_blocks
                                    : (surfels ? e->progs.vpl_blocks8 : e->progs.vpl_blocks8_vpls);
    lpv_group_grid groups[LPV_MAX_CASCADES];
    const lpv_rsm_extract d = {.first = first,
                               .count = count,
                               .step = step,
                               .base = base,
                               .prog = prog,
                               .groups = groups,
                               .group_levels = step > 1 ? lpv_engine_group_grids(e, groups) : 0,
                               .timer = &e->timer};
    return lpv_rsms_extract(&e->rsm, &d);
}

int lpv_engine_area_gv_layers(const lpv_engine *e)
{
    const int area = e->rsm.layers - e->rsm.punctual_faces;
    if (area <= 0 || e->rsm.size <= 0)
        return 0;
    const int side = e->rsm.area_face_side > 0 ? e->rsm.area_face_side : e->rsm.size;
    const int per_row = e->rsm.size / side, faces_per_layer = per_row * per_row;
    const int layers = (LPV_AREA_FACES + faces_per_layer - 1) / faces_per_layer;
    return layers < area ? layers : area;
}

void lpv_pass_rsm_run(lpv_engine *e)
{
    const int size = e->rsm.size;
    const lpv_rsm_draw d = {.geo = &e->geo, .lights = &e->light_block, .light_ubo = e->light_ubo,
                            .prog = e->progs.rsm, .prog_plain = e->progs.rsm_plain, .timer = &e->timer};
    lpv_rsms_draw(&e->rsm, &d);

    /* VPLs and surfels only for a technique whose passes read them (the
     * LPVs' injection and geometry volume); the imperfect volume reads the
     * RSM textures themselves, as shadow maps */
    if (!e->plan.pass[LPV_PASS_INJECT].run && !e->plan.pass[LPV_PASS_GV].run)
        return;
    lpv_timer_begin(&e->timer, "vpl_extract");
    /* the producers mark the VPLs that carry light (compact.h) */
    lpv_compact_clear(e->rsm.vpls_draw);
    lpv_compact_bind(e->rsm.vpls_draw);
    /* the punctual lights' layers (one face a layer), then the area lights'
     * (faces tiled four to a layer): those holding the first sample's faces,
     * whose surfels the geometry volume takes, then the others, which give
     * VPLs only (rsm.frag); each at the step of its faces' side, one after
     * the other in the buffers */
    const int punctual = e->rsm.punctual_faces < e->rsm.layers ? e->rsm.punctual_faces : e->rsm.layers;
    const int area_side = e->rsm.area_face_side > 0 ? e->rsm.area_face_side : size;
    const int area = e->rsm.layers - punctual, area_gv = lpv_engine_area_gv_layers(e);
    size_t base = 0;
    e->rsm.per_layer[0] = extract_layers(e, 0, punctual, size, base, 1);
    base += (size_t)punctual * e->rsm.per_layer[0];
    e->rsm.per_layer[1] = extract_layers(e, punctual, area_gv, area_side, base, 1);
    base += (size_t)area_gv * e->rsm.per_layer[1];
    e->rsm.per_layer[2] = extract_layers(e, punctual + area_gv, area - area_gv, area_side, base, 0);
    e->rsm.vpl_count = base + (size_t)(area - area_gv) * e->rsm.per_layer[2];
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    /* the injection draws only the VPLs that carry light (most of the
     * blocks' slots are empty) */
    lpv_compact_run(e->progs.compact, e->rsm.vpls, e->rsm.vpl_count, e->rsm.vpls_live, e->rsm.vpls_draw);
    lpv_timer_end(&e->timer);
}
