/*
 * batch_job.h - lpvd batch's job file (docs/batch.md, docs/batch.schema.json):
 * scenes x animation times x cameras x lights x settings, expanded into
 * work items with stable ids, and the deterministic shard of them one
 * process renders. No GL here: `lpvd batch --list` and the sharding test
 * use it without a context.
 */
#ifndef LPVD_BATCH_JOB_H
#define LPVD_BATCH_JOB_H

#include <stddef.h>

#include <jansson.h>

#include "scene.h"
#include "settings.h"
#include "tonemap.h"
#include "view_choice.h"

#define LPVD_BATCH_NAME_MAX 64     /* a scene, camera, lights or settings name */
#define LPVD_BATCH_MAX_ITEMS 1000000 /* a job that expands to more is refused */

/* What an item writes, as bits. */
enum {
    LPVD_OUT_PNG = 1,    /* tone-mapped 8-bit sRGB image */
    LPVD_OUT_EXR = 2,    /* linear float radiance */
    LPVD_OUT_AO = 4,     /* ambient occlusion, grey PNG (technique iv) */
    LPVD_OUT_POINTS = 8, /* irradiance at the job's points, CSV */
    LPVD_OUT_VOLUME = 16, /* the SH volume: GET_VOLUME's body (JSON) and raw fp32 attachment */
};

typedef struct lpvd_batch_scene {
    char name[LPVD_BATCH_NAME_MAX];
    char *path;        /* relative to the job's folder; NULL = the built-in Cornell box */
    char *animation;   /* name or index; NULL = every animation of the file (when times are given) */
    double *times;     /* seconds; NULL = the file as it is */
    int time_count;
    json_t *cameras;   /* the scene's own camera list, or NULL = the job's */
} lpvd_batch_scene;

typedef struct lpvd_batch_camera {
    char name[LPVD_BATCH_NAME_MAX];
    lpv_view_choice choice;  /* a file camera or eye/target/fov */
    char camera_name[LPVD_BATCH_NAME_MAX];
    int orbit_k, orbit_n;    /* orbit view k of n (n 0: not an orbit) */
    float orbit_elevation_deg, orbit_fov_deg, orbit_distance; /* distance 0: frames the bounds */
} lpvd_batch_camera;

typedef struct lpvd_batch_lights {
    char name[LPVD_BATCH_NAME_MAX];
    lpv_light *lights; /* NULL with use_file: the scene's own */
    int count;
    int use_file;
} lpvd_batch_lights;

typedef struct lpvd_batch_settings {
    char name[LPVD_BATCH_NAME_MAX];
    lpv_settings settings;
    json_t *json;      /* the object as written (for the manifest) */
} lpvd_batch_settings;

typedef struct lpvd_batch_item {
    char id[4 * LPVD_BATCH_NAME_MAX + 64]; /* four names, a time and the slashes */
    int index;          /* in the job's expansion */
    int scene, time, camera, lights, settings; /* indices; time -1 = none; camera into the scene's list */
    double cost;        /* expected cost, arbitrary units (cell-steps + pixels), for sharding */
} lpvd_batch_item;

typedef struct lpvd_batch_job {
    char *dir;          /* the job file's folder: scenes and points files may not leave it */
    int width, height;
    unsigned outputs;   /* LPVD_OUT_* */
    char *points_path;  /* LPVD_OUT_POINTS: px,py,pz,nx,ny,nz lines, relative to dir */
    int terms;          /* lpv_frame_terms */
    lpv_display display; /* PNG exposure and background */
    lpvd_batch_scene *scenes;
    int scene_count;
    lpvd_batch_camera **cameras; /* per scene: its expanded camera list */
    int *camera_count;
    lpvd_batch_lights *lights;
    int lights_count;
    lpvd_batch_settings *settings;
    int settings_count;
    lpvd_batch_item *items;
    int item_count;
} lpvd_batch_job;

/* Reads and expands the job file at path. Returns 0, or -1 with a message
 * naming the key (e.g. "scenes[2].cameras[0].fov_deg: ...") in err. */
int lpvd_batch_job_load(const char *path, lpvd_batch_job *job, char *err, size_t err_size);
void lpvd_batch_job_free(lpvd_batch_job *job);

/* The items of shard i of n (0 <= i < n): whole scenes go to the least
 * loaded shard, largest first (ties: the lower shard), a scene costing more
 * than a shard's share is cut into runs of consecutive items first; the
 * same job gives the same split on every machine. mine[k] = 1 for the items
 * of shard i. Returns how many. */
int lpvd_batch_shard(const lpvd_batch_job *job, int i, int n, unsigned char *mine);

/* Parses "I/N" (0 <= I < N <= 100000). Returns 0 or -1 (message in err). */
int lpvd_batch_parse_shard(const char *text, int *i, int *n, char *err, size_t err_size);

#endif
