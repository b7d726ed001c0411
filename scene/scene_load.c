/* scene_load.c - see scene_load.h. */
#include "scene_load.h"

#include <stdio.h>
#include <string.h>

#include "gltf_load.h"
#include "scene_defaults.h"

int lpv_scene_load(const char *path, lpv_scene *out, char *err, size_t err_size)
{
    memset(out, 0, sizeof *out);
    int rc = (path && path[0]) ? lpv_gltf_load_file(path, out, err, err_size) : lpv_scene_builtin_cornell(out);
    if (rc != 0) {
        if (!(path && path[0]))
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
