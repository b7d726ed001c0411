/*
 * lpvctl.h - what lpvctl's files share: the connection, the reporting and
 * argument helpers (lpvctl_util.c) and the commands, one file per group:
 * lpvctl_session.c (the session's scene, lights, camera, config, knobs,
 * hello, ack, bye), lpvctl_results.c (tick, volume, frame, query, stats),
 * lpvctl_streams.c (subscribe, unsubscribe); lpvctl.c runs them.
 */
#ifndef LPVCTL_H
#define LPVCTL_H

#include <stddef.h>

#include <jansson.h>

#include "flags.h"
#include "lpvc.h"

#define MAX_ARGS 64

extern lpvc *g_c;          /* the one connection: one session (R7.1) */
extern const char *g_cmd;  /* the command running, for messages */

/* "lpvctl: CMD: <fmt with arg>" and a pointer to --help on stderr; returns 2. */
int usage_error(const char *fmt, const char *arg);
/* The server's ERROR (name, code, message) on stderr; returns 1. */
int server_error(void);
void print_reply(void);
void print_json_line(const char *prefix, json_t *o);

int parse_floats(const char *s, float *out, int n); /* "1,2.5,-3": exactly n finite numbers */
int parse_int(const char *s, long lo, long hi, long *out);
int parse_float(const char *s, float *out);
/* --error-bound E (SPEC R5.16): a fraction > 0 (the server checks its
 * range); 0, or the usage error printed and -1. */
int parse_error_bound(const char *s, double *out);
const char *ext_of(const char *path);
unsigned char *read_file(const char *path, size_t *len);
int write_file(const char *path, const void *data, size_t len);

/* A command's arguments through core/flags.h with its table: args_begin,
 * then args_next until it returns 0 (the end) or -1 (a usage problem,
 * reported; the command returns 2). 1: *idx is the flag's index in the
 * table, or -1 for a positional argument, with its value in *v. */
int args_begin(lpv_flags *p, int argc, char **argv, const lpv_flag *flags, size_t n);
int args_next(lpv_flags *p, const lpv_flag *flags, int *idx, const char **v);

/* FILE.bin (raw float32 and a FILE.bin.json sidecar) or FILE.json (a
 * summary) of a decoded volume (lpvctl_results.c). 0, or -1 (reported). */
int save_volume(const lpvc_volume *v, const char *path);

int cmd_hello(int argc, char **argv);
int cmd_load(int argc, char **argv);
int cmd_update(int argc, char **argv);
int cmd_light_set(int argc, char **argv);
int cmd_light_remove(int argc, char **argv);
int cmd_camera(int argc, char **argv);
int cmd_knobs(int argc, char **argv);
int cmd_config(int argc, char **argv);
int cmd_ack(int argc, char **argv);
int cmd_bye(int argc, char **argv);
int cmd_tick(int argc, char **argv);
int cmd_volume(int argc, char **argv);
int cmd_frame(int argc, char **argv);
int cmd_query(int argc, char **argv);
int cmd_stats(int argc, char **argv);
int cmd_subscribe(int argc, char **argv);
int cmd_unsubscribe(int argc, char **argv);

#endif /* LPVCTL_H */
