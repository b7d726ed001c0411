/* scene.c - ownership and small queries of lpv_scene (see scene.h). Plain C11. */
#include "scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void lpv_scene_free(lpv_scene *scene)
{
    if (!scene)
        return;
    if (scene->textures) {
        for (uint32_t i = 0; i < scene->texture_count; i++)
            free(scene->textures[i].rgba8);
    }
    free(scene->vertices);
    free(scene->indices);
    free(scene->draws);
    free(scene->wire_indices);
    free(scene->wire_draws);
    free(scene->materials);
    free(scene->textures);
    free(scene->lights);
    free(scene->cameras);
    free(scene->medium.density);
    memset(scene, 0, sizeof *scene);
}

static void *dup_array(const void *src, size_t count, size_t size)
{
    if (!src || !count)
        return NULL;
    void *p = malloc(count * size);
    if (p)
        memcpy(p, src, count * size);
    return p;
}

int lpv_scene_copy_geometry(lpv_scene *dst, const lpv_scene *src)
{
    memset(dst, 0, sizeof *dst);
    dst->vertices = dup_array(src->vertices, src->vertex_count, sizeof *src->vertices);
    dst->indices = dup_array(src->indices, src->index_count, sizeof *src->indices);
    dst->draws = dup_array(src->draws, src->draw_count, sizeof *src->draws);
    dst->materials = dup_array(src->materials, src->material_count, sizeof *src->materials);
    dst->wire_indices = dup_array(src->wire_indices, src->wire_index_count, sizeof *src->wire_indices);
    dst->wire_draws = dup_array(src->wire_draws, src->wire_draw_count, sizeof *src->wire_draws);
    if ((src->vertex_count && !dst->vertices) || (src->index_count && !dst->indices) ||
        (src->draw_count && !dst->draws) || (src->material_count && !dst->materials) ||
        (src->wire_index_count && !dst->wire_indices) || (src->wire_draw_count && !dst->wire_draws)) {
        lpv_scene_free(dst);
        return -1;
    }
    dst->vertex_count = src->vertex_count;
    dst->index_count = src->index_count;
    dst->draw_count = src->draw_count;
    dst->wire_index_count = src->wire_index_count;
    dst->wire_draw_count = src->wire_draw_count;
    dst->material_count = src->material_count;
    memcpy(dst->bounds_min, src->bounds_min, sizeof dst->bounds_min);
    memcpy(dst->bounds_max, src->bounds_max, sizeof dst->bounds_max);
    memcpy(dst->source, src->source, sizeof dst->source);
    return 0;
}

uint64_t lpv_scene_bytes(const lpv_scene *s)
{
    uint64_t b = (uint64_t)s->vertex_count * sizeof *s->vertices + (uint64_t)s->index_count * sizeof *s->indices +
                 (uint64_t)s->draw_count * sizeof *s->draws + (uint64_t)s->material_count * sizeof *s->materials +
                 (uint64_t)s->light_count * sizeof *s->lights + (uint64_t)s->camera_count * sizeof *s->cameras +
                 (uint64_t)s->texture_count * sizeof *s->textures +
                 (uint64_t)s->wire_index_count * sizeof *s->wire_indices +
                 (uint64_t)s->wire_draw_count * sizeof *s->wire_draws;
    for (uint32_t i = 0; i < s->texture_count; ++i)
        b += (uint64_t)s->textures[i].width * (uint64_t)s->textures[i].height * 4u;
    if (s->medium.density)
        b += (uint64_t)s->medium.dims[0] * s->medium.dims[1] * s->medium.dims[2] * sizeof *s->medium.density;
    return b;
}

int lpv_light_check_intensity(const lpv_light *l, char *err, size_t err_size)
{
    double c = fmax(fmax((double)l->color[0], (double)l->color[1]), (double)l->color[2]);
    double product = (double)l->intensity * c;
    if (isfinite(product) && product <= (double)(float)LPV_MAX_LIGHT_INTENSITY) /* 1e30 itself is allowed */
        return 0;
    snprintf(err, err_size, "intensity x color = %g %s is over the largest lpvd computes with, %g %s", product,
             l->type == LPV_LIGHT_DIRECTIONAL ? "W/m^2" : "W/sr", LPV_MAX_LIGHT_INTENSITY,
             l->type == LPV_LIGHT_DIRECTIONAL ? "W/m^2" : "W/sr");
    return -1;
}

int lpv_scene_check_ranges(const lpv_scene *scene, char *err, size_t err_size)
{
    for (uint32_t i = 0; scene->vertices && i < scene->vertex_count; ++i) {
        const float *p = scene->vertices[i].position;
        for (int k = 0; k < 3; ++k)
            if (!(fabsf(p[k]) <= LPV_MAX_COORD)) {
                snprintf(err, err_size, "vertex %u lies at %g m, beyond the largest coordinate lpvd computes with "
                         "(+-%g m)", i, (double)p[k], LPV_MAX_COORD);
                return -1;
            }
    }
    for (uint32_t i = 0; i < scene->light_count; ++i) {
        const lpv_light *l = &scene->lights[i];
        char why[160];
        for (int k = 0; k < 3; ++k)
            if (!(fabsf(l->position[k]) <= LPV_MAX_COORD)) {
                snprintf(err, err_size, "light %u lies at %g m, beyond +-%g m", i, (double)l->position[k],
                         LPV_MAX_COORD);
                return -1;
            }
        if (!(l->range >= 0.0f && l->range <= LPV_MAX_COORD)) {
            snprintf(err, err_size, "light %u: range %g m is out of range (0..%g)", i, (double)l->range,
                     LPV_MAX_COORD);
            return -1;
        }
        if (lpv_light_check_intensity(l, why, sizeof why) != 0) {
            snprintf(err, err_size, "light %u: %s", i, why);
            return -1;
        }
    }
    return 0;
}

void lpv_scene_compute_bounds(lpv_scene *scene)
{
    float lo[3] = {INFINITY, INFINITY, INFINITY};
    float hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    int any = 0;

    if (!scene)
        return;
    for (uint32_t i = 0; scene->vertices && i < scene->vertex_count; i++) {
        const float *p = scene->vertices[i].position;
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
            continue;
        for (int k = 0; k < 3; k++) {
            if (p[k] < lo[k])
                lo[k] = p[k];
            if (p[k] > hi[k])
                hi[k] = p[k];
        }
        any = 1;
    }
    for (int k = 0; k < 3; k++) {
        scene->bounds_min[k] = any ? lo[k] : 0.0f;
        scene->bounds_max[k] = any ? hi[k] : 0.0f;
    }
}

void lpv_material_init(lpv_material *m)
{
    memset(m, 0, sizeof *m);
    m->base_color[0] = m->base_color[1] = m->base_color[2] = m->base_color[3] = 1.0f;
    m->roughness = 1.0f;
    m->alpha_cutoff = 0.5f;
    m->normal_scale = 1.0f;
    m->base_color_texture = m->normal_texture = m->metallic_roughness_texture = m->emissive_texture = -1;
    m->occlusion_texture = -1;
    m->occlusion_strength = 1.0f;
    lpv_uv_transform *uv[] = {&m->base_color_uv, &m->normal_uv, &m->metallic_roughness_uv, &m->emissive_uv,
                              &m->occlusion_uv};
    for (size_t i = 0; i < sizeof uv / sizeof uv[0]; ++i)
        uv[i]->scale[0] = uv[i]->scale[1] = 1.0f;
}

int lpv_material_emitting_sides(const lpv_material *m) { return m->double_sided ? 2 : 1; }

float lpv_material_alpha_cutoff(const lpv_material *m)
{
    switch (m->alpha_mode) {
    case LPV_ALPHA_MASK:
        return m->alpha_cutoff > 0.0f ? m->alpha_cutoff : 0.0f; /* NaN: nothing is cut */
    default:
        return 0.0f;
    }
}

void lpv_uv_transform_matrix(const lpv_uv_transform *t, float m[6])
{
    if (!t->has_transform) {
        m[0] = 1.0f, m[1] = 0.0f, m[2] = 0.0f;
        m[3] = 0.0f, m[4] = 1.0f, m[5] = 0.0f;
        return;
    }
    /* KHR_texture_transform: T(offset) * R(rotation) * S(scale), with
     * R = [cos sin; -sin cos] acting on column vectors (u, v). */
    const float c = cosf(t->rotation), s = sinf(t->rotation);
    m[0] = c * t->scale[0];
    m[1] = s * t->scale[1];
    m[2] = t->offset[0];
    m[3] = -s * t->scale[0];
    m[4] = c * t->scale[1];
    m[5] = t->offset[1];
}

static int material_emits(const lpv_material *m)
{
    /* NaN compares false, so a NaN emission does not count as a light. */
    return m->emission[0] > 0.0f || m->emission[1] > 0.0f || m->emission[2] > 0.0f;
}

uint32_t lpv_scene_emissive_draw_count(const lpv_scene *scene)
{
    uint32_t count = 0;

    if (!scene || !scene->materials || !scene->draws || scene->material_count == 0)
        return 0;

    unsigned char *used = calloc(scene->material_count, 1);
    if (used) {
        for (uint32_t d = 0; d < scene->draw_count; d++) {
            const lpv_draw *dr = &scene->draws[d];
            if (dr->index_count > 0 && dr->material >= 0 &&
                (uint32_t)dr->material < scene->material_count)
                used[dr->material] = 1;
        }
        for (uint32_t m = 0; m < scene->material_count; m++)
            if (used[m] && material_emits(&scene->materials[m]))
                count++;
        free(used);
        return count;
    }

    /* Out of memory for the flags: the slow quadratic scan needs none. */
    for (uint32_t m = 0; m < scene->material_count; m++) {
        if (!material_emits(&scene->materials[m]))
            continue;
        for (uint32_t d = 0; d < scene->draw_count; d++) {
            if (scene->draws[d].material == (int)m && scene->draws[d].index_count > 0) {
                count++;
                break;
            }
        }
    }
    return count;
}

int lpv_scene_triangle(const lpv_scene *s, uint32_t first, const lpv_vertex *v[3], float front[3], double *area)
{
    if ((uint64_t)first + 3 > s->index_count)
        return 0;
    for (int k = 0; k < 3; ++k) {
        uint32_t idx = s->indices[first + (uint32_t)k];
        if (idx >= s->vertex_count)
            return 0;
        v[k] = &s->vertices[idx];
        for (int i = 0; i < 3; ++i)
            if (!isfinite(v[k]->position[i]))
                return 0;
    }
    double e1[3], e2[3], c[3];
    for (int i = 0; i < 3; ++i) {
        e1[i] = (double)v[1]->position[i] - v[0]->position[i];
        e2[i] = (double)v[2]->position[i] - v[0]->position[i];
    }
    c[0] = e1[1] * e2[2] - e1[2] * e2[1];
    c[1] = e1[2] * e2[0] - e1[0] * e2[2];
    c[2] = e1[0] * e2[1] - e1[1] * e2[0];
    double len = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    if (!(len > 1e-12) || !isfinite(len))
        return 0;
    double vn = 0.0;
    for (int k = 0; k < 3; ++k) {
        const float *n = v[k]->normal;
        if (isfinite(n[0]) && isfinite(n[1]) && isfinite(n[2]))
            for (int i = 0; i < 3; ++i)
                vn += c[i] * n[i];
    }
    double sign = vn < 0.0 ? -1.0 : 1.0;
    for (int i = 0; i < 3; ++i)
        front[i] = (float)(sign * c[i] / len);
    *area = 0.5 * len;
    return 1;
}
