/*
 * lpvctl_results.c - the commands that read results: tick, volume, frame,
 * query and stats, and how a volume is summarised and saved.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "lpvctl.h"
#include "points_csv.h"

enum { TICK_STATS, TICK_COUNT };
static const lpv_flag TICK_FLAGS[TICK_COUNT] = {[TICK_STATS] = {"stats", 0, NULL, "the whole reply"}};

/* TICK: a one-line summary (revision, tick, wall and GPU ms), or the whole
 * reply with its per-stage stats with --stats. */
int cmd_tick(int argc, char **argv)
{
    long n = 1;
    int full = 0, counted = 0;
    lpv_flags p;
    int idx, r;
    const char *v;
    if (args_begin(&p, argc, argv, TICK_FLAGS, TICK_COUNT) != 0)
        return 2;
    while ((r = args_next(&p, TICK_FLAGS, &idx, &v)) > 0) {
        if (idx == TICK_STATS)
            full = 1;
        else if (counted++ || parse_int(v, 1, 1000000, &n) != 0)
            return usage_error("expected [N] [--stats], not '%s'", v);
    }
    if (r < 0)
        return 2;
    for (long i = 0; i < n; i++) {
        if (lpvc_tick(g_c, NULL) != 0)
            return server_error();
        if (full) {
            print_reply();
            continue;
        }
        json_t *rep = json_loads(lpvc_last_reply(g_c), 0, NULL);
        json_t *st = json_object_get(rep, "stats");
        json_t *o = json_object();
        json_object_set(o, "revision", json_object_get(rep, "revision"));
        json_object_set(o, "tick", json_object_get(rep, "tick"));
        if (json_object_get(st, "tick_ms"))
            json_object_set(o, "tick_ms", json_object_get(st, "tick_ms"));
        if (json_object_get(st, "total_gpu_ms"))
            json_object_set(o, "total_gpu_ms", json_object_get(st, "total_gpu_ms"));
        print_json_line("tick", o);
        json_decref(o);
        json_decref(rep);
    }
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
    json_object_set_new(o, "content", json_string(v->content[0] ? v->content : "merged"));
    if (v->error_bound > 0.0) /* SPEC R5.16: every cell within this fraction of its magnitude */
        json_object_set_new(o, "error_bound", json_real(v->error_bound));
    if (v->visibility && v->values_per_probe > 0) { /* SPEC R5.15: how many probes are on, how far they moved */
        size_t probes = v->visibility_floats / (size_t)v->values_per_probe, active = 0;
        double moved = 0.0;
        for (size_t i = 0; i < probes; i++) {
            const float *r = v->visibility + i * (size_t)v->values_per_probe;
            active += r[3] != 0.0f;
            moved = fmax(moved, sqrt((double)r[0] * r[0] + (double)r[1] * r[1] + (double)r[2] * r[2]));
        }
        json_object_set_new(o, "visibility",
                            json_pack("{s:I, s:I, s:i, s:i, s:f}", "probes", (json_int_t)probes, "active",
                                      (json_int_t)active, "irradiance_side", v->irradiance_side, "distance_side",
                                      v->distance_side, "max_offset_m", moved));
    }
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
int save_volume(const lpvc_volume *v, const char *path)
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

enum { VOL_OUTPUT, VOL_FORMAT, VOL_COMPRESSION, VOL_BOUND, VOL_CONTENT, VOL_COUNT };
static const lpv_flag VOLUME_FLAGS[VOL_COUNT] = {
    [VOL_OUTPUT] = {"output", 'o', "FILE.bin|FILE.json", ""},
    [VOL_FORMAT] = {"format", 0, "fp16|fp32", ""},
    [VOL_COMPRESSION] = {"compression", 0, "zstd|none|shq", ""},
    [VOL_BOUND] = {"error-bound", 0, "E", ""},
    [VOL_CONTENT] = {"content", 0, "merged|levels|visibility", ""},
};

int cmd_volume(int argc, char **argv)
{
    lpvc_volume_desc d = {0};
    const char *out = NULL;
    lpv_flags p;
    int idx, r;
    const char *v;
    if (args_begin(&p, argc, argv, VOLUME_FLAGS, VOL_COUNT) != 0)
        return 2;
    while ((r = args_next(&p, VOLUME_FLAGS, &idx, &v)) > 0) {
        switch (idx) {
        case -1: return usage_error("unexpected argument '%s'", v);
        case VOL_OUTPUT: out = v; break;
        case VOL_FORMAT: d.format = v; break;
        case VOL_COMPRESSION: d.compression = v; break;
        case VOL_BOUND:
            if (parse_error_bound(v, &d.error_bound) != 0)
                return 2;
            break;
        case VOL_CONTENT: d.content = v; break;
        }
    }
    if (r < 0)
        return 2;
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

enum { FR_OUTPUT, FR_TERMS, FR_COMPRESSION, FR_EXPOSURE, FR_TRANSPARENT, FR_COUNT };
static const lpv_flag FRAME_FLAGS[FR_COUNT] = {
    [FR_OUTPUT] = {"output", 'o', "OUT.png|OUT.exr|OUT.rgba", ""},
    [FR_TERMS] = {"terms", 0, "full|indirect|direct|ao", ""},
    [FR_COMPRESSION] = {"compression", 0, "zstd|none", ""},
    [FR_EXPOSURE] = {"exposure", 0, "auto|EV", ""},
    [FR_TRANSPARENT] = {"transparent", 0, NULL, ""},
};

int cmd_frame(int argc, char **argv)
{
    lpvc_frame_desc d = {0};
    const char *out = NULL;
    lpv_flags p;
    int idx, r;
    const char *v;
    if (args_begin(&p, argc, argv, FRAME_FLAGS, FR_COUNT) != 0)
        return 2;
    while ((r = args_next(&p, FRAME_FLAGS, &idx, &v)) > 0) {
        switch (idx) {
        case -1: return usage_error("unexpected argument '%s'", v);
        case FR_OUTPUT: out = v; break;
        case FR_TERMS: d.terms = v; break;
        case FR_COMPRESSION: d.compression = v; break;
        case FR_EXPOSURE: d.exposure = v; break;
        case FR_TRANSPARENT: d.transparent = true; break;
        }
    }
    if (r < 0)
        return 2;
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

enum { Q_CSV, Q_OUTPUT, Q_POINT, Q_NORMAL, Q_COUNT };
static const lpv_flag QUERY_FLAGS[Q_COUNT] = {
    [Q_CSV] = {"csv", 0, "IN.csv", ""},
    [Q_OUTPUT] = {"output", 'o', "OUT.csv", ""},
    [Q_POINT] = {"point", 0, "X,Y,Z", ""},
    [Q_NORMAL] = {"normal", 0, "X,Y,Z", ""},
};

int cmd_query(int argc, char **argv)
{
    const char *in = NULL, *out = NULL;
    float point[3], normal[3];
    int have_p = 0, have_n = 0;
    lpv_flags p;
    int idx, r;
    const char *v;
    if (args_begin(&p, argc, argv, QUERY_FLAGS, Q_COUNT) != 0)
        return 2;
    while ((r = args_next(&p, QUERY_FLAGS, &idx, &v)) > 0) {
        switch (idx) {
        case -1: return usage_error("unexpected argument '%s'", v);
        case Q_CSV: in = v; break;
        case Q_OUTPUT: out = v; break;
        case Q_POINT:
            if (parse_floats(v, point, 3) != 0)
                return usage_error("bad --point '%s'", v);
            have_p = 1;
            break;
        case Q_NORMAL:
            if (parse_floats(v, normal, 3) != 0)
                return usage_error("bad --normal '%s'", v);
            have_n = 1;
            break;
        }
    }
    if (r < 0)
        return 2;
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

enum { ST_WATCH, ST_COUNT_FLAG, ST_COUNT };
static const lpv_flag STATS_FLAGS[ST_COUNT] = {
    [ST_WATCH] = {"watch", 0, "SECONDS", ""},
    [ST_COUNT_FLAG] = {"count", 0, "N", ""},
};

int cmd_stats(int argc, char **argv)
{
    float watch = 0.0f;
    long count = 0;
    lpv_flags p;
    int idx, r;
    const char *v;
    if (args_begin(&p, argc, argv, STATS_FLAGS, ST_COUNT) != 0)
        return 2;
    while ((r = args_next(&p, STATS_FLAGS, &idx, &v)) > 0) {
        switch (idx) {
        case -1: return usage_error("unexpected argument '%s'", v);
        case ST_WATCH:
            if (parse_float(v, &watch) != 0 || watch <= 0.0f)
                return usage_error("bad --watch '%s' (seconds > 0)", v);
            break;
        case ST_COUNT_FLAG:
            if (parse_int(v, 1, 1L << 30, &count) != 0)
                return usage_error("bad --count '%s'", v);
            break;
        }
    }
    if (r < 0)
        return 2;
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
