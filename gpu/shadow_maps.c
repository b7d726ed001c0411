/*
 * shadow_maps.c - the shadow maps of direct light (docs/shadows.md): every
 * shadow-map face (lpv_shadow_faces_build) renders the scene's depth alone,
 * reversed (near / depth, docs/shadows.md "Near planes"),
 * into one layer of a DEPTH32F array texture of shadow_size^2 texels (an
 * area light sample's face: into one tile of a layer), which
 * shadow.glsl samples with hardware-compare PCF. Separate from the RSMs,
 * which stay the VPL source at rsm_size. In scenes with BLEND surfaces each
 * face also gets a transmission map: those surfaces, drawn over the face's
 * opaque depth, multiply in 1 - alpha and keep the nearest one's depth
 * (docs/scenes.md, "Alpha"). Runs at render time, because the
 * directional cascades follow the camera, and only when the faces, the scene
 * or the settings changed.
 */
#include <math.h>
#include <string.h>

#include <cglm/cglm.h>

#include "shadow_maps.h"

#include "error.h"
#include "gl_util.h"

void lpv_shadow_maps_create(lpv_shadow_maps *sm)
{
    memset(sm, 0, sizeof *sm);
    glGenBuffers(1, &sm->ubo);
    glBindBuffer(GL_UNIFORM_BUFFER, sm->ubo);
    glBufferData(GL_UNIFORM_BUFFER, sizeof(struct LpvShadowBlock), NULL, GL_DYNAMIC_DRAW);
    glBindBuffer(GL_UNIFORM_BUFFER, 0);
}

/* The maps' textures and framebuffers, not the block's buffer. */
static void release(lpv_shadow_maps *sm)
{
    if (sm->tex)
        glDeleteTextures(1, &sm->tex);
    if (sm->fbo)
        glDeleteFramebuffers(1, &sm->fbo);
    sm->tex = sm->fbo = 0;
    lpv_gl_delete_texture(&sm->transmit_tex);
    lpv_gl_delete_framebuffer(&sm->transmit_fbo);
    sm->alloc_size = sm->alloc_faces = 0;
    sm->valid = 0;
}

void lpv_shadow_maps_destroy(lpv_shadow_maps *sm)
{
    release(sm);
    lpv_gl_delete_buffer(&sm->ubo);
}

int lpv_shadow_maps_fit(const lpv_shadow_maps *sm, int size, int layers, int translucent)
{
    return sm->alloc_size == size && sm->alloc_faces == layers && !sm->transmit_fbo == !translucent;
}

int lpv_shadow_maps_allocate(lpv_shadow_maps *sm, int size, int layers, int translucent, uint64_t bytes, char *err,
                             size_t err_size)
{
    release(sm);
    for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i) { /* start from a clean error state */
    }
    glGenTextures(1, &sm->tex);
    glBindTexture(GL_TEXTURE_2D_ARRAY, sm->tex);
    glTexStorage3D(GL_TEXTURE_2D_ARRAY, 1, GL_DEPTH_COMPONENT32F, size, size, layers);
    /* Hardware compare with bilinear filtering: each tap of the PCF kernel
     * is already a 2x2 weighted comparison. */
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    /* reversed depth (docs/shadows.md "Near planes"): nearer is larger, so
     * a receiver is lit where its depth is at least the map's */
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_FUNC, GL_GEQUAL);
    glGenFramebuffers(1, &sm->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, sm->fbo);
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, sm->tex, 0, 0);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (translucent && status == GL_FRAMEBUFFER_COMPLETE) {
        glGenTextures(1, &sm->transmit_tex);
        glBindTexture(GL_TEXTURE_2D_ARRAY, sm->transmit_tex);
        glTexStorage3D(GL_TEXTURE_2D_ARRAY, 1, GL_RGBA16F, size, size, layers);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glGenFramebuffers(1, &sm->transmit_fbo);
        glBindFramebuffer(GL_FRAMEBUFFER, sm->transmit_fbo);
        glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, sm->transmit_tex, 0, 0);
        glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, sm->tex, 0, 0);
        glDrawBuffer(GL_COLOR_ATTACHMENT0);
        status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    GLenum gl_err = glGetError();
    if (gl_err != GL_NO_ERROR || status != GL_FRAMEBUFFER_COMPLETE) {
        release(sm);
        return lpv_error(err, err_size,
                         "could not allocate the shadow maps: shadow_size %d x %d layers = %.2f GB (GL error 0x%04x, "
                         "framebuffer 0x%04x)",
                         size, layers, (double)bytes / 1e9, gl_err, status);
    }
    sm->alloc_size = size;
    sm->alloc_faces = layers;
    return 0;
}

/* The BLEND draws into face f's transmission map (its tile's rect, over the
 * opaque depth just drawn, within the caller's scissor): rgb multiplied by
 * each texel's 1 - alpha, a the greatest reversed depth (the nearest
 * surface); depth is read, not written. Leaves the depth pass's framebuffer
 * and state bound again. */
static void draw_transmission(lpv_shadow_maps *sm, const lpv_shadow_draw *d, GLuint prog, int layer)
{
    static const float clear[4] = {1.0f, 1.0f, 1.0f, 0.0f}; /* all light passes; no surface (depth 0: infinitely far) */
    glBindFramebuffer(GL_FRAMEBUFFER, sm->transmit_fbo);
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, sm->transmit_tex, 0, layer);
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, sm->tex, 0, layer);
    glClearBufferfv(GL_COLOR, 0, clear); /* within the face's rect: the caller's scissor */
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendEquationSeparate(GL_FUNC_ADD, GL_MAX);
    glBlendFuncSeparate(GL_ZERO, GL_SRC_COLOR, GL_ONE, GL_ONE);
    lpv_scene_gpu_draw(d->geo, prog, 0, LPV_DRAWS_BLEND, d->timer);
    glDisable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ZERO);
    glDepthMask(GL_TRUE);
    glBindFramebuffer(GL_FRAMEBUFFER, sm->fbo);
}

/* The cone of directions light l sends light into: a spot's outer cone, an
 * area light sample's hemisphere (cosine emission); 0 for lights that light
 * every direction (points, directional cascades). */
static int light_cone(const struct LpvLightGpu *lights, int l, vec3 apex, vec3 axis, float *half_angle)
{
    const struct LpvLightGpu *g = &lights[l];
    const int type = (int)g->position_type[3];
    if (type != LPV_LIGHT_TYPE_SPOT && type != LPV_LIGHT_TYPE_AREA)
        return 0;
    glm_vec3_copy((float *)g->position_type, apex);
    glm_vec3_copy((float *)g->direction_range, axis);
    if (!(glm_vec3_norm(axis) > 1e-8f))
        return 0;
    glm_vec3_normalize(axis);
    *half_angle = type == LPV_LIGHT_TYPE_AREA ? (float)(M_PI / 2.0) : lpv_spot_outer_angle(g);
    return *half_angle < (float)M_PI;
}

/* The part of shadow face f (its tile at x, y, side texels) that can be read
 * with a non-zero weight: a spot lights only its outer cone and an area
 * light sample only the half-space its normal faces, and the shading's
 * irradiance outside them is 0 (lights.glsl), so depth there is never
 * needed. A spot wider than 45 degrees gets a cube of six faces (one behind
 * it, four mostly outside its cone), an area light sample five (half of each
 * side face behind the emitter). The rectangle bounds the cone's footprint
 * on the face: the face's border points inside the cone and the cone's rim
 * (sampled at 256 azimuths, opened by 0.02 rad) projected into the face,
 * plus a margin for the PCF kernel and the receiver offsets (shadow.glsl).
 * Returns 0 when no direction of the face is lit (the face is not drawn). */
#define RIM_SAMPLES 256
#define EDGE_SAMPLES 64
static int face_lit_rect(const lpv_shadow_maps *sm, const struct LpvLightGpu *lights, int f, int x, int y, int side,
                         int rect[4])
{
    const struct LpvShadowFaceGpu *F = &sm->block.faces[f];
    rect[0] = x, rect[1] = y, rect[2] = side, rect[3] = side;
    vec3 apex, axis;
    float half;
    if (F->info[1] != 1.0f || !light_cone(lights, (int)F->info[2], apex, axis, &half))
        return 1;
    const float open = half + 0.02f, cos_open = cosf(open), sin_open = sinf(open);
    float lo[2] = {2.0f, 2.0f}, hi[2] = {-2.0f, -2.0f};
    mat4 inv;
    glm_mat4_inv((vec4 *)F->view_proj, inv);
    /* the face's border: the NDC square's edge points whose direction is in the cone */
    for (int i = 0; i < 4 * EDGE_SAMPLES; ++i) {
        const float t = -1.0f + 2.0f * (float)(i % EDGE_SAMPLES) / (float)(EDGE_SAMPLES - 1);
        const int edge = i / EDGE_SAMPLES;
        const float u = edge < 2 ? t : (edge == 2 ? -1.0f : 1.0f), v = edge < 2 ? (edge == 0 ? -1.0f : 1.0f) : t;
        vec4 ndc = {u, v, 0.5f, 1.0f}, w; /* a point in front of the eye (depth 0 is infinitely far) */
        glm_mat4_mulv(inv, ndc, w);
        if (!(fabsf(w[3]) > 1e-20f))
            continue;
        vec3 d = {w[0] / w[3] - apex[0], w[1] / w[3] - apex[1], w[2] / w[3] - apex[2]};
        if (glm_vec3_dot(d, axis) >= cos_open * glm_vec3_norm(d)) {
            lo[0] = fminf(lo[0], u), hi[0] = fmaxf(hi[0], u);
            lo[1] = fminf(lo[1], v), hi[1] = fmaxf(hi[1], v);
        }
    }
    /* the cone's rim, where it crosses the face */
    vec3 t1, t2, up = {0.0f, 1.0f, 0.0f};
    if (fabsf(axis[1]) > 0.9f)
        glm_vec3_copy((vec3){1.0f, 0.0f, 0.0f}, up);
    glm_vec3_cross(axis, up, t1);
    glm_vec3_normalize(t1);
    glm_vec3_cross(axis, t1, t2);
    for (int i = 0; i < RIM_SAMPLES; ++i) {
        const float a = 2.0f * (float)M_PI * (float)i / (float)RIM_SAMPLES, ca = cosf(a), sa = sinf(a);
        vec4 p = {apex[0], apex[1], apex[2], 1.0f}, clip;
        for (int k = 0; k < 3; ++k)
            p[k] += cos_open * axis[k] + sin_open * (ca * t1[k] + sa * t2[k]);
        glm_mat4_mulv((vec4 *)F->view_proj, p, clip);
        if (!(clip[3] > 0.0f))
            continue;
        const float u = clip[0] / clip[3], v = clip[1] / clip[3];
        if (fabsf(u) > 1.0f || fabsf(v) > 1.0f)
            continue;
        lo[0] = fminf(lo[0], u), hi[0] = fmaxf(hi[0], u);
        lo[1] = fminf(lo[1], v), hi[1] = fmaxf(hi[1], v);
    }
    if (lo[0] > hi[0] || lo[1] > hi[1])
        return 0;
    const float margin = LPV_SHADOW_BORDER_TEXELS + 2.0f * (float)(LPV_SHADOW_PCF_RADIUS + 1);
    int r[4];
    for (int k = 0; k < 2; ++k) {
        float a = floorf((lo[k] * 0.5f + 0.5f) * (float)side - margin);
        float b = ceilf((hi[k] * 0.5f + 0.5f) * (float)side + margin);
        a = fmaxf(a, 0.0f), b = fminf(b, (float)side);
        r[k] = (int)a, r[k + 2] = (int)b - (int)a;
    }
    rect[0] = x + r[0], rect[1] = y + r[1], rect[2] = r[2], rect[3] = r[3];
    return r[2] > 0 && r[3] > 0;
}

static void draw(lpv_shadow_maps *sm, const lpv_shadow_draw *d)
{
    const int size = sm->alloc_size, faces = (int)sm->block.counts[0];
    int bound_layer = -1;
    lpv_timer_begin(d->timer, "shadow");
    glBindFramebuffer(GL_FRAMEBUFFER, sm->fbo);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE); /* both sides cast: single-sided walls still block */
    glEnable(GL_DEPTH_TEST);
    /* Reversed depth (docs/shadows.md "Near planes"): clip z in [0, w] is
     * stored as it is, near / distance for a perspective face, 1 at the
     * near plane and 0 infinitely far, so the float's relative precision
     * holds at every distance; the nearest surface is the largest. */
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    const GLuint prog = lpv_scene_gpu_program(d->geo, d->prog, d->prog_plain);
    glUseProgram(prog);
    GLint loc_vp = glGetUniformLocation(prog, "u_view_proj");
    const float far_depth = 0.0f;
    glEnable(GL_SCISSOR_TEST);
    for (int f = 0; f < faces; ++f) {
        /* A face fills its layer, or (area light samples) one tile of it, or
         * the lit half of that tile: only what it draws is cleared (the
         * clear costs as much as the drawing on llvmpipe). */
        const float *tile = sm->block.faces[f].tile;
        const int layer = (int)tile[3];
        if (layer != bound_layer) {
            glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, sm->tex, 0, layer);
            bound_layer = layer;
        }
        const int side = (int)lroundf(tile[2] * (float)size);
        const int x = (int)lroundf(tile[0] * (float)size), y = (int)lroundf(tile[1] * (float)size);
        int rect[4];
        if (!face_lit_rect(sm, d->lights, f, x, y, side, rect))
            continue;
        glScissor(rect[0], rect[1], rect[2], rect[3]);
        glClearBufferfv(GL_DEPTH, 0, &far_depth);
        glViewport(x, y, side, side);
        glUniformMatrix4fv(loc_vp, 1, GL_FALSE, (const float *)sm->block.faces[f].view_proj);
        lpv_scene_gpu_draw(d->geo, prog, 0, LPV_DRAWS_NOT_BLEND, d->timer); /* lights see both sides */
        if (sm->transmit_fbo)
            draw_transmission(sm, d, prog, layer);
    }
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    lpv_timer_end(d->timer);
}

void lpv_shadow_maps_draw(lpv_shadow_maps *sm, const struct LpvShadowBlock *b, const lpv_shadow_draw *d)
{
    if (sm->valid && memcmp(b, &sm->block, sizeof *b) == 0)
        return;
    sm->block = *b;
    glBindBuffer(GL_UNIFORM_BUFFER, sm->ubo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof *b, b);
    if (b->counts[0] > 0.0f)
        draw(sm, d);
    sm->valid = 1;
}

void lpv_shadow_maps_bind(const lpv_shadow_maps *sm)
{
    glActiveTexture(GL_TEXTURE4);
    glBindTexture(GL_TEXTURE_2D_ARRAY, sm->tex);
    glActiveTexture(GL_TEXTURE0 + LPV_TEX_SHADOW_TRANSMIT);
    glBindTexture(GL_TEXTURE_2D_ARRAY, sm->transmit_tex);
    glActiveTexture(GL_TEXTURE0);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_SHADOW, sm->ubo);
}
