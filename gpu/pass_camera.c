/*
 * pass_camera.c - the camera's passes: the G-buffer (gbuffer.c: position/
 * surfel area, normal, albedo, emission) with its pixels as GV surfels, and the final
 * shading of direct light (through the shadow maps of shadow_maps.c) plus the
 * technique's irradiance (its lookup, technique.h) into a linear-radiance frame.
 */
#include <math.h>
#include <string.h>

#include <cglm/cglm.h>

#include "engine_internal.h"

/* Deletes the G-buffer (gbuffer.c), the frame and its pixel lists (a
 * partly failed allocation too); the engine's destroy calls it too, so this
 * is the one list of them. */
void lpv_pass_camera_free(lpv_engine *e)
{
    lpv_gbuffer_free(&e->gbuf);
    lpv_gl_delete_texture(&e->frame.tex);
    lpv_gl_delete_framebuffer(&e->frame.fbo);
    lpv_gl_delete_buffer(&e->frame.shade_rest);
    lpv_gl_delete_buffer(&e->frame.area_rest);
}

/* (Re)allocates the G-buffer, the camera's surfels and the frame for the
 * view's size (lpv_engine_set_view checked that they fit the budget). */
static int ensure_targets(lpv_engine *e, char *err, size_t err_size)
{
    const int w = e->view.width, h = e->view.height;
    if (e->gbuf.w == w && e->gbuf.h == h)
        return 0;
    lpv_pass_camera_free(e);
    if (lpv_gbuffer_ensure(&e->gbuf, w, h, err, err_size) != 0)
        return -1;
    glGenFramebuffers(1, &e->frame.fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, e->frame.fbo);
    e->frame.tex = lpv_gl_new_texture_2d(GL_RGBA32F, w, h);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, e->frame.tex, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    /* the frame's two lists of pixels for a second pass: the lookup's
     * (shade_rest.comp) and the area shadow step's (area_shadow_rest.comp) */
    GLuint *lists[2] = {&e->frame.shade_rest, &e->frame.area_rest};
    for (int i = 0; i < 2; ++i) {
        glGenBuffers(1, lists[i]);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, *lists[i]);
        glBufferData(GL_SHADER_STORAGE_BUFFER,
                     (GLsizeiptr)(4 * sizeof(GLuint) + (size_t)w * (size_t)h * 2 * sizeof(GLint)), NULL,
                     GL_DYNAMIC_COPY);
    }
    GLenum gl_err = glGetError();
    if (gl_err != GL_NO_ERROR) {
        lpv_pass_camera_free(e);
        return lpv_error(err, err_size, "could not allocate the %dx%d frame (GL error 0x%04x)", w, h, gl_err);
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
                                .orthographic = v->orthographic, .prog = e->prog_gbuffer,
                                .prog_plain = e->prog_gbuffer_plain,
                                .translucent = e->geo.blend_draws && e->plan.pass[LPV_PASS_TRANSLUCENT].run,
                                .timer = &e->timer};
    if (lpv_gbuffer_draw_scene(&e->gbuf, &d, err, err_size) != 0) {
        lpv_timer_end(&e->timer);
        return -1;
    }

    glUseProgram(e->prog_camera_surfels);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, e->gbuf.tex[0]);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, e->gbuf.tex[1]);
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D, e->gbuf.tex[2]);
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_2D, e->gbuf.tex[3]);
    const int step = lpv_settings_camera_surfel_step(&e->settings, v->height);
    e->gbuf.surfel_w = (v->width + step - 1) / step;
    e->gbuf.surfel_h = (v->height + step - 1) / step;
    e->gbuf.surfel_slots = lpv_block_slots(step);
    GLuint cs = e->prog_camera_surfels;
    glUniform2i(glGetUniformLocation(cs, "u_size"), v->width, v->height);
    glUniform1i(glGetUniformLocation(cs, "u_step"), step);
    glUniform2i(glGetUniformLocation(cs, "u_out_size"), e->gbuf.surfel_w, e->gbuf.surfel_h);
    glUniform1i(glGetUniformLocation(cs, "u_slots"), e->gbuf.surfel_slots);
    lpv_engine_bind_block_groups(e, cs);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_SURFELS, e->gbuf.surfels);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    glDispatchCompute(lpv_div_up((size_t)e->gbuf.surfel_w, LPV_WG_2D), lpv_div_up((size_t)e->gbuf.surfel_h, LPV_WG_2D),
                      1);
    lpv_timer_count(&e->timer, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    lpv_timer_end(&e->timer);
    return 0;
}

/* Makes prog the current program with the shading's uniforms and the
 * technique's lookup bound. */
static void use_shading_program(lpv_engine *e, GLuint prog, lpv_frame_terms terms)
{
    glUseProgram(prog);
    lpv_engine_bind_lookup(e, prog, e->settings.lpv.damping);
    glUniform1i(glGetUniformLocation(prog, "u_lookup_step"), e->settings.lookup_step);
    glUniform1i(glGetUniformLocation(prog, "u_area_shadow_step"), e->settings.area_shadow_step);
    glUniform1f(glGetUniformLocation(prog, "u_glossy_roughness"),
                e->plan.pass[LPV_PASS_GLOSSY].run && terms != LPV_TERMS_DIRECT_ONLY ? e->settings.glossy_roughness
                                                                                  : 0.0f);
}

/* The pixel count of a list of the frame's (a uvec4 head: w the count). */
static size_t listed_pixels(GLuint list)
{
    GLuint head[4] = {0, 0, 0, 0};
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, list);
    glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, sizeof head, head);
    return head[3];
}

size_t lpv_pass_shade_full_lookups(lpv_engine *e)
{
    return e->frame.shade_split && e->frame.shade_rest ? listed_pixels(e->frame.shade_rest) : 0;
}

size_t lpv_pass_shade_area_rest_pixels(lpv_engine *e)
{
    return e->frame.shade_area_blocks && e->frame.area_rest ? listed_pixels(e->frame.area_rest) : 0;
}

/* Empties a list of the frame's (0 x 1 x 1 workgroups, 0 pixels) and binds
 * it at SSBO binding `binding`. */
static void start_list(GLuint list, GLuint binding)
{
    static const GLuint head[4] = {0, 1, 1, 0};
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, list);
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, sizeof head, head);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, list);
}

/* A second pass over a list of the frame's pixels: prog (made current with
 * the shading's uniforms) adds to the frame, as many workgroups as the list
 * holds. */
static void run_list(lpv_engine *e, GLuint prog, GLuint list, lpv_frame_terms terms, GLuint frame)
{
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    use_shading_program(e, prog, terms);
    glBindImageTexture(LPV_IMG_FRAME, frame, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, list);
    glDispatchComputeIndirect(0);
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, 0);
}

/* Pixels per dispatch of the frame's shading: 1024 rows of 512. */
#define LPV_SHADE_BAND_PIXELS ((size_t)1 << 19)

/* The frame (shading.glsl) as a compute pass writing the frame texture: on
 * llvmpipe it costs what the full-screen triangle did, and on a GPU whose
 * graphics units are few (an H100 shaded 1920x1080 in 6.5 ms through the
 * fragment path, 0.3 ms as compute; bench/README.md "The GPU path") it runs on every
 * core. The glossy and media passes then blend into the same texture.
 * gbuf: the G-buffer's targets to shade (the camera's or the translucent
 * layer's), frame: the texture written, rect: the pixels (x, y, w, h) to
 * shade, stage: the timer's name. */
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

    lpv_timer_begin(&e->timer, stage);
    struct LpvViewBlock *b = &e->view_block;
    b->shading[0] = e->settings.indirect_gain;
    b->shading[1] = terms != LPV_TERMS_INDIRECT_ONLY;
    b->shading[2] = terms != LPV_TERMS_DIRECT_ONLY;
    b->shading[3] = terms != LPV_TERMS_INDIRECT_ONLY;
    b->viewport[3] = terms == LPV_TERMS_AO; /* shading.glsl writes the ambient occlusion instead */
    glBindBuffer(GL_UNIFORM_BUFFER, e->view_ubo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof *b, b);
    for (int i = 0; i < 4; ++i) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glBindTexture(GL_TEXTURE_2D, gbuf[i]);
    }
    glActiveTexture(GL_TEXTURE0 + LPV_TEX_GBUF_OCCLUSION);
    glBindTexture(GL_TEXTURE_2D, gbuf[4]);
    lpv_shadow_maps_bind(&e->shadows);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_LIGHT, e->light_ubo);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_VIEW, e->view_ubo);
    /* the passes per block first (frame_blocks.c) */
    if (blocks)
        lpv_frame_lookup_blocks_run(e);
    if (area_blocks) {
        lpv_frame_area_shadow_blocks_run(e);
        lpv_timer_begin(&e->timer, stage);
    }
    /* the lists of pixels for the second passes start empty */
    if (split)
        start_list(e->frame.shade_rest, LPV_SSBO_SHADE_REST);
    if (area_blocks)
        start_list(e->frame.area_rest, LPV_SSBO_AREA_REST);
    use_shading_program(e, prog, terms);
    glBindImageTexture(LPV_IMG_FRAME, frame, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    /* in bands of about LPV_SHADE_BAND_PIXELS, a yield point between them
     * (timer.h): a large view's one dispatch took seconds on llvmpipe; the
     * pixels are independent, so the frame is the same */
    const GLint loc_row = glGetUniformLocation(prog, "u_row_first");
    glUniform1i(glGetUniformLocation(prog, "u_col_first"), rect[0]);
    int rows = (int)(LPV_SHADE_BAND_PIXELS / (size_t)(rect[2] > 0 ? rect[2] : 1));
    rows = rows < LPV_WG_2D ? LPV_WG_2D : rows / LPV_WG_2D * LPV_WG_2D;
    const int y_end = rect[1] + rect[3];
    for (int y = rect[1]; y < y_end;) {
        const int n = y_end - y < rows ? y_end - y : rows;
        glUniform1i(loc_row, y);
        glDispatchCompute(lpv_div_up((size_t)rect[2], LPV_WG_2D), lpv_div_up((size_t)n, LPV_WG_2D), 1);
        y += n;
        if (y < y_end)
            lpv_timer_yield(&e->timer);
    }
    /* the listed pixels' indirect light, then their area light */
    if (split)
        run_list(e, damped ? e->prog_shade_rest_damped : e->prog_shade_rest, e->frame.shade_rest, terms, frame);
    if (area_blocks)
        run_list(e, e->prog_area_shadow_rest, e->frame.area_rest, terms, frame);
    /* the glossy and media passes blend into the frame, which is then read back */
    glMemoryBarrier(GL_FRAMEBUFFER_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
    lpv_timer_count(&e->timer, (blocks ? 1 : 0) + 1 + (split ? 1 : 0) + (area_blocks ? 1 : 0));
    e->frame.shade_split = split;
    e->frame.shade_area_blocks = area_blocks;
    lpv_timer_end(&e->timer);
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
    *full_lookups += lpv_pass_shade_full_lookups(e);
    *area_rest_pixels += lpv_pass_shade_area_rest_pixels(e);
    /* only the pixels its draws can cover: the layer's shading costs what
     * the frame's does per pixel, and llvmpipe shades an uncovered pixel's
     * lanes all the same */
    int rect[4];
    if (!layer_rect(e, rect))
        return 0;
    if (shade_frame(e, terms, e->gbuf.layer_tex, e->gbuf.layer_frame_tex, rect, "translucent", err, err_size) != 0)
        return -1;
    lpv_timer_begin(&e->timer, "translucent");
    glUseProgram(e->prog_translucent);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, e->gbuf.layer_frame_tex);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, e->gbuf.layer_tex[LPV_GBUF_TARGETS]);
    glBindImageTexture(LPV_IMG_FRAME, e->frame.tex, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
    glUniform2i(glGetUniformLocation(e->prog_translucent, "u_first"), rect[0], rect[1]);
    glDispatchCompute(lpv_div_up((size_t)rect[2], LPV_WG_2D), lpv_div_up((size_t)rect[3], LPV_WG_2D), 1);
    glMemoryBarrier(GL_FRAMEBUFFER_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    lpv_timer_count(&e->timer, 1);
    lpv_timer_end(&e->timer);
    return 0;
}
