/*
 * frame.c - the shaded frame (frame.h): its target and lists, the passes
 * per block of pixels, the shading of a G-buffer as a compute pass, the
 * translucent layer's overlay and the read-back.
 *
 * The passes per block each run before the shading, which spreads their
 * blocks over the pixels along their planes (shading.glsl,
 * blocks_upsampled):
 *   - the lookup step (lookup_step > 1, lookup_blocks.comp): the
 *     technique's irradiance once per block;
 *   - the area shadow step (area_shadow_step > 1, area_shadow_blocks.comp):
 *     the area light samples' visibility once per block, as the ratio of
 *     their shadowed to unshadowed irradiance, which the frame multiplies by
 *     each pixel's own unshadowed irradiance. On llvmpipe every sample's
 *     shadow filter costs the frame about 5 ms at 512 x 512
 *     (docs/area-lights.md, "The area shadow step").
 */
#include "frame.h"

#include <string.h>

#include "error.h"
#include "gbuffer.h"
#include "gl_util.h"
#include "lpv_shared.h"

static void blocks_free(lpv_frame_blocks *b)
{
    for (int i = 0; i < 2; ++i)
        lpv_gl_delete_texture(&b->tex[i]);
    b->w = b->h = b->step = 0;
}

void lpv_frame_free(lpv_frame *f)
{
    lpv_gl_delete_texture(&f->tex);
    lpv_gl_delete_framebuffer(&f->fbo);
    lpv_gl_delete_buffer(&f->shade_rest);
    lpv_gl_delete_buffer(&f->area_rest);
    blocks_free(&f->lookup_blocks);
    blocks_free(&f->area_shadow_blocks);
    f->w = f->h = 0;
}

int lpv_frame_ensure(lpv_frame *f, int w, int h, char *err, size_t err_size)
{
    if (f->tex && f->w == w && f->h == h)
        return 0;
    lpv_frame_free(f);
    glGenFramebuffers(1, &f->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, f->fbo);
    f->tex = lpv_gl_new_texture_2d(GL_RGBA32F, w, h);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, f->tex, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    /* the two lists of pixels for a second pass: the lookup's
     * (shade_rest.comp) and the area shadow step's (area_shadow_rest.comp) */
    GLuint *lists[2] = {&f->shade_rest, &f->area_rest};
    for (int i = 0; i < 2; ++i) {
        glGenBuffers(1, lists[i]);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, *lists[i]);
        glBufferData(GL_SHADER_STORAGE_BUFFER,
                     (GLsizeiptr)(4 * sizeof(GLuint) + (size_t)w * (size_t)h * 2 * sizeof(GLint)), NULL,
                     GL_DYNAMIC_COPY);
    }
    GLenum gl_err = glGetError();
    if (gl_err != GL_NO_ERROR) {
        lpv_frame_free(f);
        return lpv_error(err, err_size, "could not allocate the %dx%d frame (GL error 0x%04x)", w, h, gl_err);
    }
    f->w = w;
    f->h = h;
    return 0;
}

/* Runs the current program (its uniforms set) over the blocks of `step`
 * pixels into b, through image units img_value and img_plane, then binds
 * the blocks for the frame at texture units tex_value and tex_plane. b's
 * textures are (re)made when the step or the frame's size changed, at unit
 * tex_value (making a texture binds it to the active unit, and the units
 * below hold the G-buffer). */
static void run_blocks(const lpv_frame *f, lpv_frame_blocks *b, int step, GLuint img_value, GLuint img_plane,
                       GLenum tex_value, GLenum tex_plane)
{
    const int w = (f->w + step - 1) / step, h = (f->h + step - 1) / step;
    if (b->step != step || b->w != w || b->h != h) {
        glActiveTexture(GL_TEXTURE0 + tex_value);
        for (int i = 0; i < 2; ++i) {
            lpv_gl_delete_texture(&b->tex[i]);
            b->tex[i] = lpv_gl_new_texture_2d(GL_RGBA32F, w, h);
        }
        b->w = w;
        b->h = h;
        b->step = step;
    }
    glBindImageTexture(img_value, b->tex[0], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glBindImageTexture(img_plane, b->tex[1], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glDispatchCompute(lpv_div_up((size_t)w, LPV_WG_2D), lpv_div_up((size_t)h, LPV_WG_2D), 1);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    glActiveTexture(GL_TEXTURE0 + tex_value);
    glBindTexture(GL_TEXTURE_2D, b->tex[0]);
    glActiveTexture(GL_TEXTURE0 + tex_plane);
    glBindTexture(GL_TEXTURE_2D, b->tex[1]);
}

/* Makes prog the current program with the shading's uniforms and the
 * technique's lookup bound. */
static void use_shading_program(const lpv_frame_shading *s, GLuint prog)
{
    glUseProgram(prog);
    s->lookup.bind(s->lookup.ctx, prog);
    glUniform1i(glGetUniformLocation(prog, "u_lookup_step"), s->lookup_step);
    glUniform1i(glGetUniformLocation(prog, "u_area_shadow_step"), s->area_shadow_step);
    glUniform1f(glGetUniformLocation(prog, "u_glossy_roughness"), s->glossy_roughness);
}

/* The pixel count of a list of the frame's (a uvec4 head: w the count). */
static size_t listed_pixels(GLuint list)
{
    GLuint head[4] = {0, 0, 0, 0};
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, list);
    glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, sizeof head, head);
    return head[3];
}

size_t lpv_frame_full_lookups(const lpv_frame *f)
{
    return f->shade_split && f->shade_rest ? listed_pixels(f->shade_rest) : 0;
}

size_t lpv_frame_area_rest_pixels(const lpv_frame *f)
{
    return f->shade_area_blocks && f->area_rest ? listed_pixels(f->area_rest) : 0;
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
 * the shading's uniforms) adds to the target, as many workgroups as the
 * list holds. */
static void run_list(const lpv_frame_shading *s, GLuint prog, GLuint list)
{
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    use_shading_program(s, prog);
    glBindImageTexture(LPV_IMG_FRAME, s->target, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, list);
    glDispatchComputeIndirect(0);
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, 0);
}

/* Pixels per dispatch of the shading: 1024 rows of 512. */
#define LPV_SHADE_BAND_PIXELS ((size_t)1 << 19)

/* The shading (shading.glsl) is a compute pass writing the target: on
 * llvmpipe it costs what the full-screen triangle did, and on a GPU whose
 * graphics units are few (an H100 shaded 1920x1080 in 6.5 ms through the
 * fragment path, 0.3 ms as compute; bench/README.md "The GPU path") it runs
 * on every core. The glossy and media passes then blend into the same
 * texture. */
void lpv_frame_shade(lpv_frame *f, const lpv_frame_shading *s)
{
    lpv_timer *timer = s->timer;
    lpv_timer_begin(timer, s->stage);
    for (int i = 0; i < 4; ++i) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glBindTexture(GL_TEXTURE_2D, s->gbuf[i]);
    }
    glActiveTexture(GL_TEXTURE0 + LPV_TEX_GBUF_OCCLUSION);
    glBindTexture(GL_TEXTURE_2D, s->gbuf[4]);
    lpv_shadow_maps_bind(s->shadows);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_LIGHT, s->light_ubo);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_VIEW, s->view_ubo);
    /* the passes per block first */
    if (s->blocks) {
        glUseProgram(s->prog_lookup_blocks);
        s->lookup.bind(s->lookup.ctx, s->prog_lookup_blocks);
        glUniform1i(glGetUniformLocation(s->prog_lookup_blocks, "u_lookup_step"), s->lookup_step);
        run_blocks(f, &f->lookup_blocks, s->lookup_step, LPV_IMG_BLOCK_IRRADIANCE, LPV_IMG_BLOCK_PLANE,
                   LPV_TEX_BLOCK_IRRADIANCE, LPV_TEX_BLOCK_PLANE);
    }
    if (s->area_blocks) {
        lpv_timer_begin(timer, "area_shadow");
        glUseProgram(s->prog_area_shadow_blocks);
        glUniform1i(glGetUniformLocation(s->prog_area_shadow_blocks, "u_area_shadow_step"), s->area_shadow_step);
        run_blocks(f, &f->area_shadow_blocks, s->area_shadow_step, LPV_IMG_AREA_SHADOW, LPV_IMG_AREA_SHADOW_PLANE,
                   LPV_TEX_AREA_SHADOW, LPV_TEX_AREA_SHADOW_PLANE);
        lpv_timer_count(timer, 1);
        lpv_timer_end(timer);
        lpv_timer_begin(timer, s->stage);
    }
    /* the lists of pixels for the second passes start empty */
    if (s->split)
        start_list(f->shade_rest, LPV_SSBO_SHADE_REST);
    if (s->area_blocks)
        start_list(f->area_rest, LPV_SSBO_AREA_REST);
    use_shading_program(s, s->prog);
    glBindImageTexture(LPV_IMG_FRAME, s->target, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    /* in bands of about LPV_SHADE_BAND_PIXELS, a yield point between them
     * (timer.h): a large view's one dispatch took seconds on llvmpipe; the
     * pixels are independent, so the frame is the same */
    const int *rect = s->rect;
    const GLint loc_row = glGetUniformLocation(s->prog, "u_row_first");
    glUniform1i(glGetUniformLocation(s->prog, "u_col_first"), rect[0]);
    int rows = (int)(LPV_SHADE_BAND_PIXELS / (size_t)(rect[2] > 0 ? rect[2] : 1));
    rows = rows < LPV_WG_2D ? LPV_WG_2D : rows / LPV_WG_2D * LPV_WG_2D;
    const int y_end = rect[1] + rect[3];
    for (int y = rect[1]; y < y_end;) {
        const int n = y_end - y < rows ? y_end - y : rows;
        glUniform1i(loc_row, y);
        glDispatchCompute(lpv_div_up((size_t)rect[2], LPV_WG_2D), lpv_div_up((size_t)n, LPV_WG_2D), 1);
        y += n;
        if (y < y_end)
            lpv_timer_yield(timer);
    }
    /* the listed pixels' indirect light, then their area light */
    if (s->split)
        run_list(s, s->prog_rest, f->shade_rest);
    if (s->area_blocks)
        run_list(s, s->prog_area_rest, f->area_rest);
    /* the glossy and media passes blend into the frame, which is then read back */
    glMemoryBarrier(GL_FRAMEBUFFER_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
    lpv_timer_count(timer, (s->blocks ? 1 : 0) + 1 + (s->split ? 1 : 0) + (s->area_blocks ? 1 : 0));
    f->shade_split = s->split;
    f->shade_area_blocks = s->area_blocks;
    lpv_timer_end(timer);
}

void lpv_frame_overlay(lpv_frame *f, GLuint prog, GLuint layer_frame, GLuint layer_alpha, const int rect[4],
                       lpv_timer *timer)
{
    glUseProgram(prog);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, layer_frame);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, layer_alpha);
    glBindImageTexture(LPV_IMG_FRAME, f->tex, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
    glUniform2i(glGetUniformLocation(prog, "u_first"), rect[0], rect[1]);
    glDispatchCompute(lpv_div_up((size_t)rect[2], LPV_WG_2D), lpv_div_up((size_t)rect[3], LPV_WG_2D), 1);
    glMemoryBarrier(GL_FRAMEBUFFER_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    lpv_timer_count(timer, 1);
}

void lpv_frame_read(const lpv_frame *f, float *rgba)
{
    const int w = f->w, h = f->h;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, f->fbo);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, rgba);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    /* GL rows run bottom-up; files and callers want the top row first. */
    const size_t row = (size_t)w * 4;
    for (int y = 0; y < h / 2; ++y) {
        float *a = rgba + (size_t)y * row, *b = rgba + (size_t)(h - 1 - y) * row;
        for (size_t i = 0; i < row; ++i) {
            float t = a[i];
            a[i] = b[i];
            b[i] = t;
        }
    }
}
