/*
 * view_choice.h - the camera a command line chooses (--camera, --eye,
 * --target, --fov, --size), as a flag group for flags.h, and its resolution
 * against a loaded scene. Shared by lpvd render, the benchmarks, the
 * accuracy sweep and lpvd-reference, which must frame the same image.
 */
#ifndef LPV_VIEW_CHOICE_H
#define LPV_VIEW_CHOICE_H

#include <stddef.h>

#include "flags.h"
#include "scene.h"
#include "view.h"

typedef struct lpv_view_choice {
    const char *camera; /* --camera: index or name, NULL = the file's first */
    int has_eye, has_target, has_fov;
    float eye[3], target[3], fov_deg;
    int width, height; /* --size; 0 = 512 wide, height from the camera's aspect */
} lpv_view_choice;

/* The flags: camera, eye, target, fov, size. */
const lpv_flag *lpv_view_flags(size_t *count);

/* Parses one camera flag (name without dashes) into c; value is kept by
 * reference (--camera). Returns 1 if it was one, 0 if not, -1 on a bad value
 * ("--NAME VALUE: expected ..." in err). */
int lpv_view_flag_parse(lpv_view_choice *c, const char *name, const char *value, char *err, size_t err_size);

/* The group for lpv_flags_begin, parsing into *c. */
lpv_flag_group lpv_view_flag_group(lpv_view_choice *c);

/* "Camera:" and the flags' help. Built once. */
const char *lpv_view_flags_help(void);

/* The view the choice names in this scene: an explicit eye/target (missing
 * parts from the file's camera or a view that frames the bounds), else the
 * chosen or first camera of the file, else one that frames the bounds.
 * Returns 0 or -1 (err). */
int lpv_view_resolve(const lpv_view_choice *c, const lpv_scene *scene, lpv_view *view, char *err, size_t err_size);

#endif /* LPV_VIEW_CHOICE_H */
