/*
 * engine_render.c - after a tick: the camera's frame (G-buffer if stale,
 * shadow maps if stale, shading, glossy, the translucent layer, media; read
 * back top row first) and irradiance queries at arbitrary points, both
 * through the technique's lookup.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "engine_internal.h"
#include "error.h"

int lpv_engine_shadows_update(lpv_engine *e, char *err, size_t err_size)
{
    struct LpvShadowBlock b;
    if (lpv_shadow_faces_build(e, &b, err, err_size) != 0)
        return -1;
    const int size = e->settings.shadow_size;
    const int layers = b.counts[3] > 0.0f ? (int)b.counts[3] : 1;
    const int translucent = e->geo.blend_draws > 0;
    b.options[0] = (float)translucent;
    if (!lpv_shadow_maps_fit(&e->shadows, size, layers, translucent)) {
        lpv_memory_need need;
        lpv_engine_memory_need(e, &need);
        if (lpv_engine_memory_check(e, err, err_size) != 0 ||
            lpv_shadow_maps_allocate(&e->shadows, size, layers, translucent, lpv_memory_shadow_bytes(&need), err,
                                     err_size) != 0)
            return -1;
    }
    const lpv_shadow_draw d = {.geo = &e->geo, .lights = e->light_block.lights, .prog = e->progs.shadow,
                               .prog_plain = e->progs.shadow_plain, .timer = &e->timer};
    lpv_shadow_maps_draw(&e->shadows, &b, &d);
    return 0;
}

int lpv_engine_render(lpv_engine *e, lpv_frame_terms terms, float *rgba, char *err, size_t err_size)
{
    if (!e->ticked)
        return lpv_error(err, err_size, "render before a tick");
    if (!e->has_view)
        return lpv_error(err, err_size, "render needs a view (camera)");
    if (terms == LPV_TERMS_AO && lpv_ao_check(&e->settings, e->tech_id, err, err_size) != 0)
        return -1;
    if (e->gbuf.stale) { /* the tick did not need the camera's G-buffer, or the camera moved since */
        if (lpv_pass_gbuffer_run(e, err, err_size) != 0)
            return -1;
        e->gbuf.stale = 0;
    }
    /* Direct light needs the shadow maps (media's in-scattering too, which
     * only a full frame has); they are redrawn only when what they show changed. */
    if (terms != LPV_TERMS_INDIRECT_ONLY && terms != LPV_TERMS_AO && lpv_engine_shadows_update(e, err, err_size) != 0)
        return -1;
    if (lpv_pass_shade_run(e, terms, err, err_size) != 0)
        return -1;
    if (e->plan.pass[LPV_PASS_GLOSSY].run && (terms == LPV_TERMS_FULL || terms == LPV_TERMS_INDIRECT_ONLY))
        lpv_pass_glossy_run(e);
    /* the BLEND surfaces' layer over the frame (not over an ambient
     * occlusion frame, which is the technique's term of the opaque surfaces) */
    size_t full_lookups = 0, area_rest_pixels = 0;
    if (e->plan.pass[LPV_PASS_TRANSLUCENT].run && e->geo.blend_draws && terms != LPV_TERMS_AO &&
        lpv_pass_translucent_run(e, terms, &full_lookups, &area_rest_pixels, err, err_size) != 0)
        return -1;
    if (e->plan.pass[LPV_PASS_MEDIA].run && terms == LPV_TERMS_FULL)
        lpv_pass_media_run(e);
    lpv_frame_read(&e->frame, rgba);
    /* read after the frame, which waited for the passes anyway */
    e->stats.frame_full_lookups = full_lookups + lpv_frame_full_lookups(&e->frame);
    e->stats.frame_area_shadow_pixels = area_rest_pixels + lpv_frame_area_rest_pixels(&e->frame);
    GLenum gl_err = glGetError();
    if (gl_err != GL_NO_ERROR)
        return lpv_error(err, err_size, "GL error 0x%04x during rendering", gl_err);
    /* Append the shading stage to the tick's stats. */
    lpv_timer_collect(&e->timer);
    lpv_engine_stats *s = &e->stats;
    for (int i = 0; i < e->timer.stage_count && s->stage_count < LPV_STAGE_MAX; ++i) {
        const lpv_timer_stage *st = &e->timer.stages[i];
        int k = s->stage_count++;
        snprintf(s->stages[k].name, sizeof s->stages[k].name, "%s", st->name);
        s->stages[k].gpu_ms = st->gpu_ms;
        s->stages[k].cpu_ms = st->cpu_ms;
        s->stages[k].calls = st->count;
    }
    return 0;
}

/* Points per dispatch of the irradiance query: the GL guarantees 65535 work
 * groups per dimension (GL_MAX_COMPUTE_WORK_GROUP_COUNT, llvmpipe's too), so
 * one dispatch of 64-point groups reaches 4,194,240 points; a larger query
 * failed with GL_INVALID_VALUE (issue 14, item 7). Chunks of 2^20 points also
 * keep the two query buffers at 48 MiB whatever the count. */
#define QUERY_CHUNK ((size_t)1 << 20)
#define QUERY_GROUP 64 /* shaders/query.comp's local_size_x */

/* One chunk of n <= QUERY_CHUNK points through the query buffers. */
static void irradiance_chunk(lpv_engine *e, const float *points, const float *normals, size_t n, float *rgb,
                             float *in, float *out)
{
    for (size_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) {
            in[i * 8 + (size_t)k] = points[i * 3 + (size_t)k];
            in[i * 8 + 4 + (size_t)k] = normals[i * 3 + (size_t)k];
        }
        in[i * 8 + 3] = in[i * 8 + 7] = 0.0f;
    }
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, e->query_in);
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(n * 8 * sizeof(float)), in);
    glUseProgram(e->progs.query);
    glUniform1i(glGetUniformLocation(e->progs.query, "u_count"), (GLint)n);
    lpv_engine_bind_lookup(e, e->progs.query, e->settings.lpv.damping);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_VPLS, e->query_in);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_SURFELS, e->query_out);
    glDispatchCompute(lpv_div_up(n, QUERY_GROUP), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, e->query_out);
    glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(n * 4 * sizeof(float)), out);
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k)
            rgb[i * 3 + (size_t)k] = out[i * 4 + (size_t)k];
}

int lpv_engine_irradiance(lpv_engine *e, const float *points, const float *normals, size_t n, float *rgb, char *err,
                          size_t err_size)
{
    if (!e->ticked)
        return lpv_error(err, err_size, "irradiance query before a tick");
    if (n == 0)
        return 0;
    const size_t cap = n < QUERY_CHUNK ? n : QUERY_CHUNK;
    float *in = malloc(cap * 8 * sizeof(float));
    float *out = malloc(cap * 4 * sizeof(float));
    if (!in || !out) {
        free(in);
        free(out);
        return lpv_error(err, err_size, "out of memory for %zu query points", cap);
    }
    if (e->query_capacity < cap) {
        lpv_gl_delete_buffer(&e->query_in);
        lpv_gl_delete_buffer(&e->query_out);
        for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i) { /* start from a clean error state */
        }
        e->query_in = lpv_gl_new_ssbo(cap * 8 * sizeof(float));
        e->query_out = lpv_gl_new_ssbo(cap * 4 * sizeof(float));
        GLenum alloc_err = glGetError();
        if (alloc_err != GL_NO_ERROR) {
            lpv_gl_delete_buffer(&e->query_in);
            lpv_gl_delete_buffer(&e->query_out);
            e->query_capacity = 0;
            free(in);
            free(out);
            return lpv_error(err, err_size,
                             "could not allocate buffers for %zu query points (%.2f GB; GL error 0x%04x)", cap,
                             (double)cap * 48.0 / 1e9, alloc_err);
        }
        e->query_capacity = cap;
    }
    for (size_t at = 0; at < n; at += cap) {
        size_t m = n - at < cap ? n - at : cap;
        irradiance_chunk(e, points + at * 3, normals + at * 3, m, rgb + at * 3, in, out);
    }
    free(in);
    free(out);
    GLenum gl_err = glGetError();
    if (gl_err != GL_NO_ERROR)
        return lpv_error(err, err_size, "GL error 0x%04x during the irradiance query", gl_err);
    return 0;
}

