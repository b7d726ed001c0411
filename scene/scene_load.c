/* scene_load.c - see scene_load.h. */
#include "scene_load.h"

#include <stdio.h>
#include <string.h>

#include "scene_defaults.h"

int lpv_scene_load(const char *path, lpv_scene *out, char *err, size_t err_size)
{
    return lpv_scene_load_animated(path, NULL, out, err, err_size);
}

static int load(const char *path, const lpv_gltf_animation_time *at, int user, lpv_scene *out, char *err,
                size_t err_size);

int lpv_scene_load_animated(const char *path, const lpv_gltf_animation_time *at, lpv_scene *out, char *err,
                            size_t err_size)
{
    return load(path, at, 0, out, err, err_size);
}

int lpv_scene_load_user(const char *path, lpv_scene *out, char *err, size_t err_size)
{
    return load(path, NULL, 1, out, err, err_size);
}

static int load(const char *path, const lpv_gltf_animation_time *at, int user, lpv_scene *out, char *err,
                size_t err_size)
{
    memset(out, 0, sizeof *out);
    const int builtin = !(path && path[0]);
    if (builtin && at) {
        snprintf(err, err_size,
                 "built-in scene: it has no animations (an animation was requested at %g s; give a glTF file "
                 "that has one)",
                 at->time);
        return -1;
    }
    int rc = builtin ? lpv_scene_builtin_cornell(out)
             : user  ? lpv_gltf_load_file_user(path, at, out, NULL, err, err_size)
                     : lpv_gltf_load_file_animated(path, at, out, err, err_size);
    if (rc != 0) {
        if (builtin)
            snprintf(err, err_size, "built-in scene: out of memory");
        lpv_scene_free(out);
        return -1;
    }
    if (lpv_scene_add_defaults(out, err, err_size) != 0) {
        lpv_scene_free(out);
        return -1;
    }
    return 0;
}
