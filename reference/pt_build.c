/*
 * pt_build.c - building the reference (pt.h lpv_ref_create): the scene's
 * usable triangles, copies of its materials, textures and lights, the
 * emitters' power CDF for next-event estimation, the ray offset, and the
 * Embree BVH over the triangles. Apart from the estimators because it runs
 * once per scene and is all that knows how the copy is laid out.
 */
#include "pt_internal.h"

#include "error.h"
#include "material_sample.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* ---- building ------------------------------------------------------------ */

/* Keeps triangle `first` of the scene if it is usable. */
static int make_tri(const lpv_scene *s, uint32_t first, int material, int vertex_color, ref_tri *t)
{
    /* The front is the same side core/emissive.c emits from. */
    const lpv_vertex *v[3];
    double area;
    if (!lpv_scene_triangle(s, first, v, t->front, &area))
        return 0;
    for (int i = 0; i < 3; ++i) {
        t->p0[i] = v[0]->position[i];
        t->e1[i] = v[1]->position[i] - v[0]->position[i];
        t->e2[i] = v[2]->position[i] - v[0]->position[i];
    }
    for (int k = 0; k < 3; ++k) {
        if (!unit3(v[k]->normal, t->vn[k]))
            memcpy(t->vn[k], t->front, sizeof t->front);
        for (int i = 0; i < 2; ++i) {
            t->uv[k][i] = isfinite(v[k]->uv[i]) ? v[k]->uv[i] : 0.0f;
            t->uv1[k][i] = isfinite(v[k]->uv1[i]) ? v[k]->uv1[i] : 0.0f;
        }
        for (int i = 0; i < 4; ++i)
            t->color[k][i] = vertex_color && isfinite(v[k]->color[i]) ? v[k]->color[i] : 1.0f;
    }
    t->material = material;
    return 1;
}

static int copy_materials(lpv_ref *r, const lpv_scene *s)
{
    if (s->material_count) {
        r->materials = calloc(s->material_count, sizeof *r->materials);
        r->look.materials = malloc(s->material_count * sizeof *r->look.materials);
        if (!r->materials || !r->look.materials)
            return -1;
        memcpy(r->look.materials, s->materials, s->material_count * sizeof *s->materials);
    }
    r->material_count = r->look.material_count = s->material_count;
    for (uint32_t m = 0; m < s->material_count; ++m) {
        const float *e = s->materials[m].emission;
        int emits = 0;
        for (int i = 0; i < 3; ++i)
            emits |= isfinite(e[i]) && e[i] > 0.0f;
        r->materials[m].emits = emits;
        r->materials[m].sides = lpv_material_emitting_sides(&s->materials[m]);
    }
    if (s->texture_count) {
        r->look.textures = calloc(s->texture_count, sizeof *r->look.textures);
        if (!r->look.textures)
            return -1;
    }
    r->look.texture_count = s->texture_count;
    for (uint32_t t = 0; t < s->texture_count; ++t) {
        const lpv_texture *src = &s->textures[t];
        lpv_texture *dst = &r->look.textures[t];
        *dst = *src;
        dst->rgba8 = NULL;
        if (!src->rgba8 || src->width < 1 || src->height < 1)
            continue;
        const size_t bytes = (size_t)src->width * (size_t)src->height * 4;
        if (!(dst->rgba8 = malloc(bytes)))
            return -1;
        memcpy(dst->rgba8, src->rgba8, bytes);
    }
    return 0;
}

/* A triangle's corners as vertices with its uv sets (for core/material_sample.h). */
static void tri_vertices(const ref_tri *t, lpv_vertex v[3])
{
    memset(v, 0, 3 * sizeof *v);
    for (int k = 0; k < 3; ++k)
        for (int i = 0; i < 2; ++i) {
            v[k].uv[i] = t->uv[k][i];
            v[k].uv1[i] = t->uv1[k][i];
        }
}

/* The emissive triangles and their power CDF, for next-event estimation. */
static int build_emitters(lpv_ref *r)
{
    uint32_t n = 0;
    for (uint32_t t = 0; t < r->tri_count; ++t)
        n += r->tris[t].material >= 0 && r->materials[r->tris[t].material].emits;
    if (!n)
        return 0;
    r->emitters = malloc(n * sizeof *r->emitters);
    r->emitter_cdf = malloc((n + 1) * sizeof *r->emitter_cdf);
    if (!r->emitters || !r->emitter_cdf)
        return -1;
    r->emitter_cdf[0] = 0.0;
    for (uint32_t t = 0; t < r->tri_count; ++t) {
        const ref_tri *tr = &r->tris[t];
        if (tr->material < 0 || !r->materials[tr->material].emits)
            continue;
        const ref_material *m = &r->materials[tr->material];
        lpv_vertex v[3];
        const lpv_vertex *pv[3] = {&v[0], &v[1], &v[2]};
        float e[3];
        tri_vertices(tr, v);
        lpv_triangle_emission(&r->look, &r->look.materials[tr->material], pv, e); /* its emissiveTexture's mean */
        const double le = isfinite((double)e[0] + e[1] + e[2]) ? fmax((double)e[0] + e[1] + e[2], 0.0) : 0.0;
        r->emitters[r->emitter_count] = t;
        r->emitter_cdf[r->emitter_count + 1] = r->emitter_cdf[r->emitter_count] + le * tri_area(tr) * m->sides;
        r->emitter_count++;
    }
    return 0;
}

static int resolve_threads(int want)
{
    if (want > 0)
        return want > 256 ? 256 : want;
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : (n > 256 ? 256 : (int)n);
}

int lpv_ref_create(const lpv_scene *scene, const lpv_ref_desc *desc, lpv_ref **out, char *err, size_t err_size)
{
    *out = NULL;
    if (!scene) {
        lpv_error(err, err_size, "%s", "no scene");
        return -1;
    }
    lpv_ref_desc d = desc ? *desc : (lpv_ref_desc){0};
    lpv_ref *r = calloc(1, sizeof *r);
    if (!r) {
        lpv_error(err, err_size, "%s", "out of memory");
        return -1;
    }
    r->threads = resolve_threads(d.threads);
    r->seed = d.seed;
    r->emitters_are_lights = d.emitters_are_lights != 0;
    r->max_bounces = d.max_bounces > 0 ? d.max_bounces : LPV_REF_MAX_BOUNCES_DEFAULT;

    /* Triangles. */
    size_t cap = 0;
    for (uint32_t i = 0; i < scene->draw_count; ++i)
        cap += scene->draws[i].index_count / 3;
    if (cap > 0x7fffffffu) {
        lpv_error(err, err_size, "%s", "too many triangles");
        goto fail;
    }
    if (cap) {
        r->tris = malloc(cap * sizeof *r->tris);
        if (!r->tris) {
            lpv_error(err, err_size, "%s", "out of memory");
            goto fail;
        }
    }
    for (uint32_t i = 0; i < scene->draw_count; ++i) {
        const lpv_draw *dr = &scene->draws[i];
        int mat = (dr->material >= 0 && (uint32_t)dr->material < scene->material_count) ? dr->material : -1;
        for (uint32_t k = 0; k + 3 <= dr->index_count; k += 3) {
            uint64_t first = (uint64_t)dr->first_index + k;
            if (!scene->indices || first + 3 > scene->index_count)
                break;
            if (make_tri(scene, (uint32_t)first, mat, dr->vertex_color, &r->tris[r->tri_count]))
                r->tri_count++;
        }
    }
    if (copy_materials(r, scene) != 0) {
        lpv_error(err, err_size, "%s", "out of memory");
        goto fail;
    }
    if (scene->light_count) {
        r->lights = malloc(scene->light_count * sizeof *r->lights);
        if (!r->lights) {
            lpv_error(err, err_size, "%s", "out of memory");
            goto fail;
        }
        memcpy(r->lights, scene->lights, scene->light_count * sizeof *r->lights);
        r->light_count = scene->light_count;
    }

    if (build_emitters(r) != 0) {
        lpv_error(err, err_size, "%s", "out of memory");
        goto fail;
    }

    /* Ray offset from the kept triangles' bounds. */
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t t = 0; t < r->tri_count; ++t)
        for (int i = 0; i < 3; ++i) {
            const ref_tri *tr = &r->tris[t];
            float a = tr->p0[i], b = tr->p0[i] + tr->e1[i], c = tr->p0[i] + tr->e2[i];
            lo[i] = fminf(lo[i], fminf(a, fminf(b, c)));
            hi[i] = fmaxf(hi[i], fmaxf(a, fmaxf(b, c)));
        }
    float diag = 0.0f;
    if (r->tri_count)
        diag = sqrtf((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                     (hi[2] - lo[2]) * (hi[2] - lo[2]));
    r->eps = (d.ray_epsilon > 0.0f && isfinite(d.ray_epsilon)) ? d.ray_epsilon : fmaxf(1e-5f * diag, 1e-6f);
    if (!isfinite(r->eps))
        r->eps = 1e-6f;

    /* Embree: one triangle geometry, unshared vertices, primID = our index.
     * One build thread keeps the build reproducible. */
    r->device = rtcNewDevice("threads=1");
    if (!r->device) {
        lpv_error(err, err_size, "%s", "Embree: rtcNewDevice failed");
        goto fail;
    }
    if (r->tri_count) {
        r->scene = rtcNewScene(r->device);
        rtcSetSceneFlags(r->scene, RTC_SCENE_FLAG_ROBUST);
        rtcSetSceneBuildQuality(r->scene, RTC_BUILD_QUALITY_HIGH);
        RTCGeometry g = rtcNewGeometry(r->device, RTC_GEOMETRY_TYPE_TRIANGLE);
        /* Embree reads vertex buffers 16 bytes at a time: one spare vertex. */
        float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                            (size_t)r->tri_count * 3 + 1);
        unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                               r->tri_count);
        if (!vb || !ib) {
            rtcReleaseGeometry(g);
            lpv_error(err, err_size, "%s", "Embree: out of memory");
            goto fail;
        }
        for (uint32_t t = 0; t < r->tri_count; ++t) {
            const ref_tri *tr = &r->tris[t];
            for (int i = 0; i < 3; ++i) {
                vb[9 * (size_t)t + (size_t)i] = tr->p0[i];
                vb[9 * (size_t)t + 3 + (size_t)i] = tr->p0[i] + tr->e1[i];
                vb[9 * (size_t)t + 6 + (size_t)i] = tr->p0[i] + tr->e2[i];
                ib[3 * (size_t)t + (size_t)i] = 3 * t + (unsigned)i;
            }
        }
        vb[9 * (size_t)r->tri_count] = vb[9 * (size_t)r->tri_count + 1] = vb[9 * (size_t)r->tri_count + 2] = 0.0f;
        int cuts = 0;
        for (uint32_t m = 0; m < r->look.material_count; ++m)
            cuts |= lpv_material_alpha_cutoff(&r->look.materials[m]) > 0.0f;
        for (uint32_t m = 0; m < r->look.material_count; ++m)
            r->has_blend |= r->look.materials[m].alpha_mode == LPV_ALPHA_BLEND;
        cuts |= r->has_blend;
        if (cuts) {
            rtcSetGeometryUserData(g, r);
            rtcSetGeometryIntersectFilterFunction(g, lpv_pt_alpha_filter);
            rtcSetGeometryOccludedFilterFunction(g, lpv_pt_alpha_filter);
        }
        rtcCommitGeometry(g);
        rtcAttachGeometry(r->scene, g);
        rtcReleaseGeometry(g);
        rtcCommitScene(r->scene);
        if (rtcGetDeviceError(r->device) != RTC_ERROR_NONE) {
            lpv_error(err, err_size, "%s", "Embree: building the scene failed");
            goto fail;
        }
    }
    *out = r;
    return 0;
fail:
    lpv_ref_destroy(r);
    return -1;
}

void lpv_ref_destroy(lpv_ref *r)
{
    if (!r)
        return;
    if (r->scene)
        rtcReleaseScene(r->scene);
    if (r->device)
        rtcReleaseDevice(r->device);
    for (uint32_t t = 0; t < r->look.texture_count; ++t)
        free(r->look.textures[t].rgba8);
    free(r->look.textures);
    free(r->look.materials);
    free(r->materials);
    free(r->lights);
    free(r->emitters);
    free(r->emitter_cdf);
    free(r->tris);
    free(r);
}

uint32_t lpv_ref_triangle_count(const lpv_ref *r)
{
    return r ? r->tri_count : 0;
}

int lpv_ref_threads(const lpv_ref *r)
{
    return r ? r->threads : 0;
}

