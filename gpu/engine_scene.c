/*
 * engine_scene.c - the scene on the GPU: geometry, materials and textures,
 * lights, the medium, the emissive surfaces (as VPLs and as area light
 * samples) and the scene surfels; and drawing it for the RSM, G-buffer and
 * shadow passes.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "emissive.h"
#include "engine_internal.h"
#include "material_sample.h"
#include "error.h"
#include "hash.h"
#include "scene_planes.h"
#include "scene_surfels.h"

static void free_samples(lpv_engine *e)
{
    lpv_gl_delete_buffer(&e->emissive_vpls);
    lpv_gl_delete_buffer(&e->scene_surfels);
    e->emissive_vpl_count = 0;
    e->scene_surfel_count = 0;
    free(e->scene_surfel_samples);
    e->scene_surfel_samples = NULL;
    e->scene_surfel_sample_count = 0;
    e->scene_surfel_grid_sig = 0;
}

void lpv_engine_free_scene(lpv_engine *e)
{
    if (e->geo.vao)
        glDeleteVertexArrays(1, &e->geo.vao);
    e->geo.vao = 0;
    lpv_gl_delete_buffer(&e->geo.vbo);
    lpv_gl_delete_buffer(&e->geo.ibo);
    free_samples(e);
    lpv_scene_free(&e->geometry);
    if (e->geo.texture_count)
        glDeleteTextures((GLsizei)e->geo.texture_count, e->geo.textures);
    free(e->geo.textures);
    free(e->geo.draws);
    free(e->geo.wire_draws);
    free(e->geo.materials);
    e->geo.textures = NULL;
    e->geo.draws = e->geo.wire_draws = NULL;
    e->geo.materials = NULL;
    e->geo.texture_count = e->geo.draw_count = e->geo.wire_draw_count = e->geo.material_count = 0;
    e->geo.blend_draws = 0;
    e->light_count = 0;
    lpv_emitters_free(&e->emitters);
    lpv_engine_reach_free(e);
    e->area_sample_count = 0;
    e->occluder_triangles = 0;
    e->has_scene = 0;
}

/* The emitters as area light samples under the current settings (0 when
 * area lights are off or nothing emits). */
void lpv_engine_update_area_samples(lpv_engine *e)
{
    e->area_sample_count = 0;
    if (e->settings.area_lights == LPV_SWITCH_ON && e->emitters.count)
        e->area_sample_count =
            lpv_area_lights_sample(&e->emitters, (size_t)e->settings.area_light_samples, e->area_samples);
}

static int upload_textures(lpv_engine *e, const lpv_scene *scene, char *err, size_t err_size)
{
    if (!scene->texture_count)
        return 0;
    e->geo.textures = calloc(scene->texture_count, sizeof(GLuint));
    if (!e->geo.textures)
        return lpv_error(err, err_size, "out of memory for textures");
    e->geo.texture_count = scene->texture_count;
    glGenTextures((GLsizei)scene->texture_count, e->geo.textures);
    for (uint32_t i = 0; i < scene->texture_count; ++i) {
        const lpv_texture *t = &scene->textures[i];
        glBindTexture(GL_TEXTURE_2D, e->geo.textures[i]);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
        /* colour is sRGB-encoded (GL decodes it); normal maps are linear data */
        const GLint format = t->linear ? GL_RGBA8 : GL_SRGB8_ALPHA8;
        if (t->rgba8 && t->width > 0 && t->height > 0)
            glTexImage2D(GL_TEXTURE_2D, 0, format, t->width, t->height, 0, GL_RGBA, GL_UNSIGNED_BYTE, t->rgba8);
        else {
            const uint8_t white[4] = {255, 255, 255, 255};
            glTexImage2D(GL_TEXTURE_2D, 0, format, 1, 1, 0, GL_RGBA, GL_UNSIGNED_BYTE, white);
        }
        glGenerateMipmap(GL_TEXTURE_2D);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
    }
    return 0;
}

/* Longest side of the bounding box of a draw's finite vertices (m). */
/* Draw d's bounding box (lo > hi on an axis when it has no finite vertex)
 * and its longest side (m; 0 then). */
static float draw_box(const lpv_scene *scene, const lpv_draw *d, float lo[3], float hi[3])
{
    for (int k = 0; k < 3; ++k)
        lo[k] = INFINITY, hi[k] = -INFINITY;
    for (uint32_t i = 0; i < d->index_count; ++i) {
        uint32_t v = scene->indices[d->first_index + i];
        if (v >= scene->vertex_count)
            continue;
        const float *p = scene->vertices[v].position;
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
            continue;
        for (int k = 0; k < 3; ++k) {
            lo[k] = fminf(lo[k], p[k]);
            hi[k] = fmaxf(hi[k], p[k]);
        }
    }
    float size = 0.0f;
    for (int k = 0; k < 3; ++k)
        if (hi[k] >= lo[k])
            size = fmaxf(size, hi[k] - lo[k]);
    return size;
}

/* Geometry, materials, textures and the medium, not lights: a scene update
 * that only moves lights re-uploads nothing and is reported as such by the
 * planner. */
static uint64_t geometry_signature(const lpv_scene *s)
{
    uint64_t h = LPV_HASH_INIT;
    for (uint32_t i = 0; i < s->texture_count; ++i) {
        const lpv_texture *t = &s->textures[i];
        h = lpv_hash_bytes(h, &t->width, sizeof t->width);
        h = lpv_hash_bytes(h, &t->height, sizeof t->height);
        h = lpv_hash_bytes(h, &t->linear, sizeof t->linear);
        if (t->rgba8 && t->width > 0 && t->height > 0)
            h = lpv_hash_bytes(h, t->rgba8, (size_t)t->width * (size_t)t->height * 4);
    }
    h = lpv_hash_bytes(h, s->vertices, (size_t)s->vertex_count * sizeof *s->vertices);
    h = lpv_hash_bytes(h, s->indices, (size_t)s->index_count * sizeof *s->indices);
    h = lpv_hash_bytes(h, s->draws, (size_t)s->draw_count * sizeof *s->draws);
    h = lpv_hash_bytes(h, s->wire_indices, (size_t)s->wire_index_count * sizeof *s->wire_indices);
    h = lpv_hash_bytes(h, s->wire_draws, (size_t)s->wire_draw_count * sizeof *s->wire_draws);
    h = lpv_hash_bytes(h, s->materials, (size_t)s->material_count * sizeof *s->materials);
    h = lpv_hash_bytes(h, &s->medium, sizeof s->medium);
    return h;
}

/* The scene as a technique that samples it itself sees it. */
static lpv_technique_scene technique_scene(const lpv_engine *e)
{
    lpv_technique_scene sc = {.geometry = &e->geometry, .settings = &e->settings};
    lpv_engine_lit_region(e, sc.lit_min, sc.lit_max, &sc.free_path);
    return sc;
}

int lpv_engine_samples_stale(const lpv_engine *e)
{
    if (!e->tech || !e->tech->cls->samples_stale)
        return 0;
    const lpv_technique_scene sc = technique_scene(e);
    return e->tech->cls->samples_stale(e->tech, &sc);
}

/* The scene's samples under the current settings, from the engine's copy of
 * its geometry: the emissive surfaces' VPLs (emissive_vpls) and the scene
 * surfels (scene_surfels, scene_surfel_count). Redone by set_settings when
 * one of those knobs changes, without the scene being sent again. */
int lpv_engine_sample_scene(lpv_engine *e, char *err, size_t err_size)
{
    const lpv_scene *scene = &e->geometry;
    free_samples(e);
    e->counters.scene_samplings++;

    /* A technique that samples the scene itself (the imperfect volume's
     * point cloud) would leave the engine's samples (emissive VPLs, scene
     * surfels) unused. */
    if (e->tech && e->tech->cls->sample_scene) {
        const lpv_technique_scene sc = technique_scene(e);
        return e->tech->cls->sample_scene(e->tech, &sc, err, err_size);
    }
    size_t target = (size_t)e->settings.emissive_vpls;
    lpv_vpl *vpls = target ? calloc(target * 2 + 1024, sizeof *vpls) : NULL;
    size_t n = vpls ? lpv_emissive_sample(scene, target, vpls, target * 2 + 1024) : 0;
    e->emissive_vpls = lpv_gl_new_ssbo(n * sizeof(lpv_vpl));
    if (n)
        glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(n * sizeof(lpv_vpl)), vpls);
    e->emissive_vpl_count = n;
    free(vpls);

    size_t want = e->settings.scene_surfels == LPV_SWITCH_ON ? (size_t)e->settings.scene_surfel_count : 0;
    lpv_surfel *surfels = want ? calloc(want + 1, sizeof *surfels) : NULL;
    if (want && !surfels)
        return lpv_error(err, err_size, "out of memory for %zu scene surfels", want);
    size_t ns = surfels ? lpv_scene_surfels(scene, want, surfels, want + 1) : 0;
    /* the buffer holds at most one group per sample; the next tick fills it
     * (lpv_engine_group_scene_surfels, once the cascades are committed) */
    e->scene_surfels = lpv_gl_new_ssbo(ns * sizeof(lpv_surfel));
    e->scene_surfel_samples = surfels;
    e->scene_surfel_sample_count = ns;
    e->scene_surfel_count = 0;
    e->scene_surfel_grid_sig = 0;
    if (glGetError() != GL_NO_ERROR)
        return lpv_error(err, err_size, "%s: GL error while storing the scene's samples", scene->source);
    return 0;
}

void lpv_engine_group_scene_surfels(lpv_engine *e)
{
    const size_t n = e->scene_surfel_sample_count;
    if (!n || !e->scene_surfels)
        return;
    lpv_group_grid g[LPV_MAX_CASCADES];
    const int levels = lpv_engine_group_grids(e, g);
    uint64_t sig = lpv_hash_bytes(lpv_hash_bytes(LPV_HASH_INIT, &levels, sizeof levels), g, sizeof g);
    if (sig == 0)
        sig = 1;
    if (sig == e->scene_surfel_grid_sig)
        return;
    /* a technique without cascades: the samples as they are */
    lpv_surfel *grouped = levels ? malloc(n * sizeof *grouped) : NULL;
    size_t m = grouped ? lpv_surfels_group(e->scene_surfel_samples, n, g, levels, grouped) : 0;
    const lpv_surfel *src = m ? grouped : e->scene_surfel_samples;
    e->scene_surfel_count = m ? m : n;
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, e->scene_surfels);
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(e->scene_surfel_count * sizeof(lpv_surfel)), src);
    free(grouped);
    e->scene_surfel_grid_sig = levels ? sig : 0;
}

static void set_lights(lpv_engine *e, const lpv_scene *scene)
{
    e->light_count = 0;
    for (uint32_t i = 0; i < scene->light_count && e->light_count < LPV_MAX_LIGHTS; ++i)
        e->lights[e->light_count++] = scene->lights[i];
    lpv_engine_reach_light(e);
}

int lpv_engine_set_scene(lpv_engine *e, const lpv_scene *scene, char *err, size_t err_size)
{
    /* nothing to light or see: a frame of background and exit 0 would pass
     * for a render (issue 32); the file's loader has said what it dropped */
    size_t triangles = 0, wires = 0;
    for (uint32_t d = 0; d < scene->draw_count; ++d)
        triangles += scene->draws[d].index_count / 3;
    for (uint32_t d = 0; d < scene->wire_draw_count; ++d)
        wires += scene->wire_draws[d].index_count;
    if (!triangles && !wires)
        return lpv_error(err, err_size, "%s: nothing to draw (no triangles, points or lines)", scene->source);
    uint64_t sig = geometry_signature(scene);
    e->shadows.valid = 0;
    e->ticked = 0;
    if (e->has_scene && sig == e->geometry_sig) {
        /* the same geometry, materials and textures: only the lights are new,
         * but they may light other spaces, and the imperfect volume's cloud
         * is kept in the box of the lit ones */
        e->lights_dirty = 1;
        set_lights(e, scene);
        if (lpv_engine_samples_stale(e) && lpv_engine_sample_scene(e, err, err_size) != 0)
            return -1;
        return lpv_engine_place_volume(e, err, err_size);
    }
    e->scene_dirty = 1;
    e->geometry_sig = sig;
    e->gbuf.stale = 1;
    lpv_engine_free_scene(e);
    e->counters.scene_uploads++;
    e->geo.draws = calloc(scene->draw_count ? scene->draw_count : 1, sizeof *e->geo.draws);
    e->geo.materials = calloc(scene->material_count ? scene->material_count : 1, sizeof *e->geo.materials);
    if (!e->geo.draws || !e->geo.materials)
        return lpv_error(err, err_size, "out of memory for the scene");
    for (uint32_t i = 0; i < scene->draw_count; ++i) {
        const lpv_draw *d = &scene->draws[i];
        if ((uint64_t)d->first_index + d->index_count > scene->index_count)
            return lpv_error(err, err_size, "%s: draw %u indexes past the index buffer", scene->source, i);
        lpv_gpu_draw *g = &e->geo.draws[e->geo.draw_count++];
        *g = (lpv_gpu_draw){d->first_index, d->index_count - d->index_count % 3, d->material, 0.0f,
                            d->vertex_color != 0};
        g->size = draw_box(scene, d, g->box_min, g->box_max);
        const lpv_material *m = (d->material >= 0 && (uint32_t)d->material < scene->material_count)
                                    ? &scene->materials[d->material]
                                    : NULL;
        int emissive = m && (m->emission[0] > 0.0f || m->emission[1] > 0.0f || m->emission[2] > 0.0f);
        if (!emissive)
            e->occluder_triangles += d->index_count / 3;
    }
    /* points and lines: drawn by the camera alone (pass_camera.c), from
     * the index buffer's tail */
    e->geo.wire_draws = calloc(scene->wire_draw_count ? scene->wire_draw_count : 1, sizeof *e->geo.wire_draws);
    if (!e->geo.wire_draws)
        return lpv_error(err, err_size, "out of memory for the scene");
    for (uint32_t i = 0; i < scene->wire_draw_count; ++i) {
        const lpv_draw *d = &scene->wire_draws[i];
        if ((uint64_t)d->first_index + d->index_count > scene->wire_index_count)
            return lpv_error(err, err_size, "%s: point or line draw %u indexes past its index buffer", scene->source,
                             i);
        const uint32_t per = d->mode == LPV_DRAW_POINTS ? 1u : 2u;
        lpv_gpu_draw *g = &e->geo.wire_draws[e->geo.wire_draw_count++];
        *g = (lpv_gpu_draw){scene->index_count + d->first_index, d->index_count - d->index_count % per, d->material,
                            0.0f, d->vertex_color != 0};
        g->mode = d->mode == LPV_DRAW_POINTS ? LPV_DRAW_POINTS : LPV_DRAW_LINES;
    }
    for (uint32_t i = 0; i < scene->material_count; ++i) {
        const lpv_material *m = &scene->materials[i];
        lpv_gpu_material *g = &e->geo.materials[i];
        memcpy(g->base_color, m->base_color, sizeof g->base_color);
        memcpy(g->emission, m->emission, sizeof g->emission);
        g->roughness = m->roughness;
        g->metallic = m->metallic;
        g->texture = (m->base_color_texture >= 0 && (uint32_t)m->base_color_texture < scene->texture_count)
                         ? m->base_color_texture
                         : -1;
        g->alpha_cutoff = lpv_material_alpha_cutoff(m);
        g->blend = m->alpha_mode == LPV_ALPHA_BLEND;
        g->double_sided = m->double_sided;
        g->base_uv_set = m->base_color_uv.texcoord == 1;
        lpv_uv_transform_matrix(&m->base_color_uv, g->base_uv);
        /* a normal map must be linear data (a memset material's 0 is not one) */
        g->normal_texture = (m->normal_texture >= 0 && (uint32_t)m->normal_texture < scene->texture_count &&
                             scene->textures[m->normal_texture].linear)
                                ? m->normal_texture
                                : -1;
        g->normal_scale = m->normal_scale;
        g->normal_uv_set = m->normal_uv.texcoord == 1;
        lpv_uv_transform_matrix(&m->normal_uv, g->normal_uv);
        g->mr_texture = lpv_material_texture(scene, m->metallic_roughness_texture, 1);
        g->mr_uv_set = m->metallic_roughness_uv.texcoord == 1;
        lpv_uv_transform_matrix(&m->metallic_roughness_uv, g->mr_uv);
        g->emissive_texture = lpv_material_texture(scene, m->emissive_texture, 0);
        g->emissive_uv_set = m->emissive_uv.texcoord == 1;
        lpv_uv_transform_matrix(&m->emissive_uv, g->emissive_uv);
        g->unlit = m->unlit != 0;
        g->occlusion_texture = lpv_material_texture(scene, m->occlusion_texture, 1);
        g->occlusion_strength = m->occlusion_strength;
        g->occlusion_uv_set = m->occlusion_uv.texcoord == 1;
        lpv_uv_transform_matrix(&m->occlusion_uv, g->occlusion_uv);
    }
    e->geo.material_count = scene->material_count;
    e->geo.materials_plain = 1;
    e->geo.materials_occlusion = e->geo.materials_unlit = 0;
    for (uint32_t i = 0; i < e->geo.material_count; ++i) {
        const lpv_gpu_material *g = &e->geo.materials[i];
        if (g->texture >= 0 || g->normal_texture >= 0 || g->mr_texture >= 0 || g->emissive_texture >= 0 ||
            g->occlusion_texture >= 0 || g->alpha_cutoff > 0.0f || g->blend)
            e->geo.materials_plain = 0;
        e->geo.materials_occlusion |= g->occlusion_texture >= 0;
        e->geo.materials_unlit |= g->unlit;
    }
    e->geo.materials_unlit |= e->geo.wire_draw_count > 0; /* points and lines show unlit (LPV_GBUF_WIRE_W) */
    e->geo.blend_draws = 0;
    for (uint32_t i = 0; i < e->geo.draw_count; ++i) {
        const int k = e->geo.draws[i].material;
        e->geo.blend_draws += k >= 0 && (uint32_t)k < e->geo.material_count && e->geo.materials[k].blend && e->geo.draws[i].index_count;
    }
    if (upload_textures(e, scene, err, err_size) != 0)
        return -1;

    glGenVertexArrays(1, &e->geo.vao);
    glBindVertexArray(e->geo.vao);
    glGenBuffers(1, &e->geo.vbo);
    glBindBuffer(GL_ARRAY_BUFFER, e->geo.vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(scene->vertex_count * sizeof(lpv_vertex)), scene->vertices,
                 GL_STATIC_DRAW);
    glGenBuffers(1, &e->geo.ibo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, e->geo.ibo);
    /* the triangles' indices, then the wire draws' (their first_index moved past the triangles') */
    glBufferData(GL_ELEMENT_ARRAY_BUFFER,
                 (GLsizeiptr)(((size_t)scene->index_count + scene->wire_index_count) * sizeof(uint32_t)), NULL,
                 GL_STATIC_DRAW);
    glBufferSubData(GL_ELEMENT_ARRAY_BUFFER, 0, (GLsizeiptr)(scene->index_count * sizeof(uint32_t)), scene->indices);
    glBufferSubData(GL_ELEMENT_ARRAY_BUFFER, (GLintptr)(scene->index_count * sizeof(uint32_t)),
                    (GLsizeiptr)(scene->wire_index_count * sizeof(uint32_t)), scene->wire_indices);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(lpv_vertex), (void *)offsetof(lpv_vertex, position));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(lpv_vertex), (void *)offsetof(lpv_vertex, normal));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, sizeof(lpv_vertex), (void *)offsetof(lpv_vertex, uv));
    glEnableVertexAttribArray(3);
    glVertexAttribPointer(3, 2, GL_FLOAT, GL_FALSE, sizeof(lpv_vertex), (void *)offsetof(lpv_vertex, uv1));
    glEnableVertexAttribArray(4);
    glVertexAttribPointer(4, 4, GL_FLOAT, GL_FALSE, sizeof(lpv_vertex), (void *)offsetof(lpv_vertex, tangent));
    glEnableVertexAttribArray(5);
    glVertexAttribPointer(5, 4, GL_FLOAT, GL_FALSE, sizeof(lpv_vertex), (void *)offsetof(lpv_vertex, color));
    glBindVertexArray(0);

    /* before the lights: a light in a solid reach voxel is looked at closer
     * in the copy (lpv_reach_light), as on every later light change */
    if (lpv_scene_copy_geometry(&e->geometry, scene) != 0)
        return lpv_error(err, err_size, "%s: out of memory for the engine's copy of the geometry", scene->source);
    if (lpv_engine_reach_build(e, scene, err, err_size) != 0)
        return -1;
    set_lights(e, scene);
    if (lpv_medium_upload(&e->medium, scene, err, err_size) != 0)
        return -1;
    memcpy(e->scene_min, scene->bounds_min, sizeof e->scene_min);
    memcpy(e->scene_max, scene->bounds_max, sizeof e->scene_max);

    e->lookup_plane_count = lpv_scene_plane_normals(scene, e->lookup_planes, LPV_MAX_LOOKUP_PLANES);
    if (e->lookup_plane_count < 0) {
        e->lookup_plane_count = 0;
        return lpv_error(err, err_size, "%s: out of memory for the flat surfaces' normals", scene->source);
    }
    if (lpv_emitters_collect(scene, &e->emitters) != 0)
        return lpv_error(err, err_size, "%s: out of memory for the emissive triangles", scene->source);
    lpv_engine_update_area_samples(e);
    e->has_scene = 1; /* auto's choice reads the scene's facts */
    if (lpv_engine_resolve_technique(e, &e->settings, err, err_size) != 0 || lpv_engine_sample_scene(e, err, err_size))
        return -1;

    if (glGetError() != GL_NO_ERROR) {
        e->has_scene = 0;
        return lpv_error(err, err_size, "%s: GL error while uploading the scene", scene->source);
    }
    return lpv_engine_place_volume(e, err, err_size);
}

