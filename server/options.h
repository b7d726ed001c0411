/*
 * options.h - the flags every lpvd command that runs the engine shares: the
 * engine settings (core/settings_flags.h), the GL backend and the camera
 * (core/view_choice.h), gathered into one lpvd_options and handed to
 * core/flags.h as flag groups. The backend is the one flag that needs gpu/,
 * which is why this lives above core.
 */
#ifndef LPVD_OPTIONS_H
#define LPVD_OPTIONS_H

#include <stddef.h>

#include "context.h"
#include "flags.h"
#include "settings.h"
#include "settings_flags.h"
#include "view.h"
#include "view_choice.h"

typedef lpv_view_choice lpvd_camera_choice;

typedef struct lpvd_options {
    lpv_settings settings;
    lpv_backend backend;
    lpv_view_choice cam;
} lpvd_options;

/* Which groups lpvd_options_groups adds. */
enum { LPVD_GROUP_SETTINGS = 1, LPVD_GROUP_BACKEND = 2, LPVD_GROUP_CAMERA = 4, LPVD_GROUP_ALL = 7 };

/* Fills out[] (room for 3) with the groups named by which (settings, backend, camera, in
 * that order), each parsing into o; returns how many. With handled = 0 the
 * groups have no parse function, so lpv_flags_next hands their flags to the
 * caller (who may refuse some and call lpvd_option_parse). */
int lpvd_options_groups(lpvd_options *o, int which, int handled, lpv_flag_group *out);

/* Tries to consume one shared flag (name without dashes, its value or NULL).
 * Returns 1 if it was one, 0 if not, -1 on a bad value (message in err). */
int lpvd_option_parse(lpvd_options *o, const char *name, const char *value, char *err, size_t err_size);

/* Whether a shared flag takes a value (every one does). -1 unknown. */
int lpvd_option_takes_value(const char *name);

/* The help text for the shared flags, from their tables. Built once. */
const char *lpvd_options_help(void);
#define LPVD_OPTIONS_HELP lpvd_options_help()

#endif
