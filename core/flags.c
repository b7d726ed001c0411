/* flags.c - see flags.h. */
#include "flags.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* getopt_long's val for long option i; above every char, so never a short letter. */
#define LONG_VAL(i) (256 + (i))

void lpv_flags_append(char *buf, size_t size, size_t *len, const char *fmt, ...)
{
    if (*len >= size)
        return;
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf + *len, size - *len, fmt, ap);
    va_end(ap);
    if (n > 0)
        *len = *len + (size_t)n < size ? *len + (size_t)n : size;
}

const char *lpv_flags_problem(lpv_flags *p, lpv_flags_item it)
{
    switch (it) {
    case LPV_FLAGS_UNKNOWN: snprintf(p->err, sizeof p->err, "unknown flag %s", p->arg); return p->err;
    case LPV_FLAGS_NO_VALUE: snprintf(p->err, sizeof p->err, "%s needs a value", p->arg); return p->err;
    case LPV_FLAGS_BAD_VALUE: return p->err;
    case LPV_FLAGS_END:
    case LPV_FLAGS_FLAG:
    case LPV_FLAGS_POSITIONAL: break;
    }
    return NULL;
}

int lpv_flags_refuse(lpv_flags *p, lpv_flags_item it, const char *value, const char *prog, int positional_ok)
{
    const char *problem = lpv_flags_problem(p, it);
    if (!problem && (positional_ok || it != LPV_FLAGS_POSITIONAL))
        return 0;
    fprintf(stderr, "%s: %s%s (see %s --help)\n", prog, problem ? "" : "unexpected argument ", problem ? problem : value,
            prog);
    return 1;
}

const lpv_flag *lpv_flag_find(const lpv_flag *flags, size_t count, const char *name)
{
    for (size_t i = 0; name && i < count; ++i)
        if (strcmp(flags[i].name, name) == 0)
            return &flags[i];
    return NULL;
}

int lpv_flags_begin(lpv_flags *p, int argc, char **argv, const lpv_flag_group *groups, int ngroups, int long_only)
{
    memset(p, 0, sizeof *p);
    p->argc = argc;
    p->argv = argv;
    p->long_only = long_only;
    /* "-": non-flags come back in order (argv stays as the caller gave it,
     * whatever POSIXLY_CORRECT says); ":": missing values are told apart
     * from unknown flags, and getopt prints nothing itself. */
    size_t olen = 0;
    lpv_flags_append(p->optstring, sizeof p->optstring, &olen, "-:");
    if (ngroups > LPV_FLAGS_MAX_GROUPS) {
        snprintf(p->err, sizeof p->err, "lpv_flags_begin: %d groups, at most %d", ngroups, LPV_FLAGS_MAX_GROUPS);
        return -1;
    }
    for (int g = 0; g < ngroups; ++g) {
        p->groups[g] = groups[g];
        for (size_t k = 0; k < groups[g].count; ++k) {
            const lpv_flag *f = &groups[g].flags[k];
            for (int j = 0; j < p->nopts; ++j)
                if (strcmp(p->flag_of[j]->name, f->name) == 0 || (f->letter && p->flag_of[j]->letter == f->letter)) {
                    snprintf(p->err, sizeof p->err, "lpv_flags_begin: --%s is in two tables", f->name);
                    return -1;
                }
            if (p->nopts == LPV_FLAGS_MAX || olen + 3 >= sizeof p->optstring) {
                snprintf(p->err, sizeof p->err, "lpv_flags_begin: more than %d flags", LPV_FLAGS_MAX);
                return -1;
            }
            int i = p->nopts++;
            p->longopts[i] = (struct option){f->name, f->metavar ? required_argument : no_argument, NULL, LONG_VAL(i)};
            p->owner[i] = g;
            p->flag_of[i] = f;
            if (f->letter)
                lpv_flags_append(p->optstring, sizeof p->optstring, &olen, "%c%s", f->letter, f->metavar ? ":" : "");
        }
    }
    p->longopts[p->nopts] = (struct option){0};
    p->ngroups = ngroups;
    optind = 0; /* glibc: 0 starts a new scan (tests parse several command lines in one process) */
    opterr = 0;
    return 0;
}

/* The option getopt just reported on, as the user wrote it. */
static void offending(lpv_flags *p)
{
    if (optopt > 0 && optopt < 256) /* a short flag, possibly inside a cluster */
        snprintf(p->arg, sizeof p->arg, "-%c", optopt);
    else /* a long flag: getopt has stepped past it */
        snprintf(p->arg, sizeof p->arg, "%s", optind > 0 && optind <= p->argc ? p->argv[optind - 1] : "");
}

lpv_flags_item lpv_flags_next(lpv_flags *p, int *group, const lpv_flag **flag, const char **value)
{
    *group = -1;
    *flag = NULL;
    *value = NULL;
    for (;;) {
        if (p->rest) { /* the arguments after "--" */
            if (p->rest >= p->argc)
                return LPV_FLAGS_END;
            *value = p->argv[p->rest++];
            return LPV_FLAGS_POSITIONAL;
        }
        int idx = -1;
        int c = p->long_only ? getopt_long_only(p->argc, p->argv, p->optstring, p->longopts, &idx)
                             : getopt_long(p->argc, p->argv, p->optstring, p->longopts, &idx);
        if (c == -1) {
            p->rest = optind < p->argc ? optind : p->argc;
            continue;
        }
        if (c == 1) {
            *value = optarg;
            return LPV_FLAGS_POSITIONAL;
        }
        if (c == '?' || c == ':') {
            offending(p);
            return c == ':' ? LPV_FLAGS_NO_VALUE : LPV_FLAGS_UNKNOWN;
        }
        int i = -1;
        if (c >= 256)
            i = c - 256;
        else
            for (int j = 0; j < p->nopts && i < 0; ++j)
                if (p->flag_of[j]->letter == c)
                    i = j;
        if (i < 0 || i >= p->nopts) { /* cannot happen: getopt returns only what the tables hold */
            snprintf(p->arg, sizeof p->arg, "-%c", c);
            return LPV_FLAGS_UNKNOWN;
        }
        const lpv_flag_group *g = &p->groups[p->owner[i]];
        const char *v = p->flag_of[i]->metavar ? optarg : NULL;
        if (g->parse) {
            if (g->parse(g->target, p->flag_of[i], v, p->err, sizeof p->err) != 0)
                return LPV_FLAGS_BAD_VALUE;
            continue;
        }
        *group = p->owner[i];
        *flag = p->flag_of[i];
        *value = v;
        return LPV_FLAGS_FLAG;
    }
}

/* The help column: the widest common "  --flag VALUE" plus two spaces. */
#define HELP_COL 26

void lpv_flags_help(char *buf, size_t size, size_t *len, const lpv_flag *flags, size_t count)
{
    for (size_t i = 0; i < count; ++i) {
        const lpv_flag *f = &flags[i];
        char left[128];
        size_t l = 0;
        if (f->letter)
            lpv_flags_append(left, sizeof left, &l, "-%c, ", f->letter);
        lpv_flags_append(left, sizeof left, &l, "--%s%s%s", f->name, f->metavar ? " " : "",
                         f->metavar ? f->metavar : "");
        if (l + 2 + 2 <= HELP_COL)
            lpv_flags_append(buf, size, len, "  %-*s", HELP_COL - 2, left);
        else
            lpv_flags_append(buf, size, len, "  %s  ", left);
        for (const char *h = f->help;;) { /* each '\n' continues at the help column */
            const char *nl = strchr(h, '\n');
            if (!nl) {
                lpv_flags_append(buf, size, len, "%s\n", h);
                break;
            }
            lpv_flags_append(buf, size, len, "%.*s\n%*s", (int)(nl - h), h, HELP_COL, "");
            h = nl + 1;
        }
    }
}

int lpv_flag_parse_floats(const char *v, float *out, int n)
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

const char *lpv_flags_section_help(char *buf, size_t size, const char *heading, const lpv_flag *flags,
                                   size_t count)
{
    if (!buf[0]) {
        size_t len = 0;
        lpv_flags_append(buf, size, &len, "%s:\n", heading);
        lpv_flags_help(buf, size, &len, flags, count);
    }
    return buf;
}
