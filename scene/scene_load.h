/*
 * scene_load.h - the one call commands use to get a scene: a glTF file, or
 * the built-in Cornell box when no path is given; either way a scene without
 * a camera or without any light gets the documented defaults (scene_defaults.h).
 */
#ifndef LPV_SCENE_LOAD_H
#define LPV_SCENE_LOAD_H

#include <stddef.h>
#include "flags.h"
#include "gltf_load.h"
#include "scene.h"

int lpv_scene_load(const char *path, lpv_scene *out, char *err, size_t err_size);

/* lpv_scene_load with the file's nodes posed by one of its animations at a
 * time (lpv_gltf_load_file_animated; docs/scenes.md, "Animations"); at NULL
 * is lpv_scene_load. The built-in scene (path NULL or "") has no animations:
 * a request for one is refused. The defaults are placed for the posed scene. */
int lpv_scene_load_animated(const char *path, const lpv_gltf_animation_time *at, lpv_scene *out, char *err,
                            size_t err_size);

/* lpv_scene_load_animated for the invoking user's own file (lpvd render,
 * lpvd-reference, the benchmarks): external URIs may lie outside the scene's
 * folder (lpv_gltf_load_file_user). Batch jobs and the daemon use the calls
 * above, which keep them beneath it. at NULL: the file's static pose. */
int lpv_scene_load_user(const char *path, const lpv_gltf_animation_time *at, lpv_scene *out, char *err,
                        size_t err_size);

/* The pose a command line asks for (--time, --animation), shared by
 * lpvd render and lpvd-reference so both pose a file alike (lpvd batch
 * items carry the same two in their job file). */
typedef struct lpv_scene_pose {
    const char *animation; /* --animation NAME|INDEX, NULL: every animation */
    double time;           /* --time SECONDS */
    int has_time;
} lpv_scene_pose;

/* The flags' group for lpv_flags_begin, parsing into *p. */
lpv_flag_group lpv_scene_pose_flag_group(lpv_scene_pose *p);
/* "Pose:" and the flags' help. */
const char *lpv_scene_pose_flags_help(void);
/* The animation time the flags ask for in *buf, or NULL (the static pose);
 * -1 with a message in err for --animation without --time. */
int lpv_scene_pose_at(const lpv_scene_pose *p, lpv_gltf_animation_time *buf, const lpv_gltf_animation_time **at,
                      char *err, size_t err_size);

#endif
