/*
 * pass_rsm.c - reflective shadow maps: every light face renders the scene's
 * position/area, normal and reflected flux into one layer (an area light's
 * face: one tile of a layer) of three 2D array textures (plus the depth its
 * own depth test needs; direct light has its own shadow maps, shadow_maps.c);
 * a compute pass then turns every texel into one VPL and one surfel.
 */
#include <math.h>

#include "compact.h"
#include "engine_internal.h"

static GLuint array_texture(GLenum format, int size, int layers)
{
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D_ARRAY, t);
    glTexStorage3D(GL_TEXTURE_2D_ARRAY, 1, format, size, size, layers);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return t;
}

/* Deletes the RSM textures and buffers (a partly failed allocation too);
 * the engine's destroy calls it too, so this is the one list of them. */
void lpv_pass_rsm_free(lpv_engine *e)
{
    lpv_gl_delete_texture(&e->rsm.position);
    lpv_gl_delete_texture(&e->rsm.normal);
    lpv_gl_delete_texture(&e->rsm.flux);
    lpv_gl_delete_texture(&e->rsm.albedo);
    lpv_gl_delete_texture(&e->rsm.depth);
    lpv_gl_delete_framebuffer(&e->rsm.fbo);
    lpv_gl_delete_buffer(&e->rsm.vpls);
    lpv_gl_delete_buffer(&e->rsm.surfels);
    lpv_gl_delete_buffer(&e->rsm.vpls_live);
    lpv_gl_delete_buffer(&e->rsm.vpls_draw);
    e->rsm.alloc_size = e->rsm.alloc_faces = 0;
}

int lpv_pass_rsm_prepare(lpv_engine *e, char *err, size_t err_size)
{
    lpv_light_faces_build(e);
    glBindBuffer(GL_UNIFORM_BUFFER, e->light_ubo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof e->light_block, &e->light_block);

    const int size = e->settings.rsm_size;
    const int layers = e->rsm.layers > 0 ? e->rsm.layers : 1;
    if (e->rsm.alloc_size == size && e->rsm.alloc_faces == layers) {
        e->rsm.size = size;
        return 0;
    }
    e->rsm.size = 0;
    e->rsm.vpl_count = 0;
    /* Estimate before allocating: past what the device holds, drivers fail
     * in ways that crash (llvmpipe segfaults on shader storage past 2 GiB). */
    lpv_memory_need need;
    lpv_engine_memory_need(e, &need);
    if (lpv_engine_memory_check(e, err, err_size) != 0)
        return -1;
    for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i) { /* start from a clean error state */
    }

    lpv_pass_rsm_free(e);
    e->rsm.position = array_texture(GL_RGBA32F, size, layers);
    e->rsm.normal = array_texture(GL_RGBA32F, size, layers);
    e->rsm.flux = array_texture(GL_RGBA32F, size, layers);
    e->rsm.albedo = array_texture(GL_RGBA8, size, layers);
    e->rsm.depth = array_texture(GL_DEPTH_COMPONENT32F, size, layers);
    glGenFramebuffers(1, &e->rsm.fbo);

    /* the most VPLs (and surfels) any step makes: see lpv_memory_block_samples */
    size_t texels = (size_t)layers * (size_t)lpv_memory_block_samples(size, size);
    glGenBuffers(1, &e->rsm.vpls);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, e->rsm.vpls);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(texels * sizeof(lpv_vpl)), NULL, GL_DYNAMIC_COPY);
    glGenBuffers(1, &e->rsm.surfels);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, e->rsm.surfels);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(texels * sizeof(lpv_surfel)), NULL, GL_DYNAMIC_COPY);
    glGenBuffers(1, &e->rsm.vpls_live);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, e->rsm.vpls_live);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(texels * sizeof(lpv_vpl)), NULL, GL_DYNAMIC_COPY);
    glGenBuffers(1, &e->rsm.vpls_draw);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, e->rsm.vpls_draw);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)lpv_compact_head_bytes(texels), NULL, GL_DYNAMIC_COPY);
    GLenum gl_err = glGetError();
    if (gl_err != GL_NO_ERROR) {
        lpv_pass_rsm_free(e);
        return lpv_error(err, err_size, "could not allocate the RSMs: rsm_size %d x %d layers = %.2f GB (GL error "
                         "0x%04x)", size, layers, (double)lpv_memory_rsm_bytes(&need) / 1e9, gl_err);
    }
    e->rsm.alloc_size = size;
    e->rsm.alloc_faces = layers;
    e->rsm.size = size;
    e->rsm.vpl_count = 0;
    return 0;
}

/* Layers [first, first + count) of the RSMs, whose faces are `side` texels
 * (a whole layer, or an area light's tile), into VPLs and surfels from
 * element `base` on: blocks of step x step texels, grouped by the cells
 * (VPLs) and GV points (surfels) of the cascades they reach
 * (block_groups.glsl), the step dividing side; surfels: whether the
 * geometry volume takes these layers' surfels (the step depends on it,
 * lpv_settings_rsm_vpl_step). Returns the elements per layer. */
static size_t extract_layers(lpv_engine *e, int first, int count, int side, size_t base, int surfels)
{
    const int size = e->rsm.size;
    const int step = lpv_settings_rsm_vpl_step(&e->settings, side, surfels);
    const int blocks = (size + step - 1) / step;
    const int slots = lpv_block_slots(step);
    if (count <= 0)
        return (size_t)blocks * (size_t)blocks * (size_t)slots;
    /* step 1: a VPL per texel (a program without the grouping: llvmpipe
     * would run its code for every texel even where it is not needed);
     * step 2: four slots (block_groups.glsl), as many as texels; larger: 8,
     * without the surfels' grouping where the GV leaves them out (their
     * slots are then not written) */
    const GLuint prog = step == 1   ? e->prog_vpl_extract
                        : step == 2 ? e->prog_vpl_blocks
                                    : (surfels ? e->prog_vpl_blocks8 : e->prog_vpl_blocks8_vpls);
    glUseProgram(prog);
    if (step > 1) {
        lpv_engine_bind_block_groups(e, prog);
        glUniform1i(glGetUniformLocation(prog, "u_step"), step);
        glUniform1i(glGetUniformLocation(prog, "u_blocks"), blocks);
        glUniform1i(glGetUniformLocation(prog, "u_slots"), slots);
    }
    GLuint tex[4] = {e->rsm.position, e->rsm.normal, e->rsm.flux, e->rsm.albedo};
    for (int i = 0; i < 4; ++i) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glBindTexture(GL_TEXTURE_2D_ARRAY, tex[i]);
    }
    glUniform1i(glGetUniformLocation(prog, "u_size"), size);
    glUniform1i(glGetUniformLocation(prog, "u_layer0"), first);
    glUniform1i(glGetUniformLocation(prog, "u_base"), (GLint)base);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_VPLS, e->rsm.vpls);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_SURFELS, e->rsm.surfels);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    glDispatchCompute(lpv_div_up((size_t)blocks, LPV_WG_2D), lpv_div_up((size_t)blocks, LPV_WG_2D), (GLuint)count);
    lpv_timer_count(&e->timer, 1);
    return (size_t)blocks * (size_t)blocks * (size_t)slots;
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
    lpv_timer_begin(&e->timer, "rsm");
    glBindFramebuffer(GL_FRAMEBUFFER, e->rsm.fbo);
    static const GLenum bufs[4] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2,
                                   GL_COLOR_ATTACHMENT3};
    glDrawBuffers(4, bufs);
    glViewport(0, 0, size, size);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    const GLuint prog = lpv_scene_gpu_program(&e->geo, e->prog_rsm, e->prog_rsm_plain);
    glUseProgram(prog);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_LIGHT, e->light_ubo);
    GLint loc_vp = glGetUniformLocation(prog, "u_view_proj");
    GLint loc_face = glGetUniformLocation(prog, "u_face");
    int bound_layer = -1;
    for (int f = 0; f < e->rsm.face_count; ++f) {
        /* A face fills its layer, or (area lights) one tile of it: a layer is
         * attached and cleared once, before its first face draws. */
        const float *tile = e->light_block.faces[f].tile;
        const int layer = (int)tile[3];
        if (layer != bound_layer) {
            glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, e->rsm.position, 0, layer);
            glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, e->rsm.normal, 0, layer);
            glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT2, e->rsm.flux, 0, layer);
            glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT3, e->rsm.albedo, 0, layer);
            glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, e->rsm.depth, 0, layer);
            static const float zero[4] = {0, 0, 0, 0};
            for (int i = 0; i < 4; ++i)
                glClearBufferfv(GL_COLOR, i, zero);
            glClearBufferfi(GL_DEPTH_STENCIL, 0, 1.0f, 0);
            bound_layer = layer;
        }
        const int side = (int)lroundf(tile[2] * (float)size);
        glViewport((int)lroundf(tile[0] * (float)size), (int)lroundf(tile[1] * (float)size), side, side);
        glUniformMatrix4fv(loc_vp, 1, GL_FALSE, (const float *)e->light_block.faces[f].view_proj);
        glUniform1i(loc_face, f);
        lpv_scene_gpu_draw(&e->geo, prog, 0, LPV_DRAWS_ALL, &e->timer); /* lights see both sides */
    }
    glDisable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    lpv_timer_end(&e->timer);

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
    lpv_compact_run(e->prog_compact, e->rsm.vpls, e->rsm.vpl_count, e->rsm.vpls_live, e->rsm.vpls_draw);
    lpv_timer_end(&e->timer);
}
