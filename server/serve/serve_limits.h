/*
 * serve_limits.h - the daemon's limits as one table (serve_limits.c): each
 * row is a flag of `lpvd serve`, its field of sv_config, its range, its
 * default, its help and the key HELLO's "limits" reports it under. The
 * defaults, the command line's parsing and range checks, `lpvd serve
 * --help` and HELLO's limits all come from the rows, as the engine's knobs
 * come from core/settings_fields.c.
 */
#ifndef SV_LIMITS_H
#define SV_LIMITS_H

#include <stddef.h>

#include <jansson.h>

#include "flags.h"

struct sv_config;

typedef enum sv_limit_type {
    SV_LIMIT_INT = 0, /* an int field */
    SV_LIMIT_U64,     /* a uint64_t field */
    SV_LIMIT_REAL,    /* a double field */
} sv_limit_type;

typedef struct sv_limit {
    const char *flag;    /* without "--" */
    const char *metavar; /* "N", "BYTES", "S", "HZ", "MS" */
    const char *section; /* the --help heading it is listed under */
    const char *hello;   /* HELLO limits' key, NULL: not reported */
    sv_limit_type type;
    size_t offset;       /* of its field in sv_config */
    double lo, hi;       /* the accepted range, inclusive; integers exact up to 2^53 */
    double deflt;
    const char *help;    /* what it bounds; '\n' continues the line */
    const char *note;    /* after the default in help ("0 = no limit"), or NULL */
} sv_limit;

extern const sv_limit sv_limits[];
extern const size_t sv_limit_count;

/* Every row's default into cfg. */
void sv_limits_defaults(struct sv_config *cfg);

/* The rows as a flag group parsing into a struct sv_config (target): a value
 * outside the row's range is refused naming the flag, the range and the value. */
lpv_flag_group sv_limits_flag_group(struct sv_config *cfg);

/* --help's lines for the rows of one section, from the table. */
void sv_limits_help(char *buf, size_t size, size_t *len, const char *section);

/* The rows' values in cfg as HELLO's "limits" object's entries, into lim. */
void sv_limits_hello(const struct sv_config *cfg, json_t *lim);

#endif /* SV_LIMITS_H */
