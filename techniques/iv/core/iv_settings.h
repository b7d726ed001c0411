/*
 * iv_settings.h - imperfect volumes' knobs as lpv_settings holds them
 * (settings.iv); their rows (range, default, help, what a change
 * recomputes) are iv_fields.c's.
 */
#ifndef LPV_IV_SETTINGS_H
#define LPV_IV_SETTINGS_H

#include "settings_switch.h"

/* Their limits (the rows' ranges) and the AO's reach when 0 (auto), in voxels. */
#define LPV_IV_AO_VOXELS 4.0f
#define LPV_IV_MAX_POINTS (1 << 24)
#define LPV_IV_MAX_POINTS_PER_TRIANGLE 64
#define LPV_IV_MAX_RAYS 1024
#define LPV_IV_MAX_BOUNCES 8
#define LPV_IV_MAX_SEED 99999999

/* Imperfect volumes (Mavridis & Papaioannou, the third seed; docs/imperfect-volumes.md):
 * a voxel copy of the whole scene from a point cloud, radiance gathered per
 * voxel by ray marching it. A zero field takes its default (every knob's
 * default and range: its row in iv_fields.c). */
typedef struct lpv_iv_settings {
    int resolution;         /* voxels along the scene's longest side (voxels are cubes) */
    int points;             /* random points per triangle (Turk's formula) */
    float split;            /* voxels: a triangle with a longer edge is split before sampling (the
                               paper's load-time tessellation) */
    int seed;               /* the points' and the rays' random seed */
    int rays;               /* stratified rays per voxel */
    int bounces;            /* diffuse bounces (ping-pong passes) */
    lpv_switch tail;        /* the bounces after these (3 or more) as the series the last ones set
                               (iv_tail.comp) */
    lpv_switch filter;      /* after the last bounce, each surface voxel takes the mean of those beside
                               it on its plane (LPV_IV_FILTER) */
    lpv_switch reprojection; /* the camera's visible points refine the volume */
    int neighbours;         /* the reconstruction blends the nearest this many of the 8 voxels around
                               the shifted point: 6 (the paper's text) .. 8 (its figure 2) */
    lpv_switch ao;          /* ambient occlusion volume */
    float ao_distance;      /* m, the AO rays' reach; 0 (default) = LPV_IV_AO_VOXELS voxels */
    int max_points;         /* the point cloud's budget: more triangles x points get fewer points per
                               triangle (the plan says so) */
} lpv_iv_settings;

#endif
