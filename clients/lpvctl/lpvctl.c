/*
 * lpvctl.c - command-line client of the lpvd daemon, one command per
 * protocol message (protocol/SPEC.md section 4), on the lpvc library.
 *
 *   lpvctl [--address A] [--token-file F] [--timeout MS] COMMAND [ARGS] [+ COMMAND [ARGS]]...
 *
 * One lpvctl run is one connection, i.e. one session (R7.1): a session's
 * scene, lights, camera and ticks live as long as the connection, so chain
 * the commands that belong together with '+', or feed them to 'lpvctl shell'
 * one per line.
 */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <jansson.h>

#include "lpvc.h"
#include "points_csv.h"

#define MAX_ARGS 64

static const char *g_usage =
    "usage: lpvctl [--address A] [--token-file F] [--timeout MS] COMMAND [ARGS] [+ COMMAND [ARGS]]...\n"
    "\n"
    "One run is one connection = one session: chain commands with '+' (or use\n"
    "'lpvctl shell', one command per line on stdin). Default address: the daemon's\n"
    "default socket ($XDG_RUNTIME_DIR/lpvd.sock, else /tmp/lpvd-$UID.sock);\n"
    "A may be a socket path, unix:PATH, HOST:PORT or tcp:HOST:PORT ($LPVD_ADDRESS\n"
    "overrides the default).\n"
    "\n"
    "commands:\n"
    "  hello                                   print the HELLO reply\n"
    "  load PATH | load --glb FILE             SCENE_LOAD by path (under --scene-root) or .glb bytes\n"
    "  update JSON | update --file F           SCENE_UPDATE with a JSON object\n"
    "  light-set ID [--type point|spot|directional] --intensity I [--color R,G,B]\n"
    "            [--position X,Y,Z] [--direction X,Y,Z] [--range R] [--inner-cone RAD] [--outer-cone RAD]\n"
    "  light-remove ID\n"
    "  camera --eye X,Y,Z --target X,Y,Z [--up X,Y,Z] [--fov DEG] [--size WxH] | camera --scene NAME|INDEX\n"
    "  config [--technique NAME] [--preset NAME] [--grid N|NxMxK] [--bounds x0,y0,z0,x1,y1,z1] [--tick-rate HZ]\n"
    "         [--KNOB VALUE]...     every knob the daemon describes in HELLO (SPEC R4.12), e.g.\n"
    "                               --damping 0.5 --normal-bins off; values are checked against its ranges\n"
    "         | config --json JSON   (the other flags override the preset's values)\n"
    "  knobs                                   the daemon's knobs: name, type, range, default, unit, help;\n"
    "                                          and its presets\n"
    "  tick [N] [--stats]                      N ticks (default 1); --stats: the whole reply\n"
    "  subscribe [volume|frame] [--format F] [--compression zstd|none] [--delta] [-n COUNT]\n"
    "            [--tick] [--wait MS] [-o PREFIX]  print stream headers; save COUNT messages as\n"
    "                                          PREFIX-TICK.bin/.json (volumes) or PREFIX-TICK.<format>;\n"
    "                                          --tick sends a TICK before each wait\n"
    "  unsubscribe [volume|frame]\n"
    "  volume [-o FILE.bin|FILE.json] [--format fp16|fp32] [--compression zstd|none]\n"
    "                                          .bin: raw float32 (all cascades' cells x 12, finest first)\n"
    "                                          + FILE.bin.json sidecar (with each cascade's placement);\n"
    "                                          .json: a summary; no -o: summary on stdout\n"
    "  frame -o OUT.png|OUT.exr|OUT.rgba [--terms full|indirect|direct|ao] [--compression zstd|none]\n"
    "        [--exposure auto|EV] [--transparent]\n"
    "  query --csv IN.csv -o OUT.csv           CSV px,py,pz,nx,ny,nz -> E_r,E_g,E_b (W/m^2)\n"
    "  query --point X,Y,Z --normal X,Y,Z      one point, printed\n"
    "  stats [--watch SECONDS] [--count N]     the reply, then the cascades and the last tick's plan\n"
    "                                          (each pass run or skipped, with its reason)\n"
    "  ack TICK                                ACK a volume tick (no reply)\n"
    "  bye\n"
    "  shell                                   read commands from stdin, one per line\n";

static lpvc *g_c;
static const char *g_cmd = "lpvctl";

static int usage_error(const char *fmt, const char *arg)
{
    fprintf(stderr, "lpvctl: %s: ", g_cmd);
    fprintf(stderr, fmt, arg ? arg : "");
    fprintf(stderr, "\n(lpvctl --help for usage)\n");
    return 2;
}

static int server_error(void)
{
    fprintf(stderr, "lpvctl: %s: %s (%d): %s\n", g_cmd, lpvc_error_name(g_c), lpvc_error_code(g_c),
            lpvc_error_message(g_c));
    return 1;
}

static void print_reply(void)
{
    printf("%s: %s\n", g_cmd, lpvc_last_reply(g_c));
    fflush(stdout);
}

static void print_json_line(const char *prefix, json_t *o)
{
    char *s = json_dumps(o, JSON_COMPACT);
    printf("%s: %s\n", prefix, s ? s : "{}");
    fflush(stdout);
    free(s);
}

/* ---- argument helpers -------------------------------------------------------- */

static int parse_floats(const char *s, float *out, int n)
{
    const char *p = s;
    for (int i = 0; i < n; i++) {
        char *end;
        errno = 0;
        double v = strtod(p, &end);
        if (end == p || errno != 0 || !isfinite(v))
            return -1;
        out[i] = (float)v;
        p = end;
        if (i + 1 < n) {
            if (*p != ',')
                return -1;
            p++;
        }
    }
    return *p == '\0' ? 0 : -1;
}

static int parse_int(const char *s, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (end == s || *end != '\0' || errno != 0 || v < lo || v > hi)
        return -1;
    *out = v;
    return 0;
}

static int parse_float(const char *s, float *out)
{
    return parse_floats(s, out, 1);
}

static const char *ext_of(const char *path)
{
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    return dot && (!slash || dot > slash) ? dot + 1 : "";
}

static unsigned char *read_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    size_t cap = 1 << 16, n = 0;
    unsigned char *buf = malloc(cap);
    while (buf) {
        size_t k = fread(buf + n, 1, cap - n, f);
        n += k;
        if (n < cap)
            break;
        unsigned char *b2 = realloc(buf, cap * 2);
        if (!b2) {
            free(buf);
            buf = NULL;
            break;
        }
        buf = b2;
        cap *= 2;
    }
    int bad = ferror(f);
    fclose(f);
    if (bad) {
        free(buf);
        return NULL;
    }
    *len = n;
    return buf;
}

static int write_file(const char *path, const void *data, size_t len)
{
    FILE *f = fopen(path, "wb");
    if (!f) {
        fprintf(stderr, "lpvctl: %s: cannot write %s: %s\n", g_cmd, path, strerror(errno));
        return -1;
    }
    size_t k = len ? fwrite(data, 1, len, f) : 0;
    if (fclose(f) != 0 || k != len) {
        fprintf(stderr, "lpvctl: %s: cannot write %s\n", g_cmd, path);
        return -1;
    }
    return 0;
}

/* ---- commands ------------------------------------------------------------------ */

static int cmd_hello(int argc, char **argv)
{
    (void)argv;
    if (argc != 1)
        return usage_error("takes no arguments%s", NULL);
    printf("hello: %s\n", lpvc_hello_reply(g_c));
    return 0;
}

static int cmd_load(int argc, char **argv)
{
    if (argc == 3 && strcmp(argv[1], "--glb") == 0) {
        size_t len = 0;
        unsigned char *glb = read_file(argv[2], &len);
        if (!glb) {
            fprintf(stderr, "lpvctl: load: cannot read %s: %s\n", argv[2], strerror(errno));
            return 1;
        }
        int rc = lpvc_scene_load_glb(g_c, glb, len);
        free(glb);
        if (rc != 0)
            return server_error();
    } else if (argc == 2 && argv[1][0] != '-') {
        if (lpvc_scene_load_file(g_c, argv[1]) != 0)
            return server_error();
    } else {
        return usage_error("expected PATH or --glb FILE%s", NULL);
    }
    print_reply();
    return 0;
}

static int cmd_update(int argc, char **argv)
{
    char *text = NULL;
    if (argc == 3 && strcmp(argv[1], "--file") == 0) {
        size_t len;
        unsigned char *b = read_file(argv[2], &len);
        if (!b) {
            fprintf(stderr, "lpvctl: update: cannot read %s: %s\n", argv[2], strerror(errno));
            return 1;
        }
        text = malloc(len + 1);
        if (text) {
            memcpy(text, b, len);
            text[len] = '\0';
        }
        free(b);
    } else if (argc == 2) {
        text = strdup(argv[1]);
    } else {
        return usage_error("expected a JSON object or --file F%s", NULL);
    }
    int rc = text ? lpvc_scene_update(g_c, text) : -1;
    free(text);
    if (rc != 0)
        return server_error();
    print_reply();
    return 0;
}

static int cmd_light_set(int argc, char **argv)
{
    lpvc_light l = {0};
    float color[3], pos[3], dir[3];
    int have_intensity = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (a[0] != '-' && !l.id) {
            l.id = a;
            continue;
        }
        if (strcmp(a, "--id") == 0 && v) {
            l.id = v;
        } else if (strcmp(a, "--type") == 0 && v) {
            l.type = v;
        } else if (strcmp(a, "--intensity") == 0 && v) {
            if (parse_float(v, &l.intensity) != 0)
                return usage_error("bad --intensity '%s'", v);
            have_intensity = 1;
        } else if (strcmp(a, "--color") == 0 && v) {
            if (parse_floats(v, color, 3) != 0)
                return usage_error("bad --color '%s' (expected R,G,B)", v);
            l.color = color;
        } else if (strcmp(a, "--position") == 0 && v) {
            if (parse_floats(v, pos, 3) != 0)
                return usage_error("bad --position '%s' (expected X,Y,Z)", v);
            l.position = pos;
        } else if (strcmp(a, "--direction") == 0 && v) {
            if (parse_floats(v, dir, 3) != 0)
                return usage_error("bad --direction '%s' (expected X,Y,Z)", v);
            l.direction = dir;
        } else if (strcmp(a, "--range") == 0 && v) {
            if (parse_float(v, &l.range) != 0)
                return usage_error("bad --range '%s'", v);
        } else if (strcmp(a, "--inner-cone") == 0 && v) {
            if (parse_float(v, &l.inner_cone) != 0)
                return usage_error("bad --inner-cone '%s'", v);
        } else if (strcmp(a, "--outer-cone") == 0 && v) {
            if (parse_float(v, &l.outer_cone) != 0)
                return usage_error("bad --outer-cone '%s'", v);
        } else {
            return usage_error("unknown or incomplete argument '%s'", a);
        }
        i++;
    }
    if (!l.id || !have_intensity)
        return usage_error("needs an ID and --intensity%s", NULL);
    if (lpvc_light_set(g_c, &l) != 0)
        return server_error();
    print_reply();
    return 0;
}

static int cmd_light_remove(int argc, char **argv)
{
    if (argc != 2)
        return usage_error("expected ID%s", NULL);
    if (lpvc_light_remove(g_c, argv[1]) != 0)
        return server_error();
    print_reply();
    return 0;
}

static int cmd_camera(int argc, char **argv)
{
    lpvc_camera cam = {0};
    float eye[3], target[3], up[3];
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v)
            return usage_error("'%s' needs a value", a);
        if (strcmp(a, "--eye") == 0) {
            if (parse_floats(v, eye, 3) != 0)
                return usage_error("bad --eye '%s'", v);
            cam.eye = eye;
        } else if (strcmp(a, "--target") == 0) {
            if (parse_floats(v, target, 3) != 0)
                return usage_error("bad --target '%s'", v);
            cam.target = target;
        } else if (strcmp(a, "--up") == 0) {
            if (parse_floats(v, up, 3) != 0)
                return usage_error("bad --up '%s'", v);
            cam.up = up;
        } else if (strcmp(a, "--fov") == 0) {
            if (parse_float(v, &cam.fov_deg) != 0)
                return usage_error("bad --fov '%s'", v);
        } else if (strcmp(a, "--size") == 0) {
            if (sscanf(v, "%dx%d", &cam.width, &cam.height) != 2 || cam.width <= 0 || cam.height <= 0)
                return usage_error("bad --size '%s' (expected WxH)", v);
        } else if (strcmp(a, "--scene") == 0) {
            long idx;
            if (parse_int(v, 0, 1000000, &idx) == 0)
                cam.scene_camera = (int)idx + 1;
            else
                cam.scene_camera_name = v;
        } else {
            return usage_error("unknown argument '%s'", a);
        }
        i++;
    }
    if (!cam.scene_camera && !cam.scene_camera_name && (!cam.eye || !cam.target))
        return usage_error("needs --eye and --target, or --scene NAME|INDEX%s", NULL);
    if (lpvc_camera_set(g_c, &cam) != 0)
        return server_error();
    print_reply();
    return 0;
}

/* A flag naming a knob of the daemon's description: "--normal-bins" or
 * "--normal_bins" for the knob "normal_bins". NULL if it names none. */
static const lpvc_knob *knob_of_flag(const char *flag)
{
    char key[96];
    if (strncmp(flag, "--", 2) != 0 || strlen(flag + 2) >= sizeof key)
        return NULL;
    snprintf(key, sizeof key, "%s", flag + 2);
    for (char *p = key; *p; ++p)
        if (*p == '-')
            *p = '_';
    return lpvc_knob_find(g_c, key);
}

/* knobs: the daemon's description, one knob per line, then the presets. */
static int cmd_knobs(int argc, char **argv)
{
    (void)argv;
    if (argc != 1)
        return usage_error("takes no arguments%s", NULL);
    const lpvc_knob *k = NULL;
    size_t n = lpvc_knobs(g_c, &k);
    for (size_t i = 0; i < n; ++i) {
        char want[96], flag[96];
        snprintf(flag, sizeof flag, "%s", k[i].name);
        for (char *p = flag; *p; ++p)
            if (*p == '_')
                *p = '-';
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

static int cmd_config(int argc, char **argv)
{
    lpvc_config cfg = {0};
    float bounds[6];
    const char *json = NULL;
    lpvc_setting set[MAX_ARGS];
    size_t nset = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        long n;
        const lpvc_knob *k;
        if (!v)
            return usage_error("'%s' needs a value", a);
        if (strcmp(a, "--json") == 0) {
            json = v;
        } else if (strcmp(a, "--preset") == 0) {
            cfg.preset = v; /* the server checks the name (BAD_FIELD lists the allowed ones) */
        } else if (strcmp(a, "--technique") == 0) {
            cfg.technique = v; /* one of HELLO's techniques; the server checks it */
        } else if (strcmp(a, "--grid") == 0) {
            if (sscanf(v, "%dx%dx%d", &cfg.grid[0], &cfg.grid[1], &cfg.grid[2]) == 3) {
            } else if (parse_int(v, 1, 100000, &n) == 0) {
                cfg.grid[0] = cfg.grid[1] = cfg.grid[2] = (int)n;
            } else {
                return usage_error("bad --grid '%s' (N or NxMxK)", v);
            }
        } else if (strcmp(a, "--bounds") == 0) {
            if (parse_floats(v, bounds, 6) != 0)
                return usage_error("bad --bounds '%s' (x0,y0,z0,x1,y1,z1)", v);
            cfg.bounds = bounds;
        } else if (strcmp(a, "--tick-rate") == 0) {
            if (parse_float(v, &cfg.tick_rate_hz) != 0)
                return usage_error("bad --tick-rate '%s'", v);
        } else if ((k = knob_of_flag(a)) != NULL) {
            char err[256];
            if (nset >= MAX_ARGS)
                return usage_error("too many knobs%s", NULL);
            set[nset].name = k->name;
            if (lpvc_knob_parse(k, v, &set[nset].value, err, sizeof err) != 0)
                return usage_error("bad %s", err);
            nset++;
        } else {
            return usage_error("unknown argument '%s' (lpvctl knobs lists the daemon's knobs)", a);
        }
        i++;
    }
    cfg.settings = set;
    cfg.setting_count = nset;
    int rc = json ? lpvc_config_json(g_c, json) : lpvc_config_set(g_c, &cfg);
    if (rc != 0)
        return server_error();
    print_reply();
    return 0;
}

/* TICK: a one-line summary (revision, tick, wall and GPU ms), or the whole
 * reply with its per-stage stats with --stats. */
static int cmd_tick(int argc, char **argv)
{
    long n = 1;
    int full = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--stats") == 0)
            full = 1;
        else if (parse_int(argv[i], 1, 1000000, &n) != 0)
            return usage_error("expected [N] [--stats], not '%s'", argv[i]);
    }
    for (long i = 0; i < n; i++) {
        if (lpvc_tick(g_c, NULL) != 0)
            return server_error();
        if (full) {
            print_reply();
            continue;
        }
        json_t *r = json_loads(lpvc_last_reply(g_c), 0, NULL);
        json_t *st = json_object_get(r, "stats");
        json_t *o = json_object();
        json_object_set(o, "revision", json_object_get(r, "revision"));
        json_object_set(o, "tick", json_object_get(r, "tick"));
        if (json_object_get(st, "tick_ms"))
            json_object_set(o, "tick_ms", json_object_get(st, "tick_ms"));
        if (json_object_get(st, "total_gpu_ms"))
            json_object_set(o, "total_gpu_ms", json_object_get(st, "total_gpu_ms"));
        print_json_line("tick", o);
        json_decref(o);
        json_decref(r);
    }
    return 0;
}

static int stream_of(const char *s, enum lpvc_stream *out)
{
    if (strcmp(s, "volume") == 0)
        *out = LPVC_STREAM_VOLUME;
    else if (strcmp(s, "frame") == 0)
        *out = LPVC_STREAM_FRAME;
    else
        return -1;
    return 0;
}

/* The cells of all cascades (a volume from an older lpvc: cells). */
static size_t volume_cells(const lpvc_volume *v)
{
    return v->cascade_count > 0 ? v->total_cells : v->cells;
}

/* Floats of data: as the volume's description says (SPEC R5.11); 12 a cell
 * for a volume without one. */
static size_t volume_floats(const lpvc_volume *v)
{
    if (v->values_per_cell <= 0)
        return volume_cells(v) * 12;
    return volume_cells(v) * (size_t)v->values_per_cell * (size_t)(v->volumes_per_level > 0 ? v->volumes_per_level : 1);
}

/* Summary of a decoded volume as a JSON object (new reference): dims,
 * origin and cell_size of cascade 0, "cells" of all cascades (what save
 * writes), "cascades" each with its placement and flux; total_flux_W is
 * cascade 0's (the cascades overlap). */
static json_t *volume_summary(const lpvc_volume *v)
{
    const double k = sqrt(4.0 * M_PI);
    double flux[LPVC_MAX_CASCADES][3] = {{0}}, maxc0 = 0.0;
    size_t nonfinite = 0, negative_c0 = 0, total = volume_cells(v), first = 0;
    int kc = 0;
    char why[256];
    if (lpvc_volume_lookup_check(v, why, sizeof why) != 0)
        total = 0; /* fluxes are SH c0 sums: not for a layout of other values */
    for (size_t i = 0; i < total; i++) {
        const float *c = v->data + 12 * i;
        while (kc + 1 < v->cascade_count && i >= first + v->cascades[kc].cells)
            first += v->cascades[kc++].cells;
        for (int j = 0; j < 12; j++)
            if (!isfinite(c[j]))
                nonfinite++;
        for (int ch = 0; ch < 3; ch++) {
            flux[kc][ch] += c[4 * ch] * k;
            if (c[4 * ch] < 0.0f)
                negative_c0++;
            if (c[4 * ch] > maxc0)
                maxc0 = c[4 * ch];
        }
    }
    json_t *cascades = json_array();
    for (int i = 0; i < v->cascade_count && i < LPVC_MAX_CASCADES; i++) {
        const lpvc_cascade *cs = &v->cascades[i];
        json_array_append_new(cascades, json_pack("{s:[i,i,i], s:[f,f,f], s:f, s:I, s:[f,f,f]}", "dims", cs->dims[0],
                                                  cs->dims[1], cs->dims[2], "origin", (double)cs->origin[0],
                                                  (double)cs->origin[1], (double)cs->origin[2], "cell_size",
                                                  (double)cs->cell_size, "cells", (json_int_t)cs->cells,
                                                  "flux_W", flux[i][0], flux[i][1], flux[i][2]));
    }
    json_t *hdr = json_loads(v->header_json ? v->header_json : "{}", 0, NULL);
    json_t *o = json_pack("{s:I, s:I, s:[i,i,i], s:[f,f,f], s:f, s:I, s:s, s:s, s:b, s:[f,f,f], s:f, s:I, s:I, s:o}",
                          "revision", (json_int_t)v->revision, "tick", (json_int_t)v->tick, "dims", v->dims[0],
                          v->dims[1], v->dims[2], "origin", (double)v->origin[0], (double)v->origin[1],
                          (double)v->origin[2], "cell_size", (double)v->cell_size, "cells", (json_int_t)total,
                          "format", v->format, "compression", v->compression, "keyframe", (int)v->keyframe,
                          "total_flux_W", flux[0][0], flux[0][1], flux[0][2], "max_c0_W_per_sr", maxc0, "non_finite",
                          (json_int_t)nonfinite, "negative_c0", (json_int_t)negative_c0, "header",
                          hdr ? hdr : json_object());
    json_object_set_new(o, "cascades", cascades);
    if (v->plan_json)
        json_object_set_new(o, "plan", json_loads(v->plan_json, 0, NULL));
    return o;
}

/* A tick plan (SPEC section 8) as lines "plan: ...", one per pass. */
static void print_plan(const json_t *plan)
{
    if (!json_is_object(plan)) {
        printf("plan: none\n");
        return;
    }
    printf("plan: cascades %lld (%s)\n", (long long)json_integer_value(json_object_get(plan, "cascades")),
           json_string_value(json_object_get(plan, "cascades_reason")) ? json_string_value(json_object_get(plan, "cascades_reason")) : "");
    const char *iters = json_string_value(json_object_get(plan, "iterations_reason"));
    if (iters && iters[0])
        printf("plan: iterations%s %s\n", json_is_true(json_object_get(plan, "iterations_warning")) ? " WARNING" : "",
               iters);
    printf("plan: recompute %s (%s)\n", json_is_true(json_object_get(plan, "recompute")) ? "yes" : "no",
           json_string_value(json_object_get(plan, "recompute_reason")) ? json_string_value(json_object_get(plan, "recompute_reason")) : "");
    size_t i;
    json_t *p;
    json_array_foreach(json_object_get(plan, "passes"), i, p) {
        const char *name = json_string_value(json_object_get(p, "name"));
        const char *why = json_string_value(json_object_get(p, "reason"));
        printf("plan:   %-10s %-4s %s\n", name ? name : "?", json_is_true(json_object_get(p, "run")) ? "run" : "skip",
               why ? why : "");
    }
}

/* The cascades of the stats' "cascades" as lines "cascade K: ...". */
static void print_cascades(const json_t *cascades)
{
    size_t i;
    json_t *c;
    json_array_foreach(cascades, i, c) {
        json_t *d = json_object_get(c, "dims"), *o = json_object_get(c, "origin_m");
        printf("cascade %zu: %lldx%lldx%lld cells of %g m, origin %g,%g,%g\n", i,
               (long long)json_integer_value(json_array_get(d, 0)), (long long)json_integer_value(json_array_get(d, 1)),
               (long long)json_integer_value(json_array_get(d, 2)), json_number_value(json_object_get(c, "cell_size_m")),
               json_number_value(json_array_get(o, 0)), json_number_value(json_array_get(o, 1)),
               json_number_value(json_array_get(o, 2)));
    }
}

/* FILE.bin: raw float32 little-endian (cells x 12) + FILE.bin.json sidecar. */
static int save_volume(const lpvc_volume *v, const char *path)
{
    const char *ext = ext_of(path);
    json_t *sum = volume_summary(v);
    int rc = 0;
    if (strcmp(ext, "json") == 0) {
        rc = json_dump_file(sum, path, JSON_INDENT(2)) == 0 ? 0 : -1;
        if (rc)
            fprintf(stderr, "lpvctl: %s: cannot write %s\n", g_cmd, path);
    } else {
        rc = write_file(path, v->data, volume_floats(v) * sizeof(float));
        if (rc == 0) {
            char side[4096];
            snprintf(side, sizeof side, "%s.json", path);
            json_object_set_new(sum, "data", json_pack("{s:s, s:s, s:s, s:s}", "file", path, "dtype", "float32 little-endian",
                                                      "shape", "per cascade in order: [dims[2]][dims[1]][dims[0]][12]", "units", "W/sr"));
            rc = json_dump_file(sum, side, JSON_INDENT(2)) == 0 ? 0 : -1;
            if (rc)
                fprintf(stderr, "lpvctl: %s: cannot write %s\n", g_cmd, side);
        }
    }
    json_decref(sum);
    return rc;
}

static int cmd_volume(int argc, char **argv)
{
    lpvc_volume_desc d = {0};
    const char *out = NULL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v)
            return usage_error("'%s' needs a value", a);
        if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0)
            out = v;
        else if (strcmp(a, "--format") == 0)
            d.format = v;
        else if (strcmp(a, "--compression") == 0)
            d.compression = v;
        else
            return usage_error("unknown argument '%s'", a);
        i++;
    }
    lpvc_volume vol;
    if (lpvc_get_volume(g_c, &d, &vol) != 0)
        return server_error();
    int rc = 0;
    if (out) {
        rc = save_volume(&vol, out) == 0 ? 0 : 1;
        if (rc == 0)
            printf("volume: tick %lld, %dx%dx%d cells of %g m, wrote %s\n", (long long)vol.tick, vol.dims[0],
                   vol.dims[1], vol.dims[2], (double)vol.cell_size, out);
    } else {
        json_t *s = volume_summary(&vol);
        json_object_del(s, "header");
        print_json_line("volume", s);
        json_decref(s);
    }
    lpvc_volume_free(&vol);
    return rc;
}

static const char *frame_format_for(const char *path)
{
    const char *ext = ext_of(path);
    if (strcmp(ext, "png") == 0)
        return "png";
    if (strcmp(ext, "exr") == 0)
        return "exr";
    if (strcmp(ext, "rgba") == 0 || strcmp(ext, "raw") == 0)
        return "rgba8";
    return NULL;
}

static int cmd_frame(int argc, char **argv)
{
    lpvc_frame_desc d = {0};
    const char *out = NULL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--transparent") == 0) {
            d.transparent = true;
            continue;
        }
        if (!v)
            return usage_error("'%s' needs a value", a);
        if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0)
            out = v;
        else if (strcmp(a, "--terms") == 0)
            d.terms = v;
        else if (strcmp(a, "--exposure") == 0)
            d.exposure = v;
        else if (strcmp(a, "--compression") == 0)
            d.compression = v;
        else
            return usage_error("unknown argument '%s'", a);
        i++;
    }
    if (!out)
        return usage_error("needs -o OUT.png|OUT.exr|OUT.rgba%s", NULL);
    d.format = frame_format_for(out);
    if (!d.format)
        return usage_error("cannot tell the format of '%s' (.png, .exr or .rgba)", out);
    if (strcmp(d.format, "rgba8") != 0)
        d.compression = NULL; /* R6.2: png and exr are never compressed further */
    lpvc_frame f;
    if (lpvc_get_frame(g_c, &d, &f) != 0)
        return server_error();
    if (strcmp(f.format, d.format) != 0) {
        fprintf(stderr, "lpvctl: frame: asked for %s, the server sent '%s'\n", d.format, f.format);
        lpvc_frame_free(&f);
        return 1;
    }
    int rc = write_file(out, f.data, f.size) == 0 ? 0 : 1;
    if (rc == 0)
        printf("frame: tick %lld, %dx%d %s (%s), %zu bytes, wrote %s\n", (long long)f.tick, f.width, f.height,
               f.format, f.terms, f.size, out);
    lpvc_frame_free(&f);
    return rc;
}

static int cmd_query(int argc, char **argv)
{
    const char *in = NULL, *out = NULL;
    float point[3], normal[3];
    int have_p = 0, have_n = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v)
            return usage_error("'%s' needs a value", a);
        if (strcmp(a, "--csv") == 0) {
            in = v;
        } else if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
            out = v;
        } else if (strcmp(a, "--point") == 0) {
            if (parse_floats(v, point, 3) != 0)
                return usage_error("bad --point '%s'", v);
            have_p = 1;
        } else if (strcmp(a, "--normal") == 0) {
            if (parse_floats(v, normal, 3) != 0)
                return usage_error("bad --normal '%s'", v);
            have_n = 1;
        } else {
            return usage_error("unknown argument '%s'", a);
        }
        i++;
    }
    if (have_p || have_n) {
        if (!(have_p && have_n) || in)
            return usage_error("needs both --point and --normal (and no --csv)%s", NULL);
        float rgb[3];
        if (lpvc_query_irradiance(g_c, point, normal, 1, rgb) != 0)
            return server_error();
        printf("query: %s E = %.9g %.9g %.9g W/m^2\n", lpvc_last_reply(g_c), (double)rgb[0], (double)rgb[1],
               (double)rgb[2]);
        return 0;
    }
    if (!in)
        return usage_error("needs --csv IN.csv [-o OUT.csv] or --point/--normal%s", NULL);
    FILE *f = strcmp(in, "-") == 0 ? stdin : fopen(in, "r");
    if (!f) {
        fprintf(stderr, "lpvctl: query: cannot read %s: %s\n", in, strerror(errno));
        return 1;
    }
    float *pts = NULL, *nrm = NULL;
    char why[512];
    long got = lpv_points_csv_read(f, in, &pts, &nrm, why, sizeof why);
    size_t n = got > 0 ? (size_t)got : 0;
    int rc = got >= 0 ? 0 : got == LPV_POINTS_BAD_LINE ? 2 : 1;
    if (rc != 0)
        fprintf(stderr, "lpvctl: query: %s\n", why);
    if (f != stdin)
        fclose(f);
    float *rgb = rc == 0 && pts && nrm ? malloc((n ? n : 1) * 3 * sizeof(float)) : NULL;
    if (rc == 0 && !rgb)
        rc = 1;
    if (rc == 0 && lpvc_query_irradiance(g_c, pts, nrm, n, rgb) != 0)
        rc = server_error();
    if (rc == 0) {
        FILE *o = out && strcmp(out, "-") != 0 ? fopen(out, "w") : stdout;
        if (!o) {
            fprintf(stderr, "lpvctl: query: cannot write %s: %s\n", out, strerror(errno));
            rc = 1;
        } else {
            fprintf(o, "E_r,E_g,E_b\n");
            for (size_t i = 0; i < n; i++)
                fprintf(o, "%.9g,%.9g,%.9g\n", (double)rgb[3 * i], (double)rgb[3 * i + 1], (double)rgb[3 * i + 2]);
            if (o != stdout && fclose(o) != 0) {
                fprintf(stderr, "lpvctl: query: cannot write %s\n", out);
                rc = 1;
            }
            if (rc == 0 && o != stdout)
                printf("query: %s %zu points -> %s\n", lpvc_last_reply(g_c), n, out);
        }
    }
    free(pts);
    free(nrm);
    free(rgb);
    return rc;
}

static int cmd_stats(int argc, char **argv)
{
    float watch = 0.0f;
    long count = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v)
            return usage_error("'%s' needs a value", a);
        if (strcmp(a, "--watch") == 0) {
            if (parse_float(v, &watch) != 0 || watch <= 0.0f)
                return usage_error("bad --watch '%s' (seconds > 0)", v);
        } else if (strcmp(a, "--count") == 0) {
            if (parse_int(v, 1, 1L << 30, &count) != 0)
                return usage_error("bad --count '%s'", v);
        } else {
            return usage_error("unknown argument '%s'", a);
        }
        i++;
    }
    if (watch <= 0.0f)
        count = 1;
    for (long i = 0; count == 0 || i < count; i++) {
        if (i > 0) {
            struct timespec ts = {.tv_sec = (time_t)watch, .tv_nsec = (long)((watch - floorf(watch)) * 1e9f)};
            nanosleep(&ts, NULL);
        }
        char *js = NULL;
        if (lpvc_stats(g_c, &js) != 0)
            return server_error();
        printf("stats: %s\n", js);
        json_t *st = json_loads(js, 0, NULL);
        json_t *tp = json_object_get(st, "plan"); /* the world's last tick (SPEC section 8) */
        if (json_object_get(tp, "cascades"))
            print_cascades(json_object_get(tp, "cascades"));
        if (json_object_get(tp, "tick"))
            print_plan(json_object_get(tp, "plan"));
        json_decref(st);
        fflush(stdout);
        free(js);
    }
    return 0;
}

static int cmd_subscribe(int argc, char **argv)
{
    lpvc_subscribe_desc d = {0};
    long count = 1, wait_ms = -1;
    int tick = 0;
    const char *prefix = NULL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (a[0] != '-' && stream_of(a, &d.stream) == 0)
            continue;
        if (strcmp(a, "--delta") == 0) {
            d.delta = true;
            continue;
        }
        if (strcmp(a, "--tick") == 0) {
            tick = 1;
            continue;
        }
        if (!v)
            return usage_error("unknown or incomplete argument '%s'", a);
        if (strcmp(a, "--format") == 0)
            d.format = v;
        else if (strcmp(a, "--compression") == 0)
            d.compression = v;
        else if (strcmp(a, "-n") == 0 || strcmp(a, "--count") == 0) {
            if (parse_int(v, 1, 1L << 30, &count) != 0)
                return usage_error("bad count '%s'", v);
        } else if (strcmp(a, "--wait") == 0) {
            if (parse_int(v, 0, 1L << 30, &wait_ms) != 0)
                return usage_error("bad --wait '%s' (ms)", v);
        } else if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0)
            prefix = v;
        else
            return usage_error("unknown argument '%s'", a);
        i++;
    }
    if (lpvc_subscribe(g_c, &d) != 0)
        return server_error();
    print_reply();
    for (long i = 0; i < count; i++) {
        if (tick && lpvc_tick(g_c, NULL) != 0)
            return server_error();
        lpvc_message m;
        if (lpvc_next_stream_message(g_c, &m, (int)wait_ms) != 0)
            return server_error();
        if (m.type == LPVC_MSG_BYE) {
            printf("subscribe: the server said BYE\n");
            return 0;
        }
        char path[4096];
        int rc = 0;
        if (m.type == LPVC_MSG_VOLUME) {
            printf("VOLUME: %s\n", m.volume.header_json);
            if (prefix) {
                snprintf(path, sizeof path, "%s-%lld.bin", prefix, (long long)m.volume.tick);
                rc = save_volume(&m.volume, path);
            }
        } else {
            printf("FRAME: %s\n", m.frame.header_json);
            if (prefix) {
                snprintf(path, sizeof path, "%s-%lld.%s", prefix, (long long)m.frame.tick,
                         strcmp(m.frame.format, "rgba8") == 0 ? "rgba" : m.frame.format);
                rc = write_file(path, m.frame.data, m.frame.size);
            }
        }
        fflush(stdout);
        lpvc_message_free(&m);
        if (rc != 0)
            return 1;
    }
    return 0;
}

static int cmd_unsubscribe(int argc, char **argv)
{
    enum lpvc_stream s = LPVC_STREAM_VOLUME;
    if (argc > 2 || (argc == 2 && stream_of(argv[1], &s) != 0))
        return usage_error("expected volume or frame%s", NULL);
    if (lpvc_unsubscribe(g_c, s) != 0)
        return server_error();
    print_reply();
    return 0;
}

static int cmd_ack(int argc, char **argv)
{
    long t;
    if (argc != 2 || parse_int(argv[1], 0, 0x7fffffffL, &t) != 0)
        return usage_error("expected TICK%s", NULL);
    if (lpvc_ack(g_c, t) != 0)
        return server_error();
    printf("ack: sent (ACK has no reply)\n");
    return 0;
}

static int cmd_bye(int argc, char **argv)
{
    (void)argv;
    if (argc != 1)
        return usage_error("takes no arguments%s", NULL);
    if (lpvc_bye(g_c) != 0)
        return server_error();
    print_reply();
    return 0;
}

typedef int (*cmd_fn)(int, char **);
static const struct {
    const char *name;
    cmd_fn fn;
} g_cmds[] = {
    {"hello", cmd_hello},         {"load", cmd_load},         {"update", cmd_update},
    {"light-set", cmd_light_set}, {"light-remove", cmd_light_remove}, {"camera", cmd_camera},
    {"config", cmd_config},       {"knobs", cmd_knobs},       {"tick", cmd_tick},         {"subscribe", cmd_subscribe},
    {"unsubscribe", cmd_unsubscribe}, {"volume", cmd_volume}, {"frame", cmd_frame},
    {"query", cmd_query},         {"stats", cmd_stats},       {"ack", cmd_ack},
    {"bye", cmd_bye},
};

static int run_command(int argc, char **argv)
{
    for (size_t i = 0; i < sizeof g_cmds / sizeof g_cmds[0]; i++) {
        if (strcmp(argv[0], g_cmds[i].name) == 0) {
            g_cmd = g_cmds[i].name;
            return g_cmds[i].fn(argc, argv);
        }
    }
    g_cmd = "lpvctl";
    return usage_error("unknown command '%s'", argv[0]);
}

/* Splits a shell line into words: whitespace separates, '...' and "..."
 * quote (no escapes inside single quotes; \" and \\ inside double quotes). */
static int split_words(char *line, char **argv, int max)
{
    int argc = 0;
    char *r = line, *w = line;
    while (*r) {
        while (*r == ' ' || *r == '\t' || *r == '\n' || *r == '\r')
            r++;
        if (!*r || *r == '#')
            break;
        if (argc == max)
            return -1;
        argv[argc++] = w;
        while (*r && *r != ' ' && *r != '\t' && *r != '\n' && *r != '\r') {
            if (*r == '\'') {
                r++;
                while (*r && *r != '\'')
                    *w++ = *r++;
                if (*r)
                    r++;
            } else if (*r == '"') {
                r++;
                while (*r && *r != '"') {
                    if (*r == '\\' && (r[1] == '"' || r[1] == '\\'))
                        r++;
                    *w++ = *r++;
                }
                if (*r)
                    r++;
            } else {
                *w++ = *r++;
            }
        }
        if (*r)
            r++;
        *w++ = '\0';
    }
    return argc;
}

static int run_shell(void)
{
    char line[8192];
    int rc = 0;
    while (fgets(line, sizeof line, stdin)) {
        char *argv[MAX_ARGS];
        int argc = split_words(line, argv, MAX_ARGS);
        if (argc < 0) {
            fprintf(stderr, "lpvctl: shell: too many words\n");
            rc = 2;
            continue;
        }
        if (argc == 0)
            continue;
        if (strcmp(argv[0], "quit") == 0 || strcmp(argv[0], "exit") == 0)
            break;
        rc = run_command(argc, argv);
        if (strcmp(argv[0], "bye") == 0 && rc == 0)
            break;
        if (lpvc_error_code(g_c) == LPVC_ERR_IO || lpvc_error_code(g_c) == LPVC_ERR_CLOSED ||
            lpvc_error_code(g_c) == LPVC_ERR_PROTOCOL) {
            break; /* the connection is gone */
        }
    }
    return rc;
}

int main(int argc, char **argv)
{
    const char *address = getenv("LPVD_ADDRESS");
    const char *token_file = NULL;
    long timeout_ms = 0;
    int i = 1;
    for (; i < argc && argv[i][0] == '-'; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(g_usage, stdout);
            return 0;
        }
        if (i + 1 >= argc) {
            fprintf(stderr, "lpvctl: '%s' needs a value\n%s", a, g_usage);
            return 2;
        }
        if (strcmp(a, "--address") == 0 || strcmp(a, "-a") == 0)
            address = argv[++i];
        else if (strcmp(a, "--token-file") == 0)
            token_file = argv[++i];
        else if (strcmp(a, "--timeout") == 0) {
            if (parse_int(argv[++i], 0, 1L << 30, &timeout_ms) != 0) {
                fprintf(stderr, "lpvctl: bad --timeout '%s' (ms)\n", argv[i]);
                return 2;
            }
        } else {
            fprintf(stderr, "lpvctl: unknown option '%s'\n%s", a, g_usage);
            return 2;
        }
    }
    if (i >= argc) {
        fputs(g_usage, stderr);
        return 2;
    }

    char token[1024];
    const char *tok = NULL;
    if (token_file) {
        FILE *f = fopen(token_file, "r");
        if (!f || !fgets(token, sizeof token, f)) {
            fprintf(stderr, "lpvctl: cannot read the token from %s: %s\n", token_file, f ? "empty file" : strerror(errno));
            if (f)
                fclose(f);
            return 2;
        }
        fclose(f);
        token[strcspn(token, "\r\n")] = '\0';
        tok = token;
    }

    char err[512];
    lpvc_connect_desc cd = {.address = address, .token = tok, .client_name = "lpvctl", .timeout_ms = (int)timeout_ms};
    g_c = lpvc_connect_with(&cd, err, sizeof err);
    if (!g_c) {
        fprintf(stderr, "lpvctl: %s\n", err);
        return 1;
    }

    int rc = 0;
    if (strcmp(argv[i], "shell") == 0 && i + 1 == argc) {
        rc = run_shell();
    } else {
        /* Commands separated by a lone '+', run in order in this session. */
        while (i < argc && rc == 0) {
            int j = i;
            while (j < argc && strcmp(argv[j], "+") != 0)
                j++;
            if (j > i)
                rc = run_command(j - i, argv + i);
            i = j + 1;
        }
    }
    lpvc_close(g_c);
    return rc;
}
