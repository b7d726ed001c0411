/*
 * scene_load.h - the one call commands use to get a scene: a glTF file, or
 * the built-in Cornell box when no path is given; either way a scene without
 * a camera or without any light gets the documented defaults (scene_defaults.h).
 */
#ifndef LPV_SCENE_LOAD_H
#define LPV_SCENE_LOAD_H

#include <stddef.h>
#include "gltf_load.h"
#include "scene.h"

int lpv_scene_load(const char *path, lpv_scene *out, char *err, size_t err_size);

/* lpv_scene_load with the file's nodes posed by one of its animations at a
 * time (lpv_gltf_load_file_animated; docs/scenes.md, "Animations"); at NULL
 * is lpv_scene_load. The built-in scene (path NULL or "") has no animations:
 * a request for one is refused. The defaults are placed for the posed scene. */
int lpv_scene_load_animated(const char *path, const lpv_gltf_animation_time *at, lpv_scene *out, char *err,
                            size_t err_size);

/* lpv_scene_load for the invoking user's own file (lpvd render,
 * lpvd-reference, the benchmarks): external URIs may lie outside the scene's
 * folder (lpv_gltf_load_file_user). Batch jobs and the daemon use the calls
 * above, which keep them beneath it. */
int lpv_scene_load_user(const char *path, lpv_scene *out, char *err, size_t err_size);

#endif
