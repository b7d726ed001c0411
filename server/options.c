/* options.c - see options.h. */
#include "options.h"

#include "lpv_shared.h"
#include "settings_fields.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char OPTIONS_HELP_HEAD[] =
    "Engine settings (--grid, --iterations, --rsm-size and --occlusion win over --preset,\n"
    "in any order):\n"
    "  --preset NAME           quality preset (default balanced; docs/accuracy.md):\n";

/* After the preset lines, which come from the preset table. */
static const char OPTIONS_HELP_KNOBS[] =
    "  --grid N | NxMxK        LPV cells per axis (default: the preset's)\n"
    "  --bounds x0,y0,z0,x1,y1,z1  grid bounds in m (default: the scene's bounds)\n"
    "  --iterations N          propagation steps (default: the preset's)\n"
    "  --rsm-size N            reflective shadow map side in texels (default: the preset's)\n"
    "  --occlusion on|off      fuzzy occlusion from the geometry volume (default: the preset's)\n"
    "  --indirect-gain G       artistic factor on the LPV term (default 1)\n"
    "  --emissive-vpls N       VPLs sampled on emissive surfaces (default 4096)\n";

/* The flags of the field table that the head above does not list. */
static const char *const HEAD_FLAGS[] = {"iterations", "rsm-size", "occlusion", "indirect-gain", "emissive-vpls",
                                         NULL};

static const char OPTIONS_HELP_TAIL[] =
    "GL:\n"
    "  --backend NAME          auto | egl-device | egl-surfaceless | osmesa\n"
    "                          (default auto; or the LPVD_GL_BACKEND variable)\n"
    "Camera:\n"
    "  --camera N|NAME         a camera of the glTF file, by index or name\n"
    "  --eye X,Y,Z --target X,Y,Z --fov DEG   an explicit camera (fov vertical)\n"
    "  --size WxH              image size (default 512 wide, height from the camera's aspect)\n";

static int in_head(const char *flag)
{
    for (int i = 0; HEAD_FLAGS[i]; ++i)
        if (strcmp(flag, HEAD_FLAGS[i]) == 0)
            return 1;
    return 0;
}

/* The allowed values in help's compact form: "0..4", "> 0, <= 1e+06", "on|off". */
static void help_range(const lpv_field *f, char *buf, size_t n)
{
    if (f->kind == LPV_FIELD_SWITCH)
        snprintf(buf, n, "on|off");
    else if (f->min_exclusive)
        snprintf(buf, n, "> %g, <= %g", f->min, f->max);
    else
        snprintf(buf, n, "%g..%g", f->min, f->max);
}

const char *lpvd_options_help(void)
{
    static char help[8192];
    if (help[0])
        return help;
    size_t len = (size_t)snprintf(help, sizeof help, "%s", OPTIONS_HELP_HEAD);
    for (int p = LPV_PRESET_DEFAULT + 1; p < LPV_PRESET_COUNT_ && len < sizeof help; ++p) {
        lpv_settings s;
        lpv_preset_settings((lpv_preset)p, &s);
        char letters[5];
        len += (size_t)snprintf(help + len, sizeof help - len,
                                "%28s%-10sgrid %d, %d iterations, RSM %d, occlusion %s, departures %s\n", "",
                                lpv_preset_name((lpv_preset)p), s.grid_dims[0], s.iterations, s.rsm_size,
                                s.occlusion == LPV_SWITCH_ON ? "on" : "off", lpv_settings_departures(&s, letters));
    }
    if (len < sizeof help)
        len += (size_t)snprintf(help + len, sizeof help - len, "%s", OPTIONS_HELP_KNOBS);
    len += (size_t)snprintf(help + len, sizeof help - len,
                            "Shadows, cascades, effects and scheduling (docs/shadows.md, docs/cascades.md,\n"
                            "docs/effects.md):\n");
    size_t count;
    const lpv_field *fields = lpv_fields(&count);
    for (size_t i = 0; i < count && len < sizeof help; ++i) {
        const lpv_field *f = &fields[i];
        if (in_head(f->flag))
            continue;
        char left[64], range[64];
        snprintf(left, sizeof left, "%s %s", f->flag, lpv_field_metavar(f));
        help_range(f, range, sizeof range);
        if (f->kind == LPV_FIELD_SWITCH) /* "  --glossy on|off   help\n   (default on)" */
            len += (size_t)snprintf(help + len, sizeof help - len, "  --%-22s%s\n%26s(default %s)\n", left, f->help,
                                    "", f->deflt);
        else /* "  --cascade-size X   help\n   (m; > 0, <= 1e+06; default 8)" */
            len += (size_t)snprintf(help + len, sizeof help - len, "  --%-22s%s\n%26s(%s%s%s%s%s; default %s)\n", left,
                                    f->help, "", f->unit, f->unit[0] ? "; " : "", range, f->note[0] ? ", " : "",
                                    f->note, f->deflt);
    }
    if (len < sizeof help)
        snprintf(help + len, sizeof help - len, "%s", OPTIONS_HELP_TAIL);
    return help;
}

static const char *const WITH_VALUE[] = {"preset", "grid", "bounds", "backend", "camera",
                                         "eye", "target", "fov", "size", NULL};

int lpvd_option_takes_value(const char *name)
{
    for (int i = 0; WITH_VALUE[i]; ++i)
        if (strcmp(name, WITH_VALUE[i]) == 0)
            return 1;
    if (lpv_field_by_flag(name))
        return 1;
    return -1;
}

static int parse_int(const char *v, int lo, int hi, int *out)
{
    char *end;
    long x = strtol(v, &end, 10);
    if (end == v || *end || x < lo || x > hi)
        return -1;
    *out = (int)x;
    return 0;
}

static int parse_floats(const char *v, float *out, int n)
{
    const char *p = v;
    for (int i = 0; i < n; ++i) {
        char *end;
        double x = strtod(p, &end);
        if (end == p || !isfinite(x))
            return -1;
        out[i] = (float)x;
        p = end;
        if (i + 1 < n) {
            if (*p != ',')
                return -1;
            ++p;
        }
    }
    return *p ? -1 : 0;
}

static int bad(char *err, size_t n, const char *name, const char *value, const char *want)
{
    snprintf(err, n, "--%s %s: expected %s", name, value ? value : "", want);
    return -1;
}

int lpvd_option_parse(lpvd_options *o, const char *name, const char *v, char *err, size_t n)
{
    lpv_settings *s = &o->settings;
    if (strcmp(name, "preset") == 0) {
        /* only the preset is recorded: resolve fills the fields no other flag set */
        if (lpv_preset_from_name(v, &s->preset) != 0) {
            snprintf(err, n, "--preset %s: unknown preset (allowed: %s)", v ? v : "", lpv_preset_names());
            return -1;
        }
    } else if (strcmp(name, "grid") == 0) {
        int d[3];
        if (parse_int(v, 1, LPV_MAX_GRID_DIM, &d[0]) == 0) {
            d[1] = d[2] = d[0];
        } else if (sscanf(v, "%dx%dx%d", &d[0], &d[1], &d[2]) != 3 || d[0] < 1 || d[1] < 1 || d[2] < 1 ||
                   d[0] > LPV_MAX_GRID_DIM || d[1] > LPV_MAX_GRID_DIM || d[2] > LPV_MAX_GRID_DIM) {
            return bad(err, n, name, v, "N or NxMxK with 1..256 cells per axis");
        }
        memcpy(s->grid_dims, d, sizeof d);
    } else if (strcmp(name, "bounds") == 0) {
        float b[6];
        if (parse_floats(v, b, 6) != 0 || !(b[3] > b[0] && b[4] > b[1] && b[5] > b[2]))
            return bad(err, n, name, v, "x0,y0,z0,x1,y1,z1 with max > min");
        memcpy(s->bounds_min, b, sizeof s->bounds_min);
        memcpy(s->bounds_max, b + 3, sizeof s->bounds_max);
    } else if (lpv_field_by_flag(name)) { /* the table's scalar knobs (core/settings_fields.c) */
        char why[160];
        if (lpv_field_set_string(s, lpv_field_by_flag(name), v, why, sizeof why) != 0) {
            snprintf(err, n, "--%s %s: %s", name, v ? v : "", why);
            return -1;
        }
    } else if (strcmp(name, "backend") == 0) {
        if (lpv_backend_parse(v, &o->backend) != 0)
            return bad(err, n, name, v, "auto, egl-device, egl-surfaceless or osmesa");
    } else if (strcmp(name, "camera") == 0) {
        o->cam.camera = v;
    } else if (strcmp(name, "eye") == 0) {
        if (parse_floats(v, o->cam.eye, 3) != 0)
            return bad(err, n, name, v, "X,Y,Z");
        o->cam.has_eye = 1;
    } else if (strcmp(name, "target") == 0) {
        if (parse_floats(v, o->cam.target, 3) != 0)
            return bad(err, n, name, v, "X,Y,Z");
        o->cam.has_target = 1;
    } else if (strcmp(name, "fov") == 0) {
        if (parse_floats(v, &o->cam.fov_deg, 1) != 0 || !(o->cam.fov_deg > 0.0f && o->cam.fov_deg < 179.0f))
            return bad(err, n, name, v, "degrees in (0, 179)");
        o->cam.has_fov = 1;
    } else if (strcmp(name, "size") == 0) {
        if (sscanf(v, "%dx%d", &o->cam.width, &o->cam.height) != 2 || o->cam.width < 1 || o->cam.height < 1 ||
            o->cam.width > 16384 || o->cam.height > 16384)
            return bad(err, n, name, v, "WxH, 1..16384 each");
    } else {
        return 0;
    }
    return 1;
}

int lpvd_resolve_view(const lpvd_camera_choice *c, const lpv_scene *scene, lpv_view *view, char *err, size_t n)
{
    int w = c->width ? c->width : 512;
    int h = c->height;
    const lpv_camera *cam = NULL;
    if (c->camera) {
        int i = lpv_view_find_camera(scene, c->camera);
        if (i < 0) {
            snprintf(err, n, "--camera %s: %s has %u camera(s) and none with that index or name", c->camera,
                     scene->source, scene->camera_count);
            return -1;
        }
        cam = &scene->cameras[i];
    } else if (scene->camera_count && !c->has_eye) {
        cam = &scene->cameras[0];
    }
    if (!h) {
        float aspect = (cam && cam->aspect > 0.0f) ? cam->aspect : 1.0f;
        h = (int)lroundf((float)w / aspect);
        if (h < 1)
            h = 1;
    }
    if (c->has_eye || c->has_target) {
        float target[3] = {0.5f * (scene->bounds_min[0] + scene->bounds_max[0]),
                           0.5f * (scene->bounds_min[1] + scene->bounds_max[1]),
                           0.5f * (scene->bounds_min[2] + scene->bounds_max[2])};
        lpv_view framed;
        lpv_view_frame_bounds(scene, w, h, &framed);
        const float *eye = c->has_eye ? c->eye : framed.eye;
        if (c->has_target)
            memcpy(target, c->target, sizeof target);
        float fov = c->has_fov ? c->fov_deg * 0.01745329252f : (cam ? cam->yfov : framed.yfov);
        if (lpv_view_look_at(eye, target, fov, w, h, view) != 0) {
            snprintf(err, n, "--eye/--target: eye and target must differ");
            return -1;
        }
        return 0;
    }
    if (cam) {
        lpv_view_from_camera(cam, w, h, view);
        if (c->has_fov)
            view->yfov = c->fov_deg * 0.01745329252f;
    } else {
        lpv_view_frame_bounds(scene, w, h, view);
        if (c->has_fov)
            view->yfov = c->fov_deg * 0.01745329252f;
    }
    return 0;
}
