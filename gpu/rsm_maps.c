/* rsm_maps.c - see rsm_maps.h. */
#include "rsm_maps.h"

#include <math.h>

#include "block_groups.h"
#include "compact.h"
#include "error.h"
#include "gl_util.h"
#include "memory_budget.h"

void lpv_rsms_free(lpv_rsms *r)
{
    lpv_gl_delete_texture(&r->position);
    lpv_gl_delete_texture(&r->normal);
    lpv_gl_delete_texture(&r->flux);
    lpv_gl_delete_texture(&r->albedo);
    lpv_gl_delete_texture(&r->depth);
    lpv_gl_delete_framebuffer(&r->fbo);
    lpv_gl_delete_buffer(&r->vpls);
    lpv_gl_delete_buffer(&r->surfels);
    lpv_gl_delete_buffer(&r->vpls_live);
    lpv_gl_delete_buffer(&r->vpls_draw);
    r->alloc_size = r->alloc_faces = 0;
}

int lpv_rsms_fit(const lpv_rsms *r, int size, int layers)
{
    return r->alloc_size == size && r->alloc_faces == layers;
}

int lpv_rsms_allocate(lpv_rsms *r, int size, int layers, uint64_t bytes, char *err, size_t err_size)
{
    for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i) { /* start from a clean error state */
    }
    lpv_rsms_free(r);
    r->position = lpv_gl_new_texture_2d_array(GL_RGBA32F, size, size, layers);
    r->normal = lpv_gl_new_texture_2d_array(GL_RGBA32F, size, size, layers);
    r->flux = lpv_gl_new_texture_2d_array(GL_RGBA32F, size, size, layers);
    r->albedo = lpv_gl_new_texture_2d_array(GL_RGBA8, size, size, layers);
    r->depth = lpv_gl_new_texture_2d_array(GL_DEPTH_COMPONENT32F, size, size, layers);
    glGenFramebuffers(1, &r->fbo);

    /* the most VPLs (and surfels) any step makes: see lpv_memory_block_samples */
    size_t texels = (size_t)layers * (size_t)lpv_memory_block_samples(size, size);
    glGenBuffers(1, &r->vpls);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, r->vpls);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(texels * sizeof(struct LpvVpl)), NULL, GL_DYNAMIC_COPY);
    glGenBuffers(1, &r->surfels);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, r->surfels);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(texels * sizeof(struct LpvSurfel)), NULL, GL_DYNAMIC_COPY);
    glGenBuffers(1, &r->vpls_live);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, r->vpls_live);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(texels * sizeof(struct LpvVpl)), NULL, GL_DYNAMIC_COPY);
    glGenBuffers(1, &r->vpls_draw);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, r->vpls_draw);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)lpv_compact_head_bytes(texels), NULL, GL_DYNAMIC_COPY);
    GLenum gl_err = glGetError();
    if (gl_err != GL_NO_ERROR) {
        lpv_rsms_free(r);
        return lpv_error(err, err_size, "could not allocate the RSMs: rsm_size %d x %d layers = %.2f GB (GL error "
                         "0x%04x)", size, layers, (double)bytes / 1e9, gl_err);
    }
    r->alloc_size = size;
    r->alloc_faces = layers;
    return 0;
}

void lpv_rsms_draw(lpv_rsms *r, const lpv_rsm_draw *d)
{
    const int size = r->size;
    lpv_timer_begin(d->timer, "rsm");
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo);
    static const GLenum bufs[4] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2,
                                   GL_COLOR_ATTACHMENT3};
    glDrawBuffers(4, bufs);
    glViewport(0, 0, size, size);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    const GLuint prog = lpv_scene_gpu_program(d->geo, d->prog, d->prog_plain);
    glUseProgram(prog);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_LIGHT, d->light_ubo);
    GLint loc_vp = glGetUniformLocation(prog, "u_view_proj");
    GLint loc_face = glGetUniformLocation(prog, "u_face");
    int bound_layer = -1;
    for (int f = 0; f < r->face_count; ++f) {
        /* A face fills its layer, or (area lights) one tile of it: a layer is
         * attached and cleared once, before its first face draws. */
        const float *tile = d->lights->faces[f].tile;
        const int layer = (int)tile[3];
        if (layer != bound_layer) {
            glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, r->position, 0, layer);
            glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, r->normal, 0, layer);
            glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT2, r->flux, 0, layer);
            glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT3, r->albedo, 0, layer);
            glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, r->depth, 0, layer);
            static const float zero[4] = {0, 0, 0, 0};
            for (int i = 0; i < 4; ++i)
                glClearBufferfv(GL_COLOR, i, zero);
            glClearBufferfi(GL_DEPTH_STENCIL, 0, 1.0f, 0);
            bound_layer = layer;
        }
        const int side = (int)lroundf(tile[2] * (float)size);
        glViewport((int)lroundf(tile[0] * (float)size), (int)lroundf(tile[1] * (float)size), side, side);
        glUniformMatrix4fv(loc_vp, 1, GL_FALSE, (const float *)d->lights->faces[f].view_proj);
        glUniform1i(loc_face, f);
        lpv_scene_gpu_draw(d->geo, prog, 0, LPV_DRAWS_ALL, d->timer); /* lights see both sides */
    }
    glDisable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    lpv_timer_end(d->timer);
}

size_t lpv_rsms_extract(lpv_rsms *r, const lpv_rsm_extract *d)
{
    const int size = r->size, step = d->step;
    const int blocks = (size + step - 1) / step;
    const int slots = lpv_block_slots(step);
    if (d->count <= 0)
        return (size_t)blocks * (size_t)blocks * (size_t)slots;
    const GLuint prog = d->prog;
    glUseProgram(prog);
    if (step > 1) {
        lpv_block_groups_bind(prog, d->groups, d->group_levels);
        glUniform1i(glGetUniformLocation(prog, "u_step"), step);
        glUniform1i(glGetUniformLocation(prog, "u_blocks"), blocks);
        glUniform1i(glGetUniformLocation(prog, "u_slots"), slots);
    }
    const GLuint tex[4] = {r->position, r->normal, r->flux, r->albedo};
    for (int i = 0; i < 4; ++i) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glBindTexture(GL_TEXTURE_2D_ARRAY, tex[i]);
    }
    glUniform1i(glGetUniformLocation(prog, "u_size"), size);
    glUniform1i(glGetUniformLocation(prog, "u_layer0"), d->first);
    glUniform1i(glGetUniformLocation(prog, "u_base"), (GLint)d->base);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_VPLS, r->vpls);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_SURFELS, r->surfels);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    glDispatchCompute(lpv_div_up((size_t)blocks, LPV_WG_2D), lpv_div_up((size_t)blocks, LPV_WG_2D), (GLuint)d->count);
    lpv_timer_count(d->timer, 1);
    return (size_t)blocks * (size_t)blocks * (size_t)slots;
}
