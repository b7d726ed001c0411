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
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lpvctl.h"

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
    "  subscribe [volume|frame] [--format F] [--compression zstd|none|shq] [--error-bound E] [--delta]\n"
    "            [-n COUNT]\n"
    "            [--tick] [--wait MS] [-o PREFIX]  print stream headers; save COUNT messages as\n"
    "                                          PREFIX-TICK.bin/.json (volumes) or PREFIX-TICK.<format>;\n"
    "                                          --tick sends a TICK before each wait\n"
    "  unsubscribe [volume|frame]\n"
    "  volume [-o FILE.bin|FILE.json] [--format fp16|fp32] [--compression zstd|none|shq] [--error-bound E]\n"
    "         [--content merged|levels|visibility]\n"
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

enum { M_ADDRESS, M_TOKEN_FILE, M_TIMEOUT, M_HELP, M_COUNT };
static const lpv_flag MAIN_FLAGS[M_COUNT] = {
    [M_ADDRESS] = {"address", 'a', "A", "the daemon's address"},
    [M_TOKEN_FILE] = {"token-file", 0, "F", "the token HELLO presents"},
    [M_TIMEOUT] = {"timeout", 0, "MS", "per request"},
    [M_HELP] = {"help", 'h', NULL, "this text"},
};

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

/* Runs one command (argv[0] its name) in this session. */
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
    /* the options before COMMAND; its arguments are its own (args_next) */
    lpv_flags p;
    const lpv_flag_group g = {MAIN_FLAGS, M_COUNT, NULL, NULL};
    if (lpv_flags_begin(&p, argc, argv, &g, 1, 0) != 0) {
        fprintf(stderr, "lpvctl: %s\n", p.err);
        return 2;
    }
    int i = argc, grp;
    const lpv_flag *fl;
    const char *v;
    for (lpv_flags_item it; i == argc && (it = lpv_flags_next(&p, &grp, &fl, &v)) != LPV_FLAGS_END;) {
        const char *problem = lpv_flags_problem(&p, it);
        if (problem) {
            fprintf(stderr, "lpvctl: %s\n%s", problem, g_usage);
            return 2;
        }
        if (it == LPV_FLAGS_POSITIONAL) { /* COMMAND: where it stands in argv */
            for (i = 1; i < argc && argv[i] != v; ++i)
                ;
            continue;
        }
        switch (fl - MAIN_FLAGS) {
        case M_HELP: fputs(g_usage, stdout); return 0;
        case M_ADDRESS: address = v; break;
        case M_TOKEN_FILE: token_file = v; break;
        case M_TIMEOUT:
            if (parse_int(v, 0, 1L << 30, &timeout_ms) != 0) {
                fprintf(stderr, "lpvctl: bad --timeout '%s' (ms)\n", v);
                return 2;
            }
            break;
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
