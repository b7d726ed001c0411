/*
 * options.h - the command-line flags every lpvd command shares: engine
 * settings, GL backend and camera. Parsed into an lpv_settings (zero fields =
 * defaults) and a camera choice that is resolved once the scene is loaded.
 */
#ifndef LPVD_OPTIONS_H
#define LPVD_OPTIONS_H

#include <stddef.h>

#include "context.h"
#include "settings.h"
#include "view.h"

typedef struct lpvd_camera_choice {
    const char *camera;   /* --camera: index or name, NULL = the file's first */
    int has_eye, has_target, has_fov;
    float eye[3], target[3], fov_deg;
    int width, height;    /* --size; 0 = 512 wide, height from the camera's aspect */
} lpvd_camera_choice;

typedef struct lpvd_options {
    lpv_settings settings;
    lpv_backend backend;
    lpvd_camera_choice cam;
} lpvd_options;

/* Tries to consume one shared flag (name without dashes, its value or NULL);
 * the settings flags of core/settings_fields.h are among them.
 * Returns 1 if it was one, 0 if not, -1 on a bad value (message in err). */
int lpvd_option_parse(lpvd_options *o, const char *name, const char *value, char *err, size_t err_size);

/* Whether a shared flag takes a value (for the commands' parsers). -1 unknown. */
int lpvd_option_takes_value(const char *name);

/* The help text for the shared flags; the settings knobs of the field table
 * (core/settings_fields.h) are listed from it. Built once, never freed. */
const char *lpvd_options_help(void);
#define LPVD_OPTIONS_HELP lpvd_options_help()

/* Resolves the camera choice against a scene. Returns 0 or -1 (err). */
int lpvd_resolve_view(const lpvd_camera_choice *c, const lpv_scene *scene, lpv_view *view, char *err,
                      size_t err_size);

#endif
