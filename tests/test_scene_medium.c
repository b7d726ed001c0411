/*
 * test_scene_medium.c - participating media and glossy materials in the
 * scene model (docs/scenes.md): scenes/glossy.glb, fog.glb and smoke.glb
 * through the glTF loader; hostile lpvd_medium objects written to a temporary
 * folder, each refused with a message naming the field; the scene_build
 * helpers lpv_scene_set_fog, lpv_scene_set_medium_box and
 * lpv_scene_set_material_roughness.
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

#include "gltf_load.h"
#include "scene.h"
#include "scene_build.h"
#include "test_util.h"

/* ---- helpers ------------------------------------------------------------- */

/* JSON written with ' for " (test_util.h). */
#define J lpvt_json

static void load_scene_file(const char *name, lpv_scene *s)
{
    char path[1024], err[1024];
    snprintf(path, sizeof path, "%s/scenes/%s", lpvt_source_dir(), name);
    int rc = lpv_gltf_load_file(path, s, err, sizeof err);
    if (rc != 0)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
}

static const lpv_material *material_named(const lpv_scene *s, const char *name)
{
    for (uint32_t i = 0; i < s->material_count; i++)
        if (strcmp(s->materials[i].name, name) == 0)
            return &s->materials[i];
    fail_msg("no material %s", name);
    return NULL;
}

static void assert_rgb(const float v[3], float r, float g, float b)
{
    assert_true(fabsf(v[0] - r) < 1e-6f && fabsf(v[1] - g) < 1e-6f && fabsf(v[2] - b) < 1e-6f);
}

/* A .gltf without geometry whose default scene carries lpvd_medium = medium
 * (any JSON text, single quotes allowed). Returns the loader's result. */
static int load_medium(const char *medium, lpv_scene *s, char *err, size_t n)
{
    static int count;
    char name[64];
    snprintf(name, sizeof name, "medium%d.gltf", count++);
    const char *doc = J("{'asset':{'version':'2.0'},'scene':0,'scenes':[{'extras':{'lpvd_medium':%s}}]}", medium);
    const char *path = lpvt_write_file(lpvt_tmpdir(), name, doc, strlen(doc));
    return lpv_gltf_load_file(path, s, err, n);
}

/* The medium is refused with a message containing every string in want
 * (NULL-terminated), and the scene is left zeroed. */
static void refused(const char *medium, ...)
{
    lpv_scene s;
    char err[1024] = "";
    memset(&s, 0xab, sizeof s);
    assert_int_equal(load_medium(medium, &s, err, sizeof err), -1);
    print_message("    %s\n", err);
    va_list ap;
    va_start(ap, medium);
    for (const char *w = va_arg(ap, const char *); w; w = va_arg(ap, const char *)) {
        if (!strstr(err, w))
            fail_msg("message \"%s\" lacks \"%s\"", err, w);
    }
    va_end(ap);
    assert_null(s.medium.density);
    assert_int_equal(s.medium.present, 0);
    assert_null(s.vertices);
}

/* ---- the generated scenes ------------------------------------------------ */

static void test_glossy_glb(void **state)
{
    (void)state;
    lpv_scene s;
    load_scene_file("glossy.glb", &s);
    assert_int_equal(s.medium.present, 0);
    assert_null(s.medium.density);
    assert_true(s.material_count >= 4);
    int glossy = 0;
    for (uint32_t i = 0; i < s.material_count; i++) {
        const lpv_material *m = &s.materials[i];
        if (strcmp(m->name, "floor") == 0) {
            assert_true(fabsf(m->roughness - 0.1f) < 1e-6f);
            glossy++;
        } else {
            assert_true(m->roughness == 1.0f);
        }
        assert_true(m->metallic == 0.0f);
    }
    assert_int_equal(glossy, 1);
    const lpv_material *red = material_named(&s, "red_wall");
    assert_true(red->base_color[0] > 3 * red->base_color[1]);
    assert_int_equal(s.light_count, 1);
    assert_int_equal(s.lights[0].type, LPV_LIGHT_POINT);
    assert_int_equal(s.camera_count, 1);
    /* a closed room about 4 m across */
    assert_true(s.bounds_max[0] - s.bounds_min[0] > 4.0f && s.bounds_max[0] - s.bounds_min[0] < 4.5f);
    lpv_scene_free(&s);
}

static void test_fog_glb(void **state)
{
    (void)state;
    lpv_scene s;
    load_scene_file("fog.glb", &s);
    assert_int_equal(s.medium.present, 1);
    assert_rgb(s.medium.sigma_s, 0.08f, 0.08f, 0.08f);
    assert_rgb(s.medium.sigma_a, 0.02f, 0.02f, 0.02f);
    assert_int_equal(s.medium.has_box, 0);
    assert_int_equal(s.medium.dims[0], 0);
    assert_null(s.medium.density);
    assert_int_equal(s.light_count, 1);
    assert_int_equal(s.lights[0].type, LPV_LIGHT_SPOT);
    for (uint32_t i = 0; i < s.material_count; i++)
        assert_true(s.materials[i].roughness == 1.0f);
    lpv_scene_free(&s);
}

static void test_smoke_glb(void **state)
{
    (void)state;
    lpv_scene s;
    load_scene_file("smoke.glb", &s);
    assert_int_equal(s.medium.present, 1);
    assert_rgb(s.medium.sigma_s, 0.5f, 0.5f, 0.5f);
    assert_int_equal(s.medium.has_box, 1);
    for (int k = 0; k < 3; k++) {
        assert_int_equal(s.medium.dims[k], 8);
        assert_true(s.medium.box_min[k] < s.medium.box_max[k]);
        assert_true(s.medium.box_min[k] >= s.bounds_min[k] && s.medium.box_max[k] <= s.bounds_max[k]);
    }
    assert_non_null(s.medium.density);
    /* a soft blob: densest in the middle, thin at the corners, never negative */
    float lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i < 8 * 8 * 8; i++) {
        lo = fminf(lo, s.medium.density[i]);
        hi = fmaxf(hi, s.medium.density[i]);
    }
    assert_true(lo >= 0.0f && lo < 0.05f);
    assert_true(hi > 0.5f && hi <= 1.0f);
    assert_true(s.medium.density[(4 * 8 + 4) * 8 + 4] == hi || s.medium.density[(3 * 8 + 3) * 8 + 3] == hi);
    assert_true(s.medium.density[0] == lo);
    lpv_scene_free(&s);
}

/* ---- the loader on hand-made media --------------------------------------- */

static void test_medium_forms(void **state)
{
    (void)state;
    lpv_scene s;
    char err[1024];

    /* rgb coefficients, a box without a texture */
    assert_int_equal(load_medium("{'sigma_s':[0.1,0.2,0.3],'sigma_a':0,'box':{'min':[-1,0,-1],'max':[1,2,1]}}", &s,
                                 err, sizeof err),
                     0);
    assert_int_equal(s.medium.present, 1);
    assert_rgb(s.medium.sigma_s, 0.1f, 0.2f, 0.3f);
    assert_rgb(s.medium.sigma_a, 0, 0, 0);
    assert_int_equal(s.medium.has_box, 1);
    assert_rgb(s.medium.box_min, -1, 0, -1);
    assert_rgb(s.medium.box_max, 1, 2, 1);
    assert_null(s.medium.density);
    lpv_scene_free(&s);

    /* a texture, x fastest; integral floats count as integers */
    assert_int_equal(load_medium("{'sigma_s':1,'sigma_a':[0,0,1000],'box':{'min':[0,0,0],'max':[1,1,1]},"
                                 "'density':{'dims':[2,1,2.0],'values':[0,1,2.5,1e6]}}",
                                 &s, err, sizeof err),
                     0);
    assert_int_equal(s.medium.present, 1);
    assert_int_equal(s.medium.dims[0], 2);
    assert_int_equal(s.medium.dims[1], 1);
    assert_int_equal(s.medium.dims[2], 2);
    assert_non_null(s.medium.density);
    assert_true(s.medium.density[0] == 0.0f && s.medium.density[1] == 1.0f && s.medium.density[2] == 2.5f &&
                s.medium.density[3] == 1e6f);
    lpv_scene_free(&s);

    /* all coefficients 0: no medium, whatever else is given */
    assert_int_equal(load_medium("{'sigma_s':0,'sigma_a':[0,0,0],'box':{'min':[0,0,0],'max':[1,1,1]},"
                                 "'density':{'dims':[1,1,1],'values':[1]}}",
                                 &s, err, sizeof err),
                     0);
    assert_int_equal(s.medium.present, 0);
    assert_int_equal(s.medium.has_box, 0);
    assert_null(s.medium.density);
    lpv_scene_free(&s);

    /* on the document's extras; the scene's wins when both carry one */
    const char *doc = J("{'asset':{'version':'2.0'},'extras':{'lpvd_medium':{'sigma_s':0.3,'sigma_a':0.1}}}");
    const char *path = lpvt_write_file(lpvt_tmpdir(), "root.gltf", doc, strlen(doc));
    assert_int_equal(lpv_gltf_load_file(path, &s, err, sizeof err), 0);
    assert_int_equal(s.medium.present, 1);
    assert_rgb(s.medium.sigma_s, 0.3f, 0.3f, 0.3f);
    lpv_scene_free(&s);
    doc = J("{'asset':{'version':'2.0'},'extras':{'lpvd_medium':{'sigma_s':0.3,'sigma_a':0.1}},"
            "'scene':0,'scenes':[{'extras':{'lpvd_medium':{'sigma_s':0.7,'sigma_a':0}}}]}");
    path = lpvt_write_file(lpvt_tmpdir(), "both.gltf", doc, strlen(doc));
    assert_int_equal(lpv_gltf_load_file(path, &s, err, sizeof err), 0);
    assert_rgb(s.medium.sigma_s, 0.7f, 0.7f, 0.7f);
    lpv_scene_free(&s);

    /* another scene's medium is not this one's */
    doc = J("{'asset':{'version':'2.0'},'scene':1,"
            "'scenes':[{'extras':{'lpvd_medium':{'sigma_s':0.7,'sigma_a':0}}},{'name':'plain'}]}");
    path = lpvt_write_file(lpvt_tmpdir(), "other.gltf", doc, strlen(doc));
    assert_int_equal(lpv_gltf_load_file(path, &s, err, sizeof err), 0);
    assert_int_equal(s.medium.present, 0);
    lpv_scene_free(&s);

    /* glTF's default roughness is 1 (no pbrMetallicRoughness at all) */
    doc = J("{'asset':{'version':'2.0'},'materials':[{'name':'plain'},"
            "{'name':'shiny','pbrMetallicRoughness':{'roughnessFactor':0.25}}]}");
    path = lpvt_write_file(lpvt_tmpdir(), "materials.gltf", doc, strlen(doc));
    assert_int_equal(lpv_gltf_load_file(path, &s, err, sizeof err), 0);
    assert_true(material_named(&s, "plain")->roughness == 1.0f);
    assert_true(material_named(&s, "shiny")->roughness == 0.25f);
    lpv_scene_free(&s);
}

static void test_medium_hostile(void **state)
{
    (void)state;
    const char *box = "'box':{'min':[0,0,0],'max':[1,1,1]}";

    refused("[1,2]", "lpvd_medium:", "must be an object", NULL);
    refused("{'sigma_a':0.1}", "lpvd_medium.sigma_s", "missing", NULL);
    refused("{'sigma_s':0.1}", "lpvd_medium.sigma_a", "missing", NULL);
    refused("{'sigma_s':-0.1,'sigma_a':0}", "lpvd_medium.sigma_s", "out of range", NULL);
    refused("{'sigma_s':0.1,'sigma_a':1000.5}", "lpvd_medium.sigma_a", "out of range", NULL);
    refused("{'sigma_s':[0.1,0.2],'sigma_a':0}", "lpvd_medium.sigma_s", "2 values", NULL);
    refused("{'sigma_s':[0.1,'NaN',0.2],'sigma_a':0}", "lpvd_medium.sigma_s[1]", "not a number", NULL);
    refused("{'sigma_s':'NaN','sigma_a':0}", "lpvd_medium.sigma_s", NULL);
    /* JSON cannot spell NaN or infinity; an overflowing literal is refused by the JSON check */
    refused("{'sigma_s':1e400,'sigma_a':0}", "1e400", NULL);
    refused("{'sigma_s':true,'sigma_a':0}", "lpvd_medium.sigma_s", NULL);

    /* the box */
    refused("{'sigma_s':1,'sigma_a':0,'box':[0,1]}", "lpvd_medium.box", "must be an object", NULL);
    refused("{'sigma_s':1,'sigma_a':0,'box':{'min':[0,0,0]}}", "lpvd_medium.box.max", "missing", NULL);
    refused("{'sigma_s':1,'sigma_a':0,'box':{'min':[0,0,0],'max':[1,0,1]}}", "lpvd_medium.box", "min.y", NULL);
    refused("{'sigma_s':1,'sigma_a':0,'box':{'min':[0,0,0],'max':[1,1]}}", "lpvd_medium.box.max", "2 values",
            NULL);
    refused("{'sigma_s':1,'sigma_a':0,'box':{'min':[0,'NaN',0],'max':[1,1,1]}}", "lpvd_medium.box.min[1]", NULL);
    refused("{'sigma_s':1,'sigma_a':0,'box':{'min':[0,0,0],'max':[1,1,1e300]}}", "lpvd_medium.box.max[2]",
            "out of range", NULL);

    /* the density texture */
    refused("{'sigma_s':1,'sigma_a':0,'density':{'dims':[1,1,1],'values':[1]}}", "lpvd_medium.density",
            "needs a \"box\"", NULL);
    refused(J("{'sigma_s':1,'sigma_a':0,%s,'density':{'dims':[2,2,2],'values':[1,1,1,1,1,1,1,1,1,1,1,1]}}", box),
            "lpvd_medium.density.values: 12 values, dims 2x2x2 need 8", NULL);
    refused(J("{'sigma_s':1,'sigma_a':0,%s,'density':{'dims':[2,2],'values':[1,1,1,1]}}", box),
            "lpvd_medium.density.dims", NULL);
    refused(J("{'sigma_s':1,'sigma_a':0,%s,'density':{'dims':[0,1,1],'values':[1]}}", box),
            "lpvd_medium.density.dims[0]", "1 .. 256", NULL);
    refused(J("{'sigma_s':1,'sigma_a':0,%s,'density':{'dims':[1,-2,1],'values':[1]}}", box),
            "lpvd_medium.density.dims[1]", NULL);
    refused(J("{'sigma_s':1,'sigma_a':0,%s,'density':{'dims':[1,1.5,1],'values':[1]}}", box),
            "lpvd_medium.density.dims[1]", "integer", NULL);
    refused(J("{'sigma_s':1,'sigma_a':0,%s,'density':{'dims':[257,1,1],'values':[1]}}", box),
            "lpvd_medium.density.dims[0]", NULL);
    /* huge dims: refused before any values are looked at (or allocated) */
    refused(J("{'sigma_s':1,'sigma_a':0,%s,'density':{'dims':[100000,100000,100000],'values':[1]}}", box),
            "lpvd_medium.density.dims[0]", NULL);
    /* 2^32 + 1 would be 1 if truncated to int */
    refused(J("{'sigma_s':1,'sigma_a':0,%s,'density':{'dims':[4294967297,1,1],'values':[1]}}", box),
            "lpvd_medium.density.dims[0]", NULL);
    refused(J("{'sigma_s':1,'sigma_a':0,%s,'density':{'dims':[2,1,1],'values':[1,-1]}}", box),
            "lpvd_medium.density.values[1]", "out of range", NULL);
    refused(J("{'sigma_s':1,'sigma_a':0,%s,'density':{'dims':[2,1,1],'values':[1,'NaN']}}", box),
            "lpvd_medium.density.values[1]", "not a number", NULL);
    refused(J("{'sigma_s':1,'sigma_a':0,%s,'density':{'dims':[2,1,1],'values':[1,1e400]}}", box),
            "1e400", NULL);
    refused(J("{'sigma_s':1,'sigma_a':0,%s,'density':{'dims':[2,1,1],'values':[1,2e6]}}", box),
            "lpvd_medium.density.values[1]", "out of range", NULL);
    /* a null is an element, not nothing */
    refused(J("{'sigma_s':1,'sigma_a':0,%s,'density':{'dims':[2,1,1],'values':[1,null]}}", box),
            "lpvd_medium.density.values[1]", "not a number", NULL);
    refused(J("{'sigma_s':1,'sigma_a':0,%s,'density':{'dims':[1,1,1]}}", box), "lpvd_medium.density.values",
            "missing", NULL);
    refused(J("{'sigma_s':1,'sigma_a':0,%s,'density':{'dims':[1,1,1],'values':{'a':1}}}", box),
            "lpvd_medium.density.values", NULL);
    /* checked even when the coefficients make it no medium */
    refused(J("{'sigma_s':0,'sigma_a':0,%s,'density':{'dims':[2,1,1],'values':[1]}}", box),
            "lpvd_medium.density.values: 1 values, dims 2x1x1 need 2", NULL);
}

/* ---- scene_build ---------------------------------------------------------- */

static void test_scene_build_media(void **state)
{
    (void)state;
    lpv_scene s = {0};
    const float ss[3] = {0.08f, 0.08f, 0.1f}, sa[3] = {0.02f, 0.02f, 0.02f}, zero[3] = {0, 0, 0};
    const float lo[3] = {-1, 0, -1}, hi[3] = {1, 2, 1};

    int grey = lpv_scene_add_material(&s, "grey", (float[3]){0.5f, 0.5f, 0.5f}, NULL);
    assert_true(grey >= 0);
    assert_true(s.materials[grey].roughness == 1.0f);
    assert_int_equal(lpv_scene_set_material_roughness(&s, grey, 0.1f), 0);
    assert_true(s.materials[grey].roughness == 0.1f);
    assert_int_equal(lpv_scene_set_material_roughness(&s, grey, 1.5f), -1);
    assert_int_equal(lpv_scene_set_material_roughness(&s, grey, NAN), -1);
    assert_int_equal(lpv_scene_set_material_roughness(&s, 1, 0.5f), -1);
    assert_int_equal(lpv_scene_set_material_roughness(&s, -1, 0.5f), -1);
    assert_true(s.materials[grey].roughness == 0.1f);

    assert_int_equal(lpv_scene_set_fog(&s, ss, sa), 0);
    assert_int_equal(s.medium.present, 1);
    assert_int_equal(s.medium.has_box, 0);
    assert_rgb(s.medium.sigma_s, 0.08f, 0.08f, 0.1f);
    assert_rgb(s.medium.sigma_a, 0.02f, 0.02f, 0.02f);

    /* a boxed texture, copied */
    float dens[2 * 3 * 4];
    for (int i = 0; i < 24; i++)
        dens[i] = (float)i;
    const int dims[3] = {2, 3, 4};
    assert_int_equal(lpv_scene_set_medium_box(&s, ss, sa, lo, hi, dims, dens), 0);
    dens[5] = -1.0f;
    assert_int_equal(s.medium.present, 1);
    assert_int_equal(s.medium.has_box, 1);
    assert_rgb(s.medium.box_min, -1, 0, -1);
    assert_rgb(s.medium.box_max, 1, 2, 1);
    assert_int_equal(s.medium.dims[2], 4);
    assert_non_null(s.medium.density);
    assert_true(s.medium.density != dens);
    assert_true(s.medium.density[5] == 5.0f && s.medium.density[23] == 23.0f);

    /* refusals leave the medium as it was */
    assert_int_equal(lpv_scene_set_medium_box(&s, ss, sa, lo, hi, dims, dens), -1); /* -1 in the values */
    dens[5] = NAN;
    assert_int_equal(lpv_scene_set_medium_box(&s, ss, sa, lo, hi, dims, dens), -1);
    dens[5] = 5.0f;
    assert_int_equal(lpv_scene_set_medium_box(&s, ss, sa, hi, lo, dims, dens), -1); /* min > max */
    assert_int_equal(lpv_scene_set_medium_box(&s, ss, sa, lo, lo, NULL, NULL), -1); /* empty box */
    assert_int_equal(lpv_scene_set_medium_box(&s, ss, sa, lo, hi, (int[3]){257, 1, 1}, dens), -1);
    assert_int_equal(lpv_scene_set_medium_box(&s, ss, sa, lo, hi, (int[3]){0, 1, 1}, dens), -1);
    assert_int_equal(lpv_scene_set_medium_box(&s, ss, sa, lo, hi, dims, NULL), -1);
    assert_int_equal(lpv_scene_set_medium_box(&s, ss, sa, lo, hi, (int[3]){0, 0, 0}, dens), -1);
    assert_int_equal(lpv_scene_set_fog(&s, (float[3]){-1, 0, 0}, sa), -1);
    assert_int_equal(lpv_scene_set_fog(&s, ss, (float[3]){0, 1001, 0}), -1);
    assert_int_equal(lpv_scene_set_fog(&s, (float[3]){NAN, 0, 0}, sa), -1);
    assert_int_equal(lpv_scene_set_fog(&s, (float[3]){INFINITY, 0, 0}, sa), -1);
    assert_int_equal(s.medium.has_box, 1);
    assert_true(s.medium.density[5] == 5.0f);

    /* homogeneous inside a box (replacing the texture), then no medium */
    assert_int_equal(lpv_scene_set_medium_box(&s, ss, sa, lo, hi, NULL, NULL), 0);
    assert_int_equal(s.medium.has_box, 1);
    assert_int_equal(s.medium.dims[0], 0);
    assert_null(s.medium.density);
    assert_int_equal(lpv_scene_set_medium_box(&s, ss, sa, lo, hi, dims, dens), 0);
    assert_int_equal(lpv_scene_set_medium_box(&s, ss, sa, lo, hi, (int[3]){0, 0, 0}, NULL), 0);
    assert_null(s.medium.density);
    assert_int_equal(lpv_scene_set_medium_box(&s, ss, sa, lo, hi, dims, dens), 0);
    assert_int_equal(lpv_scene_set_fog(&s, zero, zero), 0);
    assert_int_equal(s.medium.present, 0);
    assert_int_equal(s.medium.has_box, 0);
    assert_null(s.medium.density);
    assert_int_equal(lpv_scene_set_medium_box(&s, zero, zero, lo, hi, dims, dens), 0);
    assert_int_equal(s.medium.present, 0);
    assert_null(s.medium.density);

    /* lpv_scene_free releases a texture */
    assert_int_equal(lpv_scene_set_medium_box(&s, ss, sa, lo, hi, dims, dens), 0);
    lpv_scene_free(&s);
    assert_null(s.medium.density);
    assert_int_equal(s.medium.present, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_glossy_glb),        cmocka_unit_test(test_fog_glb),
        cmocka_unit_test(test_smoke_glb),         cmocka_unit_test(test_medium_forms),
        cmocka_unit_test(test_medium_hostile),    cmocka_unit_test(test_scene_build_media),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
