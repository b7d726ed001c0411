/* settings_flags.c - see settings_flags.h. */
#include "settings_flags.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lpv_shared.h"
#include "settings_fields.h"

/* The flags with their own syntax; the knobs follow from the field table. */
static const lpv_flag OWN_SYNTAX[] = {
    {"technique", 0, "NAME",
     "GI technique: " LPV_TECHNIQUE_LPV " (cascaded LPV), " LPV_TECHNIQUE_OCTREE
     " (octree LPV: a cubic power-of-two\ngrid), " LPV_TECHNIQUE_IV " (imperfect volumes: the --iv-* knobs), "
     LPV_TECHNIQUE_PROBES " (ray-traced\nirradiance probes, a probe per grid cell: the --probes-* knobs) or " LPV_TECHNIQUE_AUTO
     " (the default: the\nplanner chooses from the scene and the preset, and says why)"},
    {"preset", 0, "NAME", "quality preset (default balanced; docs/accuracy.md):"},
    {"grid", 0, "N | NxMxK", "LPV cells per axis (default: the preset's)"},
    {"bounds", 0, "x0,y0,z0,x1,y1,z1", "grid bounds in m (default: the scene's bounds)"},
};
#define N_OWN (sizeof OWN_SYNTAX / sizeof OWN_SYNTAX[0])
#define MAX_KNOBS 128

const lpv_flag *lpv_settings_flags(size_t *count)
{
    /* Built on first use from the field table (CLI start-up, one thread). */
    static lpv_flag flags[N_OWN + MAX_KNOBS];
    static size_t n;
    if (!n) {
        size_t nf;
        const lpv_field *fields = lpv_fields(&nf);
        if (nf > MAX_KNOBS) {
            fprintf(stderr, "lpv_settings_flags: %zu knobs, room for %d\n", nf, MAX_KNOBS);
            abort();
        }
        memcpy(flags, OWN_SYNTAX, sizeof OWN_SYNTAX);
        for (size_t i = 0; i < nf; ++i)
            flags[N_OWN + i] = (lpv_flag){fields[i].flag, 0, lpv_field_metavar(&fields[i]), fields[i].help};
        n = N_OWN + nf;
    }
    if (count)
        *count = n;
    return flags;
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

int lpv_settings_flag_parse(lpv_settings *s, const char *name, const char *v, char *err, size_t n)
{
    if (!v)
        v = "";
    if (strcmp(name, "technique") == 0) {
        if (lpv_technique_from_name(v, &s->technique) != 0) {
            snprintf(err, n, "--technique %s: unknown technique (allowed: %s)", v, lpv_technique_names());
            return -1;
        }
    } else if (strcmp(name, "preset") == 0) {
        if (lpv_preset_from_name(v, &s->preset) != 0) {
            snprintf(err, n, "--preset %s: unknown preset (allowed: %s)", v, lpv_preset_names());
            return -1;
        }
    } else if (strcmp(name, "grid") == 0) {
        int d[3];
        if (parse_int(v, 1, LPV_MAX_GRID_DIM, &d[0]) == 0) {
            d[1] = d[2] = d[0];
        } else if (sscanf(v, "%dx%dx%d", &d[0], &d[1], &d[2]) != 3 || d[0] < 1 || d[1] < 1 || d[2] < 1 ||
                   d[0] > LPV_MAX_GRID_DIM || d[1] > LPV_MAX_GRID_DIM || d[2] > LPV_MAX_GRID_DIM) {
            snprintf(err, n, "--grid %s: expected N or NxMxK with 1..256 cells per axis", v);
            return -1;
        }
        memcpy(s->grid_dims, d, sizeof d);
    } else if (strcmp(name, "bounds") == 0) {
        float b[6];
        if (lpv_flag_parse_floats(v, b, 6) != 0 || !(b[3] > b[0] && b[4] > b[1] && b[5] > b[2])) {
            snprintf(err, n, "--bounds %s: expected x0,y0,z0,x1,y1,z1 with max > min", v);
            return -1;
        }
        memcpy(s->bounds_min, b, sizeof s->bounds_min);
        memcpy(s->bounds_max, b + 3, sizeof s->bounds_max);
    } else if (lpv_field_by_flag(name)) {
        char why[160];
        if (lpv_field_set_string(s, lpv_field_by_flag(name), v, why, sizeof why) != 0) {
            snprintf(err, n, "--%s %s: %s", name, v, why);
            return -1;
        }
    } else {
        return 0;
    }
    return 1;
}

static int parse_flag(void *target, const lpv_flag *f, const char *value, char *err, size_t n)
{
    return lpv_settings_flag_parse(target, f->name, value, err, n) == 1 ? 0 : -1;
}

lpv_flag_group lpv_settings_flag_group(lpv_settings *s)
{
    size_t n;
    const lpv_flag *flags = lpv_settings_flags(&n);
    return (lpv_flag_group){flags, n, parse_flag, s};
}

/* The allowed values in help's compact form: "0..4", "> 0, <= 1e+06", "on|off". */
static void help_range(const lpv_field *f, char *buf, size_t n)
{
    if (f->kind == LPV_FIELD_SWITCH)
        snprintf(buf, n, "on|off");
    else if (f->min_exclusive)
        snprintf(buf, n, "> %g, <= %g", f->min, f->max);
    else if (f->kind == LPV_FIELD_INT)
        snprintf(buf, n, "%.0f..%.0f", f->min, f->max);
    else
        snprintf(buf, n, "%g..%g", f->min, f->max);
}

const char *lpv_settings_flags_help(void)
{
    static char help[12288]; /* the knob table's lines: room to grow */
    if (help[0])
        return help;
    size_t len = 0, sz = sizeof help;
    lpv_flags_append(help, sz, &len, "Engine settings (--grid and the knobs below win over --preset, in any order):\n");
    lpv_flags_help(help, sz, &len, &OWN_SYNTAX[0], 2); /* technique, then preset and its table */
    for (int p = LPV_PRESET_DEFAULT + 1; p < LPV_PRESET_COUNT_; ++p) { /* from the preset table */
        lpv_settings s;
        lpv_preset_settings((lpv_preset)p, &s);
        char letters[5];
        lpv_flags_append(help, sz, &len, "%28s%-10sgrid %d, %d iterations (scaled with --grid), RSM %d, occlusion %s, departures %s\n", "",
                         lpv_preset_name((lpv_preset)p), s.grid_dims[0], s.lpv.iterations, s.rsm_size,
                         s.lpv.occlusion == LPV_SWITCH_ON ? "on" : "off", lpv_settings_departures(&s, letters));
    }
    lpv_flags_help(help, sz, &len, &OWN_SYNTAX[2], N_OWN - 2);
    lpv_flags_append(help, sz, &len,
                     "Knobs (docs/propagation.md, docs/shadows.md, docs/cascades.md, docs/effects.md,\n"
                     "docs/area-lights.md, docs/imperfect-volumes.md, techniques/probes/README.md):\n");
    size_t count;
    const lpv_field *fields = lpv_fields(&count);
    for (size_t i = 0; i < count; ++i) {
        const lpv_field *f = &fields[i];
        char left[64], range[64], dflt[32];
        snprintf(left, sizeof left, "%s %s", f->flag, lpv_field_metavar(f));
        lpv_field_default_words(f, dflt, sizeof dflt);
        help_range(f, range, sizeof range);
        /* a flag too long for its column puts the help on the next line */
        const char *gap = strlen(left) >= 22 ? "\n                          " : "";
        if (f->kind == LPV_FIELD_SWITCH) /* "  --glossy on|off   help\n   (default on)" */
            lpv_flags_append(help, sz, &len, "  --%-22s%s%s\n%26s(default %s)\n", left, gap, f->help, "", dflt);
        else /* "  --cascade-size X   help\n   (m; > 0, <= 1e+06; default 8)" */
            lpv_flags_append(help, sz, &len, "  --%-22s%s%s\n%26s(%s%s%s%s%s; default %s)\n", left, gap, f->help, "",
                             f->unit, f->unit[0] ? "; " : "", range, f->note[0] ? ", " : "", f->note, dflt);
    }
    return help;
}
