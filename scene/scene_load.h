/*
 * scene_load.h - the one call commands use to get a scene: a glTF file, or
 * the built-in Cornell box when no path is given; either way a scene without
 * a camera or without any light gets the documented defaults (scene_defaults.h).
 */
#ifndef LPV_SCENE_LOAD_H
#define LPV_SCENE_LOAD_H

#include <stddef.h>
#include "scene.h"

int lpv_scene_load(const char *path, lpv_scene *out, char *err, size_t err_size);

#endif
