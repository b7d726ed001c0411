/* pt.c - see pt.h and docs/reference.md. */
#include "pt.h"

#include "error.h"
#include "lpv_shared.h" /* lpv_hash_u32 */
#include "material_sample.h"

#include <embree3/rtcore.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define PT_PI 3.14159265358979323846
#define PT_CHUNK 16 /* pixels or points a worker takes at a time */

typedef struct ref_tri {
    float p0[3], e1[3], e2[3]; /* corners p0, p0 + e1, p0 + e2 */
    float vn[3][3];            /* vertex normals (unit; the front normal where the file's was bad) */
    float uv[3][2], uv1[3][2]; /* TEXCOORD_0, TEXCOORD_1 */
    float color[3][4];         /* COLOR_0 (rgba) at the corners; 1 where the draw has none */
    float front[3]; /* unit geometric normal of the front side (the emitting one, or the first of two) */
    int material;   /* -1 = none: black, not emissive */
} ref_tri;

typedef struct ref_material {
    int emits;
    int sides;   /* emitting sides: 2 double-sided (glTF doubleSided: the back emits L_e too), else 1 */
} ref_material;

struct lpv_ref {
    RTCDevice device;
    RTCScene scene; /* NULL when there are no triangles */
    ref_tri *tris;
    uint32_t tri_count;
    ref_material *materials;
    uint32_t material_count;
    /* copies of the scene's materials and textures (nothing else): a hit's
     * albedo and emission follow core/material_sample.h, the rules lpvd's
     * shaders and CPU samplers follow */
    lpv_scene look;
    lpv_light *lights;
    uint32_t light_count;
    /* emissive triangles for next-event estimation, by emitted power */
    uint32_t *emitters;  /* triangle indices */
    double *emitter_cdf; /* emitter_count + 1 running sums of (L_r + L_g + L_b) A x sides */
    uint32_t emitter_count;
    int emitters_are_lights;
    int max_bounces; /* converged paths' cap */
    int threads;
    uint64_t seed;
    float eps;
    int has_blend; /* some material is alphaMode BLEND (its rays draw whether they pass) */
};

/* ---- small vector helpers ---------------------------------------------- */

static float dot3(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const float a[3], const float b[3], float out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Normalises v into out; returns 0 if v is not unit-able (out untouched). */
static int unit3(const float v[3], float out[3])
{
    float l = sqrtf(dot3(v, v));
    if (!(l > 1e-12f) || !isfinite(l))
        return 0;
    for (int i = 0; i < 3; ++i)
        out[i] = v[i] / l;
    return 1;
}

static int finite3(const float v[3])
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

/* ---- RNG: PCG32 (O'Neill), one stream per (index, sample) ---------------- */

typedef struct pcg32 {
    uint64_t state, inc;
} pcg32;

static uint32_t pcg32_next(pcg32 *r)
{
    uint64_t old = r->state;
    r->state = old * 6364136223846793005ULL + r->inc;
    uint32_t xs = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = (uint32_t)(old >> 59u);
    return (xs >> rot) | (xs << ((-rot) & 31u));
}

static uint64_t splitmix64(uint64_t x)
{
    x += 0x9E3779B97F4A7C15ULL;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
    return x ^ (x >> 31);
}

static void pcg32_seed(pcg32 *r, uint64_t seed, uint64_t index, uint64_t sample)
{
    uint64_t initstate = splitmix64(index ^ splitmix64(seed));
    uint64_t initseq = splitmix64(sample + 0x632BE59BD9B4E019ULL * seed);
    r->state = 0;
    r->inc = (initseq << 1u) | 1u;
    pcg32_next(r);
    r->state += initstate;
    pcg32_next(r);
}

static float pcg32_float(pcg32 *r)
{
    return (float)(pcg32_next(r) >> 8) * (1.0f / 16777216.0f);
}

/* ---- sampling ------------------------------------------------------------ */

/* Orthonormal basis around unit n (Duff et al. 2017). */
static void basis(const float n[3], float t[3], float b[3])
{
    float sign = copysignf(1.0f, n[2]);
    float a = -1.0f / (sign + n[2]);
    float c = n[0] * n[1] * a;
    t[0] = 1.0f + sign * n[0] * n[0] * a;
    t[1] = sign * c;
    t[2] = -sign * n[0];
    b[0] = c;
    b[1] = sign + n[1] * n[1] * a;
    b[2] = -n[1];
}

/* Cosine-weighted direction around unit n (pdf cos / pi). */
static void sample_cosine(pcg32 *r, const float n[3], float out[3])
{
    float u1 = pcg32_float(r), u2 = pcg32_float(r);
    float rad = sqrtf(u1), phi = (float)(2.0 * PT_PI) * u2;
    float x = rad * cosf(phi), y = rad * sinf(phi), z = sqrtf(fmaxf(0.0f, 1.0f - u1));
    float t[3], b[3];
    basis(n, t, b);
    for (int i = 0; i < 3; ++i)
        out[i] = x * t[i] + y * b[i] + z * n[i];
}

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

/* The uv sets (and, color not NULL, COLOR_0's rgba) at barycentrics
 * (1 - b1 - b2, b1, b2). */
static void tri_uv(const ref_tri *t, float b1, float b2, float uv0[2], float uv1[2], float *color)
{
    const float w = 1.0f - b1 - b2;
    for (int i = 0; i < 2; ++i) {
        uv0[i] = w * t->uv[0][i] + b1 * t->uv[1][i] + b2 * t->uv[2][i];
        uv1[i] = w * t->uv1[0][i] + b1 * t->uv1[1][i] + b2 * t->uv1[2][i];
    }
    for (int i = 0; color && i < 4; ++i)
        color[i] = w * t->color[0][i] + b1 * t->color[1][i] + b2 * t->color[2][i];
}

static double tri_area(const ref_tri *t)
{
    float c[3];
    cross3(t->e1, t->e2, c);
    return 0.5 * sqrt((double)dot3(c, c));
}

/* How a ray treats BLEND surfaces (alpha is coverage: a fraction alpha of
 * the surface is there, 1 - alpha of the light passes; docs/scenes.md
 * "Alpha"). MASK cut-outs are cut in every mode. */
typedef enum ref_blend {
    REF_BLEND_DRAW = 0, /* a path's ray: it stops at the surface with probability alpha (its draw) */
    REF_BLEND_HIT,      /* a camera ray that composites the layers itself: every BLEND texel of alpha > 0 is hit */
    REF_BLEND_SKIP,     /* a query for the opaque surface behind (the points lpvd's G-buffer holds) */
    REF_BLEND_TRANSMIT, /* a shadow ray: passes, taking the product of 1 - alpha along it */
} ref_blend;

#define REF_SEEN_MAX 16

/* The context Embree hands the filter: its own first, then how the ray
 * treats BLEND surfaces. */
typedef struct ref_context {
    struct RTCIntersectContext base;
    ref_blend blend;
    uint32_t salt;   /* REF_BLEND_DRAW: the path's draw for this ray */
    float transmit;  /* REF_BLEND_TRANSMIT: the product of 1 - alpha of the BLEND texels passed */
    /* REF_BLEND_TRANSMIT: the triangles counted (Embree may report a hit
     * twice, e.g. a triangle split between nodes) */
    unsigned seen[REF_SEEN_MAX];
    int seen_count;
} ref_context;

/* Embree's filter for both ray kinds: a hit on a texel where the material
 * is not there is no hit, as lpvd's shaders cut it (core/material_sample.h
 * lpv_material_covers_at): alpha below a MASK cutoff; for BLEND as the
 * ray's context says. Installed only when some material cuts or blends. */
static void alpha_filter(const struct RTCFilterFunctionNArguments *args)
{
    /* RTCHitN's layout (rtcore_ray.h's RTCHitN_u/_v/_primID, C++ only): N
     * floats each of Ng x, y, z, u, v, then N primIDs */
    const float *hf = (const float *)args->hit;
    const unsigned *hu = (const unsigned *)args->hit;
    const lpv_ref *r = args->geometryUserPtr;
    ref_context *ctx = (ref_context *)args->context;
    const unsigned N = args->N;
    for (unsigned i = 0; i < N; ++i) {
        if (args->valid[i] != -1)
            continue;
        const unsigned prim = hu[5 * N + i];
        if (prim >= r->tri_count)
            continue;
        const ref_tri *tr = &r->tris[prim];
        if (tr->material < 0)
            continue;
        const lpv_material *m = &r->look.materials[tr->material];
        float uv0[2], uv1[2], color[4];
        tri_uv(tr, hf[3 * N + i], hf[4 * N + i], uv0, uv1, color);
        if (m->alpha_mode == LPV_ALPHA_BLEND && ctx->blend == REF_BLEND_TRANSMIT) {
            int seen = 0;
            for (int k = 0; k < ctx->seen_count; ++k)
                seen |= ctx->seen[k] == prim;
            if (!seen) {
                const float a = lpv_material_alpha_at(&r->look, m, uv0, uv1, color[3]);
                ctx->transmit *= a > 0.0f ? (a < 1.0f ? 1.0f - a : 0.0f) : 1.0f; /* NaN: passes */
                if (ctx->seen_count < REF_SEEN_MAX)
                    ctx->seen[ctx->seen_count++] = prim;
            }
            args->valid[i] = ctx->transmit > 0.0f ? 0 : -1; /* opaque where nothing passes any more */
            continue;
        }
        const float u = ctx->blend == REF_BLEND_HIT    ? 0.0f
                        : ctx->blend == REF_BLEND_SKIP ? INFINITY
                                                       : lpv_hash_unit(lpv_hash_u32(ctx->salt ^ lpv_hash_u32(prim)));
        if (!lpv_material_covers_at(&r->look, m, uv0, uv1, color[3], u))
            args->valid[i] = 0;
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
            rtcSetGeometryIntersectFilterFunction(g, alpha_filter);
            rtcSetGeometryOccludedFilterFunction(g, alpha_filter);
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

/* ---- rays ---------------------------------------------------------------- */

typedef struct hit {
    float p[3];
    float ng[3];    /* unit geometric normal on the side the ray came from */
    float ns[3];    /* unit shading normal on that side */
    int front;      /* 1 if the ray arrived on the front side */
    uint32_t tri;
    float u, v;
    float t;
} hit;

/* The first surface along the ray in [tmin, tmax]; blend and salt: how it
 * treats BLEND surfaces (ref_blend). */
static int intersect(const lpv_ref *r, const float org[3], const float dir[3], float tmin, float tmax,
                     ref_blend blend, uint32_t salt, hit *h)
{
    if (!r->scene)
        return 0;
    ref_context ctx = {.blend = blend, .salt = salt, .transmit = 1.0f};
    rtcInitIntersectContext(&ctx.base);
    struct RTCRayHit rh;
    memset(&rh, 0, sizeof rh);
    rh.ray.org_x = org[0];
    rh.ray.org_y = org[1];
    rh.ray.org_z = org[2];
    rh.ray.dir_x = dir[0];
    rh.ray.dir_y = dir[1];
    rh.ray.dir_z = dir[2];
    rh.ray.tnear = tmin;
    rh.ray.tfar = tmax;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(r->scene, &ctx.base, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID || rh.hit.primID >= r->tri_count)
        return 0;
    const ref_tri *tr = &r->tris[rh.hit.primID];
    float u = rh.hit.u, v = rh.hit.v, w = 1.0f - u - v;
    h->tri = rh.hit.primID;
    h->u = u;
    h->v = v;
    h->t = rh.ray.tfar;
    for (int i = 0; i < 3; ++i)
        h->p[i] = tr->p0[i] + u * tr->e1[i] + v * tr->e2[i];
    float side = dot3(tr->front, dir) < 0.0f ? 1.0f : -1.0f;
    h->front = side > 0.0f;
    float ns[3];
    for (int i = 0; i < 3; ++i) {
        h->ng[i] = side * tr->front[i];
        ns[i] = side * (w * tr->vn[0][i] + u * tr->vn[1][i] + v * tr->vn[2][i]);
    }
    if (!unit3(ns, h->ns) || dot3(h->ns, h->ng) <= 0.0f)
        memcpy(h->ns, h->ng, sizeof h->ns);
    return 1;
}

/* The fraction of light that passes from org along dir to tmax: 0 behind
 * an opaque surface, else the product of 1 - alpha of the BLEND surfaces
 * between (1 with none). */
static float transmitted(const lpv_ref *r, const float org[3], const float dir[3], float tmax)
{
    if (!r->scene)
        return 1.0f;
    ref_context ctx = {.blend = REF_BLEND_TRANSMIT, .transmit = 1.0f};
    rtcInitIntersectContext(&ctx.base);
    struct RTCRay ray;
    memset(&ray, 0, sizeof ray);
    ray.org_x = org[0];
    ray.org_y = org[1];
    ray.org_z = org[2];
    ray.dir_x = dir[0];
    ray.dir_y = dir[1];
    ray.dir_z = dir[2];
    ray.tnear = 0.0f;
    ray.tfar = tmax;
    ray.mask = 0xFFFFFFFFu;
    rtcOccluded1(r->scene, &ctx.base, &ray);
    return ray.tfar < 0.0f ? 0.0f : ctx.transmit;
}

int lpv_ref_first_hit(const lpv_ref *r, const float org[3], const float dir[3], float tmin, float tmax, float *t,
                      float p[3])
{
    hit h;
    if (!r || !finite3(org) || !finite3(dir) || !intersect(r, org, dir, tmin, tmax, REF_BLEND_SKIP, 0u, &h))
        return 0;
    if (t)
        *t = h.t;
    if (p)
        memcpy(p, h.p, sizeof h.p);
    return 1;
}

int lpv_ref_first_surface(const lpv_ref *r, const float org[3], const float dir[3], float tmin, float tmax, float *t,
                          float p[3], float n[3])
{
    hit h;
    if (!r || !finite3(org) || !finite3(dir) || !intersect(r, org, dir, tmin, tmax, REF_BLEND_SKIP, 0u, &h))
        return 0;
    if (t)
        *t = h.t;
    if (p)
        memcpy(p, h.p, sizeof h.p);
    if (n)
        memcpy(n, h.ns, sizeof h.ns);
    return 1;
}

/* ---- materials ----------------------------------------------------------- */

/* The diffuse albedo at a hit (core/material_sample.h: base colour x
 * texture x (1 - metallic)); 0 without a material. */
static void hit_albedo(const lpv_ref *r, const hit *h, float out[3])
{
    const ref_tri *tr = &r->tris[h->tri];
    if (tr->material < 0) {
        out[0] = out[1] = out[2] = 0.0f;
        return;
    }
    float uv0[2], uv1[2], color[4];
    tri_uv(tr, h->u, h->v, uv0, uv1, color);
    lpv_material_albedo_at(&r->look, &r->look.materials[tr->material], uv0, uv1, color, out);
}

/* What the camera sees of an unlit material at a primary hit (its base
 * colour as luminance, core/material_sample.h); 0 where lit. Never at a
 * path's later hits: an unlit surface lights nothing. */
static int hit_unlit(const lpv_ref *r, const hit *h, float out[3])
{
    const ref_tri *tr = &r->tris[h->tri];
    if (tr->material < 0 || !r->look.materials[tr->material].unlit)
        return 0;
    float uv0[2], uv1[2], color[4];
    tri_uv(tr, h->u, h->v, uv0, uv1, color);
    lpv_material_unlit_radiance_at(&r->look, &r->look.materials[tr->material], uv0, uv1, color, out);
    return 1;
}

/* The factor a hit's indirect light takes in the image: its material's
 * occlusionTexture (core/material_sample.h), 1 without one: lpvd applies it
 * to the frame's indirect term, so the reference's image does the same. */
static float hit_occlusion(const lpv_ref *r, const hit *h)
{
    const ref_tri *tr = &r->tris[h->tri];
    if (tr->material < 0)
        return 1.0f;
    float uv0[2], uv1[2];
    tri_uv(tr, h->u, h->v, uv0, uv1, NULL);
    return lpv_material_occlusion_at(&r->look, &r->look.materials[tr->material], uv0, uv1);
}

/* The radiance a hit's side emits (W/(m^2 sr), x its emissiveTexture): 0
 * and no write where it emits none. */
static int hit_emission(const lpv_ref *r, const hit *h, float out[3])
{
    const ref_tri *tr = &r->tris[h->tri];
    if (tr->material < 0 || !r->materials[tr->material].emits || (!h->front && r->materials[tr->material].sides < 2))
        return 0;
    float uv0[2], uv1[2];
    tri_uv(tr, h->u, h->v, uv0, uv1, NULL);
    lpv_material_emission_at(&r->look, &r->look.materials[tr->material], uv0, uv1, out);
    for (int i = 0; i < 3; ++i)
        out[i] = isfinite(out[i]) && out[i] > 0.0f ? out[i] : 0.0f;
    return 1;
}

/* ---- punctual lights (shaders/lights.glsl) -------------------------------- */

static float spot_factor(const lpv_light *li, const float travel[3])
{
    if (li->type != LPV_LIGHT_SPOT)
        return 1.0f;
    float cos_inner = cosf(li->inner_cone), cos_outer = cosf(li->outer_cone);
    float cd = dot3(travel, li->direction);
    float scale = 1.0f / fmaxf(1e-3f, cos_inner - cos_outer);
    float t = fminf(fmaxf((cd - cos_outer) * scale, 0.0f), 1.0f);
    return t * t;
}

static float range_window(const lpv_light *li, float dist)
{
    if (!(li->range > 0.0f))
        return 1.0f;
    float q = dist / li->range;
    float w = fminf(fmaxf(1.0f - q * q * q * q, 0.0f), 1.0f);
    return w * w;
}

/* Direct irradiance at p: ns is the cosine's normal, ng the side's geometric
 * normal (light behind it is cut off; shadow rays start eps along it). */
static void direct(const lpv_ref *r, const float p[3], const float ns[3], const float ng[3], float out[3])
{
    out[0] = out[1] = out[2] = 0.0f;
    float org[3];
    for (int i = 0; i < 3; ++i)
        org[i] = p[i] + r->eps * ng[i];
    for (uint32_t l = 0; l < r->light_count; ++l) {
        const lpv_light *li = &r->lights[l];
        float to_light[3], e, dist = INFINITY;
        if (li->type == LPV_LIGHT_DIRECTIONAL) {
            float neg[3] = {-li->direction[0], -li->direction[1], -li->direction[2]};
            if (!unit3(neg, to_light))
                continue;
            e = li->intensity;
        } else {
            float d[3] = {li->position[0] - p[0], li->position[1] - p[1], li->position[2] - p[2]};
            float dist2 = fmaxf(dot3(d, d), 1e-12f);
            dist = sqrtf(dist2);
            for (int i = 0; i < 3; ++i)
                to_light[i] = d[i] / dist;
            float travel[3] = {-to_light[0], -to_light[1], -to_light[2]};
            e = li->intensity * spot_factor(li, travel) * range_window(li, dist) / dist2;
        }
        float c = dot3(ns, to_light);
        if (!(e > 0.0f) || !isfinite(e) || !(c > 0.0f) || !(dot3(ng, to_light) > 0.0f))
            continue;
        float tmax = isfinite(dist) ? dist - 2.0f * r->eps : INFINITY;
        if (!(tmax > 0.0f))
            continue;
        const float pass = transmitted(r, org, to_light, tmax);
        if (!(pass > 0.0f))
            continue;
        for (int i = 0; i < 3; ++i)
            out[i] += li->color[i] * e * c * pass;
    }
}

/* One sample of the irradiance at p from the emissive surfaces (their front
 * sides, and the backs of double-sided ones), by next-event estimation: a
 * triangle by emitted power, a uniform point on it, a shadow ray. Unbiased;
 * ns the cosine's normal, ng the side's. */
static void emitter_direct(const lpv_ref *r, pcg32 *rng, const float p[3], const float ns[3], const float ng[3],
                           double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    if (!r->emitter_count)
        return;
    const double total = r->emitter_cdf[r->emitter_count];
    double u = (double)pcg32_float(rng) * total;
    uint32_t lo = 0, hi = r->emitter_count - 1; /* first k with cdf[k + 1] > u */
    while (lo < hi) {
        uint32_t mid = (lo + hi) / 2;
        if (r->emitter_cdf[mid + 1] > u)
            hi = mid;
        else
            lo = mid + 1;
    }
    const ref_tri *tr = &r->tris[r->emitters[lo]];
    const ref_material *m = &r->materials[tr->material];
    float s1 = sqrtf(pcg32_float(rng)), s2 = pcg32_float(rng);
    float b1 = s1 * (1.0f - s2), b2 = s1 * s2, q[3], d[3], le[3], uv0[2], uv1[2];
    tri_uv(tr, b1, b2, uv0, uv1, NULL);
    lpv_material_emission_at(&r->look, &r->look.materials[tr->material], uv0, uv1, le); /* at q: its texture */
    for (int i = 0; i < 3; ++i) {
        q[i] = tr->p0[i] + b1 * tr->e1[i] + b2 * tr->e2[i];
        d[i] = q[i] - p[i];
    }
    float dist2 = dot3(d, d), dist = sqrtf(dist2), w[3];
    if (!(dist > 2.0f * r->eps) || !isfinite(dist))
        return;
    for (int i = 0; i < 3; ++i)
        w[i] = d[i] / dist;
    float cos_r = dot3(ns, w), cos_e = -dot3(tr->front, w);
    if (m->sides == 2) /* p sees the side it faces, which emits either way */
        cos_e = fabsf(cos_e);
    if (!(cos_r > 0.0f) || !(cos_e > 0.0f) || !(dot3(ng, w) > 0.0f))
        return;
    /* The shadow ray leaves eps off the surface and is aimed at q from
     * there: along w from the offset origin it would meet the emitter's
     * plane eps (ng . n_e) / cos_e short of q, inside the 2 eps margin only
     * when cos_e > 1/2, and so shadow itself at grazing angles (14 % of a
     * large emitter's light lost 1 m under it). */
    float org[3], to_q[3];
    for (int i = 0; i < 3; ++i) {
        org[i] = p[i] + r->eps * ng[i];
        to_q[i] = q[i] - org[i];
    }
    float len = sqrtf(dot3(to_q, to_q));
    if (!(len > 2.0f * r->eps))
        return;
    for (int i = 0; i < 3; ++i)
        to_q[i] /= len;
    const float pass = transmitted(r, org, to_q, len - 2.0f * r->eps);
    if (!(pass > 0.0f))
        return;
    /* pdf per unit area of q: the triangle's share of the CDF (its mean
     * emission x area x sides) over its area, / total */
    const double pdf_area = (r->emitter_cdf[lo + 1] - r->emitter_cdf[lo]) / (total * tri_area(tr));
    if (!(pdf_area > 0.0))
        return;
    double g = (double)pass * cos_r * cos_e / dist2 / pdf_area;
    for (int i = 0; i < 3; ++i)
        out[i] = (isfinite(le[i]) && le[i] > 0.0f ? le[i] : 0.0f) * g;
}

void lpv_ref_direct_irradiance(const lpv_ref *r, const float p[3], const float n[3], float out_rgb[3])
{
    float nu[3];
    out_rgb[0] = out_rgb[1] = out_rgb[2] = 0.0f;
    if (!r || !finite3(p) || !unit3(n, nu))
        return;
    direct(r, p, nu, nu, out_rgb);
}

/* ---- the estimator --------------------------------------------------------- */

/* One sample of E_ind(p, ns, bounces) / pi, i.e. the radiance L arriving along
 * one cosine-distributed direction, with next-event estimation at every hit. */
static void sample_path(const lpv_ref *r, pcg32 *rng, const float p_in[3], const float ns_in[3], const float ng_in[3],
                        int bounces, double out[3])
{
    float p[3], ns[3], ng[3], thr[3] = {1.0f, 1.0f, 1.0f};
    memcpy(p, p_in, sizeof p);
    memcpy(ns, ns_in, sizeof ns);
    memcpy(ng, ng_in, sizeof ng);
    out[0] = out[1] = out[2] = 0.0;
    const int converged = bounces == LPV_REF_BOUNCES_CONVERGED;
    if (converged)
        bounces = r->max_bounces;
    for (int depth = 1; depth <= bounces; ++depth) {
        float dir[3], org[3];
        if (converged && depth > LPV_REF_RR_START) {
            float q = fminf(0.95f, fmaxf(thr[0], fmaxf(thr[1], thr[2])));
            if (!(pcg32_float(rng) < q))
                break;
            for (int i = 0; i < 3; ++i)
                thr[i] /= q;
        }
        sample_cosine(rng, ns, dir);
        if (!(dot3(dir, ng) > 0.0f))
            break; /* below the surface itself (shading normal != geometric) */
        for (int i = 0; i < 3; ++i)
            org[i] = p[i] + r->eps * ng[i];
        hit h;
        if (!intersect(r, org, dir, 0.0f, INFINITY, REF_BLEND_DRAW, r->has_blend ? pcg32_next(rng) : 0u, &h))
            break;
        float alb[3], ed[3] = {0.0f, 0.0f, 0.0f};
        hit_albedo(r, &h, alb);
        float le[3] = {0.0f, 0.0f, 0.0f};
        hit_emission(r, &h, le);
        if (alb[0] > 0.0f || alb[1] > 0.0f || alb[2] > 0.0f)
            direct(r, h.p, h.ns, h.ng, ed);
        for (int i = 0; i < 3; ++i)
            out[i] += (double)thr[i] * ((double)le[i] + (double)alb[i] / PT_PI * (double)ed[i]);
        if (depth == bounces)
            break;
        for (int i = 0; i < 3; ++i)
            thr[i] *= alb[i];
        if (!(thr[0] > 0.0f || thr[1] > 0.0f || thr[2] > 0.0f))
            break;
        memcpy(p, h.p, sizeof p);
        memcpy(ns, h.ns, sizeof ns);
        memcpy(ng, h.ng, sizeof ng);
    }
}

/* With the emissive surfaces as lights (next-event estimation, never hit
 * by chance): one sample of (with_direct: the emitters' direct irradiance at
 * p, plus) pi x the radiance arriving along one cosine-distributed direction
 * after 1..bounces diffuse reflections of direct light (punctual and
 * emitted) - already an irradiance, unlike sample_path's radiance. */
static void sample_path_lights(const lpv_ref *r, pcg32 *rng, const float p_in[3], const float ns_in[3],
                               const float ng_in[3], int bounces, int with_direct, double out[3])
{
    float p[3], ns[3], ng[3];
    double thr[3] = {1.0, 1.0, 1.0};
    memcpy(p, p_in, sizeof p);
    memcpy(ns, ns_in, sizeof ns);
    memcpy(ng, ng_in, sizeof ng);
    out[0] = out[1] = out[2] = 0.0;
    if (with_direct)
        emitter_direct(r, rng, p, ns, ng, out);
    const int converged = bounces == LPV_REF_BOUNCES_CONVERGED;
    if (converged)
        bounces = r->max_bounces;
    for (int depth = 1; depth <= bounces; ++depth) {
        float dir[3], org[3];
        if (converged && depth > LPV_REF_RR_START) {
            double q = fmin(0.95, fmax(thr[0], fmax(thr[1], thr[2])));
            if (!((double)pcg32_float(rng) < q))
                break;
            for (int i = 0; i < 3; ++i)
                thr[i] /= q;
        }
        sample_cosine(rng, ns, dir);
        if (!(dot3(dir, ng) > 0.0f))
            break;
        for (int i = 0; i < 3; ++i)
            org[i] = p[i] + r->eps * ng[i];
        hit h;
        if (!intersect(r, org, dir, 0.0f, INFINITY, REF_BLEND_DRAW, r->has_blend ? pcg32_next(rng) : 0u, &h))
            break;
        float alb[3], ed[3] = {0.0f, 0.0f, 0.0f};
        double ee[3] = {0.0, 0.0, 0.0};
        hit_albedo(r, &h, alb);
        if (!(alb[0] > 0.0f || alb[1] > 0.0f || alb[2] > 0.0f))
            break;
        direct(r, h.p, h.ns, h.ng, ed);
        emitter_direct(r, rng, h.p, h.ns, h.ng, ee);
        /* E = pi L, L = albedo / pi * E_direct(q): pi cancels */
        for (int i = 0; i < 3; ++i) {
            thr[i] *= alb[i];
            out[i] += thr[i] * ((double)ed[i] + ee[i]);
        }
        memcpy(p, h.p, sizeof p);
        memcpy(ns, h.ns, sizeof ns);
        memcpy(ng, h.ng, sizeof ng);
    }
}

/* E_ind and its standard error at one point, from `samples` samples of the
 * streams (index, 0..samples-1). with_direct (emitters as lights only): add
 * the emitters' direct irradiance (the full image's estimate). */
static void estimate_mode(const lpv_ref *r, uint64_t index, const float p[3], const float ns[3], const float ng[3],
                          int bounces, int samples, int lights_mode, int with_direct, float e[3], float se[3])
{
    double sum[3] = {0, 0, 0}, sq[3] = {0, 0, 0};
    for (int s = 0; s < samples; ++s) {
        pcg32 rng;
        pcg32_seed(&rng, r->seed, index, (uint64_t)s);
        double l[3];
        if (lights_mode)
            sample_path_lights(r, &rng, p, ns, ng, bounces, with_direct, l);
        else
            sample_path(r, &rng, p, ns, ng, bounces, l);
        for (int i = 0; i < 3; ++i) {
            double v = lights_mode ? l[i] : PT_PI * l[i];
            sum[i] += v;
            sq[i] += v * v;
        }
    }
    double n = (double)samples;
    for (int i = 0; i < 3; ++i) {
        double mean = sum[i] / n;
        double var = samples > 1 ? fmax(0.0, (sq[i] - sum[i] * mean) / (n - 1.0)) : 0.0;
        e[i] = (float)mean;
        se[i] = (float)sqrt(var / n);
    }
}

static void estimate(const lpv_ref *r, uint64_t index, const float p[3], const float ns[3], const float ng[3],
                     int bounces, int samples, float e[3], float se[3])
{
    estimate_mode(r, index, p, ns, ng, bounces, samples, r->emitters_are_lights, 0, e, se);
}

/* ---- threading ------------------------------------------------------------- */

typedef struct job {
    const lpv_ref *ref;
    size_t count;
    size_t next;
    pthread_mutex_t lock;
    void (*item)(struct job *j, size_t i);
    /* points mode */
    const float *points, *normals;
    float *out, *out_se;
    /* image mode */
    const lpv_view *view;
    float *rgba, *rgba_se;
    int bounces, samples;
    int full;  /* image mode: the full frame */
} job;

static void *worker(void *arg)
{
    job *j = arg;
    for (;;) {
        pthread_mutex_lock(&j->lock);
        size_t begin = j->next;
        j->next = begin + PT_CHUNK < j->count ? begin + PT_CHUNK : j->count;
        size_t end = j->next;
        pthread_mutex_unlock(&j->lock);
        if (begin >= end)
            return NULL;
        for (size_t i = begin; i < end; ++i)
            j->item(j, i);
    }
}

static void run_job(job *j)
{
    int n = j->ref->threads;
    if ((size_t)n > (j->count + PT_CHUNK - 1) / PT_CHUNK)
        n = (int)((j->count + PT_CHUNK - 1) / PT_CHUNK);
    pthread_mutex_init(&j->lock, NULL);
    j->next = 0;
    pthread_t tid[256];
    int started = 0;
    for (int t = 1; t < n; ++t) {
        if (pthread_create(&tid[started], NULL, worker, j) != 0)
            break; /* the calling thread finishes the work alone */
        started++;
    }
    worker(j);
    for (int t = 0; t < started; ++t)
        pthread_join(tid[t], NULL);
    pthread_mutex_destroy(&j->lock);
}

static void point_item(job *j, size_t i)
{
    float e[3] = {0, 0, 0}, se[3] = {0, 0, 0}, nu[3];
    const float *p = &j->points[3 * i];
    if (finite3(p) && unit3(&j->normals[3 * i], nu))
        estimate(j->ref, (uint64_t)i, p, nu, nu, j->bounces, j->samples, e, se);
    if (j->out)
        memcpy(&j->out[3 * i], e, sizeof e);
    if (j->out_se)
        memcpy(&j->out_se[3 * i], se, sizeof se);
}

int lpv_ref_irradiance(const lpv_ref *r, const float *points, const float *normals, size_t n, int bounces,
                       int samples, float *out_rgb, float *out_stderr_rgb)
{
    if (!r || (n && (!points || !normals)) || (bounces < 1 && bounces != LPV_REF_BOUNCES_CONVERGED) || samples < 1)
        return -1;
    if (!n)
        return 0;
    job j = {.ref = r, .count = n, .item = point_item, .points = points, .normals = normals, .out = out_rgb,
             .out_se = out_stderr_rgb, .bounces = bounces, .samples = samples};
    run_job(&j);
    return 0;
}

void lpv_ref_pixel_ray(const lpv_view *v, int x, int y, float org[3], float dir[3], float *tmin, float *tmax)
{
    /* The inverse of lpv_view_project (core/view.c): right = forward x up,
     * true up = right x forward, pixel (0, 0) at the top-left. */
    float f[3], r[3], u[3];
    if (!unit3(v->forward, f)) {
        f[0] = f[1] = 0.0f;
        f[2] = -1.0f;
    }
    cross3(f, v->up, r);
    if (!unit3(r, r)) {
        r[0] = 1.0f;
        r[1] = r[2] = 0.0f;
    }
    cross3(r, f, u);
    float aspect = (float)v->width / (float)v->height;
    float ndc_x = ((float)x + 0.5f) / (float)v->width * 2.0f - 1.0f;
    float ndc_y = 1.0f - ((float)y + 0.5f) / (float)v->height * 2.0f;
    float zn = v->znear > 0.0f ? v->znear : 0.0f, zf = v->zfar > 0.0f ? v->zfar : INFINITY;
    if (v->orthographic) {
        for (int i = 0; i < 3; ++i) {
            org[i] = v->eye[i] + ndc_x * v->ymag * aspect * r[i] + ndc_y * v->ymag * u[i];
            dir[i] = f[i];
        }
        *tmin = zn;
        *tmax = zf;
        return;
    }
    float th = tanf(0.5f * v->yfov), d[3];
    for (int i = 0; i < 3; ++i) {
        org[i] = v->eye[i];
        d[i] = f[i] + ndc_x * th * aspect * r[i] + ndc_y * th * u[i];
    }
    float len = sqrtf(dot3(d, d));
    for (int i = 0; i < 3; ++i)
        dir[i] = d[i] / len;
    float cz = dot3(dir, f); /* depth along forward per unit t */
    *tmin = zn / cz;
    *tmax = zf / cz;
}

/* The pixel's light from surface h, out (W/(m^2 sr)) and its standard
 * error se, as lpvd's frame shows it (j->full) or its indirect term. */
static void shade_hit(job *j, size_t i, const hit *hp, float out[3], float out_se[3])
{
    const hit h = *hp;
    float alb[3], e[3] = {0, 0, 0}, se[3] = {0, 0, 0}, ed[3] = {0, 0, 0};
    hit_albedo(j->ref, &h, alb);
    const float occ = hit_occlusion(j->ref, &h);
    if (alb[0] > 0.0f || alb[1] > 0.0f || alb[2] > 0.0f) {
        if (j->full && occ < 1.0f) {
            /* the bounces alone take the occlusion: the emitters' direct
             * light apart (its own streams), then the bounces */
            estimate_mode(j->ref, (uint64_t)i, h.p, h.ns, h.ng, j->bounces, j->samples, 1, 0, e, se);
            double em[3] = {0, 0, 0};
            for (int s = 0; s < j->samples; ++s) {
                pcg32 rng;
                pcg32_seed(&rng, j->ref->seed ^ 0x9e3779b97f4a7c15ull, (uint64_t)i, (uint64_t)s);
                double em_s[3];
                emitter_direct(j->ref, &rng, h.p, h.ns, h.ng, em_s);
                for (int c = 0; c < 3; ++c)
                    em[c] += em_s[c] / j->samples;
            }
            for (int c = 0; c < 3; ++c) {
                e[c] = occ * e[c] + (float)em[c];
                se[c] *= occ;
            }
            direct(j->ref, h.p, h.ns, h.ng, ed);
        } else if (j->full) { /* direct light (punctual exactly, emitters sampled) and the bounces */
            estimate_mode(j->ref, (uint64_t)i, h.p, h.ns, h.ng, j->bounces, j->samples, 1, 1, e, se);
            direct(j->ref, h.p, h.ns, h.ng, ed);
        } else {
            estimate(j->ref, (uint64_t)i, h.p, h.ns, h.ng, j->bounces, j->samples, e, se);
            for (int c = 0; c < 3; ++c) {
                e[c] *= occ;
                se[c] *= occ;
            }
        }
    }
    float le[3] = {0.0f, 0.0f, 0.0f};
    if (j->full && !hit_unlit(j->ref, &h, le))
        hit_emission(j->ref, &h, le);
    for (int c = 0; c < 3; ++c) {
        out[c] = (float)(alb[c] / PT_PI) * (e[c] + ed[c]) + le[c];
        out_se[c] = (float)(alb[c] / PT_PI) * se[c];
    }
}

/* The share of the pixel a hit surface covers: its alpha for a BLEND
 * material (coverage), else 1. */
static float hit_coverage(const lpv_ref *r, const hit *h)
{
    const ref_tri *tr = &r->tris[h->tri];
    if (tr->material < 0 || r->look.materials[tr->material].alpha_mode != LPV_ALPHA_BLEND)
        return 1.0f;
    float uv0[2], uv1[2], color[4];
    tri_uv(tr, h->u, h->v, uv0, uv1, color);
    const float a = lpv_material_alpha_at(&r->look, &r->look.materials[tr->material], uv0, uv1, color[3]);
    return a > 0.0f ? (a < 1.0f ? a : 1.0f) : 0.0f;
}

/* Translucent layers a pixel composites before it takes the rest as hidden. */
#define REF_MAX_LAYERS 16

static void pixel_item(job *j, size_t i)
{
    const lpv_view *v = j->view;
    int x = (int)(i % (size_t)v->width), y = (int)(i / (size_t)v->width);
    float org[3], dir[3], tmin, tmax;
    float *px = &j->rgba[4 * i], *pse = j->rgba_se ? &j->rgba_se[4 * i] : NULL;
    px[0] = px[1] = px[2] = px[3] = 0.0f;
    if (pse)
        pse[0] = pse[1] = pse[2] = pse[3] = 0.0f;
    lpv_ref_pixel_ray(v, x, y, org, dir, &tmin, &tmax);
    if (!finite3(org) || !finite3(dir))
        return;
    /* Front to back through the BLEND surfaces, each weighing its alpha of
     * what is left ("over", as lpvd's frame lays its translucent layer over
     * the opaque one), to the first opaque surface. */
    float left = 1.0f;
    for (int layer = 0; layer < REF_MAX_LAYERS && left > 1e-6f; ++layer) {
        hit h;
        if (!intersect(j->ref, org, dir, tmin, tmax, REF_BLEND_HIT, 0u, &h))
            break;
        const float a = hit_coverage(j->ref, &h);
        float c[3], cse[3];
        shade_hit(j, i, &h, c, cse);
        for (int k = 0; k < 3; ++k) {
            px[k] += left * a * c[k];
            if (pse)
                pse[k] += left * a * cse[k];
        }
        left *= 1.0f - a;
        tmin = h.t + j->ref->eps;
    }
    px[3] = 1.0f - left;
    if (pse)
        pse[3] = px[3];
}

int lpv_ref_render_indirect(const lpv_ref *r, const lpv_view *view, int bounces, int spp, float *rgba, float *rgba_se)
{
    if (!r || !view || !rgba || view->width < 1 || view->height < 1 ||
        (bounces < 1 && bounces != LPV_REF_BOUNCES_CONVERGED) || spp < 1)
        return -1;
    job j = {.ref = r, .count = (size_t)view->width * (size_t)view->height, .item = pixel_item, .view = view,
             .rgba = rgba, .rgba_se = rgba_se, .bounces = bounces, .samples = spp};
    run_job(&j);
    return 0;
}

int lpv_ref_render_full(const lpv_ref *r, const lpv_view *view, int bounces, int spp, float *rgba, float *rgba_se)
{
    if (!r || !view || !rgba || view->width < 1 || view->height < 1 ||
        (bounces < 0 && bounces != LPV_REF_BOUNCES_CONVERGED) || spp < 1)
        return -1;
    job j = {.ref = r, .count = (size_t)view->width * (size_t)view->height, .item = pixel_item, .view = view,
             .rgba = rgba, .rgba_se = rgba_se, .bounces = bounces, .samples = spp, .full = 1};
    run_job(&j);
    return 0;
}

int lpv_ref_emitter_irradiance(const lpv_ref *r, const float *points, const float *normals, size_t n, int samples,
                               float *out_rgb, float *out_stderr_rgb)
{
    if (!r || (n && (!points || !normals)) || samples < 1)
        return -1;
    for (size_t i = 0; i < n; ++i) {
        float nu[3];
        double sum[3] = {0, 0, 0}, sq[3] = {0, 0, 0};
        const float *p = &points[3 * i];
        if (finite3(p) && unit3(&normals[3 * i], nu))
            for (int s = 0; s < samples; ++s) {
                pcg32 rng;
                pcg32_seed(&rng, r->seed, (uint64_t)i, (uint64_t)s);
                double v[3];
                emitter_direct(r, &rng, p, nu, nu, v);
                for (int c = 0; c < 3; ++c) {
                    sum[c] += v[c];
                    sq[c] += v[c] * v[c];
                }
            }
        for (int c = 0; c < 3; ++c) {
            double mean = sum[c] / samples;
            double var = samples > 1 ? fmax(0.0, (sq[c] - sum[c] * mean) / (samples - 1.0)) : 0.0;
            if (out_rgb)
                out_rgb[3 * i + (size_t)c] = (float)mean;
            if (out_stderr_rgb)
                out_stderr_rgb[3 * i + (size_t)c] = (float)sqrt(var / samples);
        }
    }
    return 0;
}

double lpv_ref_mean_relative_stderr(const float *rgba, const float *rgba_se, int width, int height)
{
    double sum = 0.0;
    size_t n = 0;
    if (!rgba || !rgba_se || width < 1 || height < 1)
        return 0.0;
    for (size_t i = 0; i < (size_t)width * (size_t)height; ++i) {
        if (!(rgba[4 * i + 3] > 0.0f))
            continue;
        for (int c = 0; c < 3; ++c) {
            float v = rgba[4 * i + (size_t)c];
            if (v > 0.0f && isfinite(v)) {
                sum += (double)rgba_se[4 * i + (size_t)c] / (double)v;
                n++;
            }
        }
    }
    return n ? sum / (double)n : 0.0;
}
