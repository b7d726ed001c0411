/*
 * test_gltf.c - the glTF loader (scene/gltf_load.h): hand-made .glb and .gltf
 * files built here, every malformed or hostile case refused with a message
 * naming the file and the problem, ../shared/scenes/cornell-box.glb
 * against the built-in Cornell box, and node animations posed at a time
 * (lpv_gltf_load_file_animated) against hand-computed positions.
 *
 * JSON in this file is written with single quotes; J() turns them into
 * double quotes.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
/* cmocka.h after the headers it needs */
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "gltf_load.h"
#include "scene.h"
#include "scene_load.h"
#include "test_util.h"

#define S45 0.70710678118654752f

/* ---- helpers ------------------------------------------------------------- */

/* JSON written with ' for " (test_util.h). */
#define J lpvt_json

typedef struct bin {
    unsigned char b[4096];
    size_t n;
} bin;

static void put(bin *b, const void *p, size_t n)
{
    assert_true(b->n + n <= sizeof b->b);
    memcpy(b->b + b->n, p, n);
    b->n += n;
}
static void put_f32(bin *b, float v) { put(b, &v, 4); }
static void put_u16(bin *b, uint16_t v) { put(b, &v, 2); }
static void put_u8(bin *b, uint8_t v) { put(b, &v, 1); }
static void put_vec3(bin *b, float x, float y, float z)
{
    put_f32(b, x);
    put_f32(b, y);
    put_f32(b, z);
}
static void pad4(bin *b)
{
    while (b->n % 4)
        put_u8(b, 0);
}

static void put_le32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16);
    p[3] = (unsigned char)(v >> 24);
}

/* Assembles a .glb from a JSON text and an optional BIN payload (malloc). */
static unsigned char *glb_build(const char *json, const void *binp, size_t bin_len, size_t *out_len)
{
    size_t jl = strlen(json), jpad = (jl + 3) & ~(size_t)3;
    size_t bpad = (bin_len + 3) & ~(size_t)3;
    size_t total = 12 + 8 + jpad + (bin_len ? 8 + bpad : 0);
    unsigned char *g = calloc(1, total);
    assert_non_null(g);
    memcpy(g, "glTF", 4);
    put_le32(g + 4, 2);
    put_le32(g + 8, (uint32_t)total);
    put_le32(g + 12, (uint32_t)jpad);
    memcpy(g + 16, "JSON", 4);
    memcpy(g + 20, json, jl);
    memset(g + 20 + jl, ' ', jpad - jl);
    if (bin_len) {
        unsigned char *c = g + 20 + jpad;
        put_le32(c, (uint32_t)bpad);
        memcpy(c + 4, "BIN\0", 4);
        memcpy(c + 8, binp, bin_len);
    }
    *out_len = total;
    return g;
}

/* Writes a file into dir and copies its path into out (PATH_MAX-sized). */
static void write_file(char *out, const char *dir, const char *name, const void *data, size_t size)
{
    snprintf(out, 512, "%s", lpvt_write_file(dir, name, data, size));
}

static void write_glb(char *out, const char *name, const char *json, const bin *b)
{
    size_t len;
    unsigned char *g = glb_build(json, b ? b->b : NULL, b ? b->n : 0, &len);
    write_file(out, lpvt_tmpdir(), name, g, len);
    free(g);
}

static int scene_is_zero(const lpv_scene *s)
{
    static const lpv_scene zero;
    return memcmp(s, &zero, sizeof zero) == 0;
}

static void load_ok(const char *path, lpv_scene *s)
{
    char err[512] = "";
    memset(s, 0x5a, sizeof *s);
    int rc = lpv_gltf_load_file(path, s, err, sizeof err);
    if (rc != 0)
        fail_msg("loading %s failed: %s", path, err);
    assert_string_equal(s->source, path);
    assert_int_equal(s->default_light_added, 0);
}

/* Loading must fail, name the file, and say `word`; the scene stays zeroed. */
static void expect_fail_path(const char *path, const char *word)
{
    lpv_scene s;
    char err[768] = "";
    memset(&s, 0x5a, sizeof s);
    int rc = lpv_gltf_load_file(path, &s, err, sizeof err);
    const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    print_message("    %-28s -> %s\n", base, err);
    if (rc != -1)
        fail_msg("%s loaded but should have failed with '%s'", path, word);
    if (!strstr(err, base))
        fail_msg("error '%s' does not name the file '%s'", err, base);
    if (!strstr(err, word))
        fail_msg("error '%s' does not mention '%s'", err, word);
    assert_true(scene_is_zero(&s));
    lpv_scene_free(&s);
}

static void expect_fail_glb(const char *name, const char *json, const bin *b, const char *word)
{
    char path[512];
    write_glb(path, name, json, b);
    expect_fail_path(path, word);
}

static void assert_vec3(const float *v, float x, float y, float z, float tol)
{
    if (fabsf(v[0] - x) > tol || fabsf(v[1] - y) > tol || fabsf(v[2] - z) > tol)
        fail_msg("(%g, %g, %g) != (%g, %g, %g) within %g", v[0], v[1], v[2], x, y, z, tol);
}

static void make_subdir(char *out, const char *name)
{
    snprintf(out, 512, "%s/%s", lpvt_tmpdir(), name);
    if (mkdir(out, 0700) != 0) {
        struct stat st;
        assert_true(stat(out, &st) == 0 && S_ISDIR(st.st_mode));
    }
}

/* The simplest valid scene: one non-indexed triangle, no material, no normals. */
static const char *TRI_JSON =
    "{'asset':{'version':'2.0'},'buffers':[{'byteLength':36}],"
    "'bufferViews':[{'buffer':0,'byteLength':36}],"
    "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
    "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
    "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}],'scene':0}";

static void tri_bin(bin *b)
{
    memset(b, 0, sizeof *b);
    put_vec3(b, 0, 0, 0);
    put_vec3(b, 1, 0, 0);
    put_vec3(b, 0, 1, 0);
}

/* ---- (a) valid files ------------------------------------------------------ */

static void test_one_triangle(void **state)
{
    (void)state;
    bin b;
    tri_bin(&b);
    char path[512];
    write_glb(path, "one-triangle.glb", J("%s", TRI_JSON), &b);
    lpv_scene s;
    load_ok(path, &s);
    assert_int_equal(s.vertex_count, 3);
    assert_int_equal(s.index_count, 3);
    assert_int_equal(s.draw_count, 1);
    assert_int_equal(s.draws[0].first_index, 0);
    assert_int_equal(s.draws[0].index_count, 3);
    /* no material: the default one, white with roughness 1 */
    assert_int_equal(s.material_count, 1);
    assert_int_equal(s.draws[0].material, 0);
    assert_vec3(s.materials[0].base_color, 1, 1, 1, 0);
    assert_true(s.materials[0].base_color[3] == 1.0f);
    assert_true(s.materials[0].roughness == 1.0f);
    assert_int_equal(s.materials[0].base_color_texture, -1);
    assert_vec3(s.vertices[s.indices[1]].position, 1, 0, 0, 0);
    assert_vec3(s.vertices[s.indices[2]].position, 0, 1, 0, 0);
    /* no normals in the file: flat from the counter-clockwise winding */
    for (int i = 0; i < 3; i++)
        assert_vec3(s.vertices[i].normal, 0, 0, 1, 1e-6f);
    assert_vec3(s.bounds_min, 0, 0, 0, 0);
    assert_vec3(s.bounds_max, 1, 1, 0, 0);
    assert_int_equal(s.light_count, 0);
    assert_int_equal(s.camera_count, 0);
    lpv_scene_free(&s);
    assert_true(scene_is_zero(&s));
}

static void test_indexed_quad_ushort_ubyte_normalized_uv(void **state)
{
    (void)state;
    bin b = {0};
    const float quad[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    for (int i = 0; i < 4; i++)
        put_vec3(&b, quad[i][0], quad[i][1], quad[i][2]); /* 0..48 */
    for (int i = 0; i < 4; i++)
        put_vec3(&b, 0, 0, 1); /* 48..96 */
    const uint8_t uv[8] = {0, 0, 255, 0, 255, 255, 0, 128};
    for (int i = 0; i < 8; i++)
        put_u8(&b, uv[i]); /* 96..104 */
    const uint16_t q[6] = {0, 1, 2, 0, 2, 3};
    for (int i = 0; i < 6; i++)
        put_u16(&b, q[i]); /* 104..116 */
    for (int i = 0; i < 6; i++)
        put_u8(&b, (uint8_t)q[i]); /* 116..122 */
    pad4(&b);
    const char *json = J(
        "{'asset':{'version':'2.0'},'buffers':[{'byteLength':%zu}],"
        "'bufferViews':[{'buffer':0,'byteOffset':0,'byteLength':48},{'buffer':0,'byteOffset':48,'byteLength':48},"
        "{'buffer':0,'byteOffset':96,'byteLength':8},{'buffer':0,'byteOffset':104,'byteLength':12},"
        "{'buffer':0,'byteOffset':116,'byteLength':6}],"
        "'accessors':[{'bufferView':0,'componentType':5126,'count':4,'type':'VEC3'},"
        "{'bufferView':1,'componentType':5126,'count':4,'type':'VEC3'},"
        "{'bufferView':2,'componentType':5121,'normalized':true,'count':4,'type':'VEC2'},"
        "{'bufferView':3,'componentType':5123,'count':6,'type':'SCALAR'},"
        "{'bufferView':4,'componentType':5121,'count':6,'type':'SCALAR'}],"
        "'materials':[{'name':'paint','doubleSided':true,'pbrMetallicRoughness':{'baseColorFactor':[0.5,0.25,1,0.75],"
        "'metallicFactor':0.3,'roughnessFactor':0.7}}],"
        "'meshes':[{'primitives':[{'attributes':{'POSITION':0,'NORMAL':1,'TEXCOORD_0':2},'indices':3,'material':0},"
        "{'attributes':{'POSITION':0,'NORMAL':1,'TEXCOORD_0':2},'indices':4}]}],"
        "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}",
        b.n);
    char path[512];
    write_glb(path, "indexed-quad.glb", json, &b);
    lpv_scene s;
    load_ok(path, &s);
    assert_int_equal(s.draw_count, 2);
    assert_int_equal(s.index_count, 12);
    assert_int_equal(s.vertex_count, 8); /* shared within each primitive */
    assert_int_equal(s.draws[1].first_index, 6);
    for (int i = 0; i < 6; i++) {
        assert_int_equal(s.indices[i], q[i]);
        assert_int_equal(s.indices[6 + i], 4 + q[i]);
    }
    for (uint32_t v = 0; v < 8; v++) {
        assert_vec3(s.vertices[v].position, quad[v % 4][0], quad[v % 4][1], quad[v % 4][2], 0);
        assert_vec3(s.vertices[v].normal, 0, 0, 1, 1e-6f);
    }
    assert_true(fabsf(s.vertices[2].uv[0] - 1.0f) < 1e-6f && fabsf(s.vertices[2].uv[1] - 1.0f) < 1e-6f);
    assert_true(fabsf(s.vertices[3].uv[0]) < 1e-6f && fabsf(s.vertices[3].uv[1] - 128.0f / 255.0f) < 1e-6f);
    /* material 0 from the file, then the default one for the second primitive */
    assert_int_equal(s.material_count, 2);
    assert_int_equal(s.draws[0].material, 0);
    assert_int_equal(s.draws[1].material, 1);
    assert_string_equal(s.materials[0].name, "paint");
    assert_true(s.materials[0].base_color[0] == 0.5f && s.materials[0].base_color[1] == 0.25f &&
                s.materials[0].base_color[2] == 1.0f && s.materials[0].base_color[3] == 0.75f);
    assert_true(fabsf(s.materials[0].metallic - 0.3f) < 1e-6f && fabsf(s.materials[0].roughness - 0.7f) < 1e-6f);
    assert_int_equal(s.materials[0].double_sided, 1);
    assert_string_equal(s.materials[1].name, "default");
    lpv_scene_free(&s);
}

static void test_node_hierarchy(void **state)
{
    (void)state;
    bin b;
    tri_bin(&b);
    /* 0: translation (1,2,3) with child 1 rotated +90 deg about z;
     * 2: mirrored in x (negative determinant); 3: a matrix translating by 10 in x. */
    const char *json = J(
        "{'asset':{'version':'2.0'},'buffers':[{'byteLength':36}],"
        "'bufferViews':[{'buffer':0,'byteLength':36}],"
        "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
        "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
        "'nodes':[{'translation':[1,2,3],'children':[1]},{'rotation':[0,0,%.9f,%.9f],'mesh':0},"
        "{'scale':[-1,1,1],'mesh':0},{'matrix':[1,0,0,0, 0,1,0,0, 0,0,1,0, 10,0,0,1],'mesh':0}],"
        "'scenes':[{'nodes':[0,2,3]}]}",
        S45, S45);
    char path[512];
    write_glb(path, "hierarchy.glb", json, &b);
    lpv_scene s;
    load_ok(path, &s);
    assert_int_equal(s.draw_count, 3);
    assert_int_equal(s.vertex_count, 9);
    /* child: R_z(90) p + (1,2,3) */
    assert_vec3(s.vertices[0].position, 1, 2, 3, 1e-6f);
    assert_vec3(s.vertices[1].position, 1, 3, 3, 1e-6f);
    assert_vec3(s.vertices[2].position, 0, 2, 3, 1e-6f);
    assert_vec3(s.vertices[0].normal, 0, 0, 1, 1e-6f);
    /* mirrored: the winding is flipped, so the flat normal still faces +z */
    assert_vec3(s.vertices[3].position, 0, 0, 0, 1e-6f);
    assert_vec3(s.vertices[4].position, 0, 1, 0, 1e-6f);
    assert_vec3(s.vertices[5].position, -1, 0, 0, 1e-6f);
    for (int i = 3; i < 6; i++)
        assert_vec3(s.vertices[i].normal, 0, 0, 1, 1e-6f);
    /* matrix */
    assert_vec3(s.vertices[7].position, 11, 0, 0, 1e-6f);
    assert_vec3(s.bounds_min, -1, 0, 0, 1e-6f);
    assert_vec3(s.bounds_max, 11, 3, 3, 1e-6f);
    lpv_scene_free(&s);
}

static void test_normals_transformed_and_degenerate(void **state)
{
    (void)state;
    bin b;
    tri_bin(&b);
    put_vec3(&b, 0, 0, 1);
    put_vec3(&b, 0, 0, 0);         /* zero-length normal */
    put_vec3(&b, NAN, 0, 0);       /* NaN normal */
    /* a scale (2,1,1) leaves the normal (0,0,1) alone */
    const char *json = J(
        "{'asset':{'version':'2.0'},'buffers':[{'byteLength':72}],"
        "'bufferViews':[{'buffer':0,'byteLength':36},{'buffer':0,'byteOffset':36,'byteLength':36}],"
        "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'},"
        "{'bufferView':1,'componentType':5126,'count':3,'type':'VEC3'}],"
        "'meshes':[{'primitives':[{'attributes':{'POSITION':0,'NORMAL':1}}]}],"
        "'nodes':[{'mesh':0,'scale':[2,1,1]}],'scenes':[{'nodes':[0]}]}");
    char path[512];
    write_glb(path, "normals.glb", json, &b);
    lpv_scene s;
    load_ok(path, &s);
    assert_int_equal(s.vertex_count, 3);
    assert_vec3(s.vertices[0].normal, 0, 0, 1, 1e-6f);
    assert_vec3(s.vertices[1].normal, 0, 0, 0, 0); /* kept, as zero */
    assert_vec3(s.vertices[2].normal, 0, 0, 0, 0);
    assert_vec3(s.vertices[1].position, 2, 0, 0, 0);
    lpv_scene_free(&s);

    /* inverse transpose under a non-uniform scale */
    bin c;
    tri_bin(&c);
    for (int i = 0; i < 3; i++)
        put_vec3(&c, S45, S45, 0);
    json = J(
        "{'asset':{'version':'2.0'},'buffers':[{'byteLength':72}],"
        "'bufferViews':[{'buffer':0,'byteLength':36},{'buffer':0,'byteOffset':36,'byteLength':36}],"
        "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'},"
        "{'bufferView':1,'componentType':5126,'count':3,'type':'VEC3'}],"
        "'meshes':[{'primitives':[{'attributes':{'POSITION':0,'NORMAL':1}}]}],"
        "'nodes':[{'mesh':0,'scale':[2,1,1]}],'scenes':[{'nodes':[0]}]}");
    write_glb(path, "normals-scaled.glb", json, &c);
    load_ok(path, &s);
    /* n' ~ S^-1 n = (0.5, 1, 0) normalised */
    float l = sqrtf(0.25f + 1.0f);
    assert_vec3(s.vertices[0].normal, 0.5f / l, 1.0f / l, 0, 1e-6f);
    lpv_scene_free(&s);
}

static void test_sparse_accessors(void **state)
{
    (void)state;
    bin b;
    tri_bin(&b); /* 0..36 */
    put_u16(&b, 1);
    pad4(&b);                 /* 36..40: sparse indices of accessor 0 */
    put_vec3(&b, 5, 5, 5);    /* 40..52: sparse values of accessor 0 */
    put_u16(&b, 0);
    put_u16(&b, 2);           /* 52..56: sparse indices of accessor 1 */
    put_vec3(&b, 1, 0, 0);
    put_vec3(&b, 0, 1, 0);    /* 56..80: sparse values of accessor 1 */
    const char *json = J(
        "{'asset':{'version':'2.0'},'buffers':[{'byteLength':80}],"
        "'bufferViews':[{'buffer':0,'byteLength':36},{'buffer':0,'byteOffset':36,'byteLength':4},"
        "{'buffer':0,'byteOffset':40,'byteLength':12},{'buffer':0,'byteOffset':52,'byteLength':4},"
        "{'buffer':0,'byteOffset':56,'byteLength':24}],"
        "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3',"
        "'sparse':{'count':1,'indices':{'bufferView':1,'componentType':5123},'values':{'bufferView':2}}},"
        "{'componentType':5126,'count':3,'type':'VEC3',"
        "'sparse':{'count':2,'indices':{'bufferView':3,'componentType':5123},'values':{'bufferView':4}}}],"
        "'meshes':[{'primitives':[{'attributes':{'POSITION':0}},{'attributes':{'POSITION':1}}]}],"
        "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}");
    char path[512];
    write_glb(path, "sparse.glb", json, &b);
    lpv_scene s;
    load_ok(path, &s);
    assert_int_equal(s.draw_count, 2);
    assert_vec3(s.vertices[0].position, 0, 0, 0, 0);
    assert_vec3(s.vertices[1].position, 5, 5, 5, 0); /* replaced */
    assert_vec3(s.vertices[2].position, 0, 1, 0, 0);
    /* no bufferView: zeros, then the sparse values */
    assert_vec3(s.vertices[3].position, 1, 0, 0, 0);
    assert_vec3(s.vertices[4].position, 0, 0, 0, 0);
    assert_vec3(s.vertices[5].position, 0, 1, 0, 0);
    lpv_scene_free(&s);
}

static void test_strip_fan_points_lines(void **state)
{
    (void)state;
    bin b = {0};
    /* a strip of 4 (offset 0) and a fan of 5 around its first vertex (offset 48) */
    put_vec3(&b, 0, 0, 0);
    put_vec3(&b, 1, 0, 0);
    put_vec3(&b, 0, 1, 0);
    put_vec3(&b, 1, 1, 0);
    put_vec3(&b, 0, 0, 0);
    put_vec3(&b, 1, 0, 0);
    put_vec3(&b, 1, 1, 0);
    put_vec3(&b, 0, 1, 0);
    put_vec3(&b, -1, 1, 0);
    const char *json = J(
        "{'asset':{'version':'2.0'},'buffers':[{'byteLength':108}],"
        "'bufferViews':[{'buffer':0,'byteLength':108}],"
        "'accessors':[{'bufferView':0,'componentType':5126,'count':4,'type':'VEC3'},"
        "{'bufferView':0,'byteOffset':48,'componentType':5126,'count':5,'type':'VEC3'}],"
        "'meshes':[{'primitives':[{'attributes':{'POSITION':0},'mode':5},{'attributes':{'POSITION':1},'mode':6},"
        "{'attributes':{'POSITION':1},'mode':0},{'attributes':{'POSITION':1},'mode':1},"
        "{'attributes':{'POSITION':1},'mode':2},{'attributes':{'POSITION':1},'mode':3}]}],"
        "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}");
    char path[512];
    write_glb(path, "strip-fan.glb", json, &b);
    lpv_scene s;
    load_ok(path, &s);
    assert_int_equal(s.draw_count, 2); /* points and lines are wire draws, apart */
    assert_int_equal(s.draws[0].index_count, 6);
    assert_int_equal(s.draws[1].index_count, 9);
    assert_int_equal(s.index_count, 15);
    /* strip triangle 1 is (v1, v3, v2) */
    assert_vec3(s.vertices[s.indices[3]].position, 1, 0, 0, 0);
    assert_vec3(s.vertices[s.indices[4]].position, 1, 1, 0, 0);
    assert_vec3(s.vertices[s.indices[5]].position, 0, 1, 0, 0);
    /* fan triangle 0 is (v1, v2, v0) */
    assert_vec3(s.vertices[s.indices[6]].position, 1, 0, 0, 0);
    assert_vec3(s.vertices[s.indices[7]].position, 1, 1, 0, 0);
    assert_vec3(s.vertices[s.indices[8]].position, 0, 0, 0, 0);
    /* every triangle of both faces +z (consistent winding) */
    for (uint32_t i = 0; i < s.index_count; i++)
        assert_vec3(s.vertices[s.indices[i]].normal, 0, 0, 1, 1e-6f);
    /* the points (5), lines (5 vertices: 2 segments, the odd one dropped),
     * the loop (5 segments, the last back to v0) and the strip (4) */
    assert_int_equal(s.wire_draw_count, 4);
    const int modes[4] = {LPV_DRAW_POINTS, LPV_DRAW_LINES, LPV_DRAW_LINES, LPV_DRAW_LINES};
    const uint32_t counts[4] = {5, 4, 10, 8};
    uint32_t at = 0;
    for (int k = 0; k < 4; k++) {
        assert_int_equal(s.wire_draws[k].mode, modes[k]);
        assert_int_equal(s.wire_draws[k].first_index, at);
        assert_int_equal(s.wire_draws[k].index_count, counts[k]);
        at += counts[k];
    }
    assert_int_equal(s.wire_index_count, at);
    const uint32_t *loop = s.wire_indices + s.wire_draws[2].first_index;
    assert_vec3(s.vertices[loop[8]].position, -1, 1, 0, 0); /* v4 ... */
    assert_vec3(s.vertices[loop[9]].position, 0, 0, 0, 0);  /* ... back to v0 */
    const uint32_t *strip = s.wire_indices + s.wire_draws[3].first_index;
    assert_vec3(s.vertices[strip[2]].position, 1, 0, 0, 0); /* segment 1 is (v1, v2) */
    assert_vec3(s.vertices[strip[3]].position, 1, 1, 0, 0);
    for (uint32_t i = 0; i < s.wire_index_count; i++)
        assert_true(s.wire_indices[i] < s.vertex_count);
    lpv_scene c; /* the engine's copy keeps them */
    assert_int_equal(lpv_scene_copy_geometry(&c, &s), 0);
    assert_int_equal(c.wire_draw_count, 4);
    assert_int_equal(c.wire_index_count, at);
    assert_memory_equal(c.wire_indices, s.wire_indices, at * sizeof *s.wire_indices);
    lpv_scene_free(&c);
    lpv_scene_free(&s);
}

static void test_lights(void **state)
{
    (void)state;
    const char *json = J(
        "{'asset':{'version':'2.0'},'extensionsUsed':['KHR_lights_punctual'],"
        "'extensions':{'KHR_lights_punctual':{'lights':["
        "{'type':'point','name':'bulb','intensity':683,'color':[1,0.5,0.25],'range':10},"
        "{'type':'spot','intensity':1366,'spot':{'innerConeAngle':0.2,'outerConeAngle':0.5}},"
        "{'type':'directional','intensity':2049},"
        "{'type':'spot','spot':{}}]}},"
        "'nodes':[{'translation':[1,2,3],'extensions':{'KHR_lights_punctual':{'light':0}}},"
        "{'translation':[0,5,0],'extensions':{'KHR_lights_punctual':{'light':1}}},"
        "{'rotation':[%.9f,0,0,%.9f],'extensions':{'KHR_lights_punctual':{'light':2}}},"
        "{'rotation':[0,%.9f,0,%.9f],'extensions':{'KHR_lights_punctual':{'light':3}}}],"
        "'scenes':[{'nodes':[0,1,2,3]}],'scene':0}",
        -S45, S45, S45, S45);
    char path[512];
    write_glb(path, "lights.glb", json, NULL);
    lpv_scene s;
    load_ok(path, &s);
    assert_int_equal(s.light_count, 4);
    assert_int_equal(s.vertex_count, 0);

    const lpv_light *l = &s.lights[0];
    assert_int_equal(l->type, LPV_LIGHT_POINT);
    assert_string_equal(l->name, "bulb");
    assert_true(fabsf(l->intensity - 1.0f) < 1e-6f); /* 683 cd -> 1 W/sr */
    assert_vec3(l->color, 1, 0.5f, 0.25f, 0);
    assert_true(l->range == 10.0f);
    assert_vec3(l->position, 1, 2, 3, 1e-6f);

    l = &s.lights[1];
    assert_int_equal(l->type, LPV_LIGHT_SPOT);
    assert_string_equal(l->name, "light1");
    assert_true(fabsf(l->intensity - 2.0f) < 1e-6f);
    assert_true(fabsf(l->inner_cone - 0.2f) < 1e-7f && fabsf(l->outer_cone - 0.5f) < 1e-7f);
    assert_vec3(l->color, 1, 1, 1, 0);
    assert_true(l->range == 0.0f);
    assert_vec3(l->position, 0, 5, 0, 1e-6f);
    assert_vec3(l->direction, 0, 0, -1, 1e-6f);

    l = &s.lights[2];
    assert_int_equal(l->type, LPV_LIGHT_DIRECTIONAL);
    assert_true(fabsf(l->intensity - 3.0f) < 1e-6f); /* 2049 lx -> 3 W/m^2 */
    assert_vec3(l->direction, 0, -1, 0, 1e-6f);      /* -90 deg about x */

    l = &s.lights[3];
    assert_int_equal(l->type, LPV_LIGHT_SPOT);
    assert_true(fabsf(l->intensity - 1.0f / 683.0f) < 1e-9f); /* default 1 cd */
    assert_true(l->inner_cone == 0.0f);
    assert_true(fabsf(l->outer_cone - 0.78539816f) < 1e-6f);
    assert_vec3(l->direction, -1, 0, 0, 1e-6f); /* +90 deg about y */
    lpv_scene_free(&s);
}

static void test_cameras(void **state)
{
    (void)state;
    const char *json = J(
        "{'asset':{'version':'2.0'},"
        "'cameras':[{'name':'cam','type':'perspective','perspective':{'yfov':0.8,'znear':0.05,'aspectRatio':1.5,"
        "'zfar':100}},"
        "{'type':'orthographic','orthographic':{'xmag':2,'ymag':3,'znear':0.1,'zfar':50}},"
        "{'type':'perspective','perspective':{'yfov':1,'znear':0.1}}],"
        "'nodes':[{'camera':0,'translation':[1,2,3],'rotation':[0,%.9f,0,%.9f]},{'camera':1},"
        "{'children':[3],'rotation':[%.9f,0,0,%.9f]},{'camera':2}],"
        "'scenes':[{'nodes':[0,1,2]}]}",
        S45, S45, -S45, S45);
    char path[512];
    write_glb(path, "cameras.glb", json, NULL);
    lpv_scene s;
    load_ok(path, &s);
    assert_int_equal(s.camera_count, 3);
    const lpv_camera *c = &s.cameras[0];
    assert_string_equal(c->name, "cam");
    assert_int_equal(c->orthographic, 0);
    assert_true(fabsf(c->yfov - 0.8f) < 1e-7f && fabsf(c->aspect - 1.5f) < 1e-7f);
    assert_true(fabsf(c->znear - 0.05f) < 1e-7f && c->zfar == 100.0f);
    assert_vec3(c->eye, 1, 2, 3, 1e-6f);
    assert_vec3(c->forward, -1, 0, 0, 1e-6f);
    assert_vec3(c->up, 0, 1, 0, 1e-6f);
    c = &s.cameras[1];
    assert_string_equal(c->name, "camera1");
    assert_int_equal(c->orthographic, 1);
    assert_true(c->xmag == 2.0f && c->ymag == 3.0f && c->zfar == 50.0f);
    assert_vec3(c->forward, 0, 0, -1, 0);
    c = &s.cameras[2];
    assert_true(c->aspect == 0.0f && c->zfar == 0.0f);
    /* parent looks down (-90 deg about x): forward (0,-1,0), up (0,0,-1) */
    assert_vec3(c->forward, 0, -1, 0, 1e-6f);
    assert_vec3(c->up, 0, 0, -1, 1e-6f);
    lpv_scene_free(&s);
}

static void test_emissive_strength(void **state)
{
    (void)state;
    const char *json = J(
        "{'asset':{'version':'2.0'},'extensionsUsed':['KHR_materials_emissive_strength'],"
        "'materials':[{'name':'lamp','emissiveFactor':[1,0.5,0.25],"
        "'extensions':{'KHR_materials_emissive_strength':{'emissiveStrength':4}}},"
        "{'emissiveFactor':[1,1,1]},{}]}");
    char path[512];
    write_glb(path, "emissive.glb", json, NULL);
    lpv_scene s;
    load_ok(path, &s);
    assert_int_equal(s.material_count, 3);
    assert_vec3(s.materials[0].emission, 4.0f / 683.0f, 2.0f / 683.0f, 1.0f / 683.0f, 1e-9f);
    assert_vec3(s.materials[1].emission, 1.0f / 683.0f, 1.0f / 683.0f, 1.0f / 683.0f, 1e-9f);
    assert_vec3(s.materials[2].emission, 0, 0, 0, 0);
    assert_string_equal(s.materials[1].name, "material1");
    /* defaults of a glTF material: metallic 1, roughness 1, single-sided */
    assert_true(s.materials[2].metallic == 1.0f && s.materials[2].roughness == 1.0f);
    assert_int_equal(s.materials[2].double_sided, 0);
    lpv_scene_free(&s);
}

/* A 2x2 RGBA PNG: red, green / blue, white at alpha 128. */
static const unsigned char png_2x2[] = {
    0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52, 0x00, 0x00, 0x00,
    0x02, 0x00, 0x00, 0x00, 0x02, 0x08, 0x06, 0x00, 0x00, 0x00, 0x72, 0xb6, 0x0d, 0x24, 0x00, 0x00, 0x00, 0x13, 0x49,
    0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0xf8, 0xcf, 0xc0, 0xf0, 0x1f, 0x0c, 0x81, 0x34, 0x08, 0x34, 0x00, 0x00, 0x49,
    0x49, 0x09, 0x78, 0x28, 0xa0, 0xdb, 0x77, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};

/* A PNG header claiming 20000 x 20000 texels (never decoded). */
static const unsigned char png_huge[] = {
    0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52, 0x00,
    0x00, 0x4e, 0x20, 0x00, 0x00, 0x4e, 0x20, 0x08, 0x06, 0x00, 0x00, 0x00, 0xe3, 0x70, 0x46, 0x39, 0x00,
    0x00, 0x00, 0x0b, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0x60, 0x80, 0x01, 0x00, 0x00, 0x0a, 0x00,
    0x01, 0x7f, 0x80, 0x74, 0x5e, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};

static const char *textured_json(size_t png_len, size_t image_offset)
{
    return J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':%zu}],"
             "'bufferViews':[{'buffer':0,'byteLength':36},{'buffer':0,'byteOffset':%zu,'byteLength':%zu}],"
             "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
             "'images':[{'bufferView':1,'mimeType':'image/png'}],'textures':[{'source':0}],"
             "'materials':[{'pbrMetallicRoughness':{'baseColorTexture':{'index':0}}}],"
             "'meshes':[{'primitives':[{'attributes':{'POSITION':0},'material':0}]}],"
             "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}",
             (size_t)((36 + png_len + 3) & ~3u), image_offset, png_len);
}

static void test_texture(void **state)
{
    (void)state;
    bin b;
    tri_bin(&b);
    put(&b, png_2x2, sizeof png_2x2);
    pad4(&b);
    char path[512];
    write_glb(path, "textured.glb", textured_json(sizeof png_2x2, 36), &b);
    lpv_scene s;
    load_ok(path, &s);
    assert_int_equal(s.texture_count, 1);
    assert_int_equal(s.materials[0].base_color_texture, 0);
    assert_int_equal(s.textures[0].width, 2);
    assert_int_equal(s.textures[0].height, 2);
    static const uint8_t want[16] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 128};
    assert_memory_equal(s.textures[0].rgba8, want, 16);
    lpv_scene_free(&s);
}

static void test_gltf_external_bin_and_data_uri(void **state)
{
    (void)state;
    char dir[512], path[512], sub[1024];
    make_subdir(dir, "ext");
    snprintf(sub, sizeof sub, "%s/bin", dir);
    mkdir(sub, 0700);
    bin b;
    tri_bin(&b);
    write_file(path, sub, "tri angle.bin", b.b, b.n);
    const char *ext_text = J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36,'uri':'bin/tri%%20angle.bin'}],"
                             "'bufferViews':[{'buffer':0,'byteLength':36}],"
                             "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
                             "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                             "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}");
    write_file(path, dir, "external.gltf", ext_text, strlen(ext_text));
    lpv_scene s;
    load_ok(path, &s);
    assert_int_equal(s.vertex_count, 3);
    assert_vec3(s.bounds_max, 1, 1, 0, 0);
    lpv_scene_free(&s);

    /* the same bytes as a data: URI (base64 of the 36 bytes) */
    static const char b64tab[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char b64[64] = "";
    size_t o = 0;
    for (size_t i = 0; i < b.n; i += 3) {
        uint32_t v = (uint32_t)b.b[i] << 16 | (uint32_t)b.b[i + 1] << 8 | b.b[i + 2];
        b64[o++] = b64tab[(v >> 18) & 63];
        b64[o++] = b64tab[(v >> 12) & 63];
        b64[o++] = b64tab[(v >> 6) & 63];
        b64[o++] = b64tab[v & 63];
    }
    b64[o] = '\0';
    const char *json = J("{'asset':{'version':'2.0'},"
                         "'buffers':[{'byteLength':36,'uri':'data:application/octet-stream;base64,%s'}],"
                         "'bufferViews':[{'buffer':0,'byteLength':36}],"
                         "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
                         "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                         "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}",
                         b64);
    write_file(path, dir, "data-uri.gltf", json, strlen(json));
    load_ok(path, &s);
    assert_int_equal(s.vertex_count, 3);
    assert_vec3(s.vertices[1].position, 1, 0, 0, 0);
    lpv_scene_free(&s);

    /* from memory: data: URIs work without a folder, external files do not */
    char err[512];
    assert_int_equal(lpv_gltf_load_memory(json, strlen(json), NULL, "mem-data", &s, err, sizeof err), 0);
    assert_string_equal(s.source, "mem-data");
    assert_int_equal(s.vertex_count, 3);
    lpv_scene_free(&s);

    const char *ext_json = J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36,'uri':'bin/tri%%20angle.bin'}],"
                             "'bufferViews':[{'buffer':0,'byteLength':36}],"
                             "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
                             "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                             "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}");
    memset(&s, 0x5a, sizeof s);
    assert_int_equal(lpv_gltf_load_memory(ext_json, strlen(ext_json), NULL, "mem-ext", &s, err, sizeof err), -1);
    print_message("    mem-ext -> %s\n", err);
    assert_non_null(strstr(err, "mem-ext"));
    assert_non_null(strstr(err, "refused"));
    assert_true(scene_is_zero(&s));
    assert_int_equal(lpv_gltf_load_memory(ext_json, strlen(ext_json), dir, "mem-dir", &s, err, sizeof err), 0);
    assert_int_equal(s.vertex_count, 3);
    lpv_scene_free(&s);

    /* a glb from memory */
    size_t len;
    unsigned char *g = glb_build(J("%s", TRI_JSON), b.b, b.n, &len);
    assert_int_equal(lpv_gltf_load_memory(g, len, NULL, "mem-glb", &s, err, sizeof err), 0);
    assert_int_equal(s.index_count, 3);
    lpv_scene_free(&s);
    assert_int_equal(lpv_gltf_load_memory(g, len - 1, NULL, "mem-cut", &s, err, sizeof err), -1);
    assert_non_null(strstr(err, "mem-cut"));
    free(g);
}

/* A project's layout (issue 32, item 4): levels/level.gltf whose buffer
 * and image lie in ../shared and at an absolute path. The user's own load
 * (lpvd render, lpvd-reference) reads them; the rooted load the daemon and
 * batch jobs use refuses them, naming the URI. */
static void test_user_paths_outside_the_folder(void **state)
{
    (void)state;
    char root[512], levels[1024], shared[1024], path[512], abs_png[512];
    make_subdir(root, "project");
    snprintf(levels, sizeof levels, "%s/levels", root);
    snprintf(shared, sizeof shared, "%s/shared", root);
    mkdir(levels, 0700);
    mkdir(shared, 0700);
    bin b;
    tri_bin(&b);
    write_file(path, shared, "tri.bin", b.b, b.n);
    write_file(abs_png, shared, "t.png", png_2x2, sizeof png_2x2);
    assert_true(abs_png[0] == '/');
    for (int absolute = 0; absolute <= 1; ++absolute) {
        const char *json = J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36,'uri':'../shared/tri.bin'}],"
                             "'bufferViews':[{'buffer':0,'byteLength':36}],"
                             "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
                             "'images':[{'uri':'%s'}],'textures':[{'source':0}],"
                             "'materials':[{'pbrMetallicRoughness':{'baseColorTexture':{'index':0}}}],"
                             "'meshes':[{'primitives':[{'attributes':{'POSITION':0},'material':0}]}],"
                             "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}",
                             absolute ? abs_png : "../shared/t.png");
        write_file(path, levels, absolute ? "absolute.gltf" : "level.gltf", json, strlen(json));
        lpv_scene s;
        char err[768] = "";
        assert_int_equal(lpv_gltf_load_file_user(path, NULL, &s, NULL, err, sizeof err), 0);
        assert_int_equal(s.vertex_count, 3);
        assert_int_equal(s.texture_count, 1);
        assert_int_equal(s.textures[0].width, 2);
        assert_int_equal(s.materials[0].base_color_texture, 0);
        lpv_scene_free(&s);
        /* the commands' call: lpv_scene_load_user */
        assert_int_equal(lpv_scene_load_user(path, NULL, &s, err, sizeof err), 0);
        assert_int_equal(s.texture_count, 1);
        lpv_scene_free(&s);
        /* rooted: refused, the URI named */
        expect_fail_path(path, "../shared/tri.bin");
        assert_int_equal(lpv_scene_load(path, &s, err, sizeof err), -1);
        assert_non_null(strstr(err, "leaves the scene's folder"));
    }
    /* a missing file outside is still named as missing */
    const char *gone = J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36,'uri':'../nowhere/tri.bin'}],"
                         "'bufferViews':[{'buffer':0,'byteLength':36}],"
                         "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
                         "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                         "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}");
    write_file(path, levels, "gone.gltf", gone, strlen(gone));
    lpv_scene s;
    char err[768] = "";
    assert_int_equal(lpv_gltf_load_file_user(path, NULL, &s, NULL, err, sizeof err), -1);
    print_message("    gone.gltf (user) -> %s\n", err);
    assert_non_null(strstr(err, "../nowhere/tri.bin"));
    assert_non_null(strstr(err, "not found"));
}

/* ---- (b) malformed and hostile files ---------------------------------------- */

static void test_truncated_glb(void **state)
{
    (void)state;
    bin b;
    tri_bin(&b);
    size_t len;
    unsigned char *g = glb_build(J("%s", TRI_JSON), b.b, b.n, &len);
    const size_t cuts[] = {0, 1, 3, 4, 8, 11, 12, 16, 19, 20, 40, len / 2, len - 44, len - 8, len - 1};
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++) {
        char name[64], path[512];
        snprintf(name, sizeof name, "truncated-%zu.glb", cuts[i]);
        write_file(path, lpvt_tmpdir(), name, g, cuts[i]);
        expect_fail_path(path, "truncated");
    }
    free(g);
}

static void test_glb_header_lies(void **state)
{
    (void)state;
    bin b;
    tri_bin(&b);
    size_t len;
    char path[512];
    unsigned char *g = glb_build(J("%s", TRI_JSON), b.b, b.n, &len);

    unsigned char *m = malloc(len);
    assert_non_null(m);
    memcpy(m, g, len);
    memcpy(m, "glTX", 4);
    write_file(path, lpvt_tmpdir(), "wrong-magic.glb", m, len);
    expect_fail_path(path, "magic");

    memcpy(m, g, len);
    put_le32(m + 8, (uint32_t)len + 100);
    write_file(path, lpvt_tmpdir(), "length-larger.glb", m, len);
    expect_fail_path(path, "larger than the file");

    memcpy(m, g, len);
    put_le32(m + 8, (uint32_t)len - 8);
    write_file(path, lpvt_tmpdir(), "length-smaller.glb", m, len);
    expect_fail_path(path, "smaller");

    memcpy(m, g, len);
    put_le32(m + 12, (uint32_t)len);
    write_file(path, lpvt_tmpdir(), "json-chunk-long.glb", m, len);
    expect_fail_path(path, "out of range");

    memcpy(m, g, len);
    put_le32(m + 12, 0xfffffff0u);
    write_file(path, lpvt_tmpdir(), "json-chunk-huge.glb", m, len);
    expect_fail_path(path, "out of range");

    /* BIN chunk longer than what is left */
    memcpy(m, g, len);
    size_t bin_hdr = 20 + ((strlen(J("%s", TRI_JSON)) + 3) & ~(size_t)3);
    put_le32(m + bin_hdr, 400);
    write_file(path, lpvt_tmpdir(), "bin-chunk-long.glb", m, len);
    expect_fail_path(path, "out of range");

    /* version 1 */
    memcpy(m, g, len);
    put_le32(m + 4, 1);
    write_file(path, lpvt_tmpdir(), "version-1.glb", m, len);
    expect_fail_path(path, "version");

    /* binary junk, no magic at all */
    memset(m, 0xee, len);
    write_file(path, lpvt_tmpdir(), "junk.bin", m, len);
    expect_fail_path(path, "magic");
    free(m);
    free(g);
}

/* The glTF 2.0 schema's JSON types of the fields lpvd reads (issue 32,
 * scene/gltf_schema.cpp): a wrong one is refused with its JSON path, where
 * tinygltf skipped it and loaded the rest (a mesh without primitives, a
 * material without its texture); a name that is not a string only warns. */
static void test_schema_types(void **state)
{
    (void)state;
    bin b;
    tri_bin(&b);
    static const char *const T = "{'asset':{'version':'2.0'},'buffers':[{'byteLength':36}],"
                                 "'bufferViews':[{'buffer':0,'byteLength':36}],"
                                 "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],";
    const struct {
        const char *name, *rest, *words;
    } bad[] = {
        {"prim-object.glb", "'meshes':[{'primitives':{'attributes':{'POSITION':0}}}],'nodes':[{'mesh':0}],"
                            "'scenes':[{'nodes':[0]}],'scene':0}",
         "meshes[0].primitives: expected an array, found an object"},
        {"attr-string.glb", "'meshes':[{'primitives':[{'attributes':{'POSITION':'0'}}]}],'nodes':[{'mesh':0}],"
                            "'scenes':[{'nodes':[0]}],'scene':0}",
         "meshes[0].primitives[0].attributes.POSITION: expected an index (an integer >= 0), found a string"},
        {"mesh-negative.glb", "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],'nodes':[{'mesh':-1}],"
                              "'scenes':[{'nodes':[0]}],'scene':0}",
         "nodes[0].mesh: expected an index (an integer >= 0), found a negative integer"},
        {"mesh-half.glb", "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],'nodes':[{'mesh':0.5}],"
                          "'scenes':[{'nodes':[0]}],'scene':0}",
         "nodes[0].mesh: expected an index (an integer >= 0), found a fractional number"},
        /* tinygltf reads 0.0 as no index at all: the mesh would have no vertices */
        {"position-float.glb", "'meshes':[{'primitives':[{'attributes':{'POSITION':0.0}}]}],'nodes':[{'mesh':0}],"
                               "'scenes':[{'nodes':[0]}],'scene':0}",
         "attributes.POSITION: expected an index (an integer >= 0), found a number with a decimal point"},
        {"pbr-array.glb", "'materials':[{'pbrMetallicRoughness':['x']}],"
                          "'meshes':[{'primitives':[{'attributes':{'POSITION':0},'material':0}]}],"
                          "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}],'scene':0}",
         "materials[0].pbrMetallicRoughness: expected an object, found an array"},
        {"factor-string.glb", "'materials':[{'emissiveFactor':[1,'1',1]}],"
                              "'meshes':[{'primitives':[{'attributes':{'POSITION':0},'material':0}]}],"
                              "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}],'scene':0}",
         "materials[0].emissiveFactor[1]: expected a number, found a string"},
        {"matrix-null.glb", "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                            "'nodes':[{'mesh':0,'matrix':null}],'scenes':[{'nodes':[0]}],'scene':0}",
         "nodes[0].matrix: expected an array, found null"},
        {"light-type.glb", "'extensions':{'KHR_lights_punctual':{'lights':[{'type':1}]}},"
                           "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],'nodes':[{'mesh':0}],"
                           "'scenes':[{'nodes':[0]}],'scene':0}",
         "extensions.KHR_lights_punctual.lights[0].type: expected a string, found an integer"},
        {"top-array.glb", "'meshes':{},'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}],'scene':0}",
         "meshes: expected an array, found an object"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i)
        expect_fail_glb(bad[i].name, J("%s%s", T, bad[i].rest), &b, bad[i].words);

    /* fine: free-form extras and unknown extensions with any types; a name
     * that is a number is a warning */
    char path[512];
    write_glb(path, "schema-ok.glb",
              J("%s%s", T,
                "'meshes':[{'name':7,'primitives':[{'attributes':{'POSITION':0},'extras':{'mode':'x'}}]}],"
                "'nodes':[{'mesh':0,'extensions':{'EXT_unknown':{'light':'x'}}}],'scenes':[{'nodes':[0]}],"
                "'scene':0}"),
              &b);
    lpv_scene s;
    lpv_gltf_warnings w;
    char err[512] = "";
    assert_int_equal(lpv_gltf_load_file_w(path, &s, &w, err, sizeof err), 0);
    assert_int_equal(s.index_count, 3);
    int named = 0;
    for (int i = 0; i < w.count; ++i)
        named += strstr(w.line[i], "meshes[0].name: expected a string, found an integer") != NULL;
    assert_int_equal(named, 1);
    lpv_scene_free(&s);
}

static void test_invalid_json(void **state)
{
    (void)state;
    expect_fail_glb("invalid-json.glb", "{'asset':{'version':'2.0'},'nodes':[{'mesh':0,}]", NULL, "invalid JSON");
    char path[512];
    const char *bad = "{\"asset\":{\"version\":\"2.0\"} trailing";
    write_file(path, lpvt_tmpdir(), "invalid-json.gltf", bad, strlen(bad));
    expect_fail_path(path, "invalid JSON");
    const char *number = "{\"asset\":{\"version\":\"2.0\"},\"extras\":1e999}";
    write_file(path, lpvt_tmpdir(), "number-overflow.gltf", number, strlen(number));
    expect_fail_path(path, "invalid JSON");
    /* not an object / no asset: tinygltf's own messages are passed on */
    const char *noasset = "{\"nodes\":[]}";
    write_file(path, lpvt_tmpdir(), "no-asset.gltf", noasset, strlen(noasset));
    expect_fail_path(path, "asset");
    /* hostile nesting */
    static char deep[8192];
    size_t n = (size_t)snprintf(deep, sizeof deep, "{\"asset\":{\"version\":\"2.0\"},\"extras\":");
    for (int i = 0; i < 3000; i++)
        deep[n++] = '[';
    for (int i = 0; i < 3000; i++)
        deep[n++] = ']';
    deep[n++] = '}';
    write_file(path, lpvt_tmpdir(), "deep-json.gltf", deep, n);
    expect_fail_path(path, "nested");
}

static void test_ranges(void **state)
{
    (void)state;
    bin b;
    tri_bin(&b);
    /* accessor past the end of its bufferView */
    expect_fail_glb("accessor-past-view.glb",
                    J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36}],"
                      "'bufferViews':[{'buffer':0,'byteLength':36}],"
                      "'accessors':[{'bufferView':0,'componentType':5126,'count':4,'type':'VEC3'}],"
                      "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                      "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}"),
                    &b, "out of range of bufferView");
    expect_fail_glb("accessor-offset.glb",
                    J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36}],"
                      "'bufferViews':[{'buffer':0,'byteLength':36}],"
                      "'accessors':[{'bufferView':0,'byteOffset':4,'componentType':5126,'count':3,'type':'VEC3'}],"
                      "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                      "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}"),
                    &b, "out of range");
    /* bufferView past the end of its buffer */
    expect_fail_glb("view-past-buffer.glb",
                    J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36}],"
                      "'bufferViews':[{'buffer':0,'byteOffset':12,'byteLength':36}],"
                      "'accessors':[{'bufferView':0,'componentType':5126,'count':2,'type':'VEC3'}],"
                      "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                      "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}"),
                    &b, "out of range of buffer");
    /* buffer and accessor indices that do not exist */
    expect_fail_glb("view-bad-buffer.glb",
                    J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36}],"
                      "'bufferViews':[{'buffer':3,'byteLength':36}],"
                      "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
                      "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                      "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}"),
                    &b, "out of range");
    expect_fail_glb("bad-accessor-index.glb",
                    J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36}],"
                      "'bufferViews':[{'buffer':0,'byteLength':36}],"
                      "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
                      "'meshes':[{'primitives':[{'attributes':{'POSITION':7}}]}],"
                      "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}"),
                    &b, "out of range");
    /* byteStride of a view smaller than the element */
    expect_fail_glb("small-stride.glb",
                    J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36}],"
                      "'bufferViews':[{'buffer':0,'byteLength':36,'byteStride':8}],"
                      "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
                      "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                      "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}"),
                    &b, "byteStride");
    /* sparse index outside the accessor */
    bin c;
    tri_bin(&c);
    put_u16(&c, 9);
    pad4(&c);
    put_vec3(&c, 1, 1, 1);
    expect_fail_glb("sparse-index.glb",
                    J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':52}],"
                      "'bufferViews':[{'buffer':0,'byteLength':36},{'buffer':0,'byteOffset':36,'byteLength':4},"
                      "{'buffer':0,'byteOffset':40,'byteLength':12}],"
                      "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3',"
                      "'sparse':{'count':1,'indices':{'bufferView':1,'componentType':5123},'values':{'bufferView':2}}}],"
                      "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                      "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}"),
                    &c, "out of range");
}

static void test_indices_and_values(void **state)
{
    (void)state;
    bin b;
    tri_bin(&b);
    put_u16(&b, 0);
    put_u16(&b, 1);
    put_u16(&b, 5);
    pad4(&b);
    expect_fail_glb("index-out-of-range.glb",
                    J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':44}],"
                      "'bufferViews':[{'buffer':0,'byteLength':36},{'buffer':0,'byteOffset':36,'byteLength':6}],"
                      "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'},"
                      "{'bufferView':1,'componentType':5123,'count':3,'type':'SCALAR'}],"
                      "'meshes':[{'primitives':[{'attributes':{'POSITION':0},'indices':1}]}],"
                      "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}"),
                    &b, "out of range");
    /* float indices are not allowed */
    expect_fail_glb("float-indices.glb",
                    J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':44}],"
                      "'bufferViews':[{'buffer':0,'byteLength':36},{'buffer':0,'byteOffset':0,'byteLength':12}],"
                      "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'},"
                      "{'bufferView':1,'componentType':5126,'count':3,'type':'SCALAR'}],"
                      "'meshes':[{'primitives':[{'attributes':{'POSITION':0},'indices':1}]}],"
                      "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}"),
                    &b, "componentType");

    const float bad[2] = {NAN, INFINITY};
    const char *names[2] = {"nan-position.glb", "inf-position.glb"};
    for (int i = 0; i < 2; i++) {
        bin c;
        tri_bin(&c);
        memcpy(c.b + 16, &bad[i], 4); /* y of vertex 1 */
        expect_fail_glb(names[i], J("%s", TRI_JSON), &c, "NaN");
    }
    /* finite in the file, infinite in the world */
    expect_fail_glb("inf-world.glb",
                    J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36}],"
                      "'bufferViews':[{'buffer':0,'byteLength':36}],"
                      "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
                      "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                      "'nodes':[{'mesh':0,'scale':[1e300,1,1]}],'scenes':[{'nodes':[0]}]}"),
                    &b, "Inf");
}

static void test_missing_buffers(void **state)
{
    (void)state;
    char path[512];
    const char *json = J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36,'uri':'no-such-file.bin'}],"
                         "'bufferViews':[{'buffer':0,'byteLength':36}],"
                         "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
                         "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                         "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}");
    write_file(path, lpvt_tmpdir(), "missing-buffer.gltf", json, strlen(json));
    expect_fail_path(path, "not found");

    json = J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36}],"
             "'bufferViews':[{'buffer':0,'byteLength':36}],"
             "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
             "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
             "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}");
    write_file(path, lpvt_tmpdir(), "buffer-without-uri.gltf", json, strlen(json));
    expect_fail_path(path, "no data");
    /* a .glb whose buffer has no BIN chunk to live in */
    expect_fail_glb("glb-without-bin.glb", json, NULL, "BIN");
    /* an external file of the wrong size */
    bin b;
    tri_bin(&b);
    write_file(path, lpvt_tmpdir(), "short.bin", b.b, 24);
    json = J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36,'uri':'short.bin'}],"
             "'bufferViews':[{'buffer':0,'byteLength':36}],"
             "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
             "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
             "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}");
    write_file(path, lpvt_tmpdir(), "short-buffer.gltf", json, strlen(json));
    expect_fail_path(path, "size");
    /* the file itself */
    snprintf(path, sizeof path, "%s/does-not-exist.glb", lpvt_tmpdir());
    expect_fail_path(path, "No such file");
    expect_fail_path(lpvt_tmpdir(), "regular file");
}

/* An external URI that leaves the folder must be refused before reading:
 * ../secret.bin holds a perfectly valid buffer, so only a refusal fails. */
static void test_uri_escapes(void **state)
{
    (void)state;
    char dir[512], path[512], secret[512], link[1024];
    bin b;
    tri_bin(&b);
    write_file(secret, lpvt_tmpdir(), "secret.bin", b.b, b.n);
    make_subdir(dir, "scene-dir");

    const char *uris[] = {"../secret.bin", "%2e%2e/secret.bin", "sub/../../secret.bin", "/etc/passwd", secret};
    const char *names[] = {"dotdot.gltf", "dotdot-encoded.gltf", "dotdot-deep.gltf", "absolute.gltf",
                           "absolute-secret.gltf"};
    for (int i = 0; i < 5; i++) {
        const char *json = J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36,'uri':'%s'}],"
                             "'bufferViews':[{'buffer':0,'byteLength':36}],"
                             "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
                             "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                             "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}",
                             uris[i]);
        write_file(path, dir, names[i], json, strlen(json));
        expect_fail_path(path, "outside");
        /* the same from a .glb */
        char gname[64];
        snprintf(gname, sizeof gname, "%s.glb", names[i]);
        size_t len;
        unsigned char *g = glb_build(json, NULL, 0, &len);
        write_file(path, dir, gname, g, len);
        free(g);
        expect_fail_path(path, "outside");
    }

    /* a symbolic link inside the folder that points outside */
    snprintf(link, sizeof link, "%s/link.bin", dir);
    unlink(link);
    assert_int_equal(symlink(secret, link), 0);
    const char *json = J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36,'uri':'link.bin'}],"
                         "'bufferViews':[{'buffer':0,'byteLength':36}],"
                         "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
                         "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                         "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}");
    write_file(path, dir, "symlink-out.gltf", json, strlen(json));
    expect_fail_path(path, "outside");

    /* a symbolic link that stays inside is refused too: URIs open beneath the
     * folder with no link on the way, in one step (core/open_beneath.h), so
     * that a file swapped for a link while it is opened cannot lead outside */
    write_file(path, dir, "inside.bin", b.b, b.n);
    snprintf(link, sizeof link, "%s/link-in.bin", dir);
    unlink(link);
    assert_int_equal(symlink("inside.bin", link), 0);
    json = J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36,'uri':'link-in.bin'}],"
             "'bufferViews':[{'buffer':0,'byteLength':36}],"
             "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
             "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
             "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}");
    write_file(path, dir, "symlink-in.gltf", json, strlen(json));
    expect_fail_path(path, "symbolic link");
    /* the plain file itself loads */
    json = J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36,'uri':'inside.bin'}],"
             "'bufferViews':[{'buffer':0,'byteLength':36}],"
             "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
             "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
             "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}");
    write_file(path, dir, "plain-in.gltf", json, strlen(json));
    lpv_scene s;
    load_ok(path, &s);
    assert_int_equal(s.vertex_count, 3);
    lpv_scene_free(&s);

    /* an image URI that leaves the folder is refused as well */
    bin t;
    tri_bin(&t);
    json = J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36}],"
             "'bufferViews':[{'buffer':0,'byteLength':36}],"
             "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
             "'images':[{'uri':'../secret.png'}],'textures':[{'source':0}],"
             "'materials':[{'pbrMetallicRoughness':{'baseColorTexture':{'index':0}}}],"
             "'meshes':[{'primitives':[{'attributes':{'POSITION':0},'material':0}]}],"
             "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}");
    write_file(path, lpvt_tmpdir(), "secret.png", png_2x2, sizeof png_2x2);
    size_t len;
    unsigned char *g = glb_build(json, t.b, t.n, &len);
    write_file(path, dir, "image-outside.glb", g, len);
    free(g);
    expect_fail_path(path, "outside");
}

static void test_node_graphs(void **state)
{
    (void)state;
    bin b;
    tri_bin(&b);
    const char *head = "{'asset':{'version':'2.0'},'buffers':[{'byteLength':36}],"
                       "'bufferViews':[{'buffer':0,'byteLength':36}],"
                       "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}],"
                       "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],";
    expect_fail_glb("self-child.glb", J("%s'nodes':[{'mesh':0,'children':[0]}],'scenes':[{'nodes':[0]}]}", head), &b,
                    "cycle");
    expect_fail_glb("node-cycle.glb",
                    J("%s'nodes':[{'children':[1]},{'children':[2]},{'mesh':0,'children':[1]}],"
                      "'scenes':[{'nodes':[0]}]}",
                      head),
                    &b, "cycle");
    /* a pure cycle with no root at all, and no scenes */
    expect_fail_glb("rootless-cycle.glb", J("%s'nodes':[{'children':[1]},{'mesh':0,'children':[0]}]}", head), &b,
                    "cycle");
    expect_fail_glb("child-range.glb", J("%s'nodes':[{'children':[5]}],'scenes':[{'nodes':[0]}]}", head), &b,
                    "out of range");
    expect_fail_glb("scene-node-range.glb", J("%s'nodes':[{'mesh':0}],'scenes':[{'nodes':[3]}]}", head), &b,
                    "out of range");
    expect_fail_glb("scene-twice.glb", J("%s'nodes':[{'mesh':0}],'scenes':[{'nodes':[0,0]}]}", head), &b, "twice");
    expect_fail_glb("default-scene-range.glb",
                    J("%s'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}],'scene':4}", head), &b, "out of range");
    expect_fail_glb("mesh-range.glb", J("%s'nodes':[{'mesh':9}],'scenes':[{'nodes':[0]}]}", head), &b,
                    "out of range");
    expect_fail_glb("light-range.glb",
                    J("%s'nodes':[{'extensions':{'KHR_lights_punctual':{'light':0}}}],'scenes':[{'nodes':[0]}]}",
                      head),
                    &b, "out of range");
    expect_fail_glb("bad-matrix.glb", J("%s'nodes':[{'mesh':0,'matrix':[1,0,0]}],'scenes':[{'nodes':[0]}]}", head),
                    &b, "matrix");

    /* 70 levels deep */
    static char json[16384];
    size_t n = (size_t)snprintf(json, sizeof json, "%s'nodes':[", head);
    for (int i = 0; i < 70; i++)
        n += (size_t)snprintf(json + n, sizeof json - n, "%s{'children':[%d]}", i ? "," : "", i + 1);
    n += (size_t)snprintf(json + n, sizeof json - n, ",{'mesh':0}],'scenes':[{'nodes':[0]}]}");
    expect_fail_glb("deep-nodes.glb", J("%s", json), &b, "deeper than 64");

    /* exactly 64 levels is fine */
    n = (size_t)snprintf(json, sizeof json, "%s'nodes':[", head);
    for (int i = 0; i < 63; i++)
        n += (size_t)snprintf(json + n, sizeof json - n, "%s{'children':[%d],'translation':[0,1,0]}", i ? "," : "",
                              i + 1);
    n += (size_t)snprintf(json + n, sizeof json - n, ",{'mesh':0}],'scenes':[{'nodes':[0]}]}");
    char path[512];
    write_glb(path, "nodes-64.glb", J("%s", json), &b);
    lpv_scene s;
    load_ok(path, &s);
    assert_vec3(s.bounds_min, 0, 63, 0, 1e-4f);
    lpv_scene_free(&s);

    /* no scenes: every root node is drawn */
    write_glb(path, "no-scenes.glb", J("%s'nodes':[{'mesh':0},{'mesh':0,'translation':[0,0,1]}]}", head), &b);
    load_ok(path, &s);
    assert_int_equal(s.draw_count, 2);
    lpv_scene_free(&s);
}

static void test_absurd_sizes(void **state)
{
    (void)state;
    bin b;
    tri_bin(&b);
    /* count 2^31 with a real bufferView and without one (zeros would need 24 GiB) */
    expect_fail_glb("huge-count.glb",
                    J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36}],"
                      "'bufferViews':[{'buffer':0,'byteLength':36}],"
                      "'accessors':[{'bufferView':0,'componentType':5126,'count':2147483648,'type':'VEC3'}],"
                      "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                      "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}"),
                    &b, "absurd");
    expect_fail_glb("huge-count-noview.glb",
                    J("{'asset':{'version':'2.0'},"
                      "'accessors':[{'componentType':5126,'count':2147483648,'type':'VEC3'}],"
                      "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                      "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}"),
                    NULL, "absurd");
    /* within the element cap, count * stride still far past the view */
    expect_fail_glb("big-stride.glb",
                    J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':36}],"
                      "'bufferViews':[{'buffer':0,'byteLength':36,'byteStride':252}],"
                      "'accessors':[{'bufferView':0,'componentType':5126,'count':40000000,'type':'VEC3'}],"
                      "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                      "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}]}"),
                    &b, "out of range");
    /* a texture header claiming 20000 x 20000 */
    bin t;
    tri_bin(&t);
    put(&t, png_huge, sizeof png_huge);
    pad4(&t);
    expect_fail_glb("huge-texture.glb", textured_json(sizeof png_huge, 36), &t, "texture limit");
    /* the same as a JPEG start-of-frame */
    static const unsigned char jpeg_huge[] = {0xff, 0xd8, 0xff, 0xe0, 0x00, 0x04, 0x00, 0x00, 0xff, 0xc0, 0x00,
                                              0x11, 0x08, 0x4e, 0x20, 0x4e, 0x20, 0x03, 0x01, 0x22, 0x00, 0x02,
                                              0x11, 0x01, 0x03, 0x11, 0x01, 0xff, 0xd9};
    bin j;
    tri_bin(&j);
    put(&j, jpeg_huge, sizeof jpeg_huge);
    pad4(&j);
    expect_fail_glb("huge-jpeg.glb", textured_json(sizeof jpeg_huge, 36), &j, "texture limit");
    /* an image whose bufferView lies outside its buffer */
    bin u;
    tri_bin(&u);
    put(&u, png_2x2, sizeof png_2x2);
    pad4(&u);
    expect_fail_glb("image-view-range.glb", textured_json(sizeof png_2x2, 4000), &u, "out of range");
    /* extensions lpvd cannot honour, each named */
    expect_fail_glb("basisu.glb",
                    J("{'asset':{'version':'2.0'},'extensionsUsed':['KHR_texture_basisu','EXT_mesh_gpu_instancing'],"
                      "'extensionsRequired':['KHR_texture_basisu','EXT_mesh_gpu_instancing']}"),
                    NULL, "does not implement: \"KHR_texture_basisu\", \"EXT_mesh_gpu_instancing\"");
}

/* ---- (c) the shared Cornell box against the built-in one -------------------- */

static double tri_area(const lpv_scene *s, uint32_t t)
{
    const float *a = s->vertices[s->indices[3 * t]].position;
    const float *b = s->vertices[s->indices[3 * t + 1]].position;
    const float *c = s->vertices[s->indices[3 * t + 2]].position;
    double e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = (double)b[k] - a[k];
        e2[k] = (double)c[k] - a[k];
    }
    double x = e1[1] * e2[2] - e1[2] * e2[1], y = e1[2] * e2[0] - e1[0] * e2[2], z = e1[0] * e2[1] - e1[1] * e2[0];
    return 0.5 * sqrt(x * x + y * y + z * z);
}

static double area_of(const lpv_scene *s, const char *material)
{
    double sum = 0.0;
    for (uint32_t d = 0; d < s->draw_count; d++) {
        if (strcmp(s->materials[s->draws[d].material].name, material) != 0)
            continue;
        for (uint32_t t = 0; t < s->draws[d].index_count / 3; t++)
            sum += tri_area(s, s->draws[d].first_index / 3 + t);
    }
    return sum;
}

static void test_cornell_glb_matches_builtin(void **state)
{
    (void)state;
    const char *shared = lpvt_shared_dir();
    if (!shared) {
        print_message("    ../shared is absent: skipped\n");
        skip();
        return;
    }
    char path[512];
    snprintf(path, sizeof path, "%s/scenes/cornell-box.glb", shared);
    lpv_scene g, b;
    load_ok(path, &g);
    assert_int_equal(lpv_scene_builtin_cornell(&b), 0);

    assert_int_equal(g.index_count, 108); /* 36 triangles */
    assert_int_equal(b.index_count, 108);
    assert_int_equal(g.material_count, 8);
    assert_int_equal(b.material_count, 8);
    assert_int_equal(g.draw_count, 8);
    assert_int_equal(g.light_count, 1);
    assert_int_equal(g.camera_count, 1);
    assert_int_equal(g.texture_count, 0);

    for (int k = 0; k < 3; k++) {
        assert_true(fabsf(g.bounds_min[k] - b.bounds_min[k]) < 1e-4f);
        assert_true(fabsf(g.bounds_max[k] - b.bounds_max[k]) < 1e-4f);
    }
    for (uint32_t m = 0; m < b.material_count; m++) {
        const char *name = b.materials[m].name;
        double ag = area_of(&g, name), ab = area_of(&b, name);
        print_message("    %-10s area glb %.6f built-in %.6f\n", name, ag, ab);
        assert_true(ab > 0.0);
        assert_true(fabs(ag - ab) < 1e-4);
        /* the same material in both */
        const lpv_material *mg = NULL;
        for (uint32_t j = 0; j < g.material_count; j++)
            if (strcmp(g.materials[j].name, name) == 0)
                mg = &g.materials[j];
        assert_non_null(mg);
        assert_vec3(mg->base_color, b.materials[m].base_color[0], b.materials[m].base_color[1],
                    b.materials[m].base_color[2], 1e-6f);
        assert_vec3(mg->emission, b.materials[m].emission[0], b.materials[m].emission[1], b.materials[m].emission[2],
                    1e-6f);
        assert_true(fabsf(mg->roughness - b.materials[m].roughness) < 1e-6f);
        assert_true(mg->metallic == b.materials[m].metallic);
        /* The file marks every material doubleSided, so its lamp emits both
         * ways (glTF's meaning, issue 30); the built-in lamp emits down only,
         * as the Cornell data's light does, and is single-sided for that. */
        const int lamp = b.materials[m].emission[0] > 0.0f || b.materials[m].emission[1] > 0.0f;
        assert_int_equal(b.materials[m].double_sided, lamp ? 0 : mg->double_sided);
    }

    /* the lamp: (17, 12, 4) nits -> W/(m^2 sr) */
    const lpv_material *lamp = NULL;
    for (uint32_t j = 0; j < g.material_count; j++)
        if (strcmp(g.materials[j].name, "light") == 0)
            lamp = &g.materials[j];
    assert_non_null(lamp);
    assert_vec3(lamp->emission, 17.0f / 683.0f, 12.0f / 683.0f, 4.0f / 683.0f, 1e-6f);

    const lpv_light *lg = &g.lights[0], *lb = &b.lights[0];
    assert_int_equal(lg->type, LPV_LIGHT_SPOT);
    assert_string_equal(lg->name, "CeilingSpot");
    assert_string_equal(lb->name, lg->name);
    assert_true(fabsf(lg->intensity - 2174.0565f / 683.0f) < 1e-5f);
    assert_true(fabsf(lb->intensity - lg->intensity) < 1e-5f);
    assert_vec3(lg->position, 0, 1.95f, 0, 1e-5f);
    assert_vec3(lg->direction, 0, -1, 0, 1e-5f);
    assert_vec3(lb->position, lg->position[0], lg->position[1], lg->position[2], 1e-5f);
    assert_vec3(lb->direction, lg->direction[0], lg->direction[1], lg->direction[2], 1e-5f);
    assert_vec3(lb->color, lg->color[0], lg->color[1], lg->color[2], 1e-6f);
    assert_true(fabsf(lb->inner_cone - lg->inner_cone) < 1e-6f);
    assert_true(fabsf(lb->outer_cone - lg->outer_cone) < 1e-6f);
    assert_true(lg->range == 0.0f && lb->range == 0.0f);

    const lpv_camera *cg = &g.cameras[0], *cb = &b.cameras[0];
    assert_string_equal(cg->name, "Camera");
    assert_string_equal(cb->name, cg->name);
    assert_vec3(cg->eye, 0, 1, 3.9f, 1e-5f);
    assert_vec3(cb->eye, cg->eye[0], cg->eye[1], cg->eye[2], 1e-5f);
    assert_vec3(cb->forward, cg->forward[0], cg->forward[1], cg->forward[2], 1e-6f);
    assert_vec3(cb->up, cg->up[0], cg->up[1], cg->up[2], 1e-6f);
    assert_int_equal(cg->orthographic, 0);
    assert_int_equal(cb->orthographic, 0);
    assert_true(fabsf(cb->yfov - cg->yfov) < 1e-6f);
    assert_true(cb->aspect == cg->aspect && cg->aspect == 1.0f);
    assert_true(fabsf(cb->znear - cg->znear) < 1e-7f && cb->zfar == cg->zfar);

    /* the glb's normals agree with the built-in orientation per material */
    for (uint32_t d = 0; d < g.draw_count; d++) {
        const char *name = g.materials[g.draws[d].material].name;
        if (strcmp(name, "shortBox") == 0 || strcmp(name, "tallBox") == 0)
            continue;
        const float *ng = g.vertices[g.indices[g.draws[d].first_index]].normal;
        for (uint32_t e = 0; e < b.draw_count; e++) {
            if (strcmp(b.materials[b.draws[e].material].name, name) != 0)
                continue;
            const float *nb = b.vertices[b.indices[b.draws[e].first_index]].normal;
            assert_true(ng[0] * nb[0] + ng[1] * nb[1] + ng[2] * nb[2] > 0.999f);
        }
    }
    lpv_scene_free(&g);
    lpv_scene_free(&b);
}

/* ---- (d) animations ---------------------------------------------------------- */

/* An animated file: TRI_JSON's triangle (accessor 0, bufferView 0) and the
 * keyframe data appended as accessors 1, 2, ... in bufferView 1. */
typedef struct anim_file {
    bin b;
    char accessors[4096];
    size_t len;
    int next;
} anim_file;

static void anim_init(anim_file *f)
{
    tri_bin(&f->b);
    f->accessors[0] = '\0';
    f->len = 0;
    f->next = 1;
}

/* An accessor given as JSON (with '); returns its index. */
static int anim_acc_json(anim_file *f, const char *json)
{
    int n = snprintf(f->accessors + f->len, sizeof f->accessors - f->len, ",%s", json);
    assert_true(n > 0 && (size_t)n < sizeof f->accessors - f->len);
    f->len += (size_t)n;
    return f->next++;
}

/* count float elements of type SCALAR, VEC3 or VEC4 from v; returns the accessor index. */
static int anim_acc(anim_file *f, const char *type, int count, const float *v)
{
    int ncomp = strcmp(type, "SCALAR") == 0 ? 1 : strcmp(type, "VEC3") == 0 ? 3 : 4;
    size_t off = f->b.n - 36;
    for (int i = 0; i < count * ncomp; i++)
        put_f32(&f->b, v[i]);
    char json[160];
    snprintf(json, sizeof json, "{'bufferView':1,'byteOffset':%zu,'componentType':5126,'count':%d,'type':'%s'}", off,
             count, type);
    return anim_acc_json(f, json);
}

/* The file with the given nodes, scene roots and animations (JSON with ' ;
 * animations NULL: none), written as name into path. */
static void anim_write(char *path, const char *name, const anim_file *f, const char *nodes, const char *roots,
                       const char *animations)
{
    char anims[4096] = "";
    if (animations)
        snprintf(anims, sizeof anims, ",'animations':%s", animations);
    const char *json = J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':%zu}],"
                         "'bufferViews':[{'buffer':0,'byteLength':36},{'buffer':0,'byteOffset':36,'byteLength':%zu}],"
                         "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}%s],"
                         "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
                         "'nodes':%s,'scenes':[{'nodes':%s}],'scene':0%s}",
                         f->b.n, f->b.n - 36, f->accessors, nodes, roots, anims);
    write_glb(path, name, json, &f->b);
}

/* One animation named name of one channel (node 0, path) with one sampler. */
static const char *one_channel(const char *name, const char *path, int input, int output, const char *interp)
{
    static char json[512];
    snprintf(json, sizeof json,
             "[{'name':'%s','channels':[{'sampler':0,'target':{'node':0,'path':'%s'}}],"
             "'samplers':[{'input':%d,'output':%d,'interpolation':'%s'}]}]",
             name, path, input, output, interp);
    return json;
}

static void load_at(const char *path, const char *animation, double t, lpv_scene *s)
{
    lpv_gltf_animation_time at = {animation, t};
    char err[768] = "";
    memset(s, 0x5a, sizeof *s);
    if (lpv_gltf_load_file_animated(path, &at, s, err, sizeof err) != 0)
        fail_msg("loading %s at %g s failed: %s", path, t, err);
    assert_string_equal(s->source, path);
}

/* Vertex `v` of the flattened scene posed at t must be (x, y, z). */
static void vertex_at(const char *path, const char *animation, double t, uint32_t v, float x, float y, float z)
{
    lpv_scene s;
    load_at(path, animation, t, &s);
    assert_true(v < s.vertex_count);
    print_message("    t = %-6g vertex %u (%g, %g, %g)\n", t, v, s.vertices[v].position[0], s.vertices[v].position[1],
                  s.vertices[v].position[2]);
    assert_vec3(s.vertices[v].position, x, y, z, 1e-5f);
    lpv_scene_free(&s);
}

/* Posing must fail, name the file and say each of the words (NULL ends them
 * early); the scene stays zeroed. */
static void expect_anim_fail(const char *path, const char *animation, double t, const char *w1, const char *w2)
{
    lpv_gltf_animation_time at = {animation, t};
    lpv_scene s;
    char err[768] = "";
    memset(&s, 0x5a, sizeof s);
    int rc = lpv_gltf_load_file_animated(path, &at, &s, err, sizeof err);
    const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    print_message("    %-28s -> %s\n", base, err);
    if (rc != -1)
        fail_msg("%s posed at %g s but should have failed with '%s'", path, t, w1);
    if (!strstr(err, base))
        fail_msg("error '%s' does not name the file '%s'", err, base);
    if (!strstr(err, w1) || (w2 && !strstr(err, w2)))
        fail_msg("error '%s' does not mention '%s' and '%s'", err, w1, w2 ? w2 : "");
    assert_true(scene_is_zero(&s));
    lpv_scene_free(&s);
}


/* A file defect: refused when posed and when its animations are listed. */
static void expect_anim_defect(const char *path, const char *w1, const char *w2)
{
    expect_anim_fail(path, "Walk", 0.5, w1, w2);
    expect_anim_fail(path, "0", 0.5, w1, w2);
    lpv_gltf_animation_list list;
    char err[768] = "";
    memset(&list, 0x5a, sizeof list);
    assert_int_equal(lpv_gltf_animations(path, &list, err, sizeof err), -1);
    assert_non_null(strstr(err, w1));
    assert_int_equal(list.count, 0);
}

static const float T01[] = {0, 1};
static const float T13[] = {1, 3};

/* Skins and morph targets (issue 32, item 2), posed at a time. One
 * triangle (0,0,0), (1,0,0), (0,1,0):
 * - skinned: joint A at the origin, joint B its child at (0, 0.5, 0) (its
 *   inverse bind matrix moves it back), vertex 0 on A, vertex 1 half on
 *   each, vertex 2 on B; B turns 90 degrees about z over 1 s. The skinned
 *   node's own translation (10, 0, 0) is not applied (glTF).
 * - morphed: one target moving vertex 2 by (0, 0, 1); the mesh's weight
 *   0.25, a node's 0.75, and a weights channel from 0 to 1 over 1 s.
 * Before, both were drawn undeformed (bind pose, base shape) with a warning. */
static void test_skins_and_morphs(void **state)
{
    (void)state;
    anim_file f;
    anim_init(&f);
    /* JOINTS_0 as UNSIGNED_SHORT VEC4: vertex 0 (0,..), 1 (0,1,..), 2 (1,..) */
    const size_t joff = f.b.n - 36;
    const uint16_t joints[12] = {0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0};
    for (int i = 0; i < 12; ++i)
        put_u16(&f.b, joints[i]);
    const int aj = anim_acc_json(&f, J("{'bufferView':1,'byteOffset':%zu,'componentType':5123,'count':3,"
                                      "'type':'VEC4'}",
                                      joff));
    const float weights[12] = {1, 0, 0, 0, 0.5f, 0.5f, 0, 0, 1, 0, 0, 0};
    const int aw = anim_acc(&f, "VEC4", 3, weights);
    const size_t moff = f.b.n - 36;
    const float ibm[32] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,
                           1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -0.5f, 0, 1};
    for (int i = 0; i < 32; ++i)
        put_f32(&f.b, ibm[i]);
    const int am = anim_acc_json(&f, J("{'bufferView':1,'byteOffset':%zu,'componentType':5126,'count':2,'type':'MAT4'}",
                                      moff));
    const int at = anim_acc(&f, "SCALAR", 2, T01);
    const float quats[8] = {0, 0, 0, 1, 0, 0, 0.70710678f, 0.70710678f};
    const int aq = anim_acc(&f, "VEC4", 2, quats);
    const float delta[9] = {0, 0, 0, 0, 0, 0, 0, 0, 1};
    const int ad = anim_acc(&f, "VEC3", 3, delta);
    const float wkeys[2] = {0, 1};
    const int awk = anim_acc(&f, "SCALAR", 2, wkeys);

    char skin_path[512], morph_path[512], node_path[512];
    const char *skin_json =
        J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':%zu}],"
          "'bufferViews':[{'buffer':0,'byteLength':36},{'buffer':0,'byteOffset':36,'byteLength':%zu}],"
          "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}%s],"
          "'meshes':[{'primitives':[{'attributes':{'POSITION':0,'JOINTS_0':%d,'WEIGHTS_0':%d}}]}],"
          "'skins':[{'joints':[1,2],'inverseBindMatrices':%d}],"
          "'nodes':[{'mesh':0,'skin':0,'translation':[10,0,0]},{'children':[2]},{'translation':[0,0.5,0]}],"
          "'scenes':[{'nodes':[0,1]}],'scene':0,"
          "'animations':[{'name':'Bend','channels':[{'sampler':0,'target':{'node':2,'path':'rotation'}}],"
          "'samplers':[{'input':%d,'output':%d}]}]}",
          f.b.n, f.b.n - 36, f.accessors, aj, aw, am, at, aq);
    write_glb(skin_path, "skinned.glb", skin_json, &f.b);
    vertex_at(skin_path, "Bend", 0.0, 2, 0, 1, 0);
    vertex_at(skin_path, "Bend", 1.0, 0, 0, 0, 0); /* on A: still, the node's (10,0,0) not applied */
    vertex_at(skin_path, "Bend", 1.0, 2, -0.5f, 0.5f, 0); /* on B: turned about (0, 0.5, 0) */
    vertex_at(skin_path, "Bend", 1.0, 1, 0.75f, 0.75f, 0); /* half each: (1,0,0) and (0.5,1.5,0) */
    lpv_scene s;
    load_ok(skin_path, &s); /* the static pose: the rest pose, no warning about skins */
    assert_vec3(s.vertices[2].position, 0, 1, 0, 1e-6f);
    lpv_scene_free(&s);

    const char *morph_json =
        J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':%zu}],"
          "'bufferViews':[{'buffer':0,'byteLength':36},{'buffer':0,'byteOffset':36,'byteLength':%zu}],"
          "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}%s],"
          "'meshes':[{'primitives':[{'attributes':{'POSITION':0},'targets':[{'POSITION':%d}]}],'weights':[0.25]}],"
          "'nodes':[{'mesh':0%s}],'scenes':[{'nodes':[0]}],'scene':0,"
          "'animations':[{'name':'Grow','channels':[{'sampler':0,'target':{'node':0,'path':'weights'}}],"
          "'samplers':[{'input':%d,'output':%d}]}]}",
          f.b.n, f.b.n - 36, f.accessors, ad, "", at, awk);
    write_glb(morph_path, "morphed.glb", morph_json, &f.b);
    load_ok(morph_path, &s); /* the mesh's weight */
    assert_vec3(s.vertices[2].position, 0, 1, 0.25f, 1e-6f);
    lpv_scene_free(&s);
    vertex_at(morph_path, "Grow", 0.5, 2, 0, 1, 0.5f); /* the channel's */
    vertex_at(morph_path, "Grow", 2.0, 2, 0, 1, 1.0f);
    const char *node_json =
        J("{'asset':{'version':'2.0'},'buffers':[{'byteLength':%zu}],"
          "'bufferViews':[{'buffer':0,'byteLength':36},{'buffer':0,'byteOffset':36,'byteLength':%zu}],"
          "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}%s],"
          "'meshes':[{'primitives':[{'attributes':{'POSITION':0},'targets':[{'POSITION':%d}]}],'weights':[0.25]}],"
          "'nodes':[{'mesh':0,'weights':[0.75]}],'scenes':[{'nodes':[0]}],'scene':0}",
          f.b.n, f.b.n - 36, f.accessors, ad);
    write_glb(node_path, "node-weights.glb", node_json, &f.b);
    load_ok(node_path, &s); /* the node's weight wins */
    assert_vec3(s.vertices[2].position, 0, 1, 0.75f, 1e-6f);
    lpv_scene_free(&s);
}

static void test_animation_linear_translation(void **state)
{
    (void)state;
    anim_file f;
    anim_init(&f);
    const float v[] = {0, 0, 0, 4, 2, 0};
    int in = anim_acc(&f, "SCALAR", 2, T13), out = anim_acc(&f, "VEC3", 2, v);
    char anims[512];
    /* no "interpolation": LINEAR is glTF's default */
    snprintf(anims, sizeof anims,
             "[{'name':'Slide','channels':[{'sampler':0,'target':{'node':0,'path':'translation'}}],"
             "'samplers':[{'input':%d,'output':%d}]}]",
             in, out);
    char path[512];
    anim_write(path, "anim-linear.glb", &f, "[{'mesh':0,'translation':[7,0,0]}]", "[0]", anims);

    /* the static pose, also for at NULL */
    lpv_scene s;
    load_ok(path, &s);
    assert_vec3(s.vertices[0].position, 7, 0, 0, 1e-6f);
    lpv_scene_free(&s);
    char err[512] = "";
    assert_int_equal(lpv_gltf_load_file_animated(path, NULL, &s, err, sizeof err), 0);
    assert_vec3(s.vertices[0].position, 7, 0, 0, 1e-6f);
    lpv_scene_free(&s);

    vertex_at(path, "Slide", 1.0, 0, 0, 0, 0);     /* the first keyframe */
    vertex_at(path, "Slide", 2.0, 0, 2, 1, 0);     /* half-way */
    vertex_at(path, "Slide", 1.5, 0, 1, 0.5f, 0);  /* a quarter */
    vertex_at(path, "Slide", 3.0, 0, 4, 2, 0);     /* the last */
    vertex_at(path, "Slide", 0.0, 0, 0, 0, 0);     /* before the first: clamped */
    vertex_at(path, "Slide", 100.0, 0, 4, 2, 0);   /* after the last: clamped */
    vertex_at(path, "Slide", 2.0, 1, 3, 1, 0);     /* the whole triangle moves */
    load_at(path, "Slide", 2.0, &s);
    assert_vec3(s.bounds_min, 2, 1, 0, 1e-6f);
    assert_vec3(s.bounds_max, 3, 2, 0, 1e-6f);
    lpv_scene_free(&s);
}

static void test_animation_step(void **state)
{
    (void)state;
    anim_file f;
    anim_init(&f);
    const float t[] = {0, 1, 2}, v[] = {0, 0, 0, 5, 0, 0, 10, 0, 0};
    int in = anim_acc(&f, "SCALAR", 3, t), out = anim_acc(&f, "VEC3", 3, v);
    char path[512];
    anim_write(path, "anim-step.glb", &f, "[{'mesh':0}]", "[0]", one_channel("Hop", "translation", in, out, "STEP"));
    vertex_at(path, "Hop", 0.0, 0, 0, 0, 0);
    vertex_at(path, "Hop", 0.5, 0, 0, 0, 0);
    vertex_at(path, "Hop", 0.999, 0, 0, 0, 0);
    vertex_at(path, "Hop", 1.0, 0, 5, 0, 0);
    vertex_at(path, "Hop", 1.5, 0, 5, 0, 0);
    vertex_at(path, "Hop", 2.0, 0, 10, 0, 0);
    vertex_at(path, "Hop", 9.0, 0, 10, 0, 0);
}

static void test_animation_cubicspline(void **state)
{
    (void)state;
    anim_file f;
    anim_init(&f);
    /* keyframes at 0 and 2 s (td = 2), each (in-tangent a, value v, out-tangent b):
     * v0 = (0,0,0), b0 = (1,0,3); a1 = (0,-1,2), v1 = (4,2,0); a0 and b1 unused (9s). */
    const float t[] = {0, 2};
    const float v[] = {9, 9, 9, 0, 0, 0, 1, 0, 3, /**/ 0, -1, 2, 4, 2, 0, 9, 9, 9};
    int in = anim_acc(&f, "SCALAR", 2, t), out = anim_acc(&f, "VEC3", 6, v);
    char path[512];
    anim_write(path, "anim-cubic.glb", &f, "[{'mesh':0}]", "[0]",
               one_channel("Curve", "translation", in, out, "CUBICSPLINE"));
    /* p(u) = h00 v0 + h10 td b0 + h01 v1 + h11 td a1 with
     * h00 = 2u^3 - 3u^2 + 1, h10 = u^3 - 2u^2 + u, h01 = -2u^3 + 3u^2, h11 = u^3 - u^2.
     * t = 0.5: u = 1/4, h = (0.84375, 0.140625, 0.15625, -0.046875):
     *   x = 0.140625*2*1 + 0.15625*4 = 0.90625
     *   y = 0.15625*2 - 0.046875*2*(-1) = 0.40625
     *   z = 0.140625*2*3 - 0.046875*2*2 = 0.65625
     * t = 1: u = 1/2, h = (0.5, 0.125, 0.5, -0.125): (2.25, 1.25, 0.25). */
    vertex_at(path, "Curve", 0.5, 0, 0.90625f, 0.40625f, 0.65625f);
    vertex_at(path, "Curve", 1.0, 0, 2.25f, 1.25f, 0.25f);
    /* the keyframes and past them: the values, never the tangents */
    vertex_at(path, "Curve", 0.0, 0, 0, 0, 0);
    vertex_at(path, "Curve", 2.0, 0, 4, 2, 0);
    vertex_at(path, "Curve", 7.0, 0, 4, 2, 0);

    /* a CUBICSPLINE rotation with zero tangents, identity -> 90 deg about y:
     * half-way the Hermite blend (0, 0.354, 0, 0.854) normalised is 45 deg */
    anim_init(&f);
    const float q[] = {0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, /**/ 0, 0, 0, 0, 0, S45, 0, S45, 0, 0, 0, 0};
    in = anim_acc(&f, "SCALAR", 2, T01);
    out = anim_acc(&f, "VEC4", 6, q);
    anim_write(path, "anim-cubic-rotation.glb", &f, "[{'mesh':0}]", "[0]",
               one_channel("Turn", "rotation", in, out, "CUBICSPLINE"));
    vertex_at(path, "Turn", 0.5, 1, S45, 0, -S45);
    vertex_at(path, "Turn", 1.0, 1, 0, 0, -1);
}

static void test_animation_rotation_slerp(void **state)
{
    (void)state;
    anim_file f;
    anim_init(&f);
    /* identity -> 90 deg about y, and the same end as -q (the same rotation) */
    const float q[] = {0, 0, 0, 1, 0, S45, 0, S45};
    const float qn[] = {0, 0, 0, 1, 0, -S45, 0, -S45};
    int in = anim_acc(&f, "SCALAR", 2, T01), out = anim_acc(&f, "VEC4", 2, q), outn = anim_acc(&f, "VEC4", 2, qn);
    char anims[1024];
    snprintf(anims, sizeof anims,
             "[{'name':'Turn','channels':[{'sampler':0,'target':{'node':0,'path':'rotation'}}],"
             "'samplers':[{'input':%d,'output':%d,'interpolation':'LINEAR'}]},"
             " {'name':'TurnNegated','channels':[{'sampler':0,'target':{'node':0,'path':'rotation'}}],"
             "'samplers':[{'input':%d,'output':%d,'interpolation':'LINEAR'}]}]",
             in, out, in, outn);
    char path[512];
    anim_write(path, "anim-slerp.glb", &f, "[{'mesh':0}]", "[0]", anims);
    /* vertex 1 is (1,0,0): R_y(a) takes it to (cos a, 0, -sin a) */
    vertex_at(path, "Turn", 0.5, 1, S45, 0, -S45);                       /* 45 deg */
    vertex_at(path, "Turn", 0.25, 1, 0.92387953f, 0, -0.38268343f);      /* 22.5 deg (a lerp gives 21.6) */
    vertex_at(path, "Turn", 1.0, 1, 0, 0, -1);                           /* 90 deg */
    vertex_at(path, "Turn", 0.5, 2, 0, 1, 0);                            /* (0,1,0) stays */
    /* -q: the shortest path is the same 45 deg, not 135 deg the other way */
    vertex_at(path, "TurnNegated", 0.5, 1, S45, 0, -S45);
    vertex_at(path, "TurnNegated", 0.25, 1, 0.92387953f, 0, -0.38268343f);
}

static void test_animation_hierarchy(void **state)
{
    (void)state;
    anim_file f;
    anim_init(&f);
    /* parent 0: translation (0,0,0) -> (2,0,0) over 1 s and one rotation
     * keyframe, 90 deg about z; child 1 (the mesh) at (0,1,0) below it */
    const float t0[] = {0}, rz[] = {0, 0, S45, S45}, v[] = {0, 0, 0, 2, 0, 0};
    int in = anim_acc(&f, "SCALAR", 2, T01), out = anim_acc(&f, "VEC3", 2, v);
    int in1 = anim_acc(&f, "SCALAR", 1, t0), out1 = anim_acc(&f, "VEC4", 1, rz);
    char anims[1024];
    snprintf(anims, sizeof anims,
             "[{'name':'Carry','channels':[{'sampler':0,'target':{'node':0,'path':'translation'}},"
             "{'sampler':1,'target':{'node':0,'path':'rotation'}}],"
             "'samplers':[{'input':%d,'output':%d},{'input':%d,'output':%d,'interpolation':'STEP'}]}]",
             in, out, in1, out1);
    char path[512];
    anim_write(path, "anim-hierarchy.glb", &f,
               "[{'translation':[0,0,5],'children':[1]},{'mesh':0,'translation':[0,1,0]}]", "[0]", anims);
    /* static: (0,0,5) + (0,1,0) */
    lpv_scene s;
    load_ok(path, &s);
    assert_vec3(s.vertices[0].position, 0, 1, 5, 1e-6f);
    lpv_scene_free(&s);
    /* t = 0.5: parent at (1,0,0) turned 90 deg about z: the child's (0,1,0) -> (-1,0,0) */
    vertex_at(path, "Carry", 0.5, 0, 0, 0, 0);
    vertex_at(path, "Carry", 0.5, 1, 0, 1, 0); /* (1,1,0) local -> (-1,1,0) + (1,0,0) */
    vertex_at(path, "Carry", 1.0, 0, 1, 0, 0);
}

static void test_animation_choice_and_list(void **state)
{
    (void)state;
    anim_file f;
    anim_init(&f);
    const float t2[] = {0, 2}, t4[] = {0, 4};
    const float left[] = {0, 0, 0, -2, 0, 0}, up[] = {0, 0, 1, 0, 4, 1};
    int in0 = anim_acc(&f, "SCALAR", 2, t2), out0 = anim_acc(&f, "VEC3", 2, left);
    int in1 = anim_acc(&f, "SCALAR", 2, t4), out1 = anim_acc(&f, "VEC3", 2, up);
    char anims[1024];
    snprintf(anims, sizeof anims,
             "[{'name':'Left','channels':[{'sampler':0,'target':{'node':0,'path':'translation'}}],"
             "'samplers':[{'input':%d,'output':%d}]},"
             " {'name':'Up','channels':[{'sampler':0,'target':{'node':1,'path':'translation'}}],"
             "'samplers':[{'input':%d,'output':%d}]}]",
             in0, out0, in1, out1);
    char path[512];
    anim_write(path, "anim-choice.glb", &f, "[{'mesh':0},{'mesh':0,'translation':[0,0,1]}]", "[0,1]", anims);
    /* node 0 draws vertices 0-2, node 1 vertices 3-5 */
    vertex_at(path, "Left", 1.0, 0, -1, 0, 0);
    vertex_at(path, "Left", 1.0, 3, 0, 0, 1);
    vertex_at(path, "0", 1.0, 0, -1, 0, 0);
    vertex_at(path, "0", 1.0, 3, 0, 0, 1);
    vertex_at(path, "Up", 1.0, 0, 0, 0, 0);
    vertex_at(path, "Up", 1.0, 3, 0, 1, 1);
    vertex_at(path, "1", 1.0, 0, 0, 0, 0);
    vertex_at(path, "1", 1.0, 3, 0, 1, 1);
    /* every animation at once */
    vertex_at(path, "", 1.0, 0, -1, 0, 0);
    vertex_at(path, "", 1.0, 3, 0, 1, 1);
    vertex_at(path, NULL, 3.0, 0, -2, 0, 0);
    vertex_at(path, NULL, 3.0, 3, 0, 3, 1);

    lpv_gltf_animation_list list;
    char err[512] = "";
    memset(&list, 0x5a, sizeof list);
    if (lpv_gltf_animations(path, &list, err, sizeof err) != 0)
        fail_msg("%s", err);
    assert_int_equal(list.count, 2);
    assert_string_equal(list.animation[0].name, "Left");
    assert_string_equal(list.animation[1].name, "Up");
    assert_true(list.animation[0].duration == 2.0);
    assert_true(list.animation[1].duration == 4.0);
    assert_int_equal(list.animation[0].channels, 1);
    assert_int_equal(list.animation[1].channels, 1);
    assert_int_equal(list.animation[2].channels, 0); /* the rest zeroed */

    /* a file without animations lists none */
    anim_write(path, "anim-none.glb", &f, "[{'mesh':0}]", "[0]", NULL);
    assert_int_equal(lpv_gltf_animations(path, &list, err, sizeof err), 0);
    assert_int_equal(list.count, 0);
}

static int warned(const lpv_gltf_warnings *w, const char *word)
{
    for (int i = 0; i < w->count; i++)
        if (strstr(w->line[i], word))
            return 1;
    return 0;
}

static void test_animation_warnings(void **state)
{
    (void)state;
    anim_file f;
    anim_init(&f);
    const float v[] = {0, 0, 0, 4, 0, 0}, wts[] = {0, 1};
    int in = anim_acc(&f, "SCALAR", 2, T01), out = anim_acc(&f, "VEC3", 2, v);
    int wout = anim_acc(&f, "SCALAR", 2, wts);
    /* channel 1 animates morph weights; channel 2 is KHR_animation_pointer's
     * (no target node: tinygltf drops it, with a warning) */
    char anims[1024];
    snprintf(anims, sizeof anims,
             "[{'name':'Walk','channels':[{'sampler':0,'target':{'node':0,'path':'translation'}},"
             "{'sampler':1,'target':{'node':0,'path':'weights'}},"
             "{'sampler':1,'target':{'path':'pointer','extensions':{'KHR_animation_pointer':"
             "{'pointer':'/nodes/0/scale'}}}}],"
             "'samplers':[{'input':%d,'output':%d},{'input':%d,'output':%d}]}]",
             in, out, in, wout);
    char path[512];
    anim_write(path, "anim-warnings.glb", &f, "[{'mesh':0}]", "[0]", anims);
    lpv_scene s;
    lpv_gltf_warnings w;
    char err[512] = "";

    /* static: the animation is not played */
    if (lpv_gltf_load_file_w(path, &s, &w, err, sizeof err) != 0)
        fail_msg("%s", err);
    for (int i = 0; i < w.count; i++)
        print_message("    static: %s\n", w.line[i]);
    assert_true(warned(&w, "1 animation: not played"));
    assert_false(warned(&w, "weights"));
    assert_vec3(s.vertices[0].position, 0, 0, 0, 1e-6f);
    lpv_scene_free(&s);

    /* played: the translation is applied, the weights channel (whose node
     * has no morph targets) warned, and no line says the animation is not
     * played */
    lpv_gltf_animation_time at = {"Walk", 0.5};
    if (lpv_gltf_load_file_animated_w(path, &at, &s, &w, err, sizeof err) != 0)
        fail_msg("%s", err);
    for (int i = 0; i < w.count; i++)
        print_message("    played: %s\n", w.line[i]);
    assert_vec3(s.vertices[0].position, 2, 0, 0, 1e-6f);
    assert_true(warned(&w, "morph target weights channel (animation 0 (\"Walk\") channel 1): node 0's mesh has no "
                           "morph targets; ignored"));
    assert_false(warned(&w, "not played"));
    lpv_scene_free(&s);

    /* KHR_animation_pointer in extensionsUsed: one line, its channels ignored */
    const char *ptr_json =
        J("{'asset':{'version':'2.0'},'extensionsUsed':['KHR_animation_pointer'],'buffers':[{'byteLength':%zu}],"
          "'bufferViews':[{'buffer':0,'byteLength':36},{'buffer':0,'byteOffset':36,'byteLength':%zu}],"
          "'accessors':[{'bufferView':0,'componentType':5126,'count':3,'type':'VEC3'}%s],"
          "'meshes':[{'primitives':[{'attributes':{'POSITION':0}}]}],"
          "'nodes':[{'mesh':0}],'scenes':[{'nodes':[0]}],'scene':0,'animations':%s}",
          f.b.n, f.b.n - 36, f.accessors, anims);
    write_glb(path, "anim-pointer.glb", ptr_json, &f.b);
    if (lpv_gltf_load_file_animated_w(path, &at, &s, &w, err, sizeof err) != 0)
        fail_msg("%s", err);
    for (int i = 0; i < w.count; i++)
        print_message("    pointer: %s\n", w.line[i]);
    assert_vec3(s.vertices[0].position, 2, 0, 0, 1e-6f);
    assert_true(warned(&w, "KHR_animation_pointer"));
    assert_true(warned(&w, "channels are ignored"));
    assert_false(warned(&w, "nothing is animated"));
    lpv_scene_free(&s);
}

static void test_animation_defects(void **state)
{
    (void)state;
    char path[512];
    anim_file f;
    const float v2[] = {0, 0, 0, 1, 1, 1}, v3[] = {0, 0, 0, 1, 1, 1, 2, 2, 2};
    const float t3[] = {0, 1, 1}, tnan[] = {0, NAN};
    const float q2[] = {0, 0, 0, 1, 0, 0, 0, 1}, qzero[] = {0, 0, 0, 0, 0, 0, 0, 1};

    /* the good file, asked wrongly */
    anim_init(&f);
    int in = anim_acc(&f, "SCALAR", 2, T01), out = anim_acc(&f, "VEC3", 2, v2);
    anim_write(path, "anim-good.glb", &f, "[{'mesh':0}]", "[0]", one_channel("Walk", "translation", in, out, "LINEAR"));
    vertex_at(path, "Walk", 0.5, 0, 0.5f, 0.5f, 0.5f);
    expect_anim_fail(path, "Run", 0.5, "animation \"Run\" does not exist", "1 animation (0 \"Walk\")");
    expect_anim_fail(path, "3", 0.5, "animation \"3\" does not exist", "1 animation");
    expect_anim_fail(path, "-1", 0.5, "does not exist", "1 animation");
    expect_anim_fail(path, "Walk", NAN, "time nan s is not finite", "\"Walk\"");
    expect_anim_fail(path, "Walk", INFINITY, "not finite", NULL);
    expect_anim_fail(path, "Walk", -0.25, "time -0.25 s is negative", "\"Walk\"");
    expect_anim_fail(path, NULL, -1.0, "every animation: time -1 s is negative", NULL);

    /* a file without animations */
    anim_write(path, "anim-none-asked.glb", &f, "[{'mesh':0}]", "[0]", NULL);
    expect_anim_fail(path, NULL, 1.0, "the file has no animations", NULL);
    expect_anim_fail(path, "Walk", 1.0, "the file has no animations", NULL);

    /* sampler input: not increasing, not finite, not SCALAR FLOAT, out of range */
    anim_init(&f);
    in = anim_acc(&f, "SCALAR", 3, t3);
    out = anim_acc(&f, "VEC3", 3, v3);
    anim_write(path, "anim-not-increasing.glb", &f, "[{'mesh':0}]", "[0]",
               one_channel("Walk", "translation", in, out, "LINEAR"));
    expect_anim_defect(path, "animation 0 (\"Walk\"): sampler 0: keyframe times are not increasing",
                       "keyframe 2 at 1 s follows one at 1 s");

    anim_init(&f);
    in = anim_acc(&f, "SCALAR", 2, tnan);
    out = anim_acc(&f, "VEC3", 2, v2);
    anim_write(path, "anim-time-nan.glb", &f, "[{'mesh':0}]", "[0]",
               one_channel("Walk", "translation", in, out, "LINEAR"));
    expect_anim_defect(path, "animation 0 (\"Walk\"): sampler 0: keyframe time 1 is not finite", NULL);

    anim_init(&f);
    in = anim_acc(&f, "VEC3", 2, v2);
    out = anim_acc(&f, "VEC3", 2, v2);
    anim_write(path, "anim-input-vec3.glb", &f, "[{'mesh':0}]", "[0]",
               one_channel("Walk", "translation", in, out, "LINEAR"));
    expect_anim_defect(path, "animation 0 (\"Walk\"): sampler 0: input accessor 1 must be SCALAR FLOAT", NULL);

    anim_init(&f);
    put_u8(&f.b, 0);
    put_u8(&f.b, 1);
    pad4(&f.b);
    in = anim_acc_json(&f, "{'bufferView':1,'byteOffset':0,'componentType':5121,'count':2,'type':'SCALAR'}");
    out = anim_acc(&f, "VEC3", 2, v2);
    anim_write(path, "anim-input-ubyte.glb", &f, "[{'mesh':0}]", "[0]",
               one_channel("Walk", "translation", in, out, "LINEAR"));
    expect_anim_defect(path, "animation 0 (\"Walk\"): sampler 0: input accessor 1 must be SCALAR FLOAT", NULL);

    anim_init(&f);
    out = anim_acc(&f, "VEC3", 2, v2);
    anim_write(path, "anim-input-range.glb", &f, "[{'mesh':0}]", "[0]",
               one_channel("Walk", "translation", 9, out, "LINEAR"));
    expect_anim_defect(path, "animation 0 (\"Walk\"): sampler 0: input accessor 9 does not exist", NULL);

    /* outputs: the count the interpolation needs, the type the path needs */
    anim_init(&f);
    in = anim_acc(&f, "SCALAR", 2, T01);
    out = anim_acc(&f, "VEC3", 3, v3);
    anim_write(path, "anim-linear-count.glb", &f, "[{'mesh':0}]", "[0]",
               one_channel("Walk", "translation", in, out, "LINEAR"));
    expect_anim_defect(path, "animation 0 (\"Walk\"): sampler 0: output accessor 2 holds 3 elements",
                       "LINEAR with 2 keyframes needs 2");
    anim_write(path, "anim-step-count.glb", &f, "[{'mesh':0}]", "[0]",
               one_channel("Walk", "translation", in, out, "STEP"));
    expect_anim_defect(path, "STEP with 2 keyframes needs 2", "\"Walk\"");

    anim_init(&f);
    in = anim_acc(&f, "SCALAR", 2, T01);
    out = anim_acc(&f, "VEC3", 2, v2);
    anim_write(path, "anim-cubic-count.glb", &f, "[{'mesh':0}]", "[0]",
               one_channel("Walk", "translation", in, out, "CUBICSPLINE"));
    expect_anim_defect(path, "animation 0 (\"Walk\"): sampler 0: output accessor 2 holds 2 elements",
                       "CUBICSPLINE with 2 keyframes needs 6");

    anim_init(&f);
    in = anim_acc(&f, "SCALAR", 2, T01);
    out = anim_acc(&f, "VEC4", 2, q2);
    anim_write(path, "anim-translation-vec4.glb", &f, "[{'mesh':0}]", "[0]",
               one_channel("Walk", "translation", in, out, "LINEAR"));
    expect_anim_defect(path, "animation 0 (\"Walk\"): channel 0 (translation): output accessor 2", "must be VEC3");
    anim_write(path, "anim-scale-vec4.glb", &f, "[{'mesh':0}]", "[0]", one_channel("Walk", "scale", in, out, "LINEAR"));
    expect_anim_defect(path, "channel 0 (scale)", "must be VEC3");

    anim_init(&f);
    in = anim_acc(&f, "SCALAR", 2, T01);
    out = anim_acc(&f, "VEC3", 2, v2);
    anim_write(path, "anim-rotation-vec3.glb", &f, "[{'mesh':0}]", "[0]",
               one_channel("Walk", "rotation", in, out, "LINEAR"));
    expect_anim_defect(path, "animation 0 (\"Walk\"): channel 0 (rotation): output accessor 2", "must be VEC4");

    anim_init(&f);
    in = anim_acc(&f, "SCALAR", 2, T01);
    out = anim_acc(&f, "VEC4", 2, qzero);
    anim_write(path, "anim-rotation-zero.glb", &f, "[{'mesh':0}]", "[0]",
               one_channel("Walk", "rotation", in, out, "LINEAR"));
    expect_anim_defect(path, "animation 0 (\"Walk\"): sampler 0: rotation 0 is not a unit quaternion", NULL);

    anim_init(&f);
    in = anim_acc(&f, "SCALAR", 2, T01);
    const float vnan[] = {0, 0, 0, 1, INFINITY, 1};
    out = anim_acc(&f, "VEC3", 2, vnan);
    anim_write(path, "anim-output-inf.glb", &f, "[{'mesh':0}]", "[0]",
               one_channel("Walk", "translation", in, out, "LINEAR"));
    expect_anim_defect(path, "animation 0 (\"Walk\"): sampler 0: output element 1 is not finite", NULL);

    /* channels and samplers */
    anim_init(&f);
    in = anim_acc(&f, "SCALAR", 2, T01);
    out = anim_acc(&f, "VEC3", 2, v2);
    char anims[512];
    snprintf(anims, sizeof anims,
             "[{'name':'Walk','channels':[{'sampler':0,'target':{'node':7,'path':'translation'}}],"
             "'samplers':[{'input':%d,'output':%d}]}]",
             in, out);
    anim_write(path, "anim-node-range.glb", &f, "[{'mesh':0}]", "[0]", anims);
    expect_anim_defect(path, "animation 0 (\"Walk\"): channel 0: target node 7 does not exist", "1 node)");
    snprintf(anims, sizeof anims,
             "[{'name':'Walk','channels':[{'sampler':4,'target':{'node':0,'path':'translation'}}],"
             "'samplers':[{'input':%d,'output':%d}]}]",
             in, out);
    anim_write(path, "anim-sampler-range.glb", &f, "[{'mesh':0}]", "[0]", anims);
    expect_anim_defect(path, "animation 0 (\"Walk\"): channel 0: sampler 4 does not exist", NULL);
    anim_write(path, "anim-interpolation.glb", &f, "[{'mesh':0}]", "[0]",
               one_channel("Walk", "translation", in, out, "BEZIER"));
    expect_anim_defect(path, "animation 0 (\"Walk\"): sampler 0: interpolation \"BEZIER\" is not LINEAR", NULL);
    anim_write(path, "anim-path.glb", &f, "[{'mesh':0}]", "[0]", one_channel("Walk", "colour", in, out, "LINEAR"));
    expect_anim_defect(path, "animation 0 (\"Walk\"): channel 0: target path \"colour\"", NULL);
    anim_write(path, "anim-matrix-node.glb", &f, "[{'mesh':0,'matrix':[1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}]", "[0]",
               one_channel("Walk", "translation", in, out, "LINEAR"));
    expect_anim_defect(path, "animation 0 (\"Walk\"): channel 0: target node 0 is given as a matrix", NULL);

    /* a name that is not an identifier is not quoted: the index names it */
    anim_write(path, "anim-odd-name.glb", &f, "[{'mesh':0}]", "[0]",
               one_channel("Walk.001", "translation", in, out, "BEZIER"));
    expect_anim_fail(path, "Walk.001", 0.5, "animation 0: sampler 0: interpolation", NULL);
    expect_anim_fail(path, "Walk", 0.5, "animation \"Walk\" does not exist", "1 animation (0)");
}

static void test_animation_scene_load(void **state)
{
    (void)state;
    lpv_gltf_animation_time at = {"Walk", 0.5};
    lpv_scene s;
    char err[512] = "";
    /* the built-in scene has no animations */
    memset(&s, 0x5a, sizeof s);
    assert_int_equal(lpv_scene_load_animated(NULL, &at, &s, err, sizeof err), -1);
    print_message("    built-in -> %s\n", err);
    assert_non_null(strstr(err, "built-in scene"));
    assert_non_null(strstr(err, "no animations"));
    assert_true(scene_is_zero(&s));
    assert_int_equal(lpv_scene_load_animated("", &at, &s, err, sizeof err), -1);
    assert_non_null(strstr(err, "built-in scene"));
    /* without a request it is the built-in scene */
    assert_int_equal(lpv_scene_load_animated(NULL, NULL, &s, err, sizeof err), 0);
    assert_true(s.vertex_count > 0);
    lpv_scene_free(&s);

    /* a file: posed, then given the default camera and light */
    anim_file f;
    anim_init(&f);
    const float v2[] = {0, 0, 0, 2, 0, 0};
    int in = anim_acc(&f, "SCALAR", 2, T01), out = anim_acc(&f, "VEC3", 2, v2);
    char path[512];
    anim_write(path, "anim-scene.glb", &f, "[{'mesh':0}]", "[0]",
               one_channel("Walk", "translation", in, out, "LINEAR"));
    if (lpv_scene_load_animated(path, &at, &s, err, sizeof err) != 0)
        fail_msg("%s", err);
    assert_vec3(s.vertices[0].position, 1, 0, 0, 1e-6f);
    assert_int_equal(s.default_camera_added, 1);
    assert_true(s.camera_count >= 1);
    lpv_scene_free(&s);
    /* and its defects reach the caller */
    at.animation = "Run";
    assert_int_equal(lpv_scene_load_animated(path, &at, &s, err, sizeof err), -1);
    assert_non_null(strstr(err, "animation \"Run\" does not exist"));
    assert_true(scene_is_zero(&s));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_one_triangle),
        cmocka_unit_test(test_indexed_quad_ushort_ubyte_normalized_uv),
        cmocka_unit_test(test_node_hierarchy),
        cmocka_unit_test(test_normals_transformed_and_degenerate),
        cmocka_unit_test(test_sparse_accessors),
        cmocka_unit_test(test_strip_fan_points_lines),
        cmocka_unit_test(test_lights),
        cmocka_unit_test(test_cameras),
        cmocka_unit_test(test_emissive_strength),
        cmocka_unit_test(test_texture),
        cmocka_unit_test(test_gltf_external_bin_and_data_uri),
        cmocka_unit_test(test_truncated_glb),
        cmocka_unit_test(test_glb_header_lies),
        cmocka_unit_test(test_invalid_json),
        cmocka_unit_test(test_ranges),
        cmocka_unit_test(test_indices_and_values),
        cmocka_unit_test(test_missing_buffers),
        cmocka_unit_test(test_uri_escapes),
        cmocka_unit_test(test_node_graphs),
        cmocka_unit_test(test_absurd_sizes),
        cmocka_unit_test(test_cornell_glb_matches_builtin),
        cmocka_unit_test(test_animation_linear_translation),
        cmocka_unit_test(test_animation_step),
        cmocka_unit_test(test_animation_cubicspline),
        cmocka_unit_test(test_animation_rotation_slerp),
        cmocka_unit_test(test_animation_hierarchy),
        cmocka_unit_test(test_animation_choice_and_list),
        cmocka_unit_test(test_animation_warnings),
        cmocka_unit_test(test_animation_defects),
        cmocka_unit_test(test_animation_scene_load),
        cmocka_unit_test(test_schema_types),
        cmocka_unit_test(test_skins_and_morphs),
        cmocka_unit_test(test_user_paths_outside_the_folder),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
