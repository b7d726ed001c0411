/* scene_load.c - see scene_load.h. */
#include "scene_load.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
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

int lpv_scene_load_user(const char *path, const lpv_gltf_animation_time *at, lpv_scene *out, char *err,
                        size_t err_size)
{
    return load(path, at, 1, out, err, err_size);
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

static const lpv_flag POSE_FLAGS[] = {
    {"time", 0, "SECONDS", "pose the file at this time of its animations (node transforms, skins,\n"
                           "morph weights; docs/scenes.md \"Animations\"); default: the static pose"},
    {"animation", 0, "NAME|INDEX", "the animation --time plays (default: every animation of the file)"},
};
#define N_POSE_FLAGS (sizeof POSE_FLAGS / sizeof POSE_FLAGS[0])

static int parse_pose(void *target, const lpv_flag *f, const char *v, char *err, size_t n)
{
    lpv_scene_pose *p = target;
    if (!strcmp(f->name, "animation")) {
        p->animation = v;
        return 0;
    }
    char *end = NULL;
    const double t = v ? strtod(v, &end) : NAN;
    if (!v || end == v || *end || !isfinite(t) || t < 0.0) {
        snprintf(err, n, "--time %s: expected seconds, a finite number >= 0", v ? v : "");
        return -1;
    }
    p->time = t;
    p->has_time = 1;
    return 0;
}

lpv_flag_group lpv_scene_pose_flag_group(lpv_scene_pose *p)
{
    return (lpv_flag_group){POSE_FLAGS, N_POSE_FLAGS, parse_pose, p};
}

const char *lpv_scene_pose_flags_help(void)
{
    static char help[1024];
    return lpv_flags_section_help(help, sizeof help, "Pose", POSE_FLAGS, N_POSE_FLAGS);
}

int lpv_scene_pose_at(const lpv_scene_pose *p, lpv_gltf_animation_time *buf, const lpv_gltf_animation_time **at,
                      char *err, size_t err_size)
{
    *at = NULL;
    if (p->animation && !p->has_time) {
        snprintf(err, err_size, "--animation %s: needs --time (the animation's time to pose the scene at)",
                 p->animation);
        return -1;
    }
    if (!p->has_time)
        return 0;
    buf->animation = p->animation;
    buf->time = p->time;
    *at = buf;
    return 0;
}
