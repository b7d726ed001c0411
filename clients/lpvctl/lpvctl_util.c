/*
 * lpvctl_util.c - lpvctl's connection, messages and argument helpers
 * (lpvctl.h). Every command's flags go through core/flags.h (getopt_long)
 * with the command's table: args_begin and args_next.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lpvctl.h"

lpvc *g_c;
const char *g_cmd = "lpvctl";

int usage_error(const char *fmt, const char *arg)
{
    fprintf(stderr, "lpvctl: %s: ", g_cmd);
    fprintf(stderr, fmt, arg ? arg : "");
    fprintf(stderr, "\n(lpvctl --help for usage)\n");
    return 2;
}

int server_error(void)
{
    fprintf(stderr, "lpvctl: %s: %s (%d): %s\n", g_cmd, lpvc_error_name(g_c), lpvc_error_code(g_c),
            lpvc_error_message(g_c));
    return 1;
}

void print_reply(void)
{
    printf("%s: %s\n", g_cmd, lpvc_last_reply(g_c));
    fflush(stdout);
}

void print_json_line(const char *prefix, json_t *o)
{
    char *s = json_dumps(o, JSON_COMPACT);
    printf("%s: %s\n", prefix, s ? s : "{}");
    fflush(stdout);
    free(s);
}

/* ---- argument helpers -------------------------------------------------------- */

int parse_floats(const char *s, float *out, int n)
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

int parse_int(const char *s, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (end == s || *end != '\0' || errno != 0 || v < lo || v > hi)
        return -1;
    *out = v;
    return 0;
}

int parse_float(const char *s, float *out)
{
    return parse_floats(s, out, 1);
}

const char *ext_of(const char *path)
{
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    return dot && (!slash || dot > slash) ? dot + 1 : "";
}

unsigned char *read_file(const char *path, size_t *len)
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

int write_file(const char *path, const void *data, size_t len)
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

int args_begin(lpv_flags *p, int argc, char **argv, const lpv_flag *flags, size_t n)
{
    const lpv_flag_group g = {flags, n, NULL, NULL};
    if (lpv_flags_begin(p, argc, argv, &g, 1, 0) != 0) {
        fprintf(stderr, "lpvctl: %s: %s\n", g_cmd, p->err);
        return -1;
    }
    return 0;
}

int args_next(lpv_flags *p, const lpv_flag *flags, int *idx, const char **v)
{
    int g;
    const lpv_flag *fl;
    const lpv_flags_item it = lpv_flags_next(p, &g, &fl, v);
    if (it == LPV_FLAGS_END)
        return 0;
    const char *problem = lpv_flags_problem(p, it);
    if (problem) {
        usage_error("%s", problem);
        return -1;
    }
    *idx = it == LPV_FLAGS_POSITIONAL ? -1 : (int)(fl - flags);
    return 1;
}

int parse_error_bound(const char *s, double *out)
{
    float e;
    if (parse_float(s, &e) != 0 || !(e > 0.0f)) {
        usage_error("bad --error-bound '%s' (a fraction, e.g. 0.01)", s);
        return -1;
    }
    *out = e;
    return 0;
}
