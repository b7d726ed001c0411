/* commands.h - the subcommands of the lpvd program; each takes its own
 * argv (argv[0] is the subcommand's name) and returns the exit status. */
#ifndef LPVD_COMMANDS_H
#define LPVD_COMMANDS_H

int lpvd_cmd_render(int argc, char **argv);
int lpvd_cmd_batch(int argc, char **argv);  /* batch jobs, cmd_batch.c */
int lpvd_cmd_serve(int argc, char **argv); /* the daemon, serve.c */
int lpvd_cmd_knobs(int argc, char **argv); /* the knob table as docs/knobs.md or JSON, cmd_knobs.c */

#endif
