/*
 * flags.h - command lines through getopt_long, driven by tables. A program
 * lists its own flags once (name, short letter, value, help with its
 * default) and adds the shared groups (the settings knobs of
 * settings_fields.c through settings_flags.h, the camera choice of
 * view_choice.h); the long-options table, the dispatch and the help text
 * all come from those lists, so a flag is written in one place.
 *
 * What getopt_long gives beyond the old hand-written loops: "--flag=value",
 * unambiguous prefixes ("--iter 8") and "--" before positional arguments.
 * Positional arguments keep their place among the flags (getopt's
 * return-in-order mode, so argv is never permuted).
 */
#ifndef LPV_FLAGS_H
#define LPV_FLAGS_H

#include <getopt.h>
#include <stddef.h>

typedef struct lpv_flag {
    const char *name;    /* long name without "--" */
    char letter;         /* the short form ('o' for -o), or 0 */
    const char *metavar; /* the value's name in help ("PATH"); NULL: the flag takes no value */
    const char *help;    /* help text with the default; '\n' starts an indented continuation line */
} lpv_flag;

/* Parses one flag of a group into target: 0, or -1 with a message that
 * names the flag in err. */
typedef int (*lpv_flag_fn)(void *target, const lpv_flag *f, const char *value, char *err, size_t err_size);

typedef struct lpv_flag_group {
    const lpv_flag *flags;
    size_t count;
    lpv_flag_fn parse; /* NULL: lpv_flags_next hands the group's flags to the caller */
    void *target;
} lpv_flag_group;

#define LPV_FLAGS_MAX_GROUPS 6
#define LPV_FLAGS_MAX 160

/* What lpv_flags_next found. */
typedef enum lpv_flags_item {
    LPV_FLAGS_END = 0,
    LPV_FLAGS_FLAG = 1,        /* a flag of a group without parse: *group, *flag, *value */
    LPV_FLAGS_POSITIONAL = 2,  /* an argument that is no flag: *value */
    LPV_FLAGS_UNKNOWN = -1,    /* p->arg: the flag as written ("--nope", "-x", "--full=1") */
    LPV_FLAGS_NO_VALUE = -2,   /* p->arg: the flag as written that lacks its value */
    LPV_FLAGS_BAD_VALUE = -3,  /* a group's parse refused the value: p->err */
} lpv_flags_item;

typedef struct lpv_flags {
    int argc;
    char **argv;
    lpv_flag_group groups[LPV_FLAGS_MAX_GROUPS];
    int ngroups;
    struct option longopts[LPV_FLAGS_MAX + 1];
    int owner[LPV_FLAGS_MAX]; /* longopts[i]'s group */
    const lpv_flag *flag_of[LPV_FLAGS_MAX];
    int nopts;
    char optstring[64];
    int long_only; /* getopt_long_only: "-spp 64" is "--spp 64" */
    int rest;      /* after "--": the index of the next positional argument, else 0 */
    char arg[256]; /* the offending argument (UNKNOWN, NO_VALUE) */
    char err[1024];
} lpv_flags;

/* Prepares to parse argv[1..argc-1] (argv[0] is the program or the
 * subcommand). long_only: single-dash long flags too. Returns 0, or -1 when
 * the tables do not fit or name a flag twice (a programming error; message
 * in p->err). */
int lpv_flags_begin(lpv_flags *p, int argc, char **argv, const lpv_flag_group *groups, int ngroups, int long_only);

/* The next item (lpv_flags_item). Flags of groups with a parse function are
 * parsed here and not returned. */
lpv_flags_item lpv_flags_next(lpv_flags *p, int *group, const lpv_flag **flag, const char **value);

/* What is wrong with an item lpv_flags_next returned, in words, for a
 * program's "PROG: %s (see PROG --help)": "unknown flag --x", "--x needs a
 * value" or the group's own message (written into p->err); NULL for a flag
 * or a positional argument, which only the program can judge. */
const char *lpv_flags_problem(lpv_flags *p, lpv_flags_item it);

/* A program's refusal of an item of lpv_flags_next: for a problem
 * (lpv_flags_problem), and for a positional argument when the program takes
 * none (positional_ok 0: "unexpected argument VALUE"), prints
 * "PROG: ... (see PROG --help)" on stderr and returns 1 (the program exits
 * 2); else 0. */
int lpv_flags_refuse(lpv_flags *p, lpv_flags_item it, const char *value, const char *prog, int positional_ok);

/* The flag named name (without dashes) in a table, or NULL. */
const lpv_flag *lpv_flag_find(const lpv_flag *flags, size_t count, const char *name);

/* n comma-separated finite numbers ("1,2.5,-3") into out. Returns 0, or -1
 * when v is not exactly that (the caller names the flag in its message). */
int lpv_flag_parse_floats(const char *v, float *out, int n);

/* Appends printf-style text to buf at *len, truncating at size. */
void lpv_flags_append(char *buf, size_t size, size_t *len, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* Appends help lines for a table to buf at *len (snprintf-style, truncating):
 * "  -o, --output PATH       help..." with continuation lines indented to the
 * help column. */
void lpv_flags_help(char *buf, size_t size, size_t *len, const lpv_flag *flags, size_t count);

/* A flag group's help section, "HEADING:\n" then the table's lines, written
 * into buf the first time (buf starts zeroed: a static buffer) and returned
 * as it is after. */
const char *lpv_flags_section_help(char *buf, size_t size, const char *heading, const lpv_flag *flags,
                                   size_t count);

#endif /* LPV_FLAGS_H */
