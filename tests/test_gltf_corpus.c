/*
 * test_gltf_corpus.c - glTF as people export it (issue 32, item 6): every
 * .gltf and .glb file of Debian's assimp-testmodels (glTF2/, installed by
 * scripts/install-deps.sh; LPVD_ASSIMP_MODELS overrides the folder), of the
 * project's scenes/ and of ../shared/scenes either loads or is refused with a
 * message that names the file and says more than its name. Each loaded one
 * goes through what `lpvd render` does at its defaults (the engine may still
 * refuse it, e.g. with no triangles, again with a message): tick and full
 * frame at 32x32 from the view `lpvd render` would choose, every channel of
 * every pixel finite and >= 0; and where the file brings its own camera,
 * that camera sees geometry (the reference's primary rays at 8x8 pixels).
 * Nothing here is fitted to a file: a file that breaks a rule fails with its
 * name.
 */
#define _XOPEN_SOURCE 700 /* nftw */
#include <ftw.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "engine.h"
#include "pt.h"
#include "scene_load.h"
#include "test_util.h"
#include "view_choice.h"

#define W 32
#define H 32
#define MAX_FILES 512

static char *files[MAX_FILES];
static int file_count;

static int collect(const char *path, const struct stat *st, int type, struct FTW *f)
{
    (void)st;
    (void)f;
    size_t n = strlen(path);
    if (type == FTW_F && file_count < MAX_FILES &&
        ((n > 5 && !strcmp(path + n - 5, ".gltf")) || (n > 4 && !strcmp(path + n - 4, ".glb"))))
        files[file_count++] = strdup(path);
    return 0;
}

static int by_name(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

static const char *models_dir(void)
{
    const char *d = getenv("LPVD_ASSIMP_MODELS");
    return d && d[0] ? d : "/usr/share/assimp/models";
}

/* A refusal's message: names the file (its last component) and says why. */
static void check_refusal(const char *path, const char *err, const char *stage)
{
    const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    const char *at = strstr(err, base);
    if (!at)
        fail_msg("%s: %s refused it without naming the file: '%s'", path, stage, err);
    if (strlen(err) < strlen(path) + 8)
        fail_msg("%s: %s refused it without saying why: '%s'", path, stage, err);
    print_message("  refused (%s): %s\n", stage, err);
}

/* The file's own camera (not a default lpvd placed) meets geometry. */
static void check_camera_sees(const char *path, const lpv_scene *s, const lpv_view *v)
{
    lpv_ref *ref = NULL;
    char err[1024] = "";
    if (lpv_ref_create(s, NULL, &ref, err, sizeof err) != 0)
        fail_msg("%s: %s", path, err);
    int hits = 0;
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            float o[3], d[3], t0, t1, p[3], n[3];
            lpv_ref_pixel_ray(v, x * v->width / 8 + v->width / 16, y * v->height / 8 + v->height / 16, o, d, &t0,
                              &t1);
            hits += lpv_ref_first_surface(ref, o, d, t0, t1, NULL, p, n) != 0;
        }
    lpv_ref_destroy(ref);
    if (!hits)
        fail_msg("%s: the file's camera sees no geometry (64 rays)", path);
}

static int check_file(const char *path)
{
    char err[1024] = "";
    lpv_scene s;
    if (lpv_scene_load(path, &s, err, sizeof err) != 0) {
        check_refusal(path, err, "load");
        return 0;
    }
    lpv_view_choice choice = {.width = W, .height = H};
    lpv_view v;
    if (lpv_view_resolve(&choice, &s, &v, err, sizeof err) != 0)
        fail_msg("%s: no view: %s", path, err);
    lpv_settings st = {0}; /* lpvd render's defaults */
    int rendered = 0;
    if (lpv_engine_set_settings(lpvt_engine, &st, err, sizeof err) != 0)
        fail_msg("%s: %s", path, err);
    if (lpv_engine_set_scene(lpvt_engine, &s, err, sizeof err) != 0) {
        check_refusal(path, err, "engine");
    } else {
        if (lpv_engine_set_view(lpvt_engine, &v, err, sizeof err) != 0 ||
            lpv_engine_tick(lpvt_engine, err, sizeof err) != 0)
            fail_msg("%s: %s", path, err);
        float *rgba = lpvt_render(W, H);
        for (size_t i = 0; i < (size_t)W * H * 4; ++i)
            if (!(isfinite(rgba[i]) && rgba[i] >= 0.0f))
                fail_msg("%s: pixel %zu channel %zu is %g", path, i / 4, i % 4, (double)rgba[i]);
        free(rgba);
        if (s.camera_count > 0 && !s.default_camera_added)
            check_camera_sees(path, &s, &v);
        rendered = 1;
        print_message("  rendered: %s (%u triangles, %s)\n", path, s.index_count / 3,
                      lpv_engine_last_plan(lpvt_engine)->technique);
    }
    lpv_scene_free(&s);
    return rendered;
}

static void run_folder(const char *dir, int min_files)
{
    file_count = 0;
    if (nftw(dir, collect, 16, FTW_PHYS) != 0 && min_files > 0)
        fail_msg("%s cannot be read: scripts/install-deps.sh installs Debian's assimp-testmodels", dir);
    qsort(files, (size_t)file_count, sizeof *files, by_name);
    if (file_count < min_files)
        fail_msg("%s holds %d glTF files, expected at least %d", dir, file_count, min_files);
    int rendered = 0;
    for (int i = 0; i < file_count; ++i) {
        rendered += check_file(files[i]);
        free(files[i]);
    }
    print_message("%s: %d files, %d rendered, %d refused with a message\n", dir, file_count, rendered,
                  file_count - rendered);
    assert_true(rendered > 0 || file_count == 0);
}

static void test_assimp_gltf2(void **state)
{
    (void)state;
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/glTF2", models_dir());
    run_folder(dir, 40); /* Debian 12's assimp-testmodels ships 46 (31 render, 15 are refused) */
}

static void test_project_scenes(void **state)
{
    (void)state;
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/scenes", lpvt_source_dir());
    run_folder(dir, 10);
}

static void test_shared_scenes(void **state)
{
    (void)state;
    const char *shared = lpvt_shared_dir();
    if (!shared)
        skip();
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/scenes", shared);
    run_folder(dir, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_assimp_gltf2),
        cmocka_unit_test(test_project_scenes),
        cmocka_unit_test(test_shared_scenes),
    };
    return cmocka_run_group_tests(tests, lpvt_gl_setup, lpvt_gl_teardown);
}
