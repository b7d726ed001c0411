/* batch_render.c - see batch_render.h. */
#include "batch_render.h"

#include <errno.h>
#include <fcntl.h>
#include <glob.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "engine.h"
#include "error.h"
#include "image_io.h"
#include "memory_limits.h"
#include "points_csv.h"

#include "scene_load.h"
#include "export.h"
#include "stats_json.h"
#include "tonemap.h"
#include "write_beneath.h"

/* The volume as GET_VOLUME would send it, between its two files' writers. */
typedef struct volume_out {
    json_t *body;
    uint8_t *att;
    size_t att_len;
} volume_out;

struct lpvd_batch_renderer {
    const lpvd_batch_job *job;
    char out[PATH_MAX];
    int out_fd; /* --out, opened once: every output is written beneath it (core/write_beneath.h) */
    char root[PATH_MAX]; /* the job folder, resolved: scenes and points stay inside */
    lpv_gl_context *ctx;
    lpv_engine *engine;
    lpv_scene scene; /* the loaded one */
    int scene_index, scene_time; /* which (-1: none) */
    int engine_scene, engine_lights; /* what the engine was last given (-1: nothing) */
    float *points, *normals; /* LPVD_OUT_POINTS: 3 floats each */
    size_t point_count;
    float *rgba;
    uint8_t *rgba8;
    volume_out vol;
    lpv_view last_view; /* the engine's view (has_view: set) */
    int has_view;
};

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return 1e3 * (double)t.tv_sec + 1e-6 * (double)t.tv_nsec;
}

static json_t *wall_time(void)
{
    struct timespec t;
    clock_gettime(CLOCK_REALTIME, &t);
    struct tm tm;
    gmtime_r(&t.tv_sec, &tm);
    char buf[64], out[80];
    strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
    snprintf(out, sizeof out, "%s.%03ldZ", buf, t.tv_nsec / 1000000L);
    return json_string(out);
}

/* dir/rel, resolved, must lie inside root (no symbolic link out of it either). */
static int inside(const char *root, const char *dir, const char *rel, char out[PATH_MAX], char *err, size_t n)
{
    char joined[2 * PATH_MAX];
    snprintf(joined, sizeof joined, "%s/%s", dir, rel);
    if (!realpath(joined, out))
        return lpv_error(err, n, "%s: %s", rel, strerror(errno));
    size_t len = strlen(root);
    if (strncmp(out, root, len) != 0 || (out[len] != '/' && out[len] != '\0'))
        return lpv_error(err, n, "%s: leaves the job file's folder", rel);
    return 0;
}

/* The points file (core/points_csv.h), read once for every item; values
 * must be finite and within LPV_MAX_COORD. */
static int load_points(lpvd_batch_renderer *r, const char *path, char *err, size_t n)
{
    /* O_NONBLOCK and a regular file only: a FIFO there would block the batch
     * for good (issue 31, item 9) */
    const int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return lpv_error(err, n, "points %s: %s", r->job->points_path, strerror(errno));
    struct stat st = {0};
    FILE *f = NULL;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || fcntl(fd, F_SETFL, 0) != 0 || !(f = fdopen(fd, "r"))) {
        const int e = errno;
        close(fd);
        return lpv_error(err, n, "points %s: %s", r->job->points_path,
                         S_ISREG(st.st_mode) ? strerror(e) : "not a regular file (a FIFO, a device or a folder)");
    }
    long got = lpv_points_csv_read(f, r->job->points_path, &r->points, &r->normals, err, n);
    fclose(f);
    if (got < 0)
        return -1;
    r->point_count = (size_t)got;
    for (size_t i = 0; i < 3 * r->point_count; ++i)
        if (!isfinite(r->points[i]) || fabsf(r->points[i]) > LPV_MAX_COORD || !isfinite(r->normals[i]) ||
            fabsf(r->normals[i]) > LPV_MAX_COORD)
            return lpv_error(err, n, "points %s: point %zu: values must be finite, within 1e9", r->job->points_path,
                             i / 3 + 1);
    return 0;
}

lpvd_batch_renderer *lpvd_batch_renderer_create(const lpvd_batch_job *job, lpv_backend backend, const char *out_dir,
                                                char *err, size_t n)
{
    lpvd_batch_renderer *r = calloc(1, sizeof *r);
    if (!r) {
        lpv_error(err, n, "out of memory");
        return NULL;
    }
    r->job = job;
    r->scene_index = r->scene_time = r->engine_scene = r->engine_lights = -1;
    snprintf(r->out, sizeof r->out, "%s", out_dir);
    r->out_fd = open(out_dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (r->out_fd < 0) {
        lpv_error(err, n, "%s: %s", out_dir, strerror(errno));
        goto bad;
    }
    if (!realpath(job->dir, r->root)) {
        lpv_error(err, n, "%s: %s", job->dir, strerror(errno));
        goto bad;
    }
    if (job->outputs & LPVD_OUT_POINTS) {
        char path[PATH_MAX];
        if (inside(r->root, job->dir, job->points_path, path, err, n) != 0 || load_points(r, path, err, n) != 0)
            goto bad;
    }
    size_t pixels = (size_t)job->width * (size_t)job->height;
    r->rgba = malloc(pixels * 4 * sizeof *r->rgba);
    r->rgba8 = malloc(pixels * 4);
    if (!r->rgba || !r->rgba8) {
        lpv_error(err, n, "out of memory for %dx%d images", job->width, job->height);
        goto bad;
    }
    lpv_gl_context_desc desc = {.backend = backend};
    r->ctx = lpv_gl_context_create(&desc, err, n);
    if (!r->ctx)
        goto bad;
    fprintf(stderr, "lpvd batch: backend %s, GL_RENDERER %s\n", lpv_backend_name(lpv_gl_context_backend(r->ctx)),
            lpv_gl_context_renderer(r->ctx));
    r->engine = lpv_engine_create(err, n);
    if (!r->engine)
        goto bad;
    { /* a size whose frame this GL can never hold fails every item: say so once, before any (issue 31, item 11) */
        lpv_memory_limits lim;
        lpv_memory_limits_query(&lim);
        const lpv_memory_need need = {.image_w = job->width, .image_h = job->height};
        char why[512];
        if (lpv_memory_check(&need, &lim, why, sizeof why) != 0) {
            lpv_error(err, n, "size %dx%d: %s", job->width, job->height, why);
            goto bad;
        }
    }
    return r;
bad:
    lpvd_batch_renderer_destroy(r);
    return NULL;
}

void lpvd_batch_renderer_destroy(lpvd_batch_renderer *r)
{
    if (!r)
        return;
    lpv_engine_destroy(r->engine);
    lpv_gl_context_destroy(r->ctx);
    if (r->out_fd > 0)
        close(r->out_fd);
    lpv_scene_free(&r->scene);
    free(r->points);
    free(r->normals);
    free(r->rgba);
    free(r->rgba8);
    free(r);
}

/* The item's scene at its time, loaded unless it already is. */
static int use_scene(lpvd_batch_renderer *r, const lpvd_batch_item *it, char *err, size_t n)
{
    if (r->scene_index == it->scene && r->scene_time == it->time)
        return 0;
    lpv_scene_free(&r->scene);
    r->scene_index = r->scene_time = r->engine_scene = -1;
    const lpvd_batch_scene *s = &r->job->scenes[it->scene];
    char path[PATH_MAX];
    if (s->path && inside(r->root, r->job->dir, s->path, path, err, n) != 0)
        return -1;
    int rc;
    if (!s->path) {
        rc = lpv_scene_load(NULL, &r->scene, err, n); /* the built-in Cornell box */
    } else if (it->time >= 0) {
        lpv_gltf_animation_time at = {.animation = s->animation, .time = s->times[it->time]};
        rc = lpv_scene_load_animated(path, &at, &r->scene, err, n);
    } else {
        rc = lpv_scene_load(path, &r->scene, err, n);
    }
    if (rc != 0)
        return -1;
    r->scene_index = it->scene;
    r->scene_time = it->time;
    return 0;
}

/* View k of an orbit of n around the scene's bounds. */
static int orbit_view(const lpvd_batch_camera *c, const lpv_scene *s, int w, int h, lpv_view *v)
{
    float centre[3], radius = 0.0f;
    for (int i = 0; i < 3; ++i) {
        centre[i] = 0.5f * (s->bounds_min[i] + s->bounds_max[i]);
        float e = 0.5f * (s->bounds_max[i] - s->bounds_min[i]);
        radius += e * e;
    }
    radius = sqrtf(radius);
    float fov = c->orbit_fov_deg * (float)(M_PI / 180.0);
    float d = c->orbit_distance > 0.0f ? c->orbit_distance : 1.05f * radius / sinf(0.5f * fov);
    if (!(d > 0.0f))
        d = 1.0f;
    double az = 2.0 * M_PI * c->orbit_k / c->orbit_n, el = c->orbit_elevation_deg * M_PI / 180.0;
    float eye[3] = {centre[0] + d * (float)(cos(el) * sin(az)), centre[1] + d * (float)sin(el),
                    centre[2] + d * (float)(cos(el) * cos(az))};
    return lpv_view_look_at(eye, centre, fov, w, h, v);
}

/* out/rel, written by fn to a temporary name in the same folder with the
 * same extension, then renamed; never through a link (core/write_beneath.h). */
typedef int (*writer)(lpvd_batch_renderer *r, const char *path, char *err, size_t n);

typedef struct write_call {
    lpvd_batch_renderer *r;
    writer fn;
} write_call;

static int call_writer(const char *path, void *arg, char *err, size_t n)
{
    const write_call *c = arg;
    return c->fn(c->r, path, err, n);
}

/* What a process killed while writing rel left (SIGKILL, a lost node):
 * never an output, since only the manifest says what is done; removed here,
 * as no other process renders this item at the same time. */
static void remove_leftovers(lpvd_batch_renderer *r, const char *rel)
{
    const char *slash = strrchr(rel, '/'), *name = slash ? slash + 1 : rel;
    char folder[PATH_MAX], pattern[2 * PATH_MAX];
    snprintf(folder, sizeof folder, "%.*s", slash ? (int)(slash - rel) : 0, rel);
    const int fd = lpv_dir_make_beneath(r->out_fd, folder);
    if (fd < 0)
        return; /* the write says why */
    const char *ext = strrchr(name, '.');
    if (!ext || ext == name)
        ext = name + strlen(name);
    char leftover[PATH_MAX];
    snprintf(leftover, sizeof leftover, "%.*s.tmp-*%s", (int)(ext - name), name, ext);
    glob_t g;
    if (lpv_fd_path(fd, leftover, pattern, sizeof pattern) == 0 &&
        glob(pattern, GLOB_NOSORT | GLOB_NOESCAPE, NULL, &g) == 0) {
        for (size_t i = 0; i < g.gl_pathc; ++i)
            unlinkat(fd, strrchr(g.gl_pathv[i], '/') + 1, 0);
        globfree(&g);
    }
    close(fd);
}

static int write_atomic(lpvd_batch_renderer *r, const char *rel, writer fn, json_t *outputs, const char *kind,
                        char *err, size_t n)
{
    remove_leftovers(r, rel);
    write_call c = {.r = r, .fn = fn};
    if (lpv_write_beneath(r->out_fd, rel, call_writer, &c, err, n) != 0)
        return -1;
    json_array_append_new(outputs, json_pack("{s:s, s:s}", "kind", kind, "path", rel));
    return 0;
}

static int w_png(lpvd_batch_renderer *r, const char *path, char *err, size_t n)
{
    size_t pixels = (size_t)r->job->width * (size_t)r->job->height;
    lpv_display_rgba8(r->rgba, pixels, &r->job->display, r->rgba8);
    return lpv_image_write_u8(path, r->job->width, r->job->height, 4, r->rgba8, err, n);
}

static int w_exr(lpvd_batch_renderer *r, const char *path, char *err, size_t n)
{
    return lpv_image_write_f32(path, r->job->width, r->job->height, 4, r->rgba, err, n);
}

static int w_ao(lpvd_batch_renderer *r, const char *path, char *err, size_t n)
{
    if (lpv_engine_render(r->engine, LPV_TERMS_AO, r->rgba, err, n) != 0)
        return -1;
    size_t pixels = (size_t)r->job->width * (size_t)r->job->height;
    lpv_fraction_gray8(r->rgba, pixels, r->rgba8); /* as lpvd render --ao */
    return lpv_image_write_u8(path, r->job->width, r->job->height, 4, r->rgba8, err, n);
}

static int w_points(lpvd_batch_renderer *r, const char *path, char *err, size_t n)
{
    size_t np = r->point_count;
    float *rgb = malloc((np ? np : 1) * 3 * sizeof *rgb);
    int rc = -1;
    FILE *f = NULL;
    if (!rgb) {
        lpv_error(err, n, "out of memory");
        goto done;
    }
    if (np && lpv_engine_irradiance(r->engine, r->points, r->normals, np, rgb, err, n) != 0)
        goto done;
    if (!(f = fopen(path, "w"))) {
        lpv_error(err, n, "%s: %s", path, strerror(errno));
        goto done;
    }
    fprintf(f, "# irradiance E (W/m^2) of the indirect light at each point of %s\nE_r,E_g,E_b\n", r->job->points_path);
    for (size_t i = 0; i < np; ++i)
        fprintf(f, "%.9g,%.9g,%.9g\n", (double)rgb[3 * i], (double)rgb[3 * i + 1], (double)rgb[3 * i + 2]);
    rc = fclose(f) == 0 ? 0 : lpv_error(err, n, "%s: %s", path, strerror(errno));
    f = NULL;
done:
    if (f)
        fclose(f);
    free(rgb);
    return rc;
}

/* The volume as GET_VOLUME would send it (SPEC section 5: the body as JSON,
 * the attachment raw fp32, keyframe, uncompressed), read back now. */

static int w_volume_json(lpvd_batch_renderer *r, const char *path, char *err, size_t n)
{
    return json_dump_file(r->vol.body, path, JSON_INDENT(1) | JSON_SORT_KEYS) == 0
               ? 0
               : lpv_error(err, n, "%s: cannot write", path);
}

static int w_volume_bin(lpvd_batch_renderer *r, const char *path, char *err, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return lpv_error(err, n, "%s: %s", path, strerror(errno));
    int ok = fwrite(r->vol.att, 1, r->vol.att_len, f) == r->vol.att_len;
    if (fclose(f) != 0 || !ok)
        return lpv_error(err, n, "%s: cannot write", path);
    return 0;
}

static int write_volume(lpvd_batch_renderer *r, const char *id, json_t *outputs, char *err, size_t n)
{
    sv_result *res = sv_result_take(r->engine, r->job->width, r->job->height, 0, err, n);
    if (!res)
        return -1;
    memset(&r->vol, 0, sizeof r->vol);
    const sv_volume_coding fp32 = {0}; /* fp32, uncompressed */
    int rc = sv_encode_volume(res, LPVP_CONTENT_MERGED, &fp32, NULL, NULL, NULL, 0, &r->vol.body, &r->vol.att,
                              &r->vol.att_len, err, n);
    sv_result_unref(res);
    char rel[PATH_MAX];
    if (rc == 0) {
        snprintf(rel, sizeof rel, "%s-volume.bin", id);
        rc = write_atomic(r, rel, w_volume_bin, outputs, "volume", err, n);
    }
    if (rc == 0) {
        snprintf(rel, sizeof rel, "%s-volume.json", id);
        rc = write_atomic(r, rel, w_volume_json, outputs, "volume_header", err, n);
    }
    json_decref(r->vol.body);
    free(r->vol.att);
    memset(&r->vol, 0, sizeof r->vol);
    return rc;
}

/* The stats' stages as {name: gpu_ms} and its plan, into e. */
static void add_stats(lpvd_batch_renderer *r, json_t *e)
{
    json_t *st = lpvd_stats_json(r->engine, r->ctx, r->scene.source);
    json_t *stages = json_object();
    size_t i;
    json_t *s;
    json_array_foreach(json_object_get(st, "stages"), i, s)
    {
        json_object_set(stages, json_string_value(json_object_get(s, "name")), json_object_get(s, "gpu_ms"));
    }
    json_object_set_new(e, "stages", stages);
    json_object_set(e, "plan", json_object_get(st, "plan") ? json_object_get(st, "plan") : json_null());
    json_decref(st);
}

json_t *lpvd_batch_render_item(lpvd_batch_renderer *r, const lpvd_batch_item *it)
{
    const lpvd_batch_job *job = r->job;
    const lpvd_batch_scene *sc = &job->scenes[it->scene];
    const lpvd_batch_camera *cam = &job->cameras[it->scene][it->camera];
    const lpvd_batch_lights *li = &job->lights[it->lights];
    const lpvd_batch_settings *se = &job->settings[it->settings];
    json_t *e = json_pack("{s:s, s:i, s:s, s:s, s:s, s:O}", "id", it->id, "index", it->index, "scene",
                          sc->path ? sc->path : "built-in:cornell-box", "camera", cam->name, "lights", li->name,
                          "settings", se->json ? se->json : json_object());
    if (!e)
        return NULL;
    json_object_set_new(e, "settings_name", json_string(se->name));
    json_object_set_new(e, "time", it->time >= 0 ? json_real(sc->times[it->time]) : json_null());
    json_object_set_new(e, "started", wall_time());
    json_t *outputs = json_array();
    json_object_set_new(e, "outputs", outputs);
    char err[1024] = "";
    double t0 = now_ms(), t_load = 0.0, t_tick = 0.0, t_render = 0.0, t_write = 0.0;
    int ok = 0;
    lpv_settings s = se->settings;
    if ((job->outputs & LPVD_OUT_AO) && !lpv_technique_has(s.technique, LPV_CAP_AO)) { /* its knob is set below */
        snprintf(err, sizeof err, "the ao output needs technique %s (settings \"%s\")", LPV_TECHNIQUE_IV, se->name);
        goto done;
    }
    if (job->outputs & LPVD_OUT_AO)
        s.iv.ao = LPV_SWITCH_ON;
    if (use_scene(r, it, err, sizeof err) != 0)
        goto done;
    t_load = now_ms() - t0;
    lpv_view view;
    memset(&view, 0, sizeof view); /* compared whole with the last one */
    if (cam->orbit_n) {
        if (orbit_view(cam, &r->scene, job->width, job->height, &view) != 0) {
            snprintf(err, sizeof err, "camera %s: the scene's bounds give no orbit view", cam->name);
            goto done;
        }
    } else {
        lpv_view_choice choice = cam->choice;
        choice.camera = cam->camera_name[0] ? cam->camera_name : NULL;
        choice.width = job->width;
        choice.height = job->height;
        if (lpv_view_resolve(&choice, &r->scene, &view, err, sizeof err) != 0)
            goto done;
        view.width = job->width; /* the job's size, whatever the camera's aspect */
        view.height = job->height;
    }
    double t1 = now_ms();
    /* the item's scene only when it is not the engine's already */
    lpv_scene given = r->scene; /* shallow: the lights replaced for this item */
    if (!li->use_file) {
        given.lights = li->lights;
        given.light_count = (uint32_t)li->count;
    }
    const int new_scene = r->engine_scene != it->scene || r->engine_lights != it->lights;
    /* An item's image must not depend on the item before it: the planner
     * serves a cached volume when the camera moved less than a cell (the
     * daemon's trade), which here would keep the previous item's camera
     * surfels; a new view recomputes, and no item inherits the probes'
     * history (lpv_engine_forget), so every image is what `lpvd render`
     * makes of its item alone (bench/batch_throughput.py and
     * tests/batch/batch_cli.py check it). */
    const int new_view = !r->has_view || memcmp(&view, &r->last_view, sizeof view) != 0;
    const lpv_engine_item item = {.settings = &s,
                                  .scene = new_scene ? &given : NULL,
                                  .view = &view,
                                  .recompute = new_view,
                                  .forget = 1,
                                  .tick = 1};
    if (lpv_engine_run_item(r->engine, &item, err, sizeof err) != 0)
        goto done;
    r->engine_scene = it->scene;
    r->engine_lights = it->lights;
    r->last_view = view;
    r->has_view = 1;
    double t2 = now_ms();
    t_tick = t2 - t1;
    if ((job->outputs & (LPVD_OUT_PNG | LPVD_OUT_EXR)) &&
        lpv_engine_render(r->engine, (lpv_frame_terms)job->terms, r->rgba, err, sizeof err) != 0)
        goto done;
    double t3 = now_ms();
    t_render = t3 - t2;
    char rel[PATH_MAX];
    if (job->outputs & LPVD_OUT_PNG) {
        snprintf(rel, sizeof rel, "%s.png", it->id);
        if (write_atomic(r, rel, w_png, outputs, "image", err, sizeof err) != 0)
            goto done;
    }
    if (job->outputs & LPVD_OUT_EXR) {
        snprintf(rel, sizeof rel, "%s.exr", it->id);
        if (write_atomic(r, rel, w_exr, outputs, "exr", err, sizeof err) != 0)
            goto done;
    }
    if (job->outputs & LPVD_OUT_AO) {
        snprintf(rel, sizeof rel, "%s-ao.png", it->id);
        if (write_atomic(r, rel, w_ao, outputs, "ao", err, sizeof err) != 0)
            goto done;
    }
    if (job->outputs & LPVD_OUT_POINTS) {
        snprintf(rel, sizeof rel, "%s-points.csv", it->id);
        if (write_atomic(r, rel, w_points, outputs, "points", err, sizeof err) != 0)
            goto done;
    }
    if ((job->outputs & LPVD_OUT_VOLUME) && write_volume(r, it->id, outputs, err, sizeof err) != 0)
        goto done;
    t_write = now_ms() - t3;
    add_stats(r, e);
    ok = 1;
done:
    json_object_set_new(e, "status", json_string(ok ? "ok" : "failed"));
    if (!ok) {
        json_object_set_new(e, "error", json_string(err));
        r->engine_scene = -1; /* a failed item may have left the engine half set */
    }
    json_object_set_new(e, "ms", json_pack("{s:f, s:f, s:f, s:f, s:f}", "load", t_load, "tick", t_tick, "render",
                                           t_render, "write", t_write, "total", now_ms() - t0));
    json_object_set_new(e, "finished", wall_time());
    return e;
}
