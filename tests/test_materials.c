/*
 * test_materials.c - glTF material features on the real GL path (issue 10):
 * alpha-masked and blended occluders cast shadows only where opaque (shadow
 * maps, G-buffer, geometry-volume surfels), single-sided back faces are
 * culled for the camera but still shadow, double-sided back faces shade with
 * the flipped normal, normal maps tilt the shading normal the way glTF says
 * (per-pixel frames and the file's TANGENTs alike), KHR_texture_transform and
 * TEXCOORD_1 move textures as specified, and the loader names each unused
 * feature once.
 *
 * The .glb files are built here: quads with normals and uvs, materials and
 * textures written as JSON (single quotes, see test_util.h), PNGs encoded
 * through lpv_image, a directional light of 683 lx = 1 W/m^2.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
/* cmocka.h after the headers it needs */
#include <cmocka.h>

#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "engine.h"
#include "gltf_load.h"
#include "emissive.h"
#include "image_io.h"
#include "iv_points.h"
#include "material_sample.h"
#include "oracle.h"
#include "pt.h"
#include "scene.h"
#include "test_util.h"
#include "view.h"

#define J lpvt_json

enum { W = 128, H = 128 };

/* ---- a small .glb builder --------------------------------------------------- */

typedef struct glb {
    unsigned char *bin;
    size_t n, cap;
    char views[8192], accessors[16384], meshes[8192], nodes[8192], images[2048];
    int view_count, accessor_count, mesh_count, node_count, image_count;
} glb;

static void cat(char *dst, size_t cap, const char *fmt, ...)
{
    size_t len = strlen(dst);
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(dst + len, cap - len, fmt, ap);
    va_end(ap);
    assert_true(n >= 0 && (size_t)n < cap - len);
}

static int add_view(glb *g, const void *data, size_t size)
{
    while (g->n % 4)
        g->bin[g->n++] = 0; /* (cap keeps room: grown below) */
    if (g->n + size + 4 > g->cap) {
        g->cap = (g->n + size + 4) * 2;
        g->bin = realloc(g->bin, g->cap);
        assert_non_null(g->bin);
    }
    memcpy(g->bin + g->n, data, size);
    cat(g->views, sizeof g->views, "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}", g->view_count ? "," : "",
        g->n, size);
    g->n += size;
    return g->view_count++;
}

static int add_accessor(glb *g, const void *data, size_t count, int comps, int ctype)
{
    static const char *types[] = {"", "SCALAR", "VEC2", "VEC3", "VEC4"};
    size_t csize = ctype == 5126 || ctype == 5125 ? 4 : 2;
    int v = add_view(g, data, count * (size_t)comps * csize);
    cat(g->accessors, sizeof g->accessors,
        "%s{\"bufferView\":%d,\"componentType\":%d,\"count\":%zu,\"type\":\"%s\"}", g->accessor_count ? "," : "", v,
        ctype, count, types[comps]);
    return g->accessor_count++;
}

typedef struct quad {
    float c[4][3];      /* corners, counter-clockwise seen from the front */
    float uv[4][2];     /* TEXCOORD_0 */
    const float *uv1;   /* 8 floats: TEXCOORD_1, or NULL */
    const float *tangent; /* 4 floats for every corner, or NULL */
    const float *color;   /* 16 floats: COLOR_0 (VEC4) at the corners, or NULL */
    int material;
} quad;

/* A quad as one mesh on one node, with flat normals from its winding. */
static void add_quad(glb *g, const quad *q)
{
    float e1[3], e2[3], n[3], nrm[4][3];
    for (int k = 0; k < 3; k++) {
        e1[k] = q->c[1][k] - q->c[0][k];
        e2[k] = q->c[2][k] - q->c[0][k];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    float l = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int c = 0; c < 4; c++)
        for (int k = 0; k < 3; k++)
            nrm[c][k] = n[k] / l;
    static const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    int ap = add_accessor(g, q->c, 4, 3, 5126);
    int an = add_accessor(g, nrm, 4, 3, 5126);
    int at = add_accessor(g, q->uv, 4, 2, 5126);
    int ai = add_accessor(g, idx, 6, 1, 5123);
    char extra[256] = "";
    if (q->uv1)
        snprintf(extra + strlen(extra), sizeof extra - strlen(extra), ",\"TEXCOORD_1\":%d",
                 add_accessor(g, q->uv1, 4, 2, 5126));
    if (q->tangent) {
        float t[4][4];
        for (int c = 0; c < 4; c++)
            memcpy(t[c], q->tangent, sizeof t[c]);
        snprintf(extra + strlen(extra), sizeof extra - strlen(extra), ",\"TANGENT\":%d", add_accessor(g, t, 4, 4, 5126));
    }
    if (q->color)
        snprintf(extra + strlen(extra), sizeof extra - strlen(extra), ",\"COLOR_0\":%d",
                 add_accessor(g, q->color, 4, 4, 5126));
    cat(g->meshes, sizeof g->meshes,
        "%s{\"primitives\":[{\"attributes\":{\"POSITION\":%d,\"NORMAL\":%d,\"TEXCOORD_0\":%d%s},\"indices\":%d,"
        "\"material\":%d}]}",
        g->mesh_count ? "," : "", ap, an, at, extra, ai, q->material);
    cat(g->nodes, sizeof g->nodes, "%s{\"mesh\":%d}", g->node_count ? "," : "", g->mesh_count);
    g->mesh_count++;
    g->node_count++;
}

/* n points as one mesh of glTF mode `mode` (0 points, 1 lines, 2 loop, 3
 * strip), positions only, on one node. */
static void add_wire(glb *g, const float (*p)[3], int n, int mode, int material)
{
    int ap = add_accessor(g, p, (size_t)n, 3, 5126);
    cat(g->meshes, sizeof g->meshes, "%s{\"primitives\":[{\"attributes\":{\"POSITION\":%d},\"mode\":%d,\"material\":%d}]}",
        g->mesh_count ? "," : "", ap, mode, material);
    cat(g->nodes, sizeof g->nodes, "%s{\"mesh\":%d}", g->node_count ? "," : "", g->mesh_count);
    g->mesh_count++;
    g->node_count++;
}

/* An RGBA8 image as a PNG in the BIN chunk; returns its image index. */
static int add_png(glb *g, int w, int h, const uint8_t *rgba)
{
    uint8_t *png = NULL;
    size_t len = 0;
    char err[256];
    if (lpv_image_encode_u8("png", w, h, 4, rgba, &png, &len, err, sizeof err) != 0)
        fail_msg("%s", err);
    int v = add_view(g, png, len);
    free(png);
    cat(g->images, sizeof g->images, "%s{\"bufferView\":%d,\"mimeType\":\"image/png\"}", g->image_count ? "," : "", v);
    return g->image_count++;
}

/* A directional light travelling along d (unit), 683 lx = 1 W/m^2: the
 * node's -Z axis is d (the loader normalises the light's direction only). */
static void add_sun(glb *g, const float d[3])
{
    cat(g->nodes, sizeof g->nodes,
        "%s{\"matrix\":[1,0,0,0, 0,1,0,0, %g,%g,%g,0, 0,0,0,1],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}",
        g->node_count ? "," : "", -d[0], -d[1], -d[2]);
    g->node_count++;
}

static void put_le32(unsigned char *p, uint32_t v)
{
    for (int k = 0; k < 4; k++)
        p[k] = (unsigned char)(v >> (8 * k));
}

/* Finishes the file: materials and textures JSON as given. Returns the
 * .glb bytes (malloc) and frees the builder. */
static unsigned char *glb_finish(glb *g, const char *materials, const char *textures, const char *extensions_used,
                                 size_t *out_len)
{
    char *json = malloc(65536);
    assert_non_null(json);
    char scene_nodes[1024] = "";
    for (int i = 0; i < g->node_count; i++)
        cat(scene_nodes, sizeof scene_nodes, "%s%d", i ? "," : "", i);
    snprintf(json, 65536,
             "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_lights_punctual\"%s%s],"
             "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"directional\",\"intensity\":683}]}},"
             "\"scene\":0,\"scenes\":[{\"nodes\":[%s]}],\"nodes\":[%s],\"meshes\":[%s],\"materials\":[%s],"
             "\"textures\":[%s],\"images\":[%s],\"samplers\":[{}],\"accessors\":[%s],\"bufferViews\":[%s],"
             "\"buffers\":[{\"byteLength\":%zu}]}",
             extensions_used && *extensions_used ? "," : "", extensions_used ? extensions_used : "", scene_nodes,
             g->nodes, g->meshes, materials, textures ? textures : "", g->images, g->accessors, g->views,
             (g->n + 3) & ~(size_t)3);
    for (char *c = json; *c; c++)
        if (*c == '\'')
            *c = '"';
    size_t jl = strlen(json), jpad = (jl + 3) & ~(size_t)3, bpad = (g->n + 3) & ~(size_t)3;
    size_t total = 12 + 8 + jpad + 8 + bpad;
    unsigned char *out = calloc(1, total);
    assert_non_null(out);
    memcpy(out, "glTF", 4);
    put_le32(out + 4, 2);
    put_le32(out + 8, (uint32_t)total);
    put_le32(out + 12, (uint32_t)jpad);
    memcpy(out + 16, "JSON", 4);
    memcpy(out + 20, json, jl);
    memset(out + 20 + jl, ' ', jpad - jl);
    unsigned char *c = out + 20 + jpad;
    put_le32(c, (uint32_t)bpad);
    memcpy(c + 4, "BIN\0", 4);
    memcpy(c + 8, g->bin, g->n);
    free(json);
    free(g->bin);
    memset(g, 0, sizeof *g);
    *out_len = total;
    return out;
}

static void load_glb(const unsigned char *data, size_t len, lpv_scene *s, lpv_gltf_warnings *w)
{
    char err[512] = "";
    if (lpv_gltf_load_memory_w(data, len, NULL, "test.glb", NULL, 0, s, w, err, sizeof err) != 0)
        fail_msg("load failed: %s", err);
}

/* ---- rendering ------------------------------------------------------------- */

static void render(const lpv_scene *scene, const lpv_view *view, float *rgba)
{
    char err[1024] = "";
    lpv_settings s = {.technique = LPV_TECHNIQUE_ID_LPV, .rsm_size = 512};
    if (lpv_engine_set_settings(lpvt_engine, &s, err, sizeof err) ||
        lpv_engine_set_scene(lpvt_engine, scene, err, sizeof err) ||
        lpv_engine_set_view(lpvt_engine, view, err, sizeof err) || lpv_engine_tick(lpvt_engine, err, sizeof err) ||
        lpv_engine_render(lpvt_engine, LPV_TERMS_DIRECT_ONLY, rgba, err, sizeof err))
        fail_msg("%s", err);
}

/* Mean radiance over the 3x3 pixels around world point p (test_util). */
static void patch(const lpv_view *v, const float *rgba, const float p[3], double out[3])
{
    lpvt_patch(v, rgba, W, H, p, 1, out);
}

static double lum(const double c[3]) { return c[0] + c[1] + c[2]; }

/* ---- the occluder scene ----------------------------------------------------------
 * A 6 m white floor at y = 0 and a 2 m occluder (material 1) at y = 1 over
 * x, z in [-1, 1]; the sun travels along (1, -1, 0)/sqrt(2), so the
 * occluder's shadow falls on x in [0, 2], where a camera on the +x side sees
 * the floor past the occluder. The occluder's uv: u = (x+1)/2, v = (z+1)/2. */

static const float FLOOR_C[4][3] = {{-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3}};
static const float OCC_UP[4][3] = {{-1, 1, 1}, {1, 1, 1}, {1, 1, -1}, {-1, 1, -1}};   /* front faces +y */
static const float OCC_DOWN[4][3] = {{-1, 1, -1}, {1, 1, -1}, {1, 1, 1}, {-1, 1, 1}}; /* front faces -y */

static void floor_quad(quad *q, int material)
{
    memset(q, 0, sizeof *q);
    memcpy(q->c, FLOOR_C, sizeof q->c);
    for (int c = 0; c < 4; c++) {
        q->uv[c][0] = (q->c[c][0] + 3.0f) / 6.0f;
        q->uv[c][1] = (q->c[c][2] + 3.0f) / 6.0f;
    }
    q->material = material;
}

static void occluder_quad(quad *q, const float c4[4][3], int material)
{
    memset(q, 0, sizeof *q);
    memcpy(q->c, c4, sizeof q->c);
    for (int c = 0; c < 4; c++) {
        q->uv[c][0] = (q->c[c][0] + 1.0f) / 2.0f;
        q->uv[c][1] = (q->c[c][2] + 1.0f) / 2.0f;
    }
    q->material = material;
}

/* 8x8 red texels, opaque where v < 0.5 (z < 0 on the occluder), alpha 0 elsewhere. */
static int add_mask_png(glb *g)
{
    uint8_t px[8 * 8 * 4];
    for (int y = 0; y < 8; y++)
        for (int x = 0; x < 8; x++) {
            uint8_t *p = &px[(y * 8 + x) * 4];
            p[0] = 255, p[1] = 0, p[2] = 0, p[3] = y < 4 ? 255 : 0;
        }
    return add_png(g, 8, 8, px);
}

#define FLOOR_MAT "{'pbrMetallicRoughness':{'baseColorFactor':[0.8,0.8,0.8,1],'metallicFactor':0}}"

/* Builds the occluder scene with the occluder's material JSON (textures
 * JSON: the mask PNG is image 0) and loads it. */
static void occluder_scene(const char *occluder_material, const float occ[4][3], const float sun[3], lpv_scene *s,
                           lpv_gltf_warnings *w)
{
    glb g = {0};
    quad f, o;
    floor_quad(&f, 0);
    occluder_quad(&o, occ, 1);
    add_quad(&g, &f);
    add_quad(&g, &o);
    add_mask_png(&g);
    add_sun(&g, sun);
    size_t len;
    unsigned char *data =
        glb_finish(&g, J("%s,%s", FLOOR_MAT, occluder_material), J("{'source':0,'sampler':0}"), NULL, &len);
    load_glb(data, len, s, w);
    free(data);
}

static const float SUN_DIAGONAL[3] = {0.70710678f, -0.70710678f, 0.0f};
static const float SUN_DOWN[3] = {0.0f, -1.0f, 0.0f};

typedef struct occ_result {
    double a, b, c;       /* floor radiance: shadow of the z<0 half, of the z>0 half, unshadowed */
    double top_red, top_green; /* camera pixel over the occluder's z>0 half: r and g */
    double rsm_area;      /* RSM surfel area on the occluder plane, m^2 */
    double cam_area;      /* camera surfel area on the occluder plane, m^2 */
    double scene_area;    /* scene surfel area on the occluder plane, m^2 (settings.scene_surfels) */
} occ_result;

static double surfel_area_at_height(size_t buffer, float y)
{
    size_t n = 1 << 21;
    lpv_surfel *sf = calloc(n, sizeof *sf);
    assert_non_null(sf);
    size_t got = lpv_engine_read_surfels(lpvt_engine, buffer, sf, n);
    assert_true(got > 0);
    double area = 0.0;
    for (size_t i = 0; i < got; i++)
        if (sf[i].position[3] > 0.0f && fabsf(sf[i].position[1] - y) < 0.02f)
            area += sf[i].position[3];
    free(sf);
    return area;
}

static occ_result run_occluder(const char *occluder_material)
{
    lpv_scene s;
    occluder_scene(occluder_material, OCC_UP, SUN_DIAGONAL, &s, NULL);
    lpv_view v;
    assert_int_equal(lpv_view_look_at((float[3]){4.5f, 5.0f, 0.0f}, (float[3]){0.8f, 0.3f, 0.0f}, 0.9f, W, H, &v), 0);
    float *rgba = calloc((size_t)W * H * 4, sizeof *rgba);
    render(&s, &v, rgba);
    occ_result r;
    double px[3];
    patch(&v, rgba, (float[3]){1.5f, 0.0f, -0.5f}, px);
    r.a = lum(px);
    patch(&v, rgba, (float[3]){1.5f, 0.0f, 0.5f}, px);
    r.b = lum(px);
    patch(&v, rgba, (float[3]){2.5f, 0.0f, 0.0f}, px);
    r.c = lum(px);
    patch(&v, rgba, (float[3]){0.0f, 1.0f, 0.5f}, px);
    r.top_red = px[0];
    r.top_green = px[1];
    r.rsm_area = surfel_area_at_height(0, 1.0f);
    /* the GV buffers: the RSM's, then the camera's, then the scene surfels' (on in the defaults) */
    const size_t buffers = lpv_engine_gv_buffer_count(lpvt_engine);
    assert_int_equal(lpv_engine_settings(lpvt_engine)->scene_surfels, LPV_SWITCH_ON);
    assert_int_equal(buffers, 3);
    r.cam_area = surfel_area_at_height(buffers - 2, 1.0f);
    r.scene_area = surfel_area_at_height(buffers - 1, 1.0f);
    free(rgba);
    lpv_scene_free(&s);
    return r;
}

static void print_result(const char *what, const occ_result *r)
{
    printf("%-14s floor under z<0 half %.4f, under z>0 half %.4f, unshadowed %.4f (W/(m^2 sr), rgb sum); "
           "pixel over z>0 half r %.4f g %.4f; occluder surfels: RSM %.3f m^2, camera %.3f m^2, scene %.3f m^2\n",
           what, r->a, r->b, r->c, r->top_red, r->top_green, r->rsm_area, r->cam_area, r->scene_area);
}

/* MASK: the cut-away half lets light through (floor lit as if unshadowed),
 * the opaque half shadows; OPAQUE (same texture) shadows both halves. */
static void test_alpha_mask_shadows_only_where_opaque(void **state)
{
    (void)state;
    occ_result op = run_occluder("{'pbrMetallicRoughness':{'baseColorTexture':{'index':0},'metallicFactor':0}}");
    occ_result mk = run_occluder(
        "{'alphaMode':'MASK','alphaCutoff':0.5,'pbrMetallicRoughness':{'baseColorTexture':{'index':0},"
        "'metallicFactor':0}}");
    print_result("OPAQUE", &op);
    print_result("MASK", &mk);
    assert_true(op.c > 0.05);
    /* OPAQUE: both halves shadow */
    assert_true(op.a < 0.1 * op.c);
    assert_true(op.b < 0.1 * op.c);
    /* MASK: only the opaque half shadows; light passes the cut-away half */
    assert_true(mk.a < 0.1 * mk.c);
    assert_true(fabs(mk.b - mk.c) < 0.05 * mk.c);
    /* the camera sees the red occluder there with OPAQUE, the (white) floor
     * through it with MASK */
    assert_true(op.top_red > 5.0 * op.top_green);
    assert_true(mk.top_green > 0.5 * mk.top_red);
    /* geometry-volume surfels: half the occluder is gone from both buffers */
    assert_true(op.rsm_area > 1.0);
    assert_true(mk.rsm_area > 0.4 * op.rsm_area && mk.rsm_area < 0.6 * op.rsm_area);
    assert_true(op.cam_area > 0.5);
    assert_true(mk.cam_area > 0.35 * op.cam_area && mk.cam_area < 0.65 * op.cam_area);
    /* scene surfels: the opaque occluder is sampled, the cut-out one is left
     * to the RSM and the camera (they do not read the alpha texture) */
    assert_true(op.scene_area > 1.0);
    assert_true(mk.scene_area == 0.0);
}

/* BLEND is coverage (docs/scenes.md, "Alpha"): a pane of alpha a lets 1 - a
 * of the light through in the shadow maps and the RSM (whose surfels and
 * VPLs it keeps on a of their texels), the camera shows a x the pane over
 * (1 - a) x the floor behind it, and the G-buffer's surfels leave it to the
 * RSM. Before, BLEND was a cut at 0.5: alpha 0.3 vanished, 0.7 was opaque. */
static void test_alpha_blend_coverage(void **state)
{
    (void)state;
    const double alphas[2] = {0.3, 0.7};
    occ_result op = run_occluder("{'pbrMetallicRoughness':{'baseColorFactor':[1,0,0,1],'metallicFactor':0}}");
    print_result("OPAQUE red", &op);
    assert_false(lpvt_stage("translucent", NULL, NULL)); /* no BLEND: no layer (the plan skips it) */
    for (int k = 0; k < 2; k++) {
        char mat[256], what[32];
        snprintf(mat, sizeof mat,
                 "{'alphaMode':'BLEND','pbrMetallicRoughness':{'baseColorFactor':[1,0,0,%.1f],'metallicFactor':0}}",
                 alphas[k]);
        snprintf(what, sizeof what, "BLEND a=%.1f", alphas[k]);
        occ_result r = run_occluder(mat);
        print_result(what, &r);
        assert_true(lpvt_stage("translucent", NULL, NULL));
        const double a = alphas[k];
        /* the floor under the pane gets 1 - a of the light (the indirect
         * light, a few percent of c, is in both) */
        assert_true(fabs(r.a / r.c - (1.0 - a)) < 0.08);
        assert_true(fabs(r.b / r.c - (1.0 - a)) < 0.08);
        /* the RSM keeps a of the pane's texels as surfels */
        assert_true(fabs(r.rsm_area / op.rsm_area - a) < 0.05);
        /* the camera's surfels are the opaque surfaces' only; the scene's
         * leave the pane out as they leave MASK out */
        assert_true(r.cam_area < 0.01 * op.cam_area);
        assert_true(r.scene_area == 0.0);
        /* the pixel over the pane: a x the red pane (lit as the opaque one)
         * + (1 - a) x the floor beneath (green only from the floor: the
         * pane has none), within 10 % */
        const double floor_g = r.top_green / (1.0 - a);
        assert_true(r.top_green > 0.0);
        assert_true(fabs(r.top_red - (a * op.top_red + (1.0 - a) * floor_g)) < 0.1 * r.top_red);
    }
}

/* The loader no longer warns about BLEND: it is drawn as glTF says. */
static void test_alpha_blend_no_warning(void **state)
{
    (void)state;
    lpv_scene s;
    lpv_gltf_warnings w;
    occluder_scene("{'alphaMode':'BLEND','pbrMetallicRoughness':{'baseColorFactor':[1,0,0,0.3]}}", OCC_UP,
                   SUN_DIAGONAL, &s, &w);
    for (int i = 0; i < w.count; i++)
        assert_null(strstr(w.line[i], "BLEND"));
    assert_int_equal(s.materials[1].alpha_mode, LPV_ALPHA_BLEND);
    lpv_scene_free(&s);
}

/* BLEND in the reference and iv's points (issue 32, item 3): the path
 * tracer's rays pass a pane of alpha a with probability 1 - a, so the
 * direct light under it, averaged over the points of a grid, is 1 - a of
 * the open floor's; iv keeps the pane's points in a of its voxels. */
static void test_blend_in_reference_and_points(void **state)
{
    (void)state;
    lpv_scene s;
    occluder_scene("{'alphaMode':'BLEND','pbrMetallicRoughness':{'baseColorFactor':[1,0,0,0.3],'metallicFactor':0}}",
                   OCC_UP, SUN_DOWN, &s, NULL);
    lpv_ref *ref = NULL;
    char err[512] = "";
    assert_int_equal(lpv_ref_create(&s, NULL, &ref, err, sizeof err), 0);
    const float up[3] = {0, 1, 0};
    float open[3];
    lpv_ref_direct_irradiance(ref, (float[3]){2.5f, 0.0f, 0.0f}, up, open);
    double under = 0.0;
    int n = 0;
    for (int i = 0; i < 30; i++)
        for (int j = 0; j < 30; j++, n++) {
            float e[3];
            lpv_ref_direct_irradiance(ref, (float[3]){-0.95f + 1.9f * (float)i / 29.0f, 0.0f,
                                                      -0.95f + 1.9f * (float)j / 29.0f}, up, e);
            under += e[1];
        }
    under /= n;
    lpv_ref_destroy(ref);
    printf("reference direct irradiance (g): under the pane (mean of %d points) %.4f, open floor %.4f: %.3f\n", n,
           under, open[1], under / open[1]);
    assert_true(open[1] > 0.5f);
    assert_true(fabs(under / open[1] - 0.7) < 0.06);

    lpv_iv_point_params pp = {.voxel = 0.1f, .points = 4, .split = 0.5f, .max_points = 1 << 22, .seed = 7};
    struct IvPoint *pts = NULL;
    size_t np = 0;
    assert_int_equal(lpv_iv_points_make(&s, &pp, &pts, &np, NULL), 0);
    /* the pane's 20 x 20 voxels of 0.1 m: which hold a point */
    int held[20][20] = {{0}};
    size_t on_pane = 0;
    for (size_t i = 0; i < np; i++)
        if (fabsf(pts[i].position[1] - 1.0f) < 1e-4f) {
            int x = (int)floorf((pts[i].position[0] + 1.0f) / 0.1f), z = (int)floorf((pts[i].position[2] + 1.0f) / 0.1f);
            if (x >= 0 && x < 20 && z >= 0 && z < 20)
                held[x][z] = 1;
            on_pane++;
        }
    int voxels = 0;
    for (int x = 0; x < 20; x++)
        for (int z = 0; z < 20; z++)
            voxels += held[x][z];
    printf("iv points on the pane: %zu, in %d of its 400 voxels (%.3f)\n", on_pane, voxels, voxels / 400.0);
    assert_true(fabs(voxels / 400.0 - 0.3) < 0.08);
    free(pts);
    lpv_scene_free(&s);
}

/* The occluder faces down and the camera looks from above, at its back:
 * single-sided it is culled (the camera sees the shadowed floor beneath,
 * so the light still saw it), double-sided it shows with its normal turned
 * to the camera, shading like a quad that faces up. */
static double occluder_pixel(const char *material, const float occ[4][3], double rgb[3])
{
    lpv_scene s;
    occluder_scene(material, occ, SUN_DOWN, &s, NULL);
    lpv_view v;
    assert_int_equal(lpv_view_look_at((float[3]){0.0f, 6.0f, 2.0f}, (float[3]){0.0f, 0.0f, 0.0f}, 0.9f, W, H, &v), 0);
    float *rgba = calloc((size_t)W * H * 4, sizeof *rgba);
    render(&s, &v, rgba);
    patch(&v, rgba, (float[3]){0.0f, 1.0f, 0.0f}, rgb);
    double lit[3];
    patch(&v, rgba, (float[3]){2.0f, 0.0f, 2.0f}, lit); /* the floor in the open */
    free(rgba);
    lpv_scene_free(&s);
    return lum(lit);
}

static void test_double_sided(void **state)
{
    (void)state;
    const char *single = "{'pbrMetallicRoughness':{'baseColorFactor':[1,0,0,1],'metallicFactor':0}}";
    const char *twosided =
        "{'doubleSided':true,'pbrMetallicRoughness':{'baseColorFactor':[1,0,0,1],'metallicFactor':0}}";
    double down1[3], down2[3], up1[3];
    double lit = occluder_pixel(single, OCC_DOWN, down1);
    occluder_pixel(twosided, OCC_DOWN, down2);
    occluder_pixel(single, OCC_UP, up1);
    printf("open floor %.4f; over the occluder: back of a single-sided one %.4f %.4f %.4f, back of a double-sided "
           "one %.4f %.4f %.4f, front of a single-sided one %.4f %.4f %.4f\n",
           lit, down1[0], down1[1], down1[2], down2[0], down2[1], down2[2], up1[0], up1[1], up1[2]);
    assert_true(lit > 0.05);
    /* culled for the camera: the floor shows, in the shadow the light still casts */
    assert_true(lum(down1) < 0.1 * lit);
    /* double-sided: the red back face, lit from above through its flipped normal */
    assert_true(down2[0] > 0.1 && down2[0] > 10.0 * down2[1]);
    assert_true(fabs(down2[0] - up1[0]) < 0.02 * up1[0]);
    /* the loader keeps the flag */
    lpv_scene s;
    occluder_scene(twosided, OCC_DOWN, SUN_DOWN, &s, NULL);
    assert_int_equal(s.materials[1].double_sided, 1);
    assert_int_equal(s.materials[0].double_sided, 0);
    lpv_scene_free(&s);
}

/* ---- normal maps ----------------------------------------------------------------
 * The floor (u along +x, v along +z) with a constant normal map whose
 * tangent-space normal leans towards +Y, i.e. towards decreasing v (glTF:
 * +Y is up in the image): the shading normal leans to -z by 30 degrees. */

static double floor_with_normal_map(const char *normal_texture, const float *tangent, const float sun[3])
{
    glb g = {0};
    quad f;
    floor_quad(&f, 0);
    f.tangent = tangent;
    add_quad(&g, &f);
    uint8_t px[4 * 4 * 4];
    for (int i = 0; i < 16; i++) { /* (0, 0.5, 0.866) encoded */
        px[i * 4 + 0] = 128, px[i * 4 + 1] = 191, px[i * 4 + 2] = 238, px[i * 4 + 3] = 255;
    }
    add_png(&g, 4, 4, px);
    add_sun(&g, sun);
    size_t len;
    const char *mat =
        normal_texture ? J("{'normalTexture':%s,'pbrMetallicRoughness':{'baseColorFactor':[0.8,0.8,0.8,1],"
                           "'metallicFactor':0}}",
                           normal_texture)
                       : FLOOR_MAT;
    unsigned char *data = glb_finish(&g, mat, J("{'source':0,'sampler':0}"), NULL, &len);
    lpv_scene s;
    load_glb(data, len, &s, NULL);
    free(data);
    lpv_view v;
    assert_int_equal(lpv_view_look_at((float[3]){0.0f, 5.0f, 5.0f}, (float[3]){0.0f, 0.0f, 0.0f}, 0.9f, W, H, &v), 0);
    float *rgba = calloc((size_t)W * H * 4, sizeof *rgba);
    render(&s, &v, rgba);
    double c[3];
    patch(&v, rgba, (float[3]){0.0f, 0.0f, 0.0f}, c);
    free(rgba);
    lpv_scene_free(&s);
    return lum(c);
}

static void test_normal_map_direction(void **state)
{
    (void)state;
    /* sun from -z (travelling to +z) and from +z, 45 degrees up */
    const float from_minus_z[3] = {0.0f, -0.70710678f, 0.70710678f};
    const float from_plus_z[3] = {0.0f, -0.70710678f, -0.70710678f};
    /* the decoded texel (128, 191, 238): t = (0.0039, 0.498, 0.867); world
     * n = normalize(t.x T + t.y B + t.z N) with T = +x, B = -z, N = +y */
    double t[3] = {128.0 / 255 * 2 - 1, 191.0 / 255 * 2 - 1, 238.0 / 255 * 2 - 1};
    double len = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    double ny = t[2] / len, nz = -t[1] / len;
    double expect_toward = (ny - nz) / sqrt(2.0) / sqrt(0.5); /* cos with to_light (0,1,-1)/sqrt2, over flat */
    double expect_away = (ny + nz) / sqrt(2.0) / sqrt(0.5);   /* to_light (0,1,1)/sqrt2 */
    const float tangent[4] = {1.0f, 0.0f, 0.0f, 1.0f};
    struct {
        const char *name, *tex;
        const float *tangent;
        double scale;
    } cases[] = {
        {"per-pixel frame", "{'index':0}", NULL, 1.0},
        {"file TANGENT", "{'index':0}", tangent, 1.0},
        {"scale 0", "{'index':0,'scale':0}", NULL, 0.0},
    };
    double flat_toward = floor_with_normal_map(NULL, NULL, from_minus_z);
    double flat_away = floor_with_normal_map(NULL, NULL, from_plus_z);
    assert_true(flat_toward > 0.05 && fabs(flat_toward - flat_away) < 0.02 * flat_toward);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        double a = floor_with_normal_map(cases[i].tex, cases[i].tangent, from_minus_z) / flat_toward;
        double b = floor_with_normal_map(cases[i].tex, cases[i].tangent, from_plus_z) / flat_away;
        double ea = cases[i].scale == 0.0 ? 1.0 : expect_toward, eb = cases[i].scale == 0.0 ? 1.0 : expect_away;
        printf("normal map, %-15s: sun from -z %.4f x flat (expected %.4f), from +z %.4f x flat (expected %.4f)\n",
               cases[i].name, a, ea, b, eb);
        assert_true(fabs(a - ea) < 0.03 * ea);
        assert_true(fabs(b - eb) < 0.05 * eb + 0.01);
    }
}

/* ---- texture transforms -----------------------------------------------------------
 * The floor's base colour texture: red where u < 0.5, green where u >= 0.5;
 * TEXCOORD_1 mirrors u. Under a sun straight down, each case below says
 * which colour lands at four floor points. */

static void floor_colours(const char *base_texture, int with_uv1, char out[5])
{
    glb g = {0};
    quad f;
    floor_quad(&f, 0);
    float uv1[8];
    for (int c = 0; c < 4; c++) {
        uv1[c * 2] = 1.0f - f.uv[c][0];
        uv1[c * 2 + 1] = f.uv[c][1];
    }
    if (with_uv1)
        f.uv1 = uv1;
    add_quad(&g, &f);
    uint8_t px[16 * 16 * 4];
    for (int y = 0; y < 16; y++)
        for (int x = 0; x < 16; x++) {
            uint8_t *p = &px[(y * 16 + x) * 4];
            p[0] = x < 8 ? 255 : 0, p[1] = x < 8 ? 0 : 255, p[2] = 0, p[3] = 255;
        }
    add_png(&g, 16, 16, px);
    add_sun(&g, SUN_DOWN);
    size_t len;
    unsigned char *data = glb_finish(
        &g, J("{'pbrMetallicRoughness':{'baseColorTexture':%s,'metallicFactor':0}}", base_texture),
        J("{'source':0,'sampler':0}"), "\"KHR_texture_transform\"", &len);
    lpv_scene s;
    load_glb(data, len, &s, NULL);
    free(data);
    lpv_view v;
    assert_int_equal(lpv_view_look_at((float[3]){0.0f, 7.0f, 3.0f}, (float[3]){0.0f, 0.0f, 0.0f}, 1.0f, W, H, &v), 0);
    float *rgba = calloc((size_t)W * H * 4, sizeof *rgba);
    render(&s, &v, rgba);
    /* (x, z): u = (x+3)/6, v = (z+3)/6; u and v on different sides at two of them */
    const float pts[4][2] = {{-2.25f, 1.5f}, {-0.75f, -1.5f}, {0.75f, 1.5f}, {2.25f, -1.5f}};
    for (int i = 0; i < 4; i++) {
        double c[3];
        patch(&v, rgba, (float[3]){pts[i][0], 0.0f, pts[i][1]}, c);
        out[i] = c[0] > 4.0 * c[1] ? 'R' : c[1] > 4.0 * c[0] ? 'G' : '?';
    }
    out[4] = '\0';
    free(rgba);
    lpv_scene_free(&s);
}

static void test_texture_transform(void **state)
{
    (void)state;
    /* the points (u, v): (.125, .75), (.375, .25), (.625, .75), (.875, .25) */
    struct {
        const char *tex;
        int uv1;
        const char *expect;
    } cases[] = {
        {"{'index':0}", 0, "RRGG"},
        /* u' = u + 0.5, repeating */
        {"{'index':0,'extensions':{'KHR_texture_transform':{'offset':[0.5,0]}}}", 0, "GGRR"},
        /* u' = 2u */
        {"{'index':0,'extensions':{'KHR_texture_transform':{'scale':[2,1]}}}", 0, "RGRG"},
        /* rotation pi/2: u' = cos(r) u + sin(r) v = v */
        {"{'index':0,'extensions':{'KHR_texture_transform':{'rotation':1.5707963}}}", 0, "GRGR"},
        /* rotation -pi/2: u' = -v */
        {"{'index':0,'extensions':{'KHR_texture_transform':{'rotation':-1.5707963}}}", 0, "RGRG"},
        /* rotation pi/2, then offset 0.5: u' = v + 0.5 */
        {"{'index':0,'extensions':{'KHR_texture_transform':{'rotation':1.5707963,'offset':[0.5,0]}}}", 0,
         "RGRG"},
        /* TEXCOORD_1 (u mirrored), by textureInfo and by the extension's override */
        {"{'index':0,'texCoord':1}", 1, "GGRR"},
        {"{'index':0,'extensions':{'KHR_texture_transform':{'texCoord':1}}}", 1, "GGRR"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char got[5];
        floor_colours(cases[i].tex, cases[i].uv1, got);
        printf("%-95s -> %s (expected %s)\n", cases[i].tex, got, cases[i].expect);
        assert_string_equal(got, cases[i].expect);
    }
}

/* ---- warnings -------------------------------------------------------------------- */

static const char *WARN_JSON =
    "{'asset':{'version':'2.0'},"
    "'extensionsUsed':['KHR_materials_clearcoat','EXT_lpvd_test_unknown'],"
    "'scene':0,'scenes':[{'nodes':[0,1,2]},{'nodes':[]}],"
    "'nodes':[{'mesh':0},{'mesh':1},{'mesh':0,'skin':0}],"
    "'skins':[{'joints':[0]}],"
    "'animations':[{'channels':[{'sampler':0,'target':{'node':0,'path':'translation'}}],"
    "  'samplers':[{'input':4,'output':5}]}],"
    "'meshes':[{'primitives':[{'attributes':{'POSITION':0,'COLOR_0':1},'indices':2,'material':0},"
    "                          {'attributes':{'POSITION':0,'COLOR_0':1},'indices':2,'material':1}]},"
    "          {'primitives':[{'attributes':{'POSITION':0},'indices':2,'material':2,"
    "                          'targets':[{'POSITION':3}]}]}],"
    "'materials':["
    "  {'occlusionTexture':{'index':0},'extensions':{'KHR_materials_clearcoat':{'clearcoatFactor':1}}},"
    "  {'occlusionTexture':{'index':0},'emissiveTexture':{'index':0},"
    "   'extensions':{'KHR_materials_clearcoat':{'clearcoatFactor':1}}},"
    "  {'occlusionTexture':{'index':0},'pbrMetallicRoughness':{'metallicRoughnessTexture':{'index':0}}}],"
    "'textures':[{'source':0}],"
    "'images':[{'uri':'data:image/png;base64,"
    "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8BQDwAEhQGAhKmMIQAAAABJRU5ErkJggg=='}],"
    "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'},"
    "             {'bufferView':1,'componentType':5126,'count':3,'type':'VEC4'},"
    "             {'bufferView':2,'componentType':5123,'count':3,'type':'SCALAR'},"
    "             {'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'},"
    "             {'bufferView':3,'componentType':5126,'count':1,'type':'SCALAR'},"
    "             {'bufferView':3,'componentType':5126,'count':1,'type':'VEC3'}],"
    "'bufferViews':[{'buffer':0,'byteOffset':0,'byteLength':36},{'buffer':0,'byteOffset':36,'byteLength':48},"
    "               {'buffer':0,'byteOffset':84,'byteLength':6},{'buffer':0,'byteOffset':92,'byteLength':12}],"
    "'buffers':[{'byteLength':104,'uri':'data:application/octet-stream;base64,%s'}]}";

/* The features above, each named by one line. */
/* (emissiveTexture, metallicRoughnessTexture, occlusionTexture, COLOR_0,
 * skins and morph targets are read since issue 32: test_material_textures,
 * test_vertex_colours, test_occlusion_texture, test_gltf's
 * test_skins_and_morphs; the skinned primitive here has no JOINTS_0) */
static const char *const WARN_FEATURES[] = {
    "KHR_materials_clearcoat", "EXT_lpvd_test_unknown", "without JOINTS_0", "animation", "2 scenes",
};

static const char *warn_gltf(void)
{
    /* 104 bytes: a triangle, colours, indices, zeros; base64 */
    static char b64[200];
    unsigned char raw[104] = {0};
    float tri[9] = {0, 0, 0, 1, 0, 0, 0, 0, 1};
    memcpy(raw, tri, sizeof tri);
    uint16_t idx[3] = {0, 1, 2};
    memcpy(raw + 84, idx, sizeof idx);
    static const char *tab = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t o = 0;
    for (size_t i = 0; i < sizeof raw; i += 3) {
        uint32_t v = (uint32_t)raw[i] << 16 | (i + 1 < sizeof raw ? (uint32_t)raw[i + 1] << 8 : 0) |
                     (i + 2 < sizeof raw ? raw[i + 2] : 0);
        b64[o++] = tab[v >> 18 & 63];
        b64[o++] = tab[v >> 12 & 63];
        b64[o++] = i + 1 < sizeof raw ? tab[v >> 6 & 63] : '=';
        b64[o++] = i + 2 < sizeof raw ? tab[v & 63] : '=';
    }
    b64[o] = '\0';
    return J(WARN_JSON, b64);
}

/* metallicRoughnessTexture and emissiveTexture (issue 32, item 1), on a 6 m
 * floor (u = (x + 3) / 6, v = (z + 3) / 6) lit straight down by 1 W/m^2:
 * - metallic 1 x the texture's B, 255 where x < 0 (metal: no diffuse, glTF's
 *   diffuse albedo is base colour x (1 - metallic)) and 0 where x > 0;
 * - emission x an emissive texture white where z < 0, black where z > 0.
 * The G-buffer's frame, the emitters' flux (core/emissive.c), the imperfect
 * volume's points (techniques/iv/core/iv_points.c) and the reference's frame all follow
 * the textures; before, the texture was ignored (the whole floor metal-free
 * grey, the whole floor glowing). */
static void test_material_textures(void **state)
{
    (void)state;
    glb g = {0};
    quad f;
    floor_quad(&f, 0);
    add_quad(&g, &f);
    uint8_t mr[8 * 8 * 4], em[8 * 8 * 4];
    for (int y = 0; y < 8; y++)
        for (int x = 0; x < 8; x++) {
            uint8_t *p = &mr[(y * 8 + x) * 4], *q = &em[(y * 8 + x) * 4];
            p[0] = 0, p[1] = 255, p[2] = x < 4 ? 255 : 0, p[3] = 255; /* G roughness 1, B metallic */
            q[0] = q[1] = q[2] = y < 4 ? 255 : 0, q[3] = 255;
        }
    add_png(&g, 8, 8, mr);
    add_png(&g, 8, 8, em);
    add_sun(&g, SUN_DOWN);
    size_t len;
    /* emission 683 nits = 1 W/(m^2 sr) */
    unsigned char *data =
        glb_finish(&g,
                   "{'pbrMetallicRoughness':{'baseColorFactor':[0.8,0.8,0.8,1],'metallicFactor':1,"
                   "'metallicRoughnessTexture':{'index':0}},'emissiveFactor':[1,1,1],'emissiveTexture':{'index':1},"
                   "'extensions':{'KHR_materials_emissive_strength':{'emissiveStrength':683}}}",
                   J("{'source':0,'sampler':0},{'source':1,'sampler':0}"), "\"KHR_materials_emissive_strength\"", &len);
    lpv_scene s;
    lpv_gltf_warnings w;
    load_glb(data, len, &s, &w);
    free(data);
    for (int i = 0; i < w.count; i++) {
        printf("warning %d: %s\n", i, w.line[i]);
        assert_null(strstr(w.line[i], "emissiveTexture"));
        assert_null(strstr(w.line[i], "metallicRoughnessTexture"));
    }
    const lpv_material *m = &s.materials[0];
    assert_int_equal(m->metallic_roughness_texture >= 0, 1);
    assert_int_equal(m->emissive_texture >= 0, 1);
    assert_int_equal(s.textures[m->metallic_roughness_texture].linear, 1);
    assert_int_equal(s.textures[m->emissive_texture].linear, 0);

    /* the CPU's reading (core/material_sample.h) */
    float alb[3], e[3];
    const float metal_uv[2] = {0.2f, 0.5f}, plain_uv[2] = {0.8f, 0.5f}, lit_uv[2] = {0.5f, 0.2f},
                dark_uv[2] = {0.5f, 0.8f};
    lpv_material_albedo_at(&s, m, metal_uv, metal_uv, NULL, alb);
    assert_true(alb[0] == 0.0f);
    lpv_material_albedo_at(&s, m, plain_uv, plain_uv, NULL, alb);
    assert_float_equal(alb[0], 0.8f, 1e-6f);
    lpv_material_emission_at(&s, m, lit_uv, lit_uv, e);
    assert_float_equal(e[1], 1.0f, 1e-5f);
    lpv_material_emission_at(&s, m, dark_uv, dark_uv, e);
    assert_true(e[1] == 0.0f);
    double flux[3];
    lpv_emissive_total_flux(&s, flux);
    printf("emitted flux %.3f W (half the floor: pi x 18 m^2 = %.3f W)\n", flux[1], M_PI * 18.0);
    assert_true(fabs(flux[1] - M_PI * 18.0) < 0.03 * M_PI * 18.0);

    /* the frame: direct light and emission */
    lpv_view v;
    assert_int_equal(lpv_view_look_at((float[3]){0.0f, 6.0f, 0.01f}, (float[3]){0.0f, 0.0f, 0.0f}, 1.0f, W, H, &v), 0);
    float *rgba = calloc((size_t)W * H * 4, sizeof *rgba);
    render(&s, &v, rgba);
    double metal_lit[3], plain_lit[3], metal_dark[3], plain_dark[3];
    patch(&v, rgba, (float[3]){-1.5f, 0.0f, -1.5f}, metal_lit);
    patch(&v, rgba, (float[3]){1.5f, 0.0f, -1.5f}, plain_lit);
    patch(&v, rgba, (float[3]){-1.5f, 0.0f, 1.5f}, metal_dark);
    patch(&v, rgba, (float[3]){1.5f, 0.0f, 1.5f}, plain_dark);
    printf("frame (g): metal+glow %.4f, plain+glow %.4f, metal %.4f, plain %.4f W/(m^2 sr)\n", metal_lit[1],
           plain_lit[1], metal_dark[1], plain_dark[1]);
    const double reflected = 0.8 / M_PI; /* 1 W/m^2 x 0.8 / pi */
    assert_true(fabs(metal_dark[1]) < 0.02 * reflected);
    assert_true(fabs(plain_dark[1] - reflected) < 0.05 * reflected);
    assert_true(fabs(metal_lit[1] - 1.0) < 0.03);
    assert_true(fabs(plain_lit[1] - (1.0 + reflected)) < 0.05);

    /* the reference's full frame: the same four places */
    lpv_ref *ref = NULL;
    char err[512] = "";
    lpv_ref_desc d = {.seed = 1};
    assert_int_equal(lpv_ref_create(&s, &d, &ref, err, sizeof err), 0);
    assert_int_equal(lpv_ref_render_full(ref, &v, 1, 16, rgba, NULL), 0);
    lpv_ref_destroy(ref);
    double r_metal_lit[3], r_plain_dark[3], r_metal_dark[3];
    patch(&v, rgba, (float[3]){-1.5f, 0.0f, -1.5f}, r_metal_lit);
    patch(&v, rgba, (float[3]){-1.5f, 0.0f, 1.5f}, r_metal_dark);
    patch(&v, rgba, (float[3]){1.5f, 0.0f, 1.5f}, r_plain_dark);
    printf("reference (g): metal+glow %.4f, metal %.4f, plain %.4f\n", r_metal_lit[1], r_metal_dark[1],
           r_plain_dark[1]);
    assert_true(fabs(r_metal_lit[1] - 1.0) < 0.03);
    assert_true(fabs(r_metal_dark[1]) < 0.02 * reflected);
    assert_true(r_plain_dark[1] > 0.9 * reflected); /* and the glowing half's light beside it */
    free(rgba);
    lpv_scene_free(&s);
}

/* COLOR_0 multiplies the base colour (issue 32, item 1): a white floor whose
 * x < 0 corners are red and x > 0 corners green, lit straight down. The
 * frame, iv's points and the reference's frame are red on the left and
 * green on the right; before, COLOR_0 was dropped with a warning (white). */
static void test_vertex_colours(void **state)
{
    (void)state;
    glb g = {0};
    quad f;
    floor_quad(&f, 0);
    float col[16];
    for (int c = 0; c < 4; c++) {
        const int left = f.c[c][0] < 0.0f;
        col[4 * c + 0] = left ? 1.0f : 0.0f, col[4 * c + 1] = left ? 0.0f : 1.0f, col[4 * c + 2] = 0.0f;
        col[4 * c + 3] = 1.0f;
    }
    f.color = col;
    add_quad(&g, &f);
    add_sun(&g, SUN_DOWN);
    size_t len;
    unsigned char *data = glb_finish(&g, "{'pbrMetallicRoughness':{'baseColorFactor':[0.8,0.8,0.8,1],'metallicFactor':0}}",
                                     NULL, NULL, &len);
    lpv_scene s;
    lpv_gltf_warnings w;
    load_glb(data, len, &s, &w);
    free(data);
    for (int i = 0; i < w.count; i++)
        assert_null(strstr(w.line[i], "COLOR_0"));
    assert_int_equal(s.draws[0].vertex_color, 1);
    lpv_view v;
    assert_int_equal(lpv_view_look_at((float[3]){0.0f, 6.0f, 0.01f}, (float[3]){0.0f, 0.0f, 0.0f}, 1.0f, W, H, &v), 0);
    float *rgba = calloc((size_t)W * H * 4, sizeof *rgba);
    render(&s, &v, rgba);
    double left[3], right[3];
    patch(&v, rgba, (float[3]){-2.5f, 0.0f, 0.0f}, left);
    patch(&v, rgba, (float[3]){2.5f, 0.0f, 0.0f}, right);
    printf("frame: x = -2.5 (%.4f %.4f %.4f), x = +2.5 (%.4f %.4f %.4f)\n", left[0], left[1], left[2], right[0],
           right[1], right[2]);
    /* 5/6 of the way to the corner: 0.8 x (11/12 red + 1/12 green) / pi */
    assert_true(fabs(left[0] - 0.8 * 11.0 / 12.0 / M_PI) < 0.02);
    assert_true(fabs(left[1] - 0.8 * 1.0 / 12.0 / M_PI) < 0.02);
    assert_true(fabs(right[1] - 0.8 * 11.0 / 12.0 / M_PI) < 0.02);
    assert_true(left[2] < 1e-4 && right[2] < 1e-4);
    /* the reference's frame */
    lpv_ref *ref = NULL;
    char err[512] = "";
    lpv_ref_desc d = {.seed = 1};
    assert_int_equal(lpv_ref_create(&s, &d, &ref, err, sizeof err), 0);
    assert_int_equal(lpv_ref_render_full(ref, &v, 1, 4, rgba, NULL), 0);
    lpv_ref_destroy(ref);
    double rl[3], rr[3];
    patch(&v, rgba, (float[3]){-2.5f, 0.0f, 0.0f}, rl);
    patch(&v, rgba, (float[3]){2.5f, 0.0f, 0.0f}, rr);
    printf("reference: x = -2.5 (%.4f %.4f %.4f), x = +2.5 (%.4f %.4f %.4f)\n", rl[0], rl[1], rl[2], rr[0], rr[1],
           rr[2]);
    assert_true(fabs(rl[0] - left[0]) < 0.02 && fabs(rr[1] - right[1]) < 0.02 && rl[2] < 1e-4);
    free(rgba);
    /* iv's points: red on the left, green on the right */
    lpv_iv_point_params pp = {.voxel = 0.5f, .points = 1, .split = 0.5f, .max_points = 1 << 20};
    struct IvPoint *pts = NULL;
    size_t n = 0;
    assert_int_equal(lpv_iv_points_make(&s, &pp, &pts, &n, NULL), 0);
    assert_true(n > 100);
    for (size_t i = 0; i < n; i++) {
        const float x = pts[i].position[0], t = (x + 3.0f) / 6.0f; /* red share 1 - t */
        assert_float_equal(pts[i].albedo[0], 0.8f * (1.0f - t), 1e-3f);
        assert_float_equal(pts[i].albedo[1], 0.8f * t, 1e-3f);
    }
    free(pts);
    lpv_scene_free(&s);
}

/* The floor (material 0) and, at x = 1.5, a 2 m white wall facing -x
 * (material 1) that throws light on it. */
static void floor_and_wall(glb *g)
{
    quad f, wall;
    floor_quad(&f, 0);
    add_quad(g, &f);
    memset(&wall, 0, sizeof wall);
    static const float WALL[4][3] = {{1.5f, 0, -3}, {1.5f, 0, 3}, {1.5f, 2, 3}, {1.5f, 2, -3}};
    memcpy(wall.c, WALL, sizeof wall.c);
    wall.material = 1;
    add_quad(g, &wall);
}

/* A floor with an occlusion texture 0 where z < 0 and 1 where z > 0 at
 * `strength`, and a white wall at x = 1.5 that the diagonal sun lights and
 * that throws light on the floor. */
static void occlusion_scene(float strength, lpv_scene *s)
{
    glb g = {0};
    floor_and_wall(&g);
    /* 64 x 64 texels: the mip levels the camera reads keep both halves pure */
    static uint8_t occ[64 * 64 * 4];
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++) {
            uint8_t *p = &occ[(y * 64 + x) * 4];
            p[0] = p[1] = p[2] = y < 32 ? 0 : 255, p[3] = 255;
        }
    add_png(&g, 64, 64, occ);
    add_sun(&g, SUN_DIAGONAL);
    size_t len;
    unsigned char *data = glb_finish(
        &g,
        J("{'pbrMetallicRoughness':{'baseColorFactor':[0.8,0.8,0.8,1],'metallicFactor':0},"
          "'occlusionTexture':{'index':0,'strength':%g}},"
          "{'pbrMetallicRoughness':{'baseColorFactor':[0.9,0.9,0.9,1],'metallicFactor':0}}",
          (double)strength),
        J("{'source':0,'sampler':0}"), NULL, &len);
    lpv_gltf_warnings w;
    load_glb(data, len, s, &w);
    free(data);
    for (int i = 0; i < w.count; i++)
        assert_null(strstr(w.line[i], "occlusionTexture"));
}

/* occlusionTexture (issue 32, item 1): the frame's indirect light, not its
 * direct light and not the GI, takes 1 + strength (R - 1). The same scene at
 * strength 0.5 and 0 (the texture then changes nothing): where R = 0 the
 * indirect frame reads exactly half, where R = 1 the same; the direct frame
 * the same everywhere; the reference's indirect image likewise. */
static void test_occlusion_texture(void **state)
{
    (void)state;
    lpv_scene s[2];
    occlusion_scene(0.5f, &s[0]);
    occlusion_scene(0.0f, &s[1]);
    assert_true(s[0].materials[0].occlusion_texture >= 0);
    assert_float_equal(s[0].materials[0].occlusion_strength, 0.5f, 0.0f);
    const float in_uv[2] = {0.5f, 0.2f}, out_uv[2] = {0.5f, 0.8f};
    assert_float_equal(lpv_material_occlusion_at(&s[0], &s[0].materials[0], in_uv, in_uv), 0.5f, 1e-6f);
    assert_float_equal(lpv_material_occlusion_at(&s[0], &s[0].materials[0], out_uv, out_uv), 1.0f, 1e-6f);
    assert_float_equal(lpv_material_occlusion_at(&s[1], &s[1].materials[0], in_uv, in_uv), 1.0f, 1e-6f);

    lpv_view v;
    assert_int_equal(lpv_view_look_at((float[3]){-2.0f, 5.0f, 0.01f}, (float[3]){0.5f, 0.0f, 0.0f}, 1.0f, W, H, &v), 0);
    float *rgba = calloc((size_t)W * H * 4, sizeof *rgba);
    char err[1024] = "";
    lpv_settings st = {.technique = LPV_TECHNIQUE_ID_LPV, .rsm_size = 256};
    const float dark[3] = {0.5f, 0.0f, -1.5f}, open[3] = {0.5f, 0.0f, 1.5f}; /* v = 1/4, 3/4 */
    double at[2][2][2]; /* [scene][terms][place] */
    for (int k = 0; k < 2; ++k)
        for (int terms = 0; terms < 2; ++terms) {
            if (lpv_engine_set_settings(lpvt_engine, &st, err, sizeof err) ||
                lpv_engine_set_scene(lpvt_engine, &s[k], err, sizeof err) ||
                lpv_engine_set_view(lpvt_engine, &v, err, sizeof err) ||
                lpv_engine_tick(lpvt_engine, err, sizeof err) ||
                lpv_engine_render(lpvt_engine, terms ? LPV_TERMS_DIRECT_ONLY : LPV_TERMS_INDIRECT_ONLY, rgba, err,
                                  sizeof err))
                fail_msg("%s", err);
            double a[3], b[3];
            lpvt_patch(&v, rgba, W, H, dark, 2, a);
            lpvt_patch(&v, rgba, W, H, open, 2, b);
            at[k][terms][0] = lum(a);
            at[k][terms][1] = lum(b);
        }
    printf("indirect: R = 0 %.5f vs %.5f without, R = 1 %.5f vs %.5f; direct %.5f vs %.5f\n", at[0][0][0], at[1][0][0],
           at[0][0][1], at[1][0][1], at[0][1][0], at[1][1][0]);
    assert_true(at[1][0][0] > 0.0 && at[1][1][0] > 0.0);
    assert_true(fabs(at[0][0][0] / at[1][0][0] - 0.5) < 0.01);
    assert_true(fabs(at[0][0][1] / at[1][0][1] - 1.0) < 0.01);
    assert_true(fabs(at[0][1][0] / at[1][1][0] - 1.0) < 1e-4);
    /* the reference's indirect image, its same streams with and without */
    double ref_at[2];
    for (int k = 0; k < 2; ++k) {
        lpv_ref *ref = NULL;
        lpv_ref_desc d = {.seed = 1};
        assert_int_equal(lpv_ref_create(&s[k], &d, &ref, err, sizeof err), 0);
        assert_int_equal(lpv_ref_render_indirect(ref, &v, 1, 16, rgba, NULL), 0);
        lpv_ref_destroy(ref);
        double a[3];
        lpvt_patch(&v, rgba, W, H, dark, 2, a);
        ref_at[k] = lum(a);
    }
    printf("reference indirect at R = 0: %.5f vs %.5f without\n", ref_at[0], ref_at[1]);
    assert_true(ref_at[1] > 0.0 && fabs(ref_at[0] / ref_at[1] - 0.5) < 0.01);
    free(rgba);
    lpv_scene_free(&s[0]);
    lpv_scene_free(&s[1]);
}

/* KHR_materials_unlit (issue 32, item 1): a floor of base colour
 * (0.5, 0.25, 1) under a 1 W/m^2 sun shows that colour as it is, 1 = 1 nit
 * = 1/683 W/(m^2 sr) (what three.js and the Khronos viewer show at exposure
 * 1), in the full and direct frames, nothing in the indirect one; it
 * reflects and emits nothing (iv's points, the RSM's light: a white wall
 * beside it gets no bounce from it); the reference's image shows the same. */
static void test_unlit(void **state)
{
    (void)state;
    lpv_scene s[2];
    for (int k = 0; k < 2; ++k) {
        glb g = {0};
        floor_and_wall(&g);
        add_sun(&g, SUN_DOWN);
        size_t len;
        unsigned char *data = glb_finish(
            &g,
            J("{'pbrMetallicRoughness':{'baseColorFactor':[0.5,0.25,1,1],'metallicFactor':0}%s},"
              "{'pbrMetallicRoughness':{'baseColorFactor':[0.9,0.9,0.9,1],'metallicFactor':0}}",
              k == 0 ? ",'extensions':{'KHR_materials_unlit':{}}" : ""),
            NULL, k == 0 ? "\"KHR_materials_unlit\"" : NULL, &len);
        lpv_gltf_warnings w;
        load_glb(data, len, &s[k], &w);
        free(data);
        for (int i = 0; i < w.count; i++)
            assert_null(strstr(w.line[i], "unlit"));
    }
    assert_int_equal(s[0].materials[0].unlit, 1);
    assert_int_equal(s[1].materials[0].unlit, 0);
    const float want[3] = {0.5f / 683.0f, 0.25f / 683.0f, 1.0f / 683.0f};
    lpv_view v;
    assert_int_equal(lpv_view_look_at((float[3]){-2.0f, 5.0f, 0.01f}, (float[3]){0.0f, 0.0f, 0.0f}, 1.0f, W, H, &v), 0);
    float *rgba = calloc((size_t)W * H * 4, sizeof *rgba);
    char err[1024] = "";
    lpv_settings st = {.technique = LPV_TECHNIQUE_ID_LPV, .rsm_size = 256};
    const float on_floor[3] = {-1.0f, 0.0f, 0.0f}, on_wall[3] = {1.5f, 0.5f, 0.0f};
    double wall_indirect[2];
    for (int k = 0; k < 2; ++k)
        for (int terms = 0; terms < 3; ++terms) {
            static const lpv_frame_terms T[3] = {LPV_TERMS_FULL, LPV_TERMS_DIRECT_ONLY, LPV_TERMS_INDIRECT_ONLY};
            if (lpv_engine_set_settings(lpvt_engine, &st, err, sizeof err) ||
                lpv_engine_set_scene(lpvt_engine, &s[k], err, sizeof err) ||
                lpv_engine_set_view(lpvt_engine, &v, err, sizeof err) ||
                lpv_engine_tick(lpvt_engine, err, sizeof err) ||
                lpv_engine_render(lpvt_engine, T[terms], rgba, err, sizeof err))
                fail_msg("%s", err);
            double a[3], b[3];
            lpvt_patch(&v, rgba, W, H, on_floor, 1, a);
            lpvt_patch(&v, rgba, W, H, on_wall, 1, b);
            if (k == 0 && terms < 2)
                for (int c = 0; c < 3; ++c)
                    assert_float_equal(a[c], want[c], 1e-6);
            if (k == 0 && terms == 2)
                assert_true(lum(a) == 0.0);
            if (k == 1 && terms == 0) /* lit: the sun's light, far more than 1 nit */
                assert_true(a[1] > 0.05);
            if (terms == 2)
                wall_indirect[k] = lum(b);
        }
    printf("the wall's indirect light beside the unlit floor %.5f, beside the lit one %.5f\n", wall_indirect[0],
           wall_indirect[1]);
    assert_true(wall_indirect[1] > 0.0);
    assert_true(wall_indirect[0] < 0.05 * wall_indirect[1]);
    /* iv's points on the unlit floor: no albedo, no emission */
    lpv_iv_point_params pp = {.voxel = 0.5f, .points = 1, .split = 0.5f, .max_points = 1 << 20, .emission = 1};
    struct IvPoint *pts = NULL;
    size_t n = 0;
    assert_int_equal(lpv_iv_points_make(&s[0], &pp, &pts, &n, NULL), 0);
    size_t floor_points = 0;
    for (size_t i = 0; i < n; i++)
        if (fabsf(pts[i].position[1]) < 1e-4f) {
            floor_points++;
            for (int c = 0; c < 3; c++)
                assert_true(pts[i].albedo[c] == 0.0f && pts[i].emission[c] == 0.0f);
        }
    assert_true(floor_points > 10);
    free(pts);
    /* the reference's full image */
    lpv_ref *ref = NULL;
    lpv_ref_desc d = {.seed = 1};
    assert_int_equal(lpv_ref_create(&s[0], &d, &ref, err, sizeof err), 0);
    assert_int_equal(lpv_ref_render_full(ref, &v, 1, 4, rgba, NULL), 0);
    lpv_ref_destroy(ref);
    double r[3];
    lpvt_patch(&v, rgba, W, H, on_floor, 1, r);
    for (int c = 0; c < 3; ++c)
        assert_float_equal(r[c], want[c], 1e-6);
    free(rgba);
    lpv_scene_free(&s[0]);
    lpv_scene_free(&s[1]);
}

/* A MASK cut-out is cut alike everywhere (issue 32: the same inputs in the
 * reference): the occluder's z > 0 half (alpha 0) casts no shadow in the
 * path tracer either, and iv's point cloud has no point there. Before, the
 * reference's rays and iv's points ignored alpha: the whole occluder
 * shadowed and carried light. */
static void test_cut_outs_in_reference_and_points(void **state)
{
    (void)state;
    lpv_scene s;
    occluder_scene("{'alphaMode':'MASK','alphaCutoff':0.5,'pbrMetallicRoughness':{'baseColorTexture':{'index':0},"
                   "'metallicFactor':0}}",
                   OCC_UP, SUN_DOWN, &s, NULL);
    lpv_ref *ref = NULL;
    char err[512] = "";
    assert_int_equal(lpv_ref_create(&s, NULL, &ref, err, sizeof err), 0);
    const float up[3] = {0, 1, 0};
    float under_opaque[3], under_cut[3], open[3];
    lpv_ref_direct_irradiance(ref, (float[3]){0.0f, 0.0f, -0.5f}, up, under_opaque);
    lpv_ref_direct_irradiance(ref, (float[3]){0.0f, 0.0f, 0.5f}, up, under_cut);
    lpv_ref_direct_irradiance(ref, (float[3]){2.5f, 0.0f, 0.0f}, up, open);
    lpv_ref_destroy(ref);
    printf("reference direct irradiance (g): under the opaque half %.4f, under the cut half %.4f, open floor %.4f\n",
           under_opaque[1], under_cut[1], open[1]);
    assert_true(open[1] > 0.5f);
    assert_true(under_opaque[1] < 0.01f * open[1]);
    assert_float_equal(under_cut[1], open[1], 1e-4f * open[1]);
    lpv_iv_point_params pp = {.voxel = 0.25f, .points = 1, .split = 0.5f, .max_points = 1 << 20};
    struct IvPoint *pts = NULL;
    size_t n = 0;
    assert_int_equal(lpv_iv_points_make(&s, &pp, &pts, &n, NULL), 0);
    size_t on_opaque = 0, on_cut = 0;
    for (size_t i = 0; i < n; i++)
        if (fabsf(pts[i].position[1] - 1.0f) < 1e-4f) {
            on_opaque += pts[i].position[2] < -0.01f;
            on_cut += pts[i].position[2] > 0.01f;
        }
    printf("iv points on the occluder: %zu on the opaque half, %zu on the cut half\n", on_opaque, on_cut);
    assert_true(on_opaque > 10);
    assert_int_equal(on_cut, 0);
    free(pts);
    lpv_scene_free(&s);
}

/* glTF's points and lines (docs/scenes.md, "Points and lines"): drawn one
 * pixel wide in their colour, lit by nothing (1 = 1 nit, as an unlit
 * material), and no surface: a red line 2 m over the floor casts no shadow
 * under a sun straight down, leaves no camera surfel, and the floor's light
 * is what it is without it. */
static void test_points_and_lines(void **state)
{
    (void)state;
    const float line[2][3] = {{-3.0f, 2.0f, 0.0f}, {3.0f, 2.0f, 0.0f}};
    const float dots[3][3] = {{0.0f, 2.0f, 1.0f}, {1.0f, 2.0f, 1.0f}, {-1.0f, 2.0f, 1.0f}};
    lpv_view v;
    assert_int_equal(lpv_view_look_at((float[3]){4.5f, 5.0f, 0.3f}, (float[3]){0.0f, 0.5f, 0.0f}, 0.9f, W, H, &v), 0);
    float *rgba[2];
    double floor_under[2][3], floor_open[2][3];
    for (int with = 0; with < 2; with++) {
        glb g = {0};
        quad f;
        floor_quad(&f, 0);
        add_quad(&g, &f);
        if (with) {
            add_wire(&g, line, 2, 1, 1);
            add_wire(&g, dots, 3, 0, 1);
        }
        add_sun(&g, SUN_DOWN);
        size_t len;
        unsigned char *data = glb_finish(
            &g, J("%s,{'pbrMetallicRoughness':{'baseColorFactor':[1,0,0,1],'metallicFactor':0}}", FLOOR_MAT), NULL,
            NULL, &len);
        lpv_scene s;
        load_glb(data, len, &s, NULL);
        free(data);
        assert_int_equal(s.wire_draw_count, with ? 2u : 0u);
        rgba[with] = calloc((size_t)W * H * 4, sizeof(float));
        render(&s, &v, rgba[with]);
        lpvt_patch(&v, rgba[with], W, H, (float[3]){1.0f, 0.0f, 0.0f}, 1, floor_under[with]);
        lpvt_patch(&v, rgba[with], W, H, (float[3]){1.0f, 0.0f, -2.0f}, 1, floor_open[with]);
        if (with) {
            const size_t buffers = lpv_engine_gv_buffer_count(lpvt_engine);
            assert_true(surfel_area_at_height(buffers - 2, 2.0f) == 0.0); /* no camera surfel on the line */
        }
        lpv_scene_free(&s);
    }
    /* the line's pixels: pure red at 1/683 W/(m^2 sr) (its colour as 1 nit);
     * the frame without it has none */
    int red[2] = {0, 0};
    for (int with = 0; with < 2; with++)
        for (int i = 0; i < W * H; i++) {
            const float *px = &rgba[with][4 * i];
            red[with] += px[0] > 0.0f && fabsf(px[0] - 1.0f / 683.0f) < 1e-5f && px[1] == 0.0f && px[2] == 0.0f;
        }
    printf("points and lines: %d pure red pixels (none without them); floor under the line %.4f, open %.4f "
           "(without: %.4f, %.4f) W/(m^2 sr), green\n",
           red[1], floor_under[1][1], floor_open[1][1], floor_under[0][1], floor_open[0][1]);
    assert_int_equal(red[0], 0);
    assert_true(red[1] >= W / 2); /* a line across the view, one pixel wide, and the points */
    /* no shadow under the line, and the floor as without it */
    assert_true(floor_under[1][1] > 0.1);
    assert_float_equal(floor_under[1][1], floor_open[1][1], 1e-3 * floor_open[1][1]);
    assert_float_equal(floor_under[1][1], floor_under[0][1], 1e-3 * floor_under[0][1]);
    free(rgba[0]);
    free(rgba[1]);
}

static void test_warnings_once_per_feature(void **state)
{
    (void)state;
    const char *json = warn_gltf();
    lpv_scene s;
    lpv_gltf_warnings w;
    char err[512] = "";
    if (lpv_gltf_load_memory_w(json, strlen(json), NULL, "warn.gltf", NULL, 0, &s, &w, err, sizeof err) != 0)
        fail_msg("%s", err);
    for (int i = 0; i < w.count; i++)
        printf("warning %d: %s\n", i, w.line[i]);
    for (size_t f = 0; f < sizeof WARN_FEATURES / sizeof WARN_FEATURES[0]; f++) {
        int n = 0;
        for (int i = 0; i < w.count; i++)
            n += strstr(w.line[i], WARN_FEATURES[f]) != NULL && !(f == 2 && strstr(w.line[i], "skinning"));
        if (n != 1)
            fail_msg("feature '%s' is named by %d warning lines, not 1", WARN_FEATURES[f], n);
    }
    assert_int_equal(w.dropped, 0);
    /* clearcoat is used by 2 materials, yet it is one line naming them */
    for (int i = 0; i < w.count; i++)
        if (strstr(w.line[i], "KHR_materials_clearcoat"))
            assert_non_null(strstr(w.line[i], "materials 0, 1"));
    lpv_scene_free(&s);

    /* the file loader prints the same lines on stderr, once each */
    char path[512];
    snprintf(path, sizeof path, "%s", lpvt_write_file(lpvt_tmpdir(), "warn.gltf", json, strlen(json)));
    char log[512];
    snprintf(log, sizeof log, "%s/warn.log", lpvt_tmpdir());
    fflush(stderr);
    int saved = dup(2), fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    assert_true(saved >= 0 && fd >= 0);
    dup2(fd, 2);
    close(fd);
    int rc = lpv_gltf_load_file(path, &s, err, sizeof err);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    assert_int_equal(rc, 0);
    lpv_scene_free(&s);
    FILE *f = fopen(log, "r");
    assert_non_null(f);
    char line[1024];
    int lines = 0, clearcoat = 0;
    while (fgets(line, sizeof line, f)) {
        assert_non_null(strstr(line, "warn.gltf: warning: "));
        lines++;
        clearcoat += strstr(line, "KHR_materials_clearcoat") != NULL;
    }
    fclose(f);
    assert_int_equal(lines, w.count);
    assert_int_equal(clearcoat, 1);
}

/* Bad material values are refused with the field named. */
static void test_bad_material_values_refused(void **state)
{
    (void)state;
    struct {
        const char *material, *word;
    } cases[] = {
        {"{'alphaMode':'CUTOUT'}", "alphaMode \"CUTOUT\" is not OPAQUE, MASK or BLEND"},
        {"{'alphaMode':'MASK','alphaCutoff':-1}", "alphaCutoff"},
        {"{'pbrMetallicRoughness':{'baseColorTexture':{'index':0,'extensions':{'KHR_texture_transform':"
         "{'scale':[1]}}}}}",
         "KHR_texture_transform.scale"},
        /* a string where the schema wants an array: the JSON check names its path */
        {"{'normalTexture':{'index':0,'extensions':{'KHR_texture_transform':{'offset':'x'}}}}",
         "materials[0].normalTexture.extensions.KHR_texture_transform.offset: expected an array"},
        {"{'normalTexture':{'index':7}}", "normalTexture 7 does not exist"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        glb g = {0};
        quad f;
        floor_quad(&f, 0);
        add_quad(&g, &f);
        add_mask_png(&g);
        size_t len;
        unsigned char *data = glb_finish(&g, J("%s", cases[i].material), J("{'source':0}"), NULL, &len);
        lpv_scene s;
        char err[512] = "";
        memset(&s, 0x5a, sizeof s);
        int rc = lpv_gltf_load_memory(data, len, NULL, "bad.glb", &s, err, sizeof err);
        free(data);
        printf("    %-40.40s -> %s\n", cases[i].material, err);
        assert_int_equal(rc, -1);
        assert_true(strstr(err, "bad.glb: material 0") || strstr(err, "bad.glb: materials[0]"));
        if (!strstr(err, cases[i].word))
            fail_msg("'%s' does not say '%s'", err, cases[i].word);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_alpha_mask_shadows_only_where_opaque),
        cmocka_unit_test(test_alpha_blend_coverage),
        cmocka_unit_test(test_alpha_blend_no_warning),
        cmocka_unit_test(test_blend_in_reference_and_points),
        cmocka_unit_test(test_double_sided),
        cmocka_unit_test(test_normal_map_direction),
        cmocka_unit_test(test_texture_transform),
        cmocka_unit_test(test_material_textures),
        cmocka_unit_test(test_vertex_colours),
        cmocka_unit_test(test_occlusion_texture),
        cmocka_unit_test(test_unlit),
        cmocka_unit_test(test_cut_outs_in_reference_and_points),
        cmocka_unit_test(test_points_and_lines),
        cmocka_unit_test(test_warnings_once_per_feature),
        cmocka_unit_test(test_bad_material_values_refused),
    };
    return cmocka_run_group_tests(tests, lpvt_gl_setup, lpvt_gl_teardown);
}
