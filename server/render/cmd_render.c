/*
 * cmd_render.c - `lpvd render [SCENE] -o OUT.png|OUT.exr [flags]`: one tick
 * of the engine on a scene and one frame from its camera, written with
 * OpenImageIO (PNG: tone-mapped 8-bit sRGB; EXR: linear float radiance).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "context.h"
#include "engine.h"
#include "image_io.h"
#include "options.h"
#include "scene_load.h"
#include "stats_json.h"
#include "tonemap.h"

enum { R_OUTPUT, R_INDIRECT, R_DIRECT, R_AO, R_EXPOSURE, R_BACKGROUND, R_TRANSPARENT, R_STATS, R_HELP, R_COUNT };

static const lpv_flag RENDER_FLAGS[R_COUNT] = {
    [R_OUTPUT] = {"output", 'o', "PATH", "image file, .png (8-bit sRGB) or .exr (linear float)\n"
                                         "(default render.png)"},
    [R_INDIRECT] = {"indirect-only", 0, NULL, "only the LPV term: albedo/pi * gain * E_lpv"},
    [R_DIRECT] = {"direct-only", 0, NULL, "only direct light and emission"},
    [R_AO] = {"ao", 0, "PATH", "also write the ambient occlusion (technique iv; turns iv_ao on), grey\n"
                               "1 = open, .png (8-bit, linear) or .exr"},
    [R_EXPOSURE] = {"exposure", 0, "auto|EV",
                    "PNG exposure: metered from the frame (auto, default) or\n"
                    "fixed: the PNG shows 683 lm/W x radiance x 2^EV before the\n"
                    "tone curve (EV 0 = three.js / Khronos viewer at exposure 1;\n"
                    "a linear factor f is EV log2(f)); docs/units.md"},
    [R_BACKGROUND] = {"background", 0, "R,G,B", "PNG background where no geometry is seen, sRGB 0..1\n"
                                                "(default 0.25,0.25,0.25, opaque)"},
    [R_TRANSPARENT] = {"transparent", 0, NULL, "PNG background alpha 0 instead"},
    [R_STATS] = {"stats", 0, NULL, "print per-stage GPU times and counts as JSON"},
    [R_HELP] = {"help", 'h', NULL, "this text"},
};

static void usage(FILE *f)
{
    char help[4096];
    size_t len = 0;
    lpv_flags_help(help, sizeof help, &len, RENDER_FLAGS, R_COUNT);
    fprintf(f,
            "usage: lpvd render [SCENE.gltf|SCENE.glb] [-o OUT.png|OUT.exr] [flags]\n"
            "Renders SCENE (default: the built-in Cornell box) from its camera.\n"
            "Output:\n%s%s%s",
            help, lpv_scene_pose_flags_help(), LPVD_OPTIONS_HELP);
}

/* The ambient occlusion term into path: linear grey, no exposure or tone
 * curve (it is a fraction, not light). rgba is scratch of w x h pixels. */
static int write_ao(lpv_engine *engine, const char *path, float *rgba, int w, int h, char *err, size_t err_size)
{
    if (lpv_engine_render(engine, LPV_TERMS_AO, rgba, err, err_size) != 0)
        return -1;
    const size_t pixels = (size_t)w * (size_t)h;
    if (lpv_image_is_float_format(path))
        return lpv_image_write_f32(path, w, h, 4, rgba, err, err_size);
    uint8_t *g = malloc(pixels * 4);
    if (!g)
        return snprintf(err, err_size, "out of memory for the ao image"), -1;
    lpv_fraction_gray8(rgba, pixels, g);
    int rc = lpv_image_write_u8(path, w, h, 4, g, err, err_size);
    free(g);
    if (rc == 0)
        fprintf(stderr, "lpvd render: wrote %s (ambient occlusion)\n", path);
    return rc;
}

int lpvd_cmd_render(int argc, char **argv)
{
    lpvd_options opt = {0};
    const char *scene_path = NULL, *out_path = "render.png", *ao_path = NULL;
    lpv_frame_terms terms = LPV_TERMS_FULL;
    lpv_display display;
    lpv_display_default(&display);
    int stats = 0;
    char err[1024] = "";

    lpv_scene_pose pose = {0};
    lpv_flag_group groups[5] = {{RENDER_FLAGS, R_COUNT, NULL, NULL}, lpv_scene_pose_flag_group(&pose)};
    int ngroups = 2 + lpvd_options_groups(&opt, LPVD_GROUP_ALL, 1, groups + 2);
    lpv_flags p;
    if (lpv_flags_begin(&p, argc, argv, groups, ngroups, 0) != 0) {
        fprintf(stderr, "lpvd render: %s\n", p.err);
        return 2;
    }
    int g;
    const lpv_flag *fl;
    const char *v;
    for (lpv_flags_item it; (it = lpv_flags_next(&p, &g, &fl, &v)) != LPV_FLAGS_END;) {
        if (lpv_flags_refuse(&p, it, v, "lpvd render", 1))
            return 2;
        if (it == LPV_FLAGS_POSITIONAL) {
            if (scene_path) {
                fprintf(stderr, "lpvd render: more than one scene given (%s, %s)\n", scene_path, v);
                return 2;
            }
            scene_path = v;
            continue;
        }
        switch (fl - RENDER_FLAGS) {
        case R_HELP: usage(stdout); return 0;
        case R_OUTPUT: out_path = v; break;
        case R_INDIRECT: terms = LPV_TERMS_INDIRECT_ONLY; break;
        case R_DIRECT: terms = LPV_TERMS_DIRECT_ONLY; break;
        case R_AO: ao_path = v; break;
        case R_STATS: stats = 1; break;
        case R_TRANSPARENT: display.transparent = 1; break;
        case R_EXPOSURE:
            if (lpv_exposure_parse(v, &display, err, sizeof err) != 0) {
                fprintf(stderr, "lpvd render: --%s\n", err);
                return 2;
            }
            break;
        case R_BACKGROUND: {
            float b[3];
            char tail;
            if (sscanf(v, "%f,%f,%f%c", &b[0], &b[1], &b[2], &tail) != 3 || !(b[0] >= 0.0f && b[0] <= 1.0f) ||
                !(b[1] >= 0.0f && b[1] <= 1.0f) || !(b[2] >= 0.0f && b[2] <= 1.0f)) {
                fprintf(stderr, "lpvd render: --background %s: expected R,G,B, sRGB values in 0..1\n", v);
                return 2;
            }
            memcpy(display.background, b, sizeof b);
            break;
        }
        }
    }

    if (ao_path) {
        if (!lpv_technique_has(opt.settings.technique, LPV_CAP_AO)) { /* its knob is set below */
            fprintf(stderr, "lpvd render: --ao needs --technique %s (ambient occlusion comes from the imperfect "
                            "volume)\n", LPV_TECHNIQUE_IV);
            return 2;
        }
        opt.settings.iv.ao = LPV_SWITCH_ON;
    }
    lpv_scene scene;
    lpv_gltf_animation_time at_buf;
    const lpv_gltf_animation_time *at = NULL;
    if (lpv_scene_pose_at(&pose, &at_buf, &at, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd render: %s\n", err);
        return 2;
    }
    if (lpv_scene_load_user(scene_path, at, &scene, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd render: %s\n", err);
        return 1;
    }
    lpv_view view;
    if (lpv_view_resolve(&opt.cam, &scene, &view, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd render: %s\n", err);
        lpv_scene_free(&scene);
        return 2;
    }

    int rc = 1;
    lpv_engine *engine = NULL;
    float *rgba = NULL;
    uint8_t *rgba8 = NULL;
    lpv_gl_context_desc desc = {.backend = opt.backend};
    lpv_gl_context *ctx = lpv_gl_context_create(&desc, err, sizeof err);
    if (!ctx) {
        fprintf(stderr, "lpvd render: no OpenGL 4.5 context: %s\n", err);
        goto done;
    }
    fprintf(stderr, "lpvd render: backend %s, GL_RENDERER %s\n", lpv_backend_name(lpv_gl_context_backend(ctx)),
            lpv_gl_context_renderer(ctx));
    engine = lpv_engine_create(err, sizeof err);
    const lpv_engine_item item = {.settings = &opt.settings, .scene = &scene, .view = &view, .tick = 1};
    if (!engine || lpv_engine_run_item(engine, &item, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd render: %s\n", err);
        goto done;
    }
    const lpv_plan *plan = lpv_engine_last_plan(engine);
    if (plan && plan->iterations_warning) /* light that stops short of the grid darkens the frame silently */
        fprintf(stderr, "lpvd render: warning: %s\n", plan->iterations_reason);
    size_t pixels = (size_t)view.width * (size_t)view.height;
    rgba = malloc(pixels * 4 * sizeof(float));
    if (!rgba) {
        fprintf(stderr, "lpvd render: out of memory for a %dx%d image\n", view.width, view.height);
        goto done;
    }
    if (lpv_engine_render(engine, terms, rgba, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd render: %s\n", err);
        goto done;
    }
    if (lpv_image_is_float_format(out_path)) {
        if (lpv_image_write_f32(out_path, view.width, view.height, 4, rgba, err, sizeof err) != 0) {
            fprintf(stderr, "lpvd render: %s\n", err);
            goto done;
        }
    } else {
        rgba8 = malloc(pixels * 4);
        if (!rgba8) {
            fprintf(stderr, "lpvd render: out of memory\n");
            goto done;
        }
        float ev = lpv_display_rgba8(rgba, pixels, &display, rgba8);
        fprintf(stderr, "lpvd render: exposure EV %.2f (%s)\n", (double)ev, display.exposure_auto ? "auto" : "fixed");
        if (lpv_image_write_u8(out_path, view.width, view.height, 4, rgba8, err, sizeof err) != 0) {
            fprintf(stderr, "lpvd render: %s\n", err);
            goto done;
        }
    }
    fprintf(stderr, "lpvd render: wrote %s (%dx%d) from %s\n", out_path, view.width, view.height, scene.source);
    if (ao_path && write_ao(engine, ao_path, rgba, view.width, view.height, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd render: %s\n", err);
        goto done;
    }
    if (stats) {
        json_t *j = lpvd_stats_json(engine, ctx, scene.source);
        json_dumpf(j, stdout, JSON_INDENT(2));
        fputc('\n', stdout);
        json_decref(j);
    }
    rc = 0;
done:
    free(rgba8);
    free(rgba);
    lpv_engine_destroy(engine);
    lpv_gl_context_destroy(ctx);
    lpv_scene_free(&scene);
    return rc;
}
