/*
 * view.h - the camera an image is rendered from, and how it is chosen: a
 * glTF camera (by index or name), an explicit eye/target/fov, or, for a
 * scene without cameras, one that frames the scene's bounds.
 */
#ifndef LPV_VIEW_H
#define LPV_VIEW_H

#include "scene.h"

typedef struct lpv_view {
    float eye[3];
    float forward[3];  /* unit */
    float up[3];       /* unit, not parallel to forward */
    int orthographic;
    float yfov;        /* rad (perspective) */
    float ymag;        /* half height, m (orthographic) */
    float znear, zfar; /* m; 0 = derived from the scene bounds */
    int width, height; /* pixels */
} lpv_view;

/* From a scene camera. width/height are taken as given. */
void lpv_view_from_camera(const lpv_camera *cam, int width, int height, lpv_view *out);

/* What lpv_view_look_at refuses (negative, so != 0 tests still work). */
enum {
    LPV_VIEW_BAD_FOV = -1,       /* yfov not in (0, pi) */
    LPV_VIEW_NOT_FINITE = -2,    /* eye or target not finite */
    LPV_VIEW_EYE_IS_TARGET = -3, /* |target - eye| <= 1e-9 m */
};

/* Looking from eye at target with vertical field of view yfov (rad, strictly
 * between 0 and pi); up is world +Y unless the view is vertical, then -Z.
 * Returns 0 or one of the LPV_VIEW_* codes above. */
int lpv_view_look_at(const float eye[3], const float target[3], float yfov, int width, int height, lpv_view *out);

/* A 45-degree view along -Z that frames the scene's bounds. */
void lpv_view_frame_bounds(const lpv_scene *scene, int width, int height, lpv_view *out);

/* Projects world point p into the image: pixel coordinates with (0, 0) at the
 * top-left corner of the top-left pixel. Returns 0, or -1 if p is behind the
 * camera. */
int lpv_view_project(const lpv_view *v, const float p[3], float *px, float *py);

/* Finds a camera by decimal index or by name; -1 if none matches. */
int lpv_view_find_camera(const lpv_scene *scene, const char *index_or_name);

#endif
