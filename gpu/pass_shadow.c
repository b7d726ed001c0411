/*
 * pass_shadow.c - the shadow maps of direct light (docs/shadows.md): every
 * shadow-map face (lpv_shadow_faces_build) renders the scene's depth alone
 * into one layer of a DEPTH32F array texture of shadow_size^2 texels (an
 * area light sample's face: into one tile of a layer), which
 * shadow.glsl samples with hardware-compare PCF. Separate from the RSMs,
 * which stay the VPL source at rsm_size. Runs at render time, because the
 * directional cascades follow the camera, and only when the faces, the scene
 * or the settings changed.
 */
#include <math.h>
#include <string.h>

#include "engine_internal.h"

void lpv_pass_shadow_free(lpv_engine *e)
{
    if (e->shadow_tex)
        glDeleteTextures(1, &e->shadow_tex);
    if (e->shadow_fbo)
        glDeleteFramebuffers(1, &e->shadow_fbo);
    e->shadow_tex = e->shadow_fbo = 0;
    e->shadow_alloc_size = e->shadow_alloc_faces = 0;
    e->shadow_valid = 0;
}

static int allocate(lpv_engine *e, int size, int layers, char *err, size_t err_size)
{
    lpv_memory_need need;
    lpv_engine_memory_need(e, &need);
    if (lpv_engine_memory_check(e, err, err_size) != 0)
        return -1;
    lpv_pass_shadow_free(e);
    for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i) { /* start from a clean error state */
    }
    glGenTextures(1, &e->shadow_tex);
    glBindTexture(GL_TEXTURE_2D_ARRAY, e->shadow_tex);
    glTexStorage3D(GL_TEXTURE_2D_ARRAY, 1, GL_DEPTH_COMPONENT32F, size, size, layers);
    /* Hardware compare with bilinear filtering: each tap of the PCF kernel
     * is already a 2x2 weighted comparison. */
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glGenFramebuffers(1, &e->shadow_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, e->shadow_fbo);
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, e->shadow_tex, 0, 0);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    GLenum gl_err = glGetError();
    if (gl_err != GL_NO_ERROR || status != GL_FRAMEBUFFER_COMPLETE) {
        lpv_pass_shadow_free(e);
        return lpv_error(err, err_size,
                         "could not allocate the shadow maps: shadow_size %d x %d layers = %.2f GB (GL error 0x%04x, "
                         "framebuffer 0x%04x)",
                         size, layers, (double)lpv_memory_shadow_bytes(&need) / 1e9, gl_err, status);
    }
    e->shadow_alloc_size = size;
    e->shadow_alloc_faces = layers;
    return 0;
}

static void draw(lpv_engine *e)
{
    const int size = e->shadow_alloc_size, faces = (int)e->shadow_block.counts[0];
    int bound_layer = -1;
    lpv_timer_begin(&e->timer, "shadow");
    glBindFramebuffer(GL_FRAMEBUFFER, e->shadow_fbo);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE); /* both sides cast: single-sided walls still block */
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glUseProgram(e->prog_shadow);
    GLint loc_vp = glGetUniformLocation(e->prog_shadow, "u_view_proj");
    for (int f = 0; f < faces; ++f) {
        /* A face fills its layer, or (area light samples) one tile of it: a
         * layer is attached and cleared once, before its first face draws. */
        const float *tile = e->shadow_block.faces[f].tile;
        const int layer = (int)tile[3];
        if (layer != bound_layer) {
            glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, e->shadow_tex, 0, layer);
            glClearBufferfi(GL_DEPTH_STENCIL, 0, 1.0f, 0);
            bound_layer = layer;
        }
        const int side = (int)lroundf(tile[2] * (float)size);
        glViewport((int)lroundf(tile[0] * (float)size), (int)lroundf(tile[1] * (float)size), side, side);
        glUniformMatrix4fv(loc_vp, 1, GL_FALSE, (const float *)e->shadow_block.faces[f].view_proj);
        lpv_engine_draw_scene(e, e->prog_shadow, 0); /* lights see both sides */
    }
    glDisable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    lpv_timer_end(&e->timer);
}

int lpv_pass_shadow_update(lpv_engine *e, char *err, size_t err_size)
{
    struct LpvShadowBlock b;
    if (lpv_shadow_faces_build(e, &b, err, err_size) != 0)
        return -1;
    const int size = e->settings.shadow_size, faces = (int)b.counts[0];
    const int layers = b.counts[3] > 0.0f ? (int)b.counts[3] : 1;
    if (e->shadow_alloc_size != size || e->shadow_alloc_faces != layers)
        if (allocate(e, size, layers, err, err_size) != 0)
            return -1;
    if (e->shadow_valid && memcmp(&b, &e->shadow_block, sizeof b) == 0)
        return 0;
    e->shadow_block = b;
    glBindBuffer(GL_UNIFORM_BUFFER, e->shadow_ubo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof b, &b);
    if (faces > 0)
        draw(e);
    e->shadow_valid = 1;
    return 0;
}
