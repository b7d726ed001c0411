/* gbuffer.c - see gbuffer.h. */
#include "gbuffer.h"

#include "block_groups.h"
#include "error.h"
#include "gl_util.h"
#include "memory_budget.h"

void lpv_gbuffer_free(lpv_gbuffer *g)
{
    for (int i = 0; i < LPV_GBUF_TARGETS; ++i)
        lpv_gl_delete_texture(&g->tex[i]);
    lpv_gl_delete_texture(&g->depth);
    lpv_gl_delete_framebuffer(&g->fbo);
    lpv_gl_delete_buffer(&g->surfels);
    for (int i = 0; i < LPV_GBUF_TARGETS + 1; ++i)
        lpv_gl_delete_texture(&g->layer_tex[i]);
    lpv_gl_delete_texture(&g->layer_frame_tex);
    lpv_gl_delete_framebuffer(&g->layer_fbo);
    g->layer_w = g->layer_h = 0;
    g->w = g->h = 0;
    g->surfel_w = g->surfel_h = g->surfel_slots = 0;
}

/* The G-buffer's targets' formats (gbuffer.frag's outputs 0..4); the
 * translucent layer's G-buffer adds its coverage. */
#define GBUF_FORMATS GL_RGBA32F, GL_RGBA32F, GL_RGBA16F, GL_RGBA32F, GL_R8
#define LAYER_COVERAGE_FORMAT GL_R8

int lpv_gbuffer_ensure(lpv_gbuffer *g, int w, int h, char *err, size_t err_size)
{
    if (g->w == w && g->h == h)
        return 0;
    lpv_gbuffer_free(g);
    for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i) { /* start from a clean error state */
    }
    static const GLenum formats[LPV_GBUF_TARGETS] = {GBUF_FORMATS};
    glGenFramebuffers(1, &g->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, g->fbo);
    GLenum bufs[LPV_GBUF_TARGETS];
    for (int i = 0; i < LPV_GBUF_TARGETS; ++i) {
        g->tex[i] = lpv_gl_new_texture_2d(formats[i], w, h);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + (GLenum)i, GL_TEXTURE_2D, g->tex[i], 0);
        bufs[i] = GL_COLOR_ATTACHMENT0 + (GLenum)i;
    }
    g->depth = lpv_gl_new_texture_2d(GL_DEPTH_COMPONENT32F, w, h);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, g->depth, 0);
    glDrawBuffers(LPV_GBUF_TARGETS, bufs);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);

    glGenBuffers(1, &g->surfels);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, g->surfels);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(lpv_memory_block_samples(w, h) * sizeof(struct LpvSurfel)),
                 NULL, GL_DYNAMIC_COPY);
    GLenum gl_err = glGetError();
    if (gl_err != GL_NO_ERROR) {
        lpv_gbuffer_free(g);
        return lpv_error(err, err_size, "could not allocate the %dx%d G-buffer and surfels (GL error 0x%04x)", w, h,
                         gl_err);
    }
    g->w = w;
    g->h = h;
    return 0;
}

/* (Re)allocates the translucent layer's G-buffer and frame for the
 * G-buffer's size (scenes with BLEND draws; lpv_gbuffer_ensure ran): its
 * depth is the G-buffer's, so the layer keeps the nearest BLEND surface in
 * front of the opaque one. Their memory is the G-buffer's and the frame's
 * again (docs/memory.md counts it with them). */
static int ensure_layer(lpv_gbuffer *g, char *err, size_t err_size)
{
    const int w = g->w, h = g->h;
    if (g->layer_fbo && g->layer_w == w && g->layer_h == h)
        return 0;
    for (int i = 0; i < LPV_GBUF_TARGETS + 1; ++i)
        lpv_gl_delete_texture(&g->layer_tex[i]);
    lpv_gl_delete_texture(&g->layer_frame_tex);
    lpv_gl_delete_framebuffer(&g->layer_fbo);
    for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i) { /* start from a clean error state */
    }
    static const GLenum formats[LPV_GBUF_TARGETS + 1] = {GBUF_FORMATS, LAYER_COVERAGE_FORMAT};
    glGenFramebuffers(1, &g->layer_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, g->layer_fbo);
    GLenum bufs[LPV_GBUF_TARGETS + 1];
    for (int i = 0; i < LPV_GBUF_TARGETS + 1; ++i) {
        g->layer_tex[i] = lpv_gl_new_texture_2d(formats[i], w, h);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + (GLenum)i, GL_TEXTURE_2D, g->layer_tex[i], 0);
        bufs[i] = GL_COLOR_ATTACHMENT0 + (GLenum)i;
    }
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, g->depth, 0);
    glDrawBuffers(LPV_GBUF_TARGETS + 1, bufs);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    g->layer_frame_tex = lpv_gl_new_texture_2d(GL_RGBA32F, w, h);
    GLenum gl_err = glGetError();
    if (gl_err != GL_NO_ERROR) {
        for (int i = 0; i < LPV_GBUF_TARGETS + 1; ++i)
            lpv_gl_delete_texture(&g->layer_tex[i]);
        lpv_gl_delete_texture(&g->layer_frame_tex);
        lpv_gl_delete_framebuffer(&g->layer_fbo);
        return lpv_error(err, err_size, "could not allocate the %dx%d translucent layer (GL error 0x%04x)", w, h,
                         gl_err);
    }
    g->layer_w = w;
    g->layer_h = h;
    return 0;
}

int lpv_gbuffer_draw_scene(lpv_gbuffer *g, const lpv_gbuffer_draw *d, char *err, size_t err_size)
{
    glBindFramebuffer(GL_FRAMEBUFFER, g->fbo);
    glViewport(0, 0, d->width, d->height);
    static const float zero[4] = {0, 0, 0, 0};
    for (int i = 0; i < LPV_GBUF_TARGETS; ++i)
        glClearBufferfv(GL_COLOR, i, zero);
    glClearBufferfi(GL_DEPTH_STENCIL, 0, 1.0f, 0);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    GLuint p = lpv_scene_gpu_program(d->geo, d->prog, d->prog_plain);
    glUseProgram(p);
    glUniformMatrix4fv(glGetUniformLocation(p, "u_view_proj"), 1, GL_FALSE, (const float *)d->view->view_proj);
    glUniform3fv(glGetUniformLocation(p, "u_eye"), 1, d->view->eye);
    glUniform3fv(glGetUniformLocation(p, "u_forward"), 1, d->view->forward);
    float pixel = 2.0f * d->view->forward[3] / (float)d->height; /* tan-plane or metres per pixel */
    glUniform1f(glGetUniformLocation(p, "u_pixel_solid_angle"), d->orthographic ? 0.0f : pixel * pixel);
    glUniform1f(glGetUniformLocation(p, "u_pixel_area"), d->orthographic ? pixel * pixel : 0.0f);
    lpv_scene_gpu_draw(d->geo, p, 1, LPV_DRAWS_NOT_BLEND, d->timer);
    lpv_scene_gpu_draw_wires(d->geo, p, d->timer); /* points and lines: seen, one pixel wide, but no surfels (no area) */
    /* the translucent layer: the BLEND draws over the opaque depth, the
     * nearest in front of it kept (the same program and uniforms) */
    if (d->translucent) {
        if (ensure_layer(g, err, err_size) != 0) {
            glDisable(GL_DEPTH_TEST);
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
            return -1;
        }
        glBindFramebuffer(GL_FRAMEBUFFER, g->layer_fbo);
        for (int i = 0; i < LPV_GBUF_TARGETS + 1; ++i)
            glClearBufferfv(GL_COLOR, i, zero);
        lpv_scene_gpu_draw(d->geo, p, 1, LPV_DRAWS_BLEND, d->timer);
    }
    glDisable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    return 0;
}

void lpv_gbuffer_extract_surfels(lpv_gbuffer *g, const lpv_gbuffer_surfels *d)
{
    const GLuint cs = d->prog;
    glUseProgram(cs);
    for (int i = 0; i < 4; ++i) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glBindTexture(GL_TEXTURE_2D, g->tex[i]);
    }
    const int step = d->step;
    g->surfel_w = (g->w + step - 1) / step;
    g->surfel_h = (g->h + step - 1) / step;
    g->surfel_slots = lpv_block_slots(step);
    glUniform2i(glGetUniformLocation(cs, "u_size"), g->w, g->h);
    glUniform1i(glGetUniformLocation(cs, "u_step"), step);
    glUniform2i(glGetUniformLocation(cs, "u_out_size"), g->surfel_w, g->surfel_h);
    glUniform1i(glGetUniformLocation(cs, "u_slots"), g->surfel_slots);
    lpv_block_groups_bind(cs, d->groups, d->group_levels);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_SURFELS, g->surfels);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    glDispatchCompute(lpv_div_up((size_t)g->surfel_w, LPV_WG_2D), lpv_div_up((size_t)g->surfel_h, LPV_WG_2D), 1);
    lpv_timer_count(d->timer, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}
