/*
 * acc_scenes.c - the --scenes list: names (cornell, cornell-inside, engine,
 * clearcoat, a scene under scenes/) and paths into scene entries, with their
 * cameras and cascade sizes. Shared by the sweep and --iv-tables.
 */
#include <stdio.h>
#include <string.h>

#include "accuracy_internal.h"

/* The scenes of a --scenes list (names or paths) into scenes[] (paths[]
 * holds their files). Returns the count, or -1 after saying why. */
int acc_parse_scenes(const char *list, scene_entry *scenes, char (*paths)[1024])
{
    int nscenes = 0;
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", list);
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        if (nscenes >= MAX_SCENES) {
            fprintf(stderr, "lpvd-accuracy: at most %d scenes\n", MAX_SCENES);
            return -1;
        }
        scene_entry *e = &scenes[nscenes];
        const char *base = strrchr(tok, '/') ? strrchr(tok, '/') + 1 : tok;
        snprintf(e->name, sizeof e->name, "%s", base);
        char *dot = strrchr(e->name, '.');
        int is_file = strchr(tok, '/') || (dot && (strcmp(dot, ".glb") == 0 || strcmp(dot, ".gltf") == 0));
        if (dot)
            *dot = '\0';
        for (char *c = e->name; *c; ++c)
            if (!((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') ||
                  *c == '-' || *c == '_'))
                *c = '_';
        if (is_file) {
            snprintf(paths[nscenes], sizeof paths[nscenes], "%s", tok);
            e->path = paths[nscenes];
        } else if (strcmp(tok, "cornell") == 0) {
            e->path = NULL;
        } else if (strcmp(tok, "engine") == 0 || strcmp(tok, "clearcoat") == 0) {
            /* real scenes the project did not write (scripts/install-deps.sh installs them) */
            snprintf(paths[nscenes], sizeof paths[nscenes], "%s/%s", ASSIMP_GLTF2_DIR,
                     strcmp(tok, "engine") == 0 ? "2CylinderEngine-glTF-Binary/2CylinderEngine.glb"
                                                : "ClearCoat-glTF/ClearCoatTest.gltf");
            e->path = paths[nscenes];
            e->scale_free = 1;
        } else if (strcmp(tok, "cornell-inside") == 0) {
            /* the built-in box seen from inside its opening: the box's own
             * camera stands 2.9 m in front of it, and camera-following
             * cascades of 1 m would then hold no geometry */
            e->path = NULL;
            e->has_cam = 1;
            e->eye[0] = 0.0f, e->eye[1] = 1.0f, e->eye[2] = 0.9f;
            e->target[0] = 0.0f, e->target[1] = 1.0f, e->target[2] = -1.0f;
            e->fov = 70.0f;
        } else {
            snprintf(paths[nscenes], sizeof paths[nscenes], "%s/%s.glb", LPVD_ACCURACY_SCENES_DIR,
                     tok);
            e->path = paths[nscenes];
        }
        /* "cascades-3" of --features: a finest cascade well inside the scene */
        e->cascade_size = e->scale_free ? 0.0f /* auto: a quarter of the scene */
                          : e->path == NULL ? 1.0f : strcmp(e->name, "blinds") == 0 ? 4.0f : 8.0f;
        ++nscenes;
    }
    return nscenes;
}
