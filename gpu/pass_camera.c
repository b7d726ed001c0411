/*
 * pass_camera.c - the camera's producer as the engine runs it: the view
 * block from the lpv_view, the G-buffer (gbuffer.c) and its pixels as GV
 * surfels grouped by the cascades, and the frame (frame.c) shaded with the
 * variant and passes this file chooses from the settings, the plan, the
 * lights, the scene's materials and the technique (its lookup, technique.h):
 * direct light through the shadow maps plus the technique's irradiance.
 */
#include <math.h>
#include <string.h>

#include <cglm/cglm.h>

#include "engine_internal.h"

/* Deletes the G-buffer and the frame (a partly failed allocation too); the
 * engine's destroy calls it too, so this is the one list of them. */
void lpv_pass_camera_free(lpv_engine *e)
{
    lpv_gbuffer_free(&e->gbuf);
    lpv_frame_free(&e->frame);
}

/* (Re)allocates the G-buffer, the camera's surfels and the frame for the
 * view's size (lpv_engine_set_view checked that they fit the budget). */
static int ensure_targets(lpv_engine *e, char *err, size_t err_size)
{
    const int w = e->view.width, h = e->view.height;
    if (lpv_gbuffer_ensure(&e->gbuf, w, h, err, err_size) != 0 ||
        lpv_frame_ensure(&e->frame, w, h, err, err_size) != 0) {
        lpv_pass_camera_free(e);
        return -1;
    }
    return 0;
}

/* The view block: matrices from the lpv_view, far plane from the bounds. */
static void build_view_block(lpv_engine *e)
{
    const lpv_view *v = &e->view;
    struct LpvViewBlock *b = &e->view_block;
    memset(b, 0, sizeof *b);
    vec3 eye = {v->eye[0], v->eye[1], v->eye[2]}, fwd = {v->forward[0], v->forward[1], v->forward[2]},
         up = {v->up[0], v->up[1], v->up[2]}, centre;
    glm_vec3_normalize(fwd);
    glm_vec3_add(eye, fwd, centre);
    vec3 ext;
    glm_vec3_sub(e->scene_max, e->scene_min, ext);
    float radius = 0.5f * glm_vec3_norm(ext);
    if (!(radius > 1e-6f))
        radius = 1.0f;
    float far_z = v->zfar;
    if (!(far_z > 0.0f)) {
        vec3 mid;
        glm_vec3_center(e->scene_min, e->scene_max, mid);
        far_z = glm_vec3_distance(eye, mid) + 2.0f * radius;
    }
    float near_z = v->znear > 0.0f ? v->znear : 1e-3f * radius;
    float aspect = (float)v->width / (float)v->height;
    mat4 view, proj;
    glm_lookat(eye, centre, up, view);
    if (v->orthographic)
        glm_ortho(-v->ymag * aspect, v->ymag * aspect, -v->ymag, v->ymag, near_z, far_z, proj);
    else
        glm_perspective(v->yfov, aspect, near_z, far_z, proj);
    glm_mat4_mul(proj, view, b->view_proj);
    glm_vec3_copy(eye, b->eye);
    b->eye[3] = v->orthographic ? 0.0f : 1.0f;
    glm_vec3_copy(fwd, b->forward);
    b->forward[3] = v->orthographic ? v->ymag : tanf(0.5f * v->yfov);
    b->viewport[0] = (float)v->width;
    b->viewport[1] = (float)v->height;
    b->viewport[2] = aspect;
}

int lpv_pass_gbuffer_run(lpv_engine *e, char *err, size_t err_size)
{
    if (ensure_targets(e, err, err_size) != 0)
        return -1;
    lpv_timer_begin(&e->timer, "gbuffer");
    build_view_block(e);
    const lpv_view *v = &e->view;
    const lpv_gbuffer_draw d = {.geo = &e->geo, .view = &e->view_block, .width = v->width, .height = v->height,
                                .orthographic = v->orthographic, .prog = e->progs.gbuffer,
                                .prog_plain = e->progs.gbuffer_plain,
                                .translucent = e->geo.blend_draws && e->plan.pass[LPV_PASS_TRANSLUCENT].run,
                                .timer = &e->timer};
    if (lpv_gbuffer_draw_scene(&e->gbuf, &d, err, err_size) != 0) {
        lpv_timer_end(&e->timer);
        return -1;
    }

    lpv_group_grid groups[LPV_MAX_CASCADES];
    const lpv_gbuffer_surfels sd = {.prog = e->progs.camera_surfels,
                                    .step = lpv_settings_camera_surfel_step(&e->settings, v->height),
                                    .groups = groups,
                                    .group_levels = lpv_engine_group_grids(e, groups),
                                    .timer = &e->timer};
    lpv_gbuffer_extract_surfels(&e->gbuf, &sd);
    lpv_timer_end(&e->timer);
    return 0;
}

/* The technique's lookup for the frame's programs (lpv_frame_lookup). */
static void bind_lookup(void *ctx, GLuint prog)
{
    lpv_engine *e = ctx;
    lpv_engine_bind_lookup(e, prog, e->settings.lpv.damping);
}

/* Shades gbuf's rect into frame (the camera's frame, or the translucent
 * layer's): chooses the variant and the passes, writes the view block's
 * shading terms and hands the rest to frame.c. stage: the timer's name. */
static int shade_frame(lpv_engine *e, lpv_frame_terms terms, const GLuint gbuf[LPV_GBUF_TARGETS], GLuint frame,
                       const int rect[4], const char *stage, char *err, size_t err_size)
{
    /* the frame's variant: the lookup step's blocks (frames with the LPV
     * term), else the technique's two passes; the area shadow step's blocks
     * (frames with direct light, scenes with area light samples); without
     * the directional lights' loop where there are none (llvmpipe would run
     * its code once for every pixel even with no light in it) */
    const int indirect = terms == LPV_TERMS_FULL || terms == LPV_TERMS_INDIRECT_ONLY;
    const int direct = terms == LPV_TERMS_FULL || terms == LPV_TERMS_DIRECT_ONLY;
    const int blocks = e->settings.lookup_step > 1 && indirect;
    const int area_blocks = e->settings.area_shadow_step > 1 && direct && e->light_block.counts[0] > e->light_block.counts[2];
    const int damped = e->settings.lpv.damping > 0.0f;
    const int split = !blocks && e->tech->cls->lookup_split && e->tech->cls->lookup_split(e->tech);
    const unsigned variant = (e->light_block.counts[3] > 0.0f ? LPV_FRAME_DIRECTIONAL : 0u) |
                             (damped ? LPV_FRAME_DAMPED : 0u) | (split ? LPV_FRAME_SPLIT : 0u) |
                             (blocks ? LPV_FRAME_BLOCKS : 0u) | (area_blocks ? LPV_FRAME_AREA_BLOCKS : 0u) |
                             (e->geo.materials_occlusion ? LPV_FRAME_OCCLUSION : 0u) |
                             (e->geo.materials_unlit ? LPV_FRAME_UNLIT : 0u);
    const GLuint prog = lpv_engine_frame_program(e, variant, err, err_size);
    if (!prog)
        return -1;

    struct LpvViewBlock *b = &e->view_block;
    b->shading[0] = e->settings.indirect_gain;
    b->shading[1] = terms != LPV_TERMS_INDIRECT_ONLY;
    b->shading[2] = terms != LPV_TERMS_DIRECT_ONLY;
    b->shading[3] = terms != LPV_TERMS_INDIRECT_ONLY;
    b->viewport[3] = terms == LPV_TERMS_AO; /* shading.glsl writes the ambient occlusion instead */
    glBindBuffer(GL_UNIFORM_BUFFER, e->view_ubo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof *b, b);
    const lpv_frame_shading s = {
        .gbuf = gbuf,
        .target = frame,
        .rect = {rect[0], rect[1], rect[2], rect[3]},
        .stage = stage,
        .blocks = blocks,
        .area_blocks = area_blocks,
        .split = split,
        .lookup_step = e->settings.lookup_step,
        .area_shadow_step = e->settings.area_shadow_step,
        .glossy_roughness = e->plan.pass[LPV_PASS_GLOSSY].run && terms != LPV_TERMS_DIRECT_ONLY
                                ? e->settings.glossy_roughness
                                : 0.0f,
        .prog = prog,
        .prog_rest = damped ? e->progs.shade_rest_damped : e->progs.shade_rest,
        .prog_area_rest = e->progs.area_shadow_rest,
        .prog_lookup_blocks = damped ? e->progs.lookup_blocks_damped : e->progs.lookup_blocks,
        .prog_area_shadow_blocks = e->progs.area_shadow_blocks,
        .lookup = {bind_lookup, e},
        .shadows = &e->shadows,
        .light_ubo = e->light_ubo,
        .view_ubo = e->view_ubo,
        .timer = &e->timer,
    };
    lpv_frame_shade(&e->frame, &s);
    return 0;
}

int lpv_pass_shade_run(lpv_engine *e, lpv_frame_terms terms, char *err, size_t err_size)
{
    const int whole[4] = {0, 0, e->gbuf.w, e->gbuf.h};
    return shade_frame(e, terms, e->gbuf.tex, e->frame.tex, whole, "shade", err, err_size);
}

/* The pixels the BLEND draws can cover: the bounding rectangle of their
 * bounding boxes' corners projected by the G-buffer's camera, a pixel wider
 * each way and clipped to the frame (the whole frame when a corner lies
 * behind the eye). Returns 0 when none can be seen. */
static int layer_rect(const lpv_engine *e, int rect[4])
{
    const float w = (float)e->gbuf.w, h = (float)e->gbuf.h;
    float lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (uint32_t i = 0; i < e->geo.draw_count; ++i) {
        const lpv_gpu_draw *d = &e->geo.draws[i];
        if (d->material < 0 || (uint32_t)d->material >= e->geo.material_count || !e->geo.materials[d->material].blend ||
            !(d->box_max[0] >= d->box_min[0]) || !d->index_count)
            continue;
        for (int c = 0; c < 8; ++c) {
            vec4 p = {(c & 1) ? d->box_max[0] : d->box_min[0], (c & 2) ? d->box_max[1] : d->box_min[1],
                      (c & 4) ? d->box_max[2] : d->box_min[2], 1.0f},
                 clip;
            glm_mat4_mulv((vec4 *)e->view_block.view_proj, p, clip);
            if (!(clip[3] > 1e-6f)) { /* behind the eye (or on its plane): it may reach any pixel */
                rect[0] = rect[1] = 0, rect[2] = e->gbuf.w, rect[3] = e->gbuf.h;
                return 1;
            }
            const float x = (clip[0] / clip[3] * 0.5f + 0.5f) * w, y = (clip[1] / clip[3] * 0.5f + 0.5f) * h;
            lo[0] = fminf(lo[0], x), hi[0] = fmaxf(hi[0], x);
            lo[1] = fminf(lo[1], y), hi[1] = fmaxf(hi[1], y);
        }
    }
    const float x0 = fmaxf(floorf(lo[0]) - 1.0f, 0.0f), y0 = fmaxf(floorf(lo[1]) - 1.0f, 0.0f);
    const float x1 = fminf(ceilf(hi[0]) + 1.0f, w), y1 = fminf(ceilf(hi[1]) + 1.0f, h);
    if (!(x1 > x0) || !(y1 > y0))
        return 0;
    rect[0] = (int)x0, rect[1] = (int)y0, rect[2] = (int)(x1 - x0), rect[3] = (int)(y1 - y0);
    return 1;
}

int lpv_pass_translucent_run(lpv_engine *e, lpv_frame_terms terms, size_t *full_lookups, size_t *area_rest_pixels,
                             char *err, size_t err_size)
{
    if (!e->gbuf.layer_fbo || e->gbuf.layer_w != e->gbuf.w || e->gbuf.layer_h != e->gbuf.h)
        return lpv_error(err, err_size, "the translucent layer was not drawn for this %dx%d frame", e->gbuf.w,
                         e->gbuf.h);
    /* the frame's pixels listed for second passes, before the layer's
     * shading lists its own in the same buffers */
    *full_lookups += lpv_frame_full_lookups(&e->frame);
    *area_rest_pixels += lpv_frame_area_rest_pixels(&e->frame);
    /* only the pixels its draws can cover: the layer's shading costs what
     * the frame's does per pixel, and llvmpipe shades an uncovered pixel's
     * lanes all the same */
    int rect[4];
    if (!layer_rect(e, rect))
        return 0;
    if (shade_frame(e, terms, e->gbuf.layer_tex, e->gbuf.layer_frame_tex, rect, "translucent", err, err_size) != 0)
        return -1;
    lpv_timer_begin(&e->timer, "translucent");
    lpv_frame_overlay(&e->frame, e->progs.translucent, e->gbuf.layer_frame_tex, e->gbuf.layer_tex[LPV_GBUF_TARGETS],
                      rect, &e->timer);
    lpv_timer_end(&e->timer);
    return 0;
}
