/*
 * lpvctl_session.c - the commands that shape a session: hello, load,
 * update, light-set, light-remove, camera, knobs, config, ack and bye.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lpvctl.h"

/* A command that takes no arguments. */
static int no_args(int argc)
{
    return argc != 1 ? usage_error("takes no arguments%s", NULL) : 0;
}

int cmd_hello(int argc, char **argv)
{
    (void)argv;
    if (no_args(argc))
        return 2;
    printf("hello: %s\n", lpvc_hello_reply(g_c));
    return 0;
}

enum { LOAD_GLB, LOAD_COUNT };
static const lpv_flag LOAD_FLAGS[LOAD_COUNT] = {[LOAD_GLB] = {"glb", 0, "FILE", "the scene's .glb bytes"}};

int cmd_load(int argc, char **argv)
{
    const char *path = NULL, *glb_path = NULL;
    lpv_flags p;
    int idx, r;
    const char *v;
    if (args_begin(&p, argc, argv, LOAD_FLAGS, LOAD_COUNT) != 0)
        return 2;
    while ((r = args_next(&p, LOAD_FLAGS, &idx, &v)) > 0) {
        if (idx == LOAD_GLB && !glb_path)
            glb_path = v;
        else if (idx < 0 && !path)
            path = v;
        else
            return usage_error("expected PATH or --glb FILE%s", NULL);
    }
    if (r < 0)
        return 2;
    if (!path == !glb_path)
        return usage_error("expected PATH or --glb FILE%s", NULL);
    if (glb_path) {
        size_t len = 0;
        unsigned char *glb = read_file(glb_path, &len);
        if (!glb) {
            fprintf(stderr, "lpvctl: load: cannot read %s: %s\n", glb_path, strerror(errno));
            return 1;
        }
        int rc = lpvc_scene_load_glb(g_c, glb, len);
        free(glb);
        if (rc != 0)
            return server_error();
    } else if (lpvc_scene_load_file(g_c, path) != 0) {
        return server_error();
    }
    print_reply();
    return 0;
}

enum { UPDATE_FILE, UPDATE_COUNT };
static const lpv_flag UPDATE_FLAGS[UPDATE_COUNT] = {[UPDATE_FILE] = {"file", 0, "F", "the JSON object from a file"}};

int cmd_update(int argc, char **argv)
{
    const char *json = NULL, *file = NULL;
    lpv_flags p;
    int idx, r;
    const char *v;
    if (args_begin(&p, argc, argv, UPDATE_FLAGS, UPDATE_COUNT) != 0)
        return 2;
    while ((r = args_next(&p, UPDATE_FLAGS, &idx, &v)) > 0) {
        if (idx == UPDATE_FILE && !file)
            file = v;
        else if (idx < 0 && !json)
            json = v;
        else
            return usage_error("expected a JSON object or --file F%s", NULL);
    }
    if (r < 0)
        return 2;
    if (!json == !file)
        return usage_error("expected a JSON object or --file F%s", NULL);
    char *text = NULL;
    if (file) {
        size_t len;
        unsigned char *b = read_file(file, &len);
        if (!b) {
            fprintf(stderr, "lpvctl: update: cannot read %s: %s\n", file, strerror(errno));
            return 1;
        }
        text = malloc(len + 1);
        if (text) {
            memcpy(text, b, len);
            text[len] = '\0';
        }
        free(b);
    } else {
        text = strdup(json);
    }
    int rc = text ? lpvc_scene_update(g_c, text) : -1;
    free(text);
    if (rc != 0)
        return server_error();
    print_reply();
    return 0;
}

enum { LS_ID, LS_TYPE, LS_INTENSITY, LS_COLOR, LS_POSITION, LS_DIRECTION, LS_RANGE, LS_INNER, LS_OUTER, LS_COUNT };
static const lpv_flag LIGHT_FLAGS[LS_COUNT] = {
    [LS_ID] = {"id", 0, "ID", "the light's id (or the first argument)"},
    [LS_TYPE] = {"type", 0, "point|spot|directional", ""},
    [LS_INTENSITY] = {"intensity", 0, "I", ""},
    [LS_COLOR] = {"color", 0, "R,G,B", ""},
    [LS_POSITION] = {"position", 0, "X,Y,Z", ""},
    [LS_DIRECTION] = {"direction", 0, "X,Y,Z", ""},
    [LS_RANGE] = {"range", 0, "R", ""},
    [LS_INNER] = {"inner-cone", 0, "RAD", ""},
    [LS_OUTER] = {"outer-cone", 0, "RAD", ""},
};

int cmd_light_set(int argc, char **argv)
{
    lpvc_light l = {0};
    float color[3], pos[3], dir[3];
    int have_intensity = 0;
    lpv_flags p;
    int idx, r;
    const char *v;
    if (args_begin(&p, argc, argv, LIGHT_FLAGS, LS_COUNT) != 0)
        return 2;
    while ((r = args_next(&p, LIGHT_FLAGS, &idx, &v)) > 0) {
        int bad = 0;
        switch (idx) {
        case -1:
            if (l.id)
                return usage_error("unexpected argument '%s'", v);
            l.id = v;
            break;
        case LS_ID: l.id = v; break;
        case LS_TYPE: l.type = v; break;
        case LS_INTENSITY:
            bad = parse_float(v, &l.intensity);
            have_intensity = 1;
            break;
        case LS_COLOR: bad = parse_floats(v, color, 3), l.color = color; break;
        case LS_POSITION: bad = parse_floats(v, pos, 3), l.position = pos; break;
        case LS_DIRECTION: bad = parse_floats(v, dir, 3), l.direction = dir; break;
        case LS_RANGE: bad = parse_float(v, &l.range); break;
        case LS_INNER: bad = parse_float(v, &l.inner_cone); break;
        case LS_OUTER: bad = parse_float(v, &l.outer_cone); break;
        }
        if (bad) {
            fprintf(stderr, "lpvctl: light-set: bad --%s '%s' (expected %s)\n(lpvctl --help for usage)\n",
                    LIGHT_FLAGS[idx].name, v, LIGHT_FLAGS[idx].metavar);
            return 2;
        }
    }
    if (r < 0)
        return 2;
    if (!l.id || !have_intensity)
        return usage_error("needs an ID and --intensity%s", NULL);
    if (lpvc_light_set(g_c, &l) != 0)
        return server_error();
    print_reply();
    return 0;
}

int cmd_light_remove(int argc, char **argv)
{
    if (argc != 2 || argv[1][0] == '-')
        return usage_error("expected ID%s", NULL);
    if (lpvc_light_remove(g_c, argv[1]) != 0)
        return server_error();
    print_reply();
    return 0;
}

enum { CAM_EYE, CAM_TARGET, CAM_UP, CAM_FOV, CAM_SIZE, CAM_SCENE, CAM_COUNT };
static const lpv_flag CAMERA_FLAGS[CAM_COUNT] = {
    [CAM_EYE] = {"eye", 0, "X,Y,Z", ""},         [CAM_TARGET] = {"target", 0, "X,Y,Z", ""},
    [CAM_UP] = {"up", 0, "X,Y,Z", ""},           [CAM_FOV] = {"fov", 0, "DEG", ""},
    [CAM_SIZE] = {"size", 0, "WxH", ""},         [CAM_SCENE] = {"scene", 0, "NAME|INDEX", ""},
};

int cmd_camera(int argc, char **argv)
{
    lpvc_camera cam = {0};
    float eye[3], target[3], up[3];
    lpv_flags p;
    int idx, r;
    const char *v;
    if (args_begin(&p, argc, argv, CAMERA_FLAGS, CAM_COUNT) != 0)
        return 2;
    while ((r = args_next(&p, CAMERA_FLAGS, &idx, &v)) > 0) {
        int bad = 0;
        long n;
        switch (idx) {
        case -1: return usage_error("unexpected argument '%s'", v);
        case CAM_EYE: bad = parse_floats(v, eye, 3), cam.eye = eye; break;
        case CAM_TARGET: bad = parse_floats(v, target, 3), cam.target = target; break;
        case CAM_UP: bad = parse_floats(v, up, 3), cam.up = up; break;
        case CAM_FOV: bad = parse_float(v, &cam.fov_deg); break;
        case CAM_SIZE:
            bad = sscanf(v, "%dx%d", &cam.width, &cam.height) != 2 || cam.width <= 0 || cam.height <= 0;
            break;
        case CAM_SCENE:
            if (parse_int(v, 0, 1000000, &n) == 0)
                cam.scene_camera = (int)n + 1;
            else
                cam.scene_camera_name = v;
            break;
        }
        if (bad) {
            fprintf(stderr, "lpvctl: camera: bad --%s '%s' (expected %s)\n(lpvctl --help for usage)\n",
                    CAMERA_FLAGS[idx].name, v, CAMERA_FLAGS[idx].metavar);
            return 2;
        }
    }
    if (r < 0)
        return 2;
    if (!cam.scene_camera && !cam.scene_camera_name && (!cam.eye || !cam.target))
        return usage_error("needs --eye and --target, or --scene NAME|INDEX%s", NULL);
    if (lpvc_camera_set(g_c, &cam) != 0)
        return server_error();
    print_reply();
    return 0;
}

/* knobs: the daemon's description, one knob per line, then the presets. */
int cmd_knobs(int argc, char **argv)
{
    (void)argv;
    if (no_args(argc))
        return 2;
    const lpvc_knob *k = NULL;
    size_t n = lpvc_knobs(g_c, &k);
    for (size_t i = 0; i < n; ++i) {
        char want[96], flag[96];
        snprintf(flag, sizeof flag, "%s", k[i].name);
        for (char *q = flag; *q; ++q)
            if (*q == '_')
                *q = '-';
        printf("--%-22s %s; default %s%s%s%s%s: %s\n", flag, lpvc_knob_expect(&k[i], want, sizeof want),
               k[i].default_text, k[i].unit[0] ? "; unit " : "", k[i].unit, k[i].note[0] ? "; " : "", k[i].note,
               k[i].help);
    }
    size_t np = 0;
    const char *const *presets = lpvc_presets(g_c, &np);
    printf("presets:");
    for (size_t i = 0; i < np; ++i)
        printf(" %s", presets[i]);
    size_t nt = 0;
    const char *const *techniques = lpvc_techniques(g_c, &nt);
    printf("\ntechniques:");
    for (size_t i = 0; i < nt; ++i)
        printf(" %s", techniques[i]);
    printf("\n");
    fflush(stdout);
    return 0;
}

/* config's own flags; the daemon's knobs follow them in the table, built
 * from HELLO's description (SPEC R4.12), each as --kebab-case and as
 * --snake_case. */
enum { CFG_JSON, CFG_PRESET, CFG_TECHNIQUE, CFG_GRID, CFG_BOUNDS, CFG_TICK_RATE, CFG_OWN };
static const lpv_flag CONFIG_OWN[CFG_OWN] = {
    [CFG_JSON] = {"json", 0, "JSON", ""},
    [CFG_PRESET] = {"preset", 0, "NAME", ""},      /* the server checks the name (BAD_FIELD lists them) */
    [CFG_TECHNIQUE] = {"technique", 0, "NAME", ""}, /* one of HELLO's techniques; the server checks it */
    [CFG_GRID] = {"grid", 0, "N|NxMxK", ""},
    [CFG_BOUNDS] = {"bounds", 0, "x0,y0,z0,x1,y1,z1", ""},
    [CFG_TICK_RATE] = {"tick-rate", 0, "HZ", ""},
};

int cmd_config(int argc, char **argv)
{
    static lpv_flag flags[LPV_FLAGS_MAX];
    static char names[LPV_FLAGS_MAX][96];
    const lpvc_knob *knob_of[LPV_FLAGS_MAX] = {0};
    size_t nflags = 0;
    for (; nflags < CFG_OWN; ++nflags)
        flags[nflags] = CONFIG_OWN[nflags];
    const lpvc_knob *k = NULL;
    const size_t nk = lpvc_knobs(g_c, &k);
    for (size_t i = 0; i < nk; ++i)
        for (int snake = 0; snake < 2 && nflags < LPV_FLAGS_MAX; ++snake) {
            snprintf(names[nflags], sizeof names[nflags], "%s", k[i].name);
            for (char *q = names[nflags]; *q && !snake; ++q)
                if (*q == '_')
                    *q = '-';
            if (snake && strcmp(names[nflags], names[nflags - 1]) == 0)
                continue; /* no '_' in the name: one spelling */
            flags[nflags] = (lpv_flag){names[nflags], 0, "VALUE", k[i].help};
            knob_of[nflags++] = &k[i];
        }

    lpvc_config cfg = {0};
    float bounds[6];
    const char *json = NULL;
    lpvc_setting set[MAX_ARGS];
    size_t nset = 0;
    lpv_flags p;
    int idx, r;
    const char *v;
    if (args_begin(&p, argc, argv, flags, nflags) != 0)
        return 2;
    while ((r = args_next(&p, flags, &idx, &v)) > 0) {
        long n;
        switch (idx) {
        case -1: return usage_error("unexpected argument '%s' (lpvctl knobs lists the daemon's knobs)", v);
        case CFG_JSON: json = v; break;
        case CFG_PRESET: cfg.preset = v; break;
        case CFG_TECHNIQUE: cfg.technique = v; break;
        case CFG_GRID:
            if (sscanf(v, "%dx%dx%d", &cfg.grid[0], &cfg.grid[1], &cfg.grid[2]) == 3)
                break;
            if (parse_int(v, 1, 100000, &n) != 0)
                return usage_error("bad --grid '%s' (N or NxMxK)", v);
            cfg.grid[0] = cfg.grid[1] = cfg.grid[2] = (int)n;
            break;
        case CFG_BOUNDS:
            if (parse_floats(v, bounds, 6) != 0)
                return usage_error("bad --bounds '%s' (x0,y0,z0,x1,y1,z1)", v);
            cfg.bounds = bounds;
            break;
        case CFG_TICK_RATE:
            if (parse_float(v, &cfg.tick_rate_hz) != 0)
                return usage_error("bad --tick-rate '%s'", v);
            break;
        default: { /* a knob of the daemon's description */
            char err[256];
            if (nset >= MAX_ARGS)
                return usage_error("too many knobs%s", NULL);
            set[nset].name = knob_of[idx]->name;
            if (lpvc_knob_parse(knob_of[idx], v, &set[nset].value, err, sizeof err) != 0)
                return usage_error("bad %s", err);
            nset++;
        }
        }
    }
    if (r < 0)
        return 2;
    cfg.settings = set;
    cfg.setting_count = nset;
    int rc = json ? lpvc_config_json(g_c, json) : lpvc_config_set(g_c, &cfg);
    if (rc != 0)
        return server_error();
    print_reply();
    return 0;
}

int cmd_ack(int argc, char **argv)
{
    long t;
    if (argc != 2 || parse_int(argv[1], 0, 0x7fffffffL, &t) != 0)
        return usage_error("expected TICK%s", NULL);
    if (lpvc_ack(g_c, t) != 0)
        return server_error();
    printf("ack: sent (ACK has no reply)\n");
    return 0;
}

int cmd_bye(int argc, char **argv)
{
    (void)argv;
    if (no_args(argc))
        return 2;
    if (lpvc_bye(g_c) != 0)
        return server_error();
    print_reply();
    return 0;
}
