/*
 * engine.c - the engine object: programs, scene upload, settings, the tick's
 * order of passes, and read-backs. The passes themselves are in pass_*.c.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "emissive.h"
#include "scene_surfels.h"
#include "error.h"
#include "engine_internal.h"
#include "memory_limits.h"
#include "shader.h"

GLuint lpv_engine_program(const char *first, const char *geom, const char *frag, const char *const *includes,
                          char *err, size_t err_size)
{
    /* The includes use the shared header's types, so it goes first; its
     * include guard makes the copy shader.c adds afterwards a no-op. */
    const char *shared = lpv_shader_text("lpv_shared.h");
    size_t len = strlen(shared) + 2;
    for (const char *const *i = includes; i && *i; ++i) {
        const char *t = lpv_shader_text(*i);
        if (!t) {
            lpv_error(err, err_size, "shader include %s is not embedded", *i);
            return 0;
        }
        len += strlen(t) + 64;
    }
    char *prelude = malloc(len);
    if (!prelude) {
        lpv_error(err, err_size, "out of memory building %s", first);
        return 0;
    }
    strcpy(prelude, shared);
    strcat(prelude, "\n");
    for (const char *const *i = includes; i && *i; ++i) {
        strcat(prelude, lpv_shader_text(*i));
        strcat(prelude, "\n");
    }
    GLuint p = frag ? lpv_program_graphics(first, geom, frag, prelude, err, err_size)
                    : lpv_program_compute(first, prelude, err, err_size);
    free(prelude);
    return p;
}

static const char *const INC_GRID[] = {"grid.glsl", NULL};
static const char *const INC_PROPAGATE[] = {"grid.glsl", "flux_limit.glsl", "medium.glsl", NULL};
static const char *const INC_MATERIAL[] = {"material.glsl", NULL};
static const char *const INC_RSM[] = {"material.glsl", "lights.glsl", NULL};
static const char *const INC_SHADE[] = {"grid.glsl", "lights.glsl", "shadow.glsl", "lookup.glsl", NULL};
static const char *const INC_MEDIA[] = {"grid.glsl", "lights.glsl", "shadow.glsl", "lookup.glsl", "medium.glsl",
                                        NULL};
static const char *const INC_LOOKUP[] = {"grid.glsl", "lookup.glsl", NULL};

lpv_engine *lpv_engine_create(char *err, size_t err_size)
{
    lpv_engine *e = calloc(1, sizeof *e);
    if (!e) {
        lpv_error(err, err_size, "out of memory");
        return NULL;
    }
    struct {
        GLuint *prog;
        const char *a, *b;
        const char *const *inc;
    } progs[] = {
        {&e->prog_rsm, "scene.vert", "rsm.frag", INC_RSM},
        {&e->prog_vpl_extract, "vpl_extract.comp", NULL, NULL},
        {&e->prog_inject_vpl, "inject_vpl.vert", "inject_vpl.frag", INC_GRID},
        {&e->prog_inject_gv, "inject_gv.vert", "inject_gv.frag", INC_GRID},
        {&e->prog_pack, "lpv_pack.comp", NULL, INC_PROPAGATE},
        {&e->prog_gv_merge, "gv_merge.comp", NULL, INC_GRID},
        {&e->prog_transmit, "transmit.comp", NULL, INC_GRID},
        {&e->prog_propagate, "propagate.comp", NULL, INC_PROPAGATE},
        {&e->prog_handoff, "lpv_handoff.comp", NULL, INC_PROPAGATE},
        {&e->prog_gbuffer, "scene.vert", "gbuffer.frag", INC_MATERIAL},
        {&e->prog_camera_surfels, "camera_surfels.comp", NULL, NULL},
        {&e->prog_shade, "fullscreen.vert", "shade.frag", INC_SHADE},
        {&e->prog_query, "query.comp", NULL, INC_LOOKUP},
        {&e->prog_glossy, "fullscreen.vert", "glossy.frag", INC_LOOKUP},
        {&e->prog_media, "fullscreen.vert", "media.frag", INC_MEDIA},
        {&e->prog_shadow, "scene.vert", "shadow_depth.frag", INC_MATERIAL},
    };
    for (size_t i = 0; i < sizeof progs / sizeof progs[0]; ++i) {
        *progs[i].prog = lpv_engine_program(progs[i].a, NULL, progs[i].b, progs[i].inc, err, err_size);
        if (!*progs[i].prog) {
            lpv_engine_destroy(e);
            return NULL;
        }
    }
    GLint max_block = 0;
    glGetIntegerv(GL_MAX_UNIFORM_BLOCK_SIZE, &max_block);
    if ((size_t)max_block < sizeof(struct LpvLightBlock) || (size_t)max_block < sizeof(struct LpvShadowBlock)) {
        lpv_error(err, err_size, "the light and shadow blocks need %zu and %zu bytes of uniform block, GL allows %d",
                  sizeof(struct LpvLightBlock), sizeof(struct LpvShadowBlock), max_block);
        lpv_engine_destroy(e);
        return NULL;
    }
    glGenVertexArrays(1, &e->empty_vao);
    glGenBuffers(1, &e->grid_ubo);
    glGenBuffers(1, &e->light_ubo);
    glGenBuffers(1, &e->view_ubo);
    glGenBuffers(1, &e->shadow_ubo);
    glBindBuffer(GL_UNIFORM_BUFFER, e->shadow_ubo);
    glBufferData(GL_UNIFORM_BUFFER, sizeof(struct LpvShadowBlock), NULL, GL_DYNAMIC_DRAW);
    glBindBuffer(GL_UNIFORM_BUFFER, e->light_ubo);
    glBufferData(GL_UNIFORM_BUFFER, sizeof(struct LpvLightBlock), NULL, GL_DYNAMIC_DRAW);
    glBindBuffer(GL_UNIFORM_BUFFER, e->view_ubo);
    glBufferData(GL_UNIFORM_BUFFER, sizeof(struct LpvViewBlock), NULL, GL_DYNAMIC_DRAW);
    glBindBuffer(GL_UNIFORM_BUFFER, e->grid_ubo);
    glBufferData(GL_UNIFORM_BUFFER, sizeof(struct LpvGridParams), NULL, GL_DYNAMIC_DRAW);
    lpv_timer_init(&e->timer);
    lpv_settings_resolve(&e->settings);
    lpv_memory_limits_query(&e->mem_limits);
    return e;
}

static void delete_buffer(GLuint *b)
{
    if (*b)
        glDeleteBuffers(1, b);
    *b = 0;
}

static void delete_texture(GLuint *t)
{
    if (*t)
        glDeleteTextures(1, t);
    *t = 0;
}

static void delete_framebuffer(GLuint *f)
{
    if (*f)
        glDeleteFramebuffers(1, f);
    *f = 0;
}

static void free_scene(lpv_engine *e)
{
    if (e->vao)
        glDeleteVertexArrays(1, &e->vao);
    e->vao = 0;
    delete_buffer(&e->vbo);
    delete_buffer(&e->ibo);
    delete_buffer(&e->emissive_vpls);
    delete_buffer(&e->scene_surfels);
    e->scene_surfel_count = 0;
    if (e->texture_count)
        glDeleteTextures((GLsizei)e->texture_count, e->textures);
    free(e->textures);
    free(e->draws);
    free(e->materials);
    e->textures = NULL;
    e->draws = NULL;
    e->materials = NULL;
    e->texture_count = e->draw_count = e->material_count = 0;
    e->light_count = 0;
    e->emissive_vpl_count = 0;
    lpv_emitters_free(&e->emitters);
    e->area_sample_count = 0;
    e->occluder_triangles = 0;
    e->has_scene = 0;
}

static void free_rsm(lpv_engine *e)
{
    delete_texture(&e->rsm_position);
    delete_texture(&e->rsm_normal);
    delete_texture(&e->rsm_flux);
    delete_texture(&e->rsm_albedo);
    delete_texture(&e->rsm_depth);
    delete_framebuffer(&e->rsm_fbo);
    delete_buffer(&e->vpls);
    delete_buffer(&e->surfels);
    e->rsm_alloc_size = e->rsm_alloc_faces = 0;
}

static void free_grids(lpv_engine *e)
{
    lpv_atlas_destroy(&e->lpv_atlas);
    lpv_atlas_destroy(&e->gv_atlas);
    delete_buffer(&e->lpv_injected);
    delete_buffer(&e->lpv_ping);
    delete_buffer(&e->lpv_pong);
    delete_buffer(&e->lpv_acc);
    delete_buffer(&e->gv_total);
    delete_buffer(&e->transmit);
    delete_buffer(&e->reflect);
    delete_buffer(&e->sigma[0]);
    delete_buffer(&e->sigma[1]);
    GLuint *views[] = {&e->tbo_injected, &e->tbo_ping, &e->tbo_pong, &e->tbo_sigma[0], &e->tbo_sigma[1],
                       &e->tbo_acc, &e->tbo_transmit, &e->tbo_reflect};
    for (size_t i = 0; i < sizeof views / sizeof views[0]; ++i)
        delete_texture(views[i]);
    e->grid_alloc_cells = 0;
    e->grid_alloc_cascades = 0;
    e->ticked = 0;
    e->computed = 0;
}

static void free_camera(lpv_engine *e)
{
    for (int i = 0; i < 4; ++i)
        delete_texture(&e->gbuf_tex[i]);
    delete_texture(&e->gbuf_depth);
    delete_texture(&e->frame_tex);
    delete_framebuffer(&e->gbuf_fbo);
    delete_framebuffer(&e->frame_fbo);
    delete_buffer(&e->camera_surfels);
    e->gbuf_w = e->gbuf_h = 0;
}

void lpv_engine_destroy(lpv_engine *e)
{
    if (!e)
        return;
    free_scene(e);
    free_rsm(e);
    free_grids(e);
    free_camera(e);
    lpv_pass_shadow_free(e);
    delete_texture(&e->medium_density);
    delete_buffer(&e->query_in);
    delete_buffer(&e->query_out);
    GLuint *progs[] = {&e->prog_rsm, &e->prog_vpl_extract, &e->prog_inject_vpl, &e->prog_inject_gv,
                       &e->prog_pack, &e->prog_gv_merge, &e->prog_transmit, &e->prog_propagate,
                       &e->prog_gbuffer, &e->prog_camera_surfels, &e->prog_shade, &e->prog_query,
                       &e->prog_glossy, &e->prog_media, &e->prog_handoff, &e->prog_shadow};
    for (size_t i = 0; i < sizeof progs / sizeof progs[0]; ++i)
        if (*progs[i])
            glDeleteProgram(*progs[i]);
    if (e->empty_vao)
        glDeleteVertexArrays(1, &e->empty_vao);
    delete_buffer(&e->grid_ubo);
    delete_buffer(&e->light_ubo);
    delete_buffer(&e->view_ubo);
    delete_buffer(&e->shadow_ubo);
    lpv_timer_destroy(&e->timer);
    free(e);
}

static GLuint new_ssbo(size_t bytes)
{
    GLuint b;
    glGenBuffers(1, &b);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, b);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(bytes ? bytes : 16), NULL, GL_DYNAMIC_COPY);
    return b;
}

/* A buffer texture of the given format over buffer b. */
static GLuint buffer_view(GLuint b, GLenum format)
{
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_BUFFER, t);
    glTexBuffer(GL_TEXTURE_BUFFER, format, b);
    glBindTexture(GL_TEXTURE_BUFFER, 0);
    return t;
}

/* Uploads the placement of the cascades and (re)sizes their buffers when the
 * dims or the cascade count changed. */
static int apply_cascades(lpv_engine *e, const lpv_cascade_set *set, char *err, size_t err_size)
{
    const lpv_grid *g = &set->grid[0];
    e->cascades = *set;
    e->grid = *g;
    e->bins = e->settings.normal_bins == LPV_SWITCH_ON ? LPV_NORMAL_BINS : 1;
    struct LpvGridParams params = {
        .dims = {(float)g->dims[0], (float)g->dims[1], (float)g->dims[2], (float)lpv_grid_cell_count(g)},
        .info = {(float)set->count, set->count > 1 && !set->handoff ? 1.0f : 0.0f, (float)e->bins,
                 e->settings.central_transport == LPV_SWITCH_ON ? (float)LPV_TRANSPORT_CENTRAL
                                                                : (float)LPV_TRANSPORT_PAPER},
    };
    params.mode[0] = set->handoff ? 1.0f : 0.0f;
    for (int k = 0; k < set->count; ++k) {
        for (int i = 0; i < 3; ++i)
            params.cascade[k][i] = set->origin_cells[k][i];
        params.cascade[k][3] = set->grid[k].cell_size;
    }
    glBindBuffer(GL_UNIFORM_BUFFER, e->grid_ubo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof params, &params);
    if (e->grid_alloc_cells && memcmp(g->dims, e->grid_alloc_dims, sizeof g->dims) == 0 &&
        e->grid_alloc_cascades == set->count && e->grid_alloc_bins == e->bins)
        return 0;

    lpv_memory_need need;
    lpv_engine_memory_need(e, set, &need);
    if (lpv_engine_memory_check(e, &need, err, err_size) != 0)
        return -1;
    free_grids(e);
    const size_t K = (size_t)set->count;
    size_t cells = lpv_grid_cell_count(g) * K, gv = lpv_grid_gv_count(g) * K;
    size_t vcells = cells * (size_t)e->bins; /* LPV volumes: cascades x bins */
    int lpv_dims[3] = {g->dims[0], g->dims[1], g->dims[2] * set->count * e->bins};
    int gv_dims[3] = {g->dims[0] + 1, g->dims[1] + 1, (g->dims[2] + 1) * set->count};
    if (lpv_atlas_create(&e->lpv_atlas, lpv_dims, 3, err, err_size) != 0 ||
        lpv_atlas_create(&e->gv_atlas, gv_dims, 2, err, err_size) != 0)
        return -1;
    e->lpv_injected = new_ssbo(vcells * sizeof(lpv_cell));
    e->lpv_ping = new_ssbo(vcells * sizeof(lpv_cell));
    e->lpv_pong = new_ssbo(vcells * sizeof(lpv_cell));
    e->lpv_acc = new_ssbo(vcells * sizeof(lpv_cell));
    e->gv_total = new_ssbo(gv * sizeof(lpv_gv_point));
    e->transmit = new_ssbo(cells * LPV_DIR_COUNT * sizeof(float));
    e->reflect = new_ssbo(cells * LPV_DIR_COUNT * 4 * sizeof(float));
    e->sigma[0] = new_ssbo(vcells * 4 * sizeof(float));
    e->sigma[1] = new_ssbo(vcells * 4 * sizeof(float));
    e->tbo_injected = buffer_view(e->lpv_injected, GL_RGBA32F);
    e->tbo_ping = buffer_view(e->lpv_ping, GL_RGBA32F);
    e->tbo_pong = buffer_view(e->lpv_pong, GL_RGBA32F);
    e->tbo_sigma[0] = buffer_view(e->sigma[0], GL_RGBA32F);
    e->tbo_sigma[1] = buffer_view(e->sigma[1], GL_RGBA32F);
    e->tbo_acc = buffer_view(e->lpv_acc, GL_RGBA32F);
    e->tbo_transmit = buffer_view(e->transmit, GL_R32F);
    e->tbo_reflect = buffer_view(e->reflect, GL_RGBA32F);
    e->grid_alloc_cells = cells;
    memcpy(e->grid_alloc_dims, g->dims, sizeof g->dims);
    e->grid_alloc_cascades = set->count;
    e->grid_alloc_bins = e->bins;
    if (glGetError() != GL_NO_ERROR)
        return lpv_error(err, err_size, "could not allocate %d cascades of %dx%dx%d cells", set->count, g->dims[0],
                         g->dims[1], g->dims[2]);
    return 0;
}

/* Where the cascades of `count` go now (settings, scene, camera). */
static int place_cascades(const lpv_engine *e, int count, lpv_cascade_set *out, char *err, size_t err_size)
{
    const float *eye = e->has_view ? e->view.eye : NULL, *fwd = e->has_view ? e->view.forward : NULL;
    float f[3];
    if (fwd) {
        float len = sqrtf(fwd[0] * fwd[0] + fwd[1] * fwd[1] + fwd[2] * fwd[2]);
        for (int i = 0; i < 3; ++i)
            f[i] = len > 0.0f ? fwd[i] / len : 0.0f;
        fwd = f;
    }
    if (lpv_cascades_place(&e->settings, count, e->scene_min, e->scene_max, eye, fwd, out) != 0)
        return lpv_error(err, err_size, "%d cascades of %dx%dx%d cells cannot be placed", count,
                         e->settings.grid_dims[0], e->settings.grid_dims[1], e->settings.grid_dims[2]);
    return 0;
}

static void gather_facts(const lpv_engine *e, lpv_plan_facts *f);

/* Places the grid for the current settings and scene without a tick, so
 * lpv_engine_grid() answers right after set_scene/set_settings. */
static int place_grid(lpv_engine *e, char *err, size_t err_size)
{
    lpv_plan_facts f;
    gather_facts(e, &f);
    char why[LPV_PLAN_REASON_MAX];
    lpv_cascade_set set;
    if (place_cascades(e, lpv_plan_cascades(&e->settings, &f, why, sizeof why), &set, err, err_size) != 0)
        return -1;
    return apply_cascades(e, &set, err, err_size);
}

/* The emitters as area light samples under the current settings (0 when
 * area lights are off or nothing emits). */
static void update_area_samples(lpv_engine *e)
{
    e->area_sample_count = 0;
    if (e->settings.area_lights == LPV_SWITCH_ON && e->emitters.count)
        e->area_sample_count =
            lpv_area_lights_sample(&e->emitters, (size_t)e->settings.area_light_samples, e->area_samples);
}

int lpv_engine_set_settings(lpv_engine *e, const lpv_settings *settings, char *err, size_t err_size)
{
    lpv_settings s = *settings;
    lpv_settings_resolve(&s);
    if (lpv_settings_validate(&s, err, err_size) != 0)
        return -1;
    if (memcmp(&s, &e->settings, sizeof s) == 0)
        return 0;
    e->settings = s;
    e->settings_dirty = 1;
    e->shadow_valid = 0;
    e->gbuf_stale = 1;
    e->ticked = 0;
    update_area_samples(e);
    if (e->has_scene)
        return place_grid(e, err, err_size);
    return 0;
}

static int upload_textures(lpv_engine *e, const lpv_scene *scene, char *err, size_t err_size)
{
    if (!scene->texture_count)
        return 0;
    e->textures = calloc(scene->texture_count, sizeof(GLuint));
    if (!e->textures)
        return lpv_error(err, err_size, "out of memory for textures");
    e->texture_count = scene->texture_count;
    glGenTextures((GLsizei)scene->texture_count, e->textures);
    for (uint32_t i = 0; i < scene->texture_count; ++i) {
        const lpv_texture *t = &scene->textures[i];
        glBindTexture(GL_TEXTURE_2D, e->textures[i]);
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
static float draw_size(const lpv_scene *scene, const lpv_draw *d)
{
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
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

/* FNV-1a over bytes, chained from h. */
static uint64_t hash_bytes(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; ++i)
        h = (h ^ b[i]) * 1099511628211ull;
    return h;
}

/* Geometry and materials, not lights: a scene update that only moves lights
 * is reported as such by the planner. */
static uint64_t geometry_signature(const lpv_scene *s)
{
    uint64_t h = 1469598103934665603ull;
    h = hash_bytes(h, s->vertices, (size_t)s->vertex_count * sizeof *s->vertices);
    h = hash_bytes(h, s->indices, (size_t)s->index_count * sizeof *s->indices);
    h = hash_bytes(h, s->draws, (size_t)s->draw_count * sizeof *s->draws);
    h = hash_bytes(h, s->materials, (size_t)s->material_count * sizeof *s->materials);
    h = hash_bytes(h, &s->medium, sizeof s->medium);
    return h;
}

int lpv_engine_set_scene(lpv_engine *e, const lpv_scene *scene, char *err, size_t err_size)
{
    uint64_t sig = geometry_signature(scene);
    if (e->has_scene && sig == e->geometry_sig)
        e->lights_dirty = 1;
    else
        e->scene_dirty = 1;
    e->geometry_sig = sig;
    e->gbuf_stale = 1;
    e->shadow_valid = 0;
    free_scene(e);
    e->ticked = 0;
    e->draws = calloc(scene->draw_count ? scene->draw_count : 1, sizeof *e->draws);
    e->materials = calloc(scene->material_count ? scene->material_count : 1, sizeof *e->materials);
    if (!e->draws || !e->materials)
        return lpv_error(err, err_size, "out of memory for the scene");
    for (uint32_t i = 0; i < scene->draw_count; ++i) {
        const lpv_draw *d = &scene->draws[i];
        if ((uint64_t)d->first_index + d->index_count > scene->index_count)
            return lpv_error(err, err_size, "%s: draw %u indexes past the index buffer", scene->source, i);
        e->draws[e->draw_count++] =
            (lpv_gpu_draw){d->first_index, d->index_count - d->index_count % 3, d->material, draw_size(scene, d)};
        const lpv_material *m = (d->material >= 0 && (uint32_t)d->material < scene->material_count)
                                    ? &scene->materials[d->material]
                                    : NULL;
        int emissive = m && (m->emission[0] > 0.0f || m->emission[1] > 0.0f || m->emission[2] > 0.0f);
        if (!emissive)
            e->occluder_triangles += d->index_count / 3;
    }
    for (uint32_t i = 0; i < scene->material_count; ++i) {
        const lpv_material *m = &scene->materials[i];
        lpv_gpu_material *g = &e->materials[i];
        memcpy(g->base_color, m->base_color, sizeof g->base_color);
        memcpy(g->emission, m->emission, sizeof g->emission);
        g->roughness = m->roughness;
        g->metallic = m->metallic;
        g->texture = (m->base_color_texture >= 0 && (uint32_t)m->base_color_texture < scene->texture_count)
                         ? m->base_color_texture
                         : -1;
        g->alpha_cutoff = lpv_material_alpha_cutoff(m);
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
    }
    e->material_count = scene->material_count;
    if (upload_textures(e, scene, err, err_size) != 0)
        return -1;

    glGenVertexArrays(1, &e->vao);
    glBindVertexArray(e->vao);
    glGenBuffers(1, &e->vbo);
    glBindBuffer(GL_ARRAY_BUFFER, e->vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(scene->vertex_count * sizeof(lpv_vertex)), scene->vertices,
                 GL_STATIC_DRAW);
    glGenBuffers(1, &e->ibo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, e->ibo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(scene->index_count * sizeof(uint32_t)), scene->indices,
                 GL_STATIC_DRAW);
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
    glBindVertexArray(0);

    e->light_count = 0;
    for (uint32_t i = 0; i < scene->light_count && e->light_count < LPV_MAX_LIGHTS; ++i)
        e->lights[e->light_count++] = scene->lights[i];
    e->has_medium = scene->medium.present;
    if (lpv_medium_upload(e, scene, err, err_size) != 0)
        return -1;
    memcpy(e->scene_min, scene->bounds_min, sizeof e->scene_min);
    memcpy(e->scene_max, scene->bounds_max, sizeof e->scene_max);

    size_t target = (size_t)e->settings.emissive_vpls;
    lpv_vpl *vpls = target ? calloc(target * 2 + 1024, sizeof *vpls) : NULL;
    size_t n = vpls ? lpv_emissive_sample(scene, target, vpls, target * 2 + 1024) : 0;
    e->emissive_vpls = new_ssbo(n * sizeof(lpv_vpl));
    if (n)
        glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(n * sizeof(lpv_vpl)), vpls);
    e->emissive_vpl_count = n;
    free(vpls);
    if (lpv_emitters_collect(scene, &e->emitters) != 0)
        return lpv_error(err, err_size, "%s: out of memory for the emissive triangles", scene->source);
    update_area_samples(e);

    size_t want = e->settings.scene_surfels == LPV_SWITCH_ON ? (size_t)e->settings.scene_surfel_count : 0;
    lpv_surfel *surfels = want ? calloc(want + 1, sizeof *surfels) : NULL;
    if (want && !surfels)
        return lpv_error(err, err_size, "out of memory for %zu scene surfels", want);
    size_t ns = surfels ? lpv_scene_surfels(scene, want, surfels, want + 1) : 0;
    e->scene_surfels = new_ssbo(ns * sizeof(lpv_surfel));
    if (ns)
        glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(ns * sizeof(lpv_surfel)), surfels);
    e->scene_surfel_count = ns;
    free(surfels);

    if (glGetError() != GL_NO_ERROR)
        return lpv_error(err, err_size, "%s: GL error while uploading the scene", scene->source);
    e->has_scene = 1;
    return place_grid(e, err, err_size);
}

int lpv_engine_set_view(lpv_engine *e, const lpv_view *view, char *err, size_t err_size)
{
    if (!view) {
        e->has_view = 0;
        e->gbuf_stale = 1;
        return 0;
    }
    if (view->width < 1 || view->height < 1 || view->width > 16384 || view->height > 16384)
        return lpv_error(err, err_size, "image size %dx%d outside 1..16384", view->width, view->height);
    if (e->has_scene) { /* the image's storage must fit next to the rest */
        lpv_memory_need need;
        lpv_engine_memory_need(e, NULL, &need);
        need.image_w = view->width;
        need.image_h = view->height;
        if (lpv_engine_memory_check(e, &need, err, err_size) != 0)
            return -1;
    }
    if (!e->has_view || memcmp(&e->view, view, sizeof *view) != 0)
        e->gbuf_stale = 1;
    e->view = *view;
    e->has_view = 1;
    return 0;
}

void lpv_engine_draw_scene(lpv_engine *e, GLuint prog, int cull_single_sided)
{
    GLint loc_color = glGetUniformLocation(prog, "u_base_color");
    GLint loc_has_tex = glGetUniformLocation(prog, "u_has_texture");
    GLint loc_emission = glGetUniformLocation(prog, "u_emission");
    GLint loc_roughness = glGetUniformLocation(prog, "u_roughness");
    GLint loc_metallic = glGetUniformLocation(prog, "u_metallic");
    GLint loc_size = glGetUniformLocation(prog, "u_object_size");
    GLint loc_cutoff = glGetUniformLocation(prog, "u_alpha_cutoff");
    GLint loc_base_set = glGetUniformLocation(prog, "u_base_uv_set");
    GLint loc_base_row0 = glGetUniformLocation(prog, "u_base_uv_row0");
    GLint loc_base_row1 = glGetUniformLocation(prog, "u_base_uv_row1");
    GLint loc_has_normal = glGetUniformLocation(prog, "u_has_normal_texture");
    GLint loc_normal_scale = glGetUniformLocation(prog, "u_normal_scale");
    GLint loc_normal_set = glGetUniformLocation(prog, "u_normal_uv_set");
    GLint loc_normal_row0 = glGetUniformLocation(prog, "u_normal_uv_row0");
    GLint loc_normal_row1 = glGetUniformLocation(prog, "u_normal_uv_row1");
    glBindVertexArray(e->vao);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW); /* glTF's front faces; the loader rewinds mirrored nodes */
    for (uint32_t i = 0; i < e->draw_count; ++i) {
        const lpv_gpu_draw *d = &e->draws[i];
        static const lpv_gpu_material fallback = {
            .base_color = {1, 1, 1, 1}, .roughness = 1.0f, .texture = -1, .double_sided = 1,
            .base_uv = {1, 0, 0, 0, 1, 0}, .normal_texture = -1, .normal_uv = {1, 0, 0, 0, 1, 0}};
        const lpv_gpu_material *m =
            (d->material >= 0 && (uint32_t)d->material < e->material_count) ? &e->materials[d->material] : &fallback;
        glUniform4fv(loc_color, 1, m->base_color);
        glUniform3fv(loc_emission, 1, m->emission);
        glUniform1f(loc_roughness, m->roughness);
        glUniform1f(loc_metallic, m->metallic);
        glUniform1f(loc_size, d->size);
        glUniform1f(loc_cutoff, m->alpha_cutoff);
        glUniform1i(loc_has_tex, m->texture >= 0);
        glUniform1i(loc_base_set, m->base_uv_set);
        glUniform3fv(loc_base_row0, 1, &m->base_uv[0]);
        glUniform3fv(loc_base_row1, 1, &m->base_uv[3]);
        glUniform1i(loc_has_normal, m->normal_texture >= 0);
        glUniform1f(loc_normal_scale, m->normal_scale);
        glUniform1i(loc_normal_set, m->normal_uv_set);
        glUniform3fv(loc_normal_row0, 1, &m->normal_uv[0]);
        glUniform3fv(loc_normal_row1, 1, &m->normal_uv[3]);
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D, m->texture >= 0 ? e->textures[m->texture] : 0);
        glActiveTexture(GL_TEXTURE1);
        glBindTexture(GL_TEXTURE_2D, m->normal_texture >= 0 ? e->textures[m->normal_texture] : 0);
        glActiveTexture(GL_TEXTURE0);
        if (cull_single_sided && !m->double_sided)
            glEnable(GL_CULL_FACE);
        else
            glDisable(GL_CULL_FACE);
        if (d->index_count)
            glDrawElements(GL_TRIANGLES, (GLsizei)d->index_count, GL_UNSIGNED_INT,
                           (void *)(uintptr_t)(d->first_index * sizeof(uint32_t)));
        lpv_timer_count(&e->timer, 1);
    }
    glDisable(GL_CULL_FACE);
    glBindVertexArray(0);
}

static void record_stats(lpv_engine *e)
{
    lpv_engine_stats *s = &e->stats;
    memset(s, 0, sizeof *s);
    lpv_timer_collect(&e->timer);
    int n = e->timer.stage_count;
    for (int i = 0; i < n && i < LPV_STAGE_MAX; ++i) {
        const lpv_timer_stage *st = &e->timer.stages[i];
        snprintf(s->stages[i].name, sizeof s->stages[i].name, "%s", st->name);
        s->stages[i].gpu_ms = st->gpu_ms;
        s->stages[i].cpu_ms = st->cpu_ms;
        s->stages[i].calls = st->count;
        s->stage_count = i + 1;
    }
    s->lights = (unsigned)e->light_block.counts[2];
    s->area_lights = (unsigned)(e->light_block.counts[0] - e->light_block.counts[2]);
    s->rsm_faces = (unsigned)e->face_count;
    s->rsm_size = (unsigned)e->settings.rsm_size;
    s->vpls_rsm = e->rsm_texels;
    s->vpls_emissive = e->plan.pass[LPV_PASS_EMISSIVE].run ? e->emissive_vpl_count : 0;
    const int gv = e->plan.pass[LPV_PASS_GV].run;
    s->surfels_rsm = 0;
    for (size_t b = 0, first, count; gv && (lpv_engine_gv_buffer_range(e, b, &first, &count), count > 0); ++b)
        s->surfels_rsm += count;
    s->surfels_camera = (gv && e->plan.pass[LPV_PASS_GBUFFER].run) ? (size_t)e->gbuf_w * e->gbuf_h : 0;
    s->cascades = e->cascades.count;
    s->cells = lpv_engine_all_cells(e);
    s->iterations = e->settings.iterations;
    s->cell_steps =
        e->plan.pass[LPV_PASS_PROPAGATE].run ? (double)lpv_engine_volume_cells(e) * e->settings.iterations : 0.0;
    s->occlusion = gv;
}

/* Draws using a material rougher than nothing but below the glossy threshold. */
static size_t glossy_draws(const lpv_engine *e)
{
    size_t n = 0;
    for (uint32_t i = 0; i < e->draw_count; ++i) {
        int m = e->draws[i].material;
        if (m >= 0 && (uint32_t)m < e->material_count && e->materials[m].roughness < e->settings.glossy_roughness)
            ++n;
    }
    return n;
}

/* The planner's facts about the scene, the settings and what changed. */
static void gather_facts(const lpv_engine *e, lpv_plan_facts *f)
{
    memset(f, 0, sizeof *f);
    f->lights = e->light_count;
    f->emissive_vpls = e->emissive_vpl_count;
    f->emissive_surfaces = e->emitters.surfaces;
    f->area_light_samples = e->area_sample_count;
    f->occluder_triangles = e->occluder_triangles;
    f->glossy_draws = glossy_draws(e);
    f->has_medium = e->has_medium || e->settings.fog_sigma_s > 0.0f || e->settings.fog_sigma_a > 0.0f;
    f->has_view = e->has_view;
    f->camera_inside = e->has_view && lpv_point_in_bounds(e->view.eye, e->scene_min, e->scene_max);
    f->scene_extent = fmaxf(e->scene_max[0] - e->scene_min[0],
                            fmaxf(e->scene_max[1] - e->scene_min[1], e->scene_max[2] - e->scene_min[2]));
    f->scene_shortest = fminf(e->scene_max[0] - e->scene_min[0],
                              fminf(e->scene_max[1] - e->scene_min[1], e->scene_max[2] - e->scene_min[2]));
    f->bounds_given = lpv_settings_bounds_given(&e->settings);
    f->first_tick = !e->computed;
    f->scene_changed = e->scene_dirty;
    f->lights_changed = e->lights_dirty;
    f->settings_changed = e->settings_dirty;
    f->forced = e->forced;
    if (e->has_view != e->computed_has_view) {
        f->camera_move_cells = INFINITY;
    } else if (e->has_view) {
        float d2 = 0.0f;
        for (int i = 0; i < 3; ++i)
            d2 += (e->view.eye[i] - e->computed_eye[i]) * (e->view.eye[i] - e->computed_eye[i]);
        f->camera_move_cells = sqrtf(d2) / e->grid.cell_size;
    }
}

/* Zeroes the injected grid and the accumulation (nothing to inject). */
static void clear_volume(lpv_engine *e)
{
    GLuint bufs[] = {e->lpv_injected, e->lpv_acc};
    for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; ++i) {
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, bufs[i]);
        glClearBufferData(GL_SHADER_STORAGE_BUFFER, GL_RGBA32F, GL_RGBA, GL_FLOAT, NULL);
    }
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}

void lpv_engine_invalidate(lpv_engine *e)
{
    e->forced = 1;
    e->shadow_valid = 0;
}

int lpv_engine_tick(lpv_engine *e, char *err, size_t err_size)
{
    if (!e->has_scene)
        return lpv_error(err, err_size, "no scene loaded");
    lpv_plan_facts facts;
    gather_facts(e, &facts);
    char why[LPV_PLAN_REASON_MAX];
    lpv_cascade_set set;
    if (place_cascades(e, lpv_plan_cascades(&e->settings, &facts, why, sizeof why), &set, err, err_size) != 0)
        return -1;
    facts.placement_changed = e->computed && !lpv_cascades_equal(&set, &e->cascades);
    lpv_plan_make(&e->settings, &facts, &e->plan);
    const lpv_plan *p = &e->plan;
    if (!p->recompute) {
        /* The cached volume stands: no pass runs, no stage is recorded. */
        lpv_timer_collect(&e->timer);
        e->stats.stage_count = 0;
        e->ticked = 1;
        return 0;
    }
    if (apply_cascades(e, &set, err, err_size) != 0)
        return -1;
    if (lpv_pass_rsm_prepare(e, err, err_size) != 0)
        return -1;
    if (p->pass[LPV_PASS_RSM].run)
        lpv_pass_rsm_run(e);
    if (p->pass[LPV_PASS_INJECT].run)
        lpv_pass_inject_run(e, p->pass[LPV_PASS_RSM].run, p->pass[LPV_PASS_EMISSIVE].run);
    else
        clear_volume(e);
    if (p->pass[LPV_PASS_GBUFFER].run) {
        if (lpv_pass_gbuffer_run(e, err, err_size) != 0)
            return -1;
        e->gbuf_stale = 0;
    }
    if (p->pass[LPV_PASS_GV].run)
        lpv_pass_gv_run(e, p->pass[LPV_PASS_BOUNCE].run, p->pass[LPV_PASS_GBUFFER].run);
    if (p->pass[LPV_PASS_PROPAGATE].run)
        lpv_pass_propagate_run(e, p->pass[LPV_PASS_GV].run, p->pass[LPV_PASS_BOUNCE].run);
    GLenum gl_err = glGetError();
    if (gl_err != GL_NO_ERROR)
        return lpv_error(err, err_size, "GL error 0x%04x during the tick", gl_err);
    e->ticked = 1;
    e->computed = 1;
    e->scene_dirty = e->lights_dirty = e->settings_dirty = e->forced = 0;
    e->computed_has_view = e->has_view;
    if (e->has_view)
        memcpy(e->computed_eye, e->view.eye, sizeof e->computed_eye);
    record_stats(e);
    return 0;
}

int lpv_engine_render(lpv_engine *e, lpv_frame_terms terms, float *rgba, char *err, size_t err_size)
{
    if (!e->ticked)
        return lpv_error(err, err_size, "render before a tick");
    if (!e->has_view)
        return lpv_error(err, err_size, "render needs a view (camera)");
    if (e->gbuf_stale) { /* the tick did not need the camera's G-buffer, or the camera moved since */
        if (lpv_pass_gbuffer_run(e, err, err_size) != 0)
            return -1;
        e->gbuf_stale = 0;
    }
    /* Direct light needs the shadow maps (media's in-scattering too, which
     * only a full frame has); they are redrawn only when what they show changed. */
    if (terms != LPV_TERMS_INDIRECT_ONLY && lpv_pass_shadow_update(e, err, err_size) != 0)
        return -1;
    lpv_pass_shade_run(e, terms);
    if (e->plan.pass[LPV_PASS_GLOSSY].run && terms != LPV_TERMS_DIRECT_ONLY)
        lpv_pass_glossy_run(e);
    if (e->plan.pass[LPV_PASS_MEDIA].run && terms == LPV_TERMS_FULL)
        lpv_pass_media_run(e);
    const int w = e->gbuf_w, h = e->gbuf_h;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, e->frame_fbo);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, rgba);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    /* GL rows run bottom-up; files and callers want the top row first. */
    size_t row = (size_t)w * 4;
    for (int y = 0; y < h / 2; ++y) {
        float *a = rgba + (size_t)y * row, *b = rgba + (size_t)(h - 1 - y) * row;
        for (size_t i = 0; i < row; ++i) {
            float t = a[i];
            a[i] = b[i];
            b[i] = t;
        }
    }
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

int lpv_engine_irradiance(lpv_engine *e, const float *points, const float *normals, size_t n, float *rgb, char *err,
                          size_t err_size)
{
    if (!e->ticked)
        return lpv_error(err, err_size, "irradiance query before a tick");
    if (n == 0)
        return 0;
    if (n > (size_t)1 << 26)
        return lpv_error(err, err_size, "%zu query points, at most %zu per call", n, (size_t)1 << 26);
    float *in = malloc(n * 8 * sizeof(float));
    float *out = malloc(n * 4 * sizeof(float));
    if (!in || !out) {
        free(in);
        free(out);
        return lpv_error(err, err_size, "out of memory for %zu query points", n);
    }
    for (size_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) {
            in[i * 8 + (size_t)k] = points[i * 3 + (size_t)k];
            in[i * 8 + 4 + (size_t)k] = normals[i * 3 + (size_t)k];
        }
        in[i * 8 + 3] = in[i * 8 + 7] = 0.0f;
    }
    if (e->query_capacity < n) {
        delete_buffer(&e->query_in);
        delete_buffer(&e->query_out);
        for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i) { /* start from a clean error state */
        }
        e->query_in = new_ssbo(n * 8 * sizeof(float));
        e->query_out = new_ssbo(n * 4 * sizeof(float));
        GLenum alloc_err = glGetError();
        if (alloc_err != GL_NO_ERROR) {
            delete_buffer(&e->query_in);
            delete_buffer(&e->query_out);
            e->query_capacity = 0;
            free(in);
            free(out);
            return lpv_error(err, err_size,
                             "could not allocate buffers for %zu query points (%.2f GB; GL error 0x%04x)", n,
                             (double)n * 48.0 / 1e9, alloc_err);
        }
        e->query_capacity = n;
    }
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, e->query_in);
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(n * 8 * sizeof(float)), in);
    glUseProgram(e->prog_query);
    glUniform1i(glGetUniformLocation(e->prog_query, "u_count"), (GLint)n);
    glUniform1f(glGetUniformLocation(e->prog_query, "u_damping"), e->settings.damping);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, e->grid_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_VPLS, e->query_in);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_SURFELS, e->query_out);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_ACC, e->lpv_acc);
    glDispatchCompute(lpv_div_up(n, 64), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, e->query_out);
    glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(n * 4 * sizeof(float)), out);
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k)
            rgb[i * 3 + (size_t)k] = out[i * 4 + (size_t)k];
    free(in);
    free(out);
    GLenum gl_err = glGetError();
    if (gl_err != GL_NO_ERROR)
        return lpv_error(err, err_size, "GL error 0x%04x during the irradiance query", gl_err);
    return 0;
}

const lpv_grid *lpv_engine_grid(const lpv_engine *e) { return &e->grid; }
const lpv_settings *lpv_engine_settings(const lpv_engine *e) { return &e->settings; }
const lpv_engine_stats *lpv_engine_last_stats(const lpv_engine *e) { return &e->stats; }
const lpv_plan *lpv_engine_last_plan(const lpv_engine *e) { return &e->plan; }
int lpv_engine_cascade_count(const lpv_engine *e) { return e->cascades.count > 0 ? e->cascades.count : 1; }

const lpv_grid *lpv_engine_cascade(const lpv_engine *e, int k)
{
    return (k >= 0 && k < e->cascades.count) ? &e->cascades.grid[k] : &e->grid;
}

static size_t read_buffer(GLuint buf, size_t elem_size, size_t available, void *out, size_t max)
{
    size_t n = available < max ? available : max;
    if (!buf || !n)
        return 0;
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, buf);
    glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(n * elem_size), out);
    return n;
}

/* The buffer holding the chosen grid of every LPV volume. */
static GLuint grid_buffer(const lpv_engine *e, lpv_grid_which which)
{
    const int steps = e->plan.pass[LPV_PASS_PROPAGATE].run ? e->settings.iterations : 0;
    if (which == LPV_GRID_INJECTED || (which == LPV_GRID_LAST_STEP && steps == 0))
        return e->lpv_injected;
    if (which == LPV_GRID_LAST_STEP)
        return e->lpv_last;
    return e->lpv_acc;
}

size_t lpv_engine_read_grid(lpv_engine *e, lpv_grid_which which, lpv_cell *out, size_t max)
{
    if (!e->ticked)
        return 0;
    GLuint b = grid_buffer(e, which);
    if (e->bins <= 1)
        return read_buffer(b, sizeof(lpv_cell), lpv_engine_all_cells(e), out, max);
    /* Normal bins: the physical field of a cascade is the sum of its bins. */
    const size_t per = lpv_engine_cascade_cells(e), all = lpv_engine_volume_cells(e);
    lpv_cell *raw = malloc(all * sizeof *raw);
    if (!raw)
        return 0;
    read_buffer(b, sizeof(lpv_cell), all, raw, all);
    size_t n = lpv_engine_all_cells(e) < max ? lpv_engine_all_cells(e) : max;
    for (size_t i = 0; i < n; ++i) {
        size_t k = i / per, c = i % per;
        lpv_cell sum = raw[k * (size_t)e->bins * per + c];
        for (int bin = 1; bin < e->bins; ++bin) {
            const lpv_cell *x = &raw[(k * (size_t)e->bins + (size_t)bin) * per + c];
            for (int j = 0; j < 4; ++j) {
                sum.r[j] += x->r[j];
                sum.g[j] += x->g[j];
                sum.b[j] += x->b[j];
            }
        }
        out[i] = sum;
    }
    free(raw);
    return n;
}

size_t lpv_engine_read_volumes(lpv_engine *e, lpv_grid_which which, lpv_cell *out, size_t max)
{
    if (!e->ticked)
        return 0;
    return read_buffer(grid_buffer(e, which), sizeof(lpv_cell), lpv_engine_volume_cells(e), out, max);
}

int lpv_engine_bins(const lpv_engine *e) { return e->bins > 1 ? e->bins : 1; }

size_t lpv_engine_read_gv(lpv_engine *e, lpv_gv_point *out, size_t max)
{
    if (!e->ticked || !e->plan.pass[LPV_PASS_GV].run)
        return 0;
    return read_buffer(e->gv_total, sizeof *out, lpv_grid_gv_count(&e->grid) * (size_t)e->cascades.count, out, max);
}

size_t lpv_engine_read_transmittance(lpv_engine *e, float *out, size_t max_floats)
{
    if (!e->ticked || !e->plan.pass[LPV_PASS_GV].run)
        return 0;
    return read_buffer(e->transmit, sizeof(float), lpv_engine_all_cells(e) * LPV_DIR_COUNT, out, max_floats);
}

size_t lpv_engine_read_vpls(lpv_engine *e, lpv_vpl *out, size_t max)
{
    if (!e->ticked)
        return 0;
    size_t n = read_buffer(e->vpls, sizeof(lpv_vpl), e->rsm_texels, out, max);
    if (n < max && e->plan.pass[LPV_PASS_EMISSIVE].run) /* what the LPV got */
        n += read_buffer(e->emissive_vpls, sizeof(lpv_vpl), e->emissive_vpl_count, out + n, max - n);
    return n;
}

/* GV buffers: each punctual light, then (if any) the area light samples as
 * one (their first sample's faces; rsm.frag leaves the others' out), then the
 * camera. */
static size_t area_gv_buffers(const lpv_engine *e)
{
    return e->light_block.counts[0] > e->light_block.counts[2] ? 1 : 0;
}

size_t lpv_engine_gv_buffer_count(const lpv_engine *e)
{
    return (size_t)e->light_block.counts[2] + area_gv_buffers(e) + (e->has_view ? 1 : 0) +
           (e->scene_surfel_count ? 1 : 0);
}

void lpv_engine_gv_buffer_range(const lpv_engine *e, size_t buffer, size_t *first, size_t *count)
{
    const size_t per_layer = (size_t)e->rsm_size * (size_t)e->rsm_size;
    const size_t lights = (size_t)e->light_block.counts[2];
    *first = *count = 0;
    if (buffer < lights) {
        const struct LpvLightGpu *l = &e->light_block.lights[buffer];
        *first = (size_t)l->cone_faces[2] * per_layer; /* a punctual face is a layer */
        *count = (size_t)l->cone_faces[3] * per_layer;
    } else if (buffer == lights && area_gv_buffers(e)) {
        /* only the layers holding the first sample's faces: the other
         * samples' surfels are left out of the GV anyway (rsm.frag) */
        const int side = e->area_face_side > 0 ? e->area_face_side : e->rsm_size;
        const int per_row = e->rsm_size / side, faces_per_layer = per_row * per_row;
        int layers = (LPV_AREA_FACES + faces_per_layer - 1) / faces_per_layer;
        if (layers > e->rsm_layers - e->punctual_faces)
            layers = e->rsm_layers - e->punctual_faces;
        *first = (size_t)e->punctual_faces * per_layer;
        *count = (size_t)layers * per_layer;
    }
}

size_t lpv_engine_read_surfels(lpv_engine *e, size_t buffer, lpv_surfel *out, size_t max)
{
    if (!e->ticked || !e->plan.pass[LPV_PASS_GV].run)
        return 0;
    size_t rsm_buffers = (size_t)e->light_block.counts[2] + area_gv_buffers(e);
    if (buffer < rsm_buffers) {
        size_t first, count;
        lpv_engine_gv_buffer_range(e, buffer, &first, &count);
        size_t n = count < max ? count : max;
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, e->surfels);
        glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, (GLintptr)(first * sizeof(lpv_surfel)),
                           (GLsizeiptr)(n * sizeof(lpv_surfel)), out);
        return n;
    }
    if (buffer == rsm_buffers && e->has_view)
        return read_buffer(e->camera_surfels, sizeof(lpv_surfel), (size_t)e->gbuf_w * e->gbuf_h, out, max);
    if (buffer == rsm_buffers + (e->has_view ? 1 : 0) && e->scene_surfel_count)
        return read_buffer(e->scene_surfels, sizeof(lpv_surfel), e->scene_surfel_count, out, max);
    return 0;
}
