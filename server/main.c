/*
 * main.c - the lpvd program: a dispatcher over subcommands.
 *   lpvd render ...   one frame of a scene to an image (offline, batch jobs)
 *   lpvd batch ...    many items of a job file in one process (docs/batch.md)
 *   lpvd serve ...    the daemon: clients over a Unix socket or TCP (docs/server.md)
 *   lpvd knobs ...    every knob's range and default, from the table (docs/knobs.md)
 */
#include <stdio.h>
#include <string.h>

#include "commands.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: lpvd <command> [args]\n"
            "commands:\n"
            "  render [SCENE] -o OUT.png|OUT.exr   render a glTF scene (default: built-in Cornell box)\n"
            "  batch JOB.json --out DIR            render every item of a job file, resumable (docs/batch.md)\n"
            "  serve [flags]                       run the daemon (Unix socket / TCP, protocol/SPEC.md)\n"
            "  knobs [--markdown|--json]           every knob's range and default (docs/knobs.md)\n"
            "  version                             print the version\n"
            "Run 'lpvd <command> --help' for a command's flags.\n");
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    const char *cmd = argv[1];
    if (strcmp(cmd, "render") == 0)
        return lpvd_cmd_render(argc - 1, argv + 1);
    if (strcmp(cmd, "batch") == 0)
        return lpvd_cmd_batch(argc - 1, argv + 1);
    if (strcmp(cmd, "serve") == 0)
        return lpvd_cmd_serve(argc - 1, argv + 1);
    if (strcmp(cmd, "knobs") == 0)
        return lpvd_cmd_knobs(argc - 1, argv + 1);
    if (strcmp(cmd, "version") == 0 || strcmp(cmd, "--version") == 0) {
        printf("lpvd %s\n", LPVD_VERSION);
        return 0;
    }
    if (strcmp(cmd, "help") == 0 || strcmp(cmd, "--help") == 0 || strcmp(cmd, "-h") == 0) {
        usage(stdout);
        return 0;
    }
    fprintf(stderr, "lpvd: unknown command '%s'\n", cmd);
    usage(stderr);
    return 2;
}
