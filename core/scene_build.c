/*
 * scene_build.c - see scene_build.h. Small appends over the flat scene model;
 * each grows its arrays by exactly what it adds (scenes built in code are
 * small, so simplicity beats amortised growth).
 */
#include "scene_build.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* realloc that keeps the old block on failure. */
static int grow(void **p, size_t count, size_t size)
{
    void *q = realloc(*p, count * size);
    if (!q)
        return -1;
    *p = q;
    return 0;
}

int lpv_scene_add_material(lpv_scene *s, const char *name, const float albedo[3], const float emission[3])
{
    if (grow((void **)&s->materials, s->material_count + 1, sizeof *s->materials) != 0)
        return -1;
    lpv_material *m = &s->materials[s->material_count];
    lpv_material_init(m);
    snprintf(m->name, sizeof m->name, "%s", name ? name : "");
    memcpy(m->base_color, albedo, 3 * sizeof(float));
    m->double_sided = 1; /* code-built surfaces have always been two-sided */
    if (emission) {
        memcpy(m->emission, emission, sizeof m->emission);
        /* ... but their emitters lit from the front only: a double-sided
         * emitter emits from both sides (glTF), so they stay single-sided;
         * set double_sided afterwards for one that emits both ways */
        if (emission[0] != 0.0f || emission[1] != 0.0f || emission[2] != 0.0f)
            m->double_sided = 0;
    }
    return (int)s->material_count++;
}

/* Appends vertices (positions with one normal each) and triangle indices
 * relative to them as a new draw of material m. */
static int add_mesh(lpv_scene *s, int material, const float (*pos)[3], const float (*nrm)[3], uint32_t nv,
                    const uint32_t *idx, uint32_t ni)
{
    if (grow((void **)&s->vertices, s->vertex_count + nv, sizeof *s->vertices) != 0 ||
        grow((void **)&s->indices, s->index_count + ni, sizeof *s->indices) != 0 ||
        grow((void **)&s->draws, s->draw_count + 1, sizeof *s->draws) != 0)
        return -1;
    uint32_t base = s->vertex_count;
    for (uint32_t i = 0; i < nv; i++) {
        lpv_vertex *v = &s->vertices[base + i];
        memset(v, 0, sizeof *v);
        memcpy(v->position, pos[i], sizeof v->position);
        memcpy(v->normal, nrm[i], sizeof v->normal);
        v->uv[0] = (i % 4 == 1 || i % 4 == 2) ? 1.0f : 0.0f;
        v->uv[1] = (i % 4 >= 2) ? 1.0f : 0.0f;
    }
    s->draws[s->draw_count] = (lpv_draw){.first_index = s->index_count, .index_count = ni, .material = material};
    for (uint32_t i = 0; i < ni; i++)
        s->indices[s->index_count + i] = base + idx[i];
    s->vertex_count += nv;
    s->index_count += ni;
    return (int)s->draw_count++;
}

static void winding_normal(const float c[4][3], float n[3])
{
    float a[3], b[3];
    for (int k = 0; k < 3; k++) {
        a[k] = c[2][k] - c[0][k];
        b[k] = c[3][k] - c[1][k];
    }
    n[0] = a[1] * b[2] - a[2] * b[1];
    n[1] = a[2] * b[0] - a[0] * b[2];
    n[2] = a[0] * b[1] - a[1] * b[0];
    float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int k = 0; k < 3 && len > 0.0f; k++)
        n[k] /= len;
}

static const uint32_t QUAD_INDICES[6] = {0, 1, 2, 0, 2, 3};

int lpv_scene_add_quad(lpv_scene *s, int material, const float c[4][3], const float normal[3])
{
    float n[4][3];
    float wn[3];
    winding_normal(c, wn);
    for (int i = 0; i < 4; i++)
        memcpy(n[i], normal ? normal : wn, sizeof n[i]);
    return add_mesh(s, material, c, (const float(*)[3])n, 4, QUAD_INDICES, 6);
}

int lpv_scene_add_box(lpv_scene *s, int material, const float lo[3], const float hi[3])
{
    float x0 = lo[0], y0 = lo[1], z0 = lo[2], x1 = hi[0], y1 = hi[1], z1 = hi[2];
    /* Each face counter-clockwise seen from outside. */
    const float faces[6][4][3] = {
        {{x1, y0, z1}, {x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}}, /* +x */
        {{x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0}}, /* -x */
        {{x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0}, {x0, y1, z0}}, /* +y */
        {{x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1}}, /* -y */
        {{x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}}, /* +z */
        {{x1, y0, z0}, {x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}}, /* -z */
    };
    static const float normals[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    float pos[24][3], nrm[24][3];
    uint32_t idx[36];
    for (int f = 0; f < 6; f++) {
        for (int i = 0; i < 4; i++) {
            memcpy(pos[4 * f + i], faces[f][i], sizeof pos[0]);
            memcpy(nrm[4 * f + i], normals[f], sizeof nrm[0]);
        }
        for (int i = 0; i < 6; i++)
            idx[6 * f + i] = (uint32_t)(4 * f) + QUAD_INDICES[i];
    }
    return add_mesh(s, material, (const float(*)[3])pos, (const float(*)[3])nrm, 24, idx, 36);
}

static lpv_light *add_light(lpv_scene *s, lpv_light_type type, float intensity)
{
    if (grow((void **)&s->lights, s->light_count + 1, sizeof *s->lights) != 0)
        return NULL;
    lpv_light *l = &s->lights[s->light_count++];
    memset(l, 0, sizeof *l);
    l->type = type;
    snprintf(l->name, sizeof l->name, "light%u", s->light_count - 1);
    l->color[0] = l->color[1] = l->color[2] = 1.0f;
    l->intensity = intensity;
    l->direction[1] = -1.0f;
    return l;
}

lpv_light *lpv_scene_add_point_light(lpv_scene *s, const float pos[3], float intensity)
{
    lpv_light *l = add_light(s, LPV_LIGHT_POINT, intensity);
    if (l)
        memcpy(l->position, pos, sizeof l->position);
    return l;
}

lpv_light *lpv_scene_add_directional_light(lpv_scene *s, const float dir[3], float irradiance)
{
    lpv_light *l = add_light(s, LPV_LIGHT_DIRECTIONAL, irradiance);
    if (l) {
        float len = sqrtf(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        for (int k = 0; k < 3; k++)
            l->direction[k] = len > 0.0f ? dir[k] / len : (k == 1 ? -1.0f : 0.0f);
    }
    return l;
}

int lpv_scene_set_material_roughness(lpv_scene *s, int material, float roughness)
{
    if (!s || material < 0 || (uint32_t)material >= s->material_count || !(roughness >= 0.0f && roughness <= 1.0f))
        return -1;
    s->materials[material].roughness = roughness;
    return 0;
}

static int coefficients_ok(const float sigma_s[3], const float sigma_a[3])
{
    if (!sigma_s || !sigma_a)
        return 0;
    for (int k = 0; k < 3; k++) {
        /* written so that NaN fails */
        if (!(sigma_s[k] >= 0.0f && sigma_s[k] <= LPV_MEDIUM_SIGMA_MAX) ||
            !(sigma_a[k] >= 0.0f && sigma_a[k] <= LPV_MEDIUM_SIGMA_MAX))
            return 0;
    }
    return 1;
}

/* Replaces s->medium with m (taking its density), or clears it when every
 * coefficient is 0 (freeing m's density). */
static void put_medium(lpv_scene *s, lpv_medium *m)
{
    int any = 0;
    for (int k = 0; k < 3; k++)
        any |= m->sigma_s[k] > 0.0f || m->sigma_a[k] > 0.0f;
    free(s->medium.density);
    if (!any) {
        free(m->density);
        memset(&s->medium, 0, sizeof s->medium);
        return;
    }
    m->present = 1;
    s->medium = *m;
}

int lpv_scene_set_fog(lpv_scene *s, const float sigma_s[3], const float sigma_a[3])
{
    if (!s || !coefficients_ok(sigma_s, sigma_a))
        return -1;
    lpv_medium m;
    memset(&m, 0, sizeof m);
    memcpy(m.sigma_s, sigma_s, sizeof m.sigma_s);
    memcpy(m.sigma_a, sigma_a, sizeof m.sigma_a);
    put_medium(s, &m);
    return 0;
}

int lpv_scene_set_medium_box(lpv_scene *s, const float sigma_s[3], const float sigma_a[3], const float box_min[3],
                             const float box_max[3], const int dims[3], const float *density)
{
    if (!s || !coefficients_ok(sigma_s, sigma_a) || !box_min || !box_max)
        return -1;
    for (int k = 0; k < 3; k++)
        if (!isfinite(box_min[k]) || !isfinite(box_max[k]) || !(box_min[k] < box_max[k]))
            return -1;
    lpv_medium m;
    memset(&m, 0, sizeof m);
    memcpy(m.sigma_s, sigma_s, sizeof m.sigma_s);
    memcpy(m.sigma_a, sigma_a, sizeof m.sigma_a);
    m.has_box = 1;
    memcpy(m.box_min, box_min, sizeof m.box_min);
    memcpy(m.box_max, box_max, sizeof m.box_max);
    int none = !dims || (dims[0] == 0 && dims[1] == 0 && dims[2] == 0);
    if (none != !density)
        return -1; /* a texture needs both dims and values */
    if (!none) {
        size_t count = 1;
        for (int k = 0; k < 3; k++) {
            if (dims[k] < 1 || dims[k] > LPV_MEDIUM_DIMS_MAX)
                return -1;
            count *= (size_t)dims[k];
        }
        for (size_t i = 0; i < count; i++)
            if (!(density[i] >= 0.0f && density[i] <= LPV_MEDIUM_DENSITY_MAX))
                return -1;
        m.density = malloc(count * sizeof *m.density);
        if (!m.density)
            return -1;
        memcpy(m.density, density, count * sizeof *m.density);
        memcpy(m.dims, dims, sizeof m.dims);
    }
    put_medium(s, &m);
    return 0;
}
