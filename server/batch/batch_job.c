/* batch_job.c - see batch_job.h. */
#include "batch_job.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "engine.h"
#include "error.h"
#include "light_json.h"
#include "proto.h"
#include "settings_fields.h"
#include "settings_json.h"
#include "tick_cost.h"

static char *dup_str(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

/* A name becomes part of item ids and output paths: letters, digits, '.',
 * '_' and '-', not starting with '.', 1..63 characters. */
static int take_name(const json_t *o, const char *where, const char *deflt, char out[LPVD_BATCH_NAME_MAX], char *err,
                     size_t n)
{
    const json_t *v = json_object_get(o, "name");
    const char *s = deflt;
    if (v) {
        if (!json_is_string(v))
            return lpv_error(err, n, "%s.name: expected a string", where);
        s = json_string_value(v);
    }
    if (!s)
        return lpv_error(err, n, "%s.name: required", where);
    size_t len = strlen(s);
    if (len == 0 || len >= LPVD_BATCH_NAME_MAX || s[0] == '.')
        return lpv_error(err, n, "%s.name: must be 1..%d characters, not starting with '.'", where, LPVD_BATCH_NAME_MAX - 1);
    for (size_t i = 0; i < len; ++i) {
        char c = s[i];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
              c == '-'))
            return lpv_error(err, n, "%s.name: \"%s\" may hold only letters, digits, '.', '_' and '-' (it names files)",
                        where, s);
    }
    memcpy(out, s, len + 1);
    return 0;
}

/* A path inside the job's folder: relative, no "..", no empty part. */
static int take_path(const json_t *v, const char *where, char **out, char *err, size_t n)
{
    if (!json_is_string(v))
        return lpv_error(err, n, "%s: expected a string path", where);
    const char *s = json_string_value(v);
    if (s[0] == '\0' || s[0] == '/')
        return lpv_error(err, n, "%s: must be a path relative to the job file's folder", where);
    for (const char *p = s; *p;) {
        const char *e = strchr(p, '/');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        if (len == 0 || (len == 2 && p[0] == '.' && p[1] == '.'))
            return lpv_error(err, n, "%s: \"%s\" leaves the job file's folder or has an empty part", where, s);
        p += len + (e ? 1 : 0);
    }
    *out = dup_str(s);
    return *out ? 0 : lpv_error(err, n, "out of memory");
}

/* Checks that o has only the keys in allowed (NULL-terminated). */
static int only_keys(const json_t *o, const char *where, const char *const *allowed, char *err, size_t n)
{
    const char *key;
    json_t *v;
    json_object_foreach((json_t *)o, key, v)
    {
        (void)v;
        int ok = 0;
        for (const char *const *a = allowed; *a && !ok; ++a)
            ok = strcmp(*a, key) == 0;
        if (!ok)
            return lpv_error(err, n, "%s: unknown key \"%s\"", where, key);
    }
    return 0;
}

static int take_floats(const json_t *o, const char *key, const char *where, int count, float *out, char *err, size_t n)
{
    char why[256];
    int rc = lpvp_get_floats(o, key, 1, (size_t)count, -LPV_MAX_COORD, LPV_MAX_COORD, out, why, sizeof why);
    return rc == LPVP_FIELD_OK ? 0 : lpv_error(err, n, "%s.%s", where, why);
}

/* ---- cameras ----------------------------------------------------------------- */

static int parse_camera(const json_t *c, const char *where, lpvd_batch_camera *out, int *views, char *err, size_t n)
{
    static const char *const KEYS[] = {"name", "camera", "eye", "target", "fov_deg", "orbit", NULL};
    memset(out, 0, sizeof *out);
    *views = 1;
    if (!json_is_object(c))
        return lpv_error(err, n, "%s: expected an object", where);
    if (only_keys(c, where, KEYS, err, n) != 0 || take_name(c, where, "default", out->name, err, n) != 0)
        return -1;
    const json_t *cam = json_object_get(c, "camera"), *orbit = json_object_get(c, "orbit");
    const json_t *eye = json_object_get(c, "eye"), *fov = json_object_get(c, "fov_deg");
    if (!!cam + !!orbit + !!eye > 1)
        return lpv_error(err, n, "%s: give one of camera, eye/target and orbit", where);
    if (fov) {
        if (!json_is_number(fov) || !(json_number_value(fov) > 0.0 && json_number_value(fov) < 180.0))
            return lpv_error(err, n, "%s.fov_deg: expected a number in (0, 180)", where);
        out->choice.has_fov = 1;
        out->choice.fov_deg = (float)json_number_value(fov);
    }
    if (cam) {
        char buf[32];
        const char *s;
        if (json_is_integer(cam) && json_integer_value(cam) >= 0 && json_integer_value(cam) < INT_MAX) {
            snprintf(buf, sizeof buf, "%lld", (long long)json_integer_value(cam));
            s = buf;
        } else if (json_is_string(cam) && json_string_length(cam) > 0 &&
                   json_string_length(cam) < LPVD_BATCH_NAME_MAX) {
            s = json_string_value(cam);
        } else {
            return lpv_error(err, n, "%s.camera: expected the file's camera index or name", where);
        }
        snprintf(out->camera_name, sizeof out->camera_name, "%s", s);
    } else if (eye) {
        if (take_floats(c, "eye", where, 3, out->choice.eye, err, n) != 0 ||
            take_floats(c, "target", where, 3, out->choice.target, err, n) != 0)
            return -1;
        out->choice.has_eye = out->choice.has_target = 1;
    } else if (json_object_get(c, "target")) {
        return lpv_error(err, n, "%s.target: needs eye", where);
    } else if (orbit) {
        static const char *const OKEYS[] = {"views", "elevation_deg", "distance", NULL};
        char w[160];
        snprintf(w, sizeof w, "%s.orbit", where);
        if (!json_is_object(orbit) || only_keys(orbit, w, OKEYS, err, n) != 0)
            return json_is_object(orbit) ? -1 : lpv_error(err, n, "%s: expected an object", w);
        int64_t v = 8;
        double el = 25.0, dist = 0.0;
        char why[256];
        if (lpvp_get_int(orbit, "views", 0, 1, 3600, &v, why, sizeof why) == LPVP_FIELD_BAD ||
            lpvp_get_number(orbit, "elevation_deg", 0, -89.0, 89.0, &el, why, sizeof why) == LPVP_FIELD_BAD ||
            lpvp_get_number(orbit, "distance", 0, 0.0, LPV_MAX_COORD, &dist, why, sizeof why) == LPVP_FIELD_BAD)
            return lpv_error(err, n, "%s.%s", w, why);
        out->orbit_n = (int)v;
        out->orbit_elevation_deg = (float)el;
        out->orbit_distance = (float)dist;
        out->orbit_fov_deg = out->choice.has_fov ? out->choice.fov_deg : 45.0f;
        *views = (int)v;
    }
    return 0;
}

/* The camera list c (NULL: one default camera) expanded (orbits into their
 * views, named NAME-K). */
static int expand_cameras(const json_t *c, const char *where, lpvd_batch_camera **out, int *count, char *err, size_t n)
{
    *out = NULL;
    *count = 0;
    json_t *def = NULL;
    if (!c) {
        def = json_pack("[{}]");
        c = def;
    }
    int rc = -1;
    if (!json_is_array(c) || json_array_size(c) == 0) {
        lpv_error(err, n, "%s: expected a non-empty array", where);
        goto done;
    }
    size_t total = 0;
    lpvd_batch_camera one;
    for (size_t i = 0; i < json_array_size(c); ++i) {
        char w[128];
        int views;
        snprintf(w, sizeof w, "%s[%zu]", where, i);
        if (parse_camera(json_array_get(c, i), w, &one, &views, err, n) != 0)
            goto done;
        total += (size_t)views;
    }
    if (total > LPVD_BATCH_MAX_ITEMS) {
        lpv_error(err, n, "%s: %zu views, more than %d", where, total, LPVD_BATCH_MAX_ITEMS);
        goto done;
    }
    *out = calloc(total, sizeof **out);
    if (!*out) {
        lpv_error(err, n, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < json_array_size(c); ++i) {
        int views;
        parse_camera(json_array_get(c, i), "", &one, &views, err, n);
        for (int k = 0; k < views; ++k) {
            lpvd_batch_camera *d = &(*out)[(*count)++];
            *d = one;
            if (one.orbit_n) {
                d->orbit_k = k;
                char named[LPVD_BATCH_NAME_MAX + 16]; /* a name of <= 57 characters + "-3599" */
                snprintf(named, sizeof named, "%.57s-%d", one.name, k);
                memcpy(d->name, named, LPVD_BATCH_NAME_MAX - 1);
                d->name[LPVD_BATCH_NAME_MAX - 1] = '\0';
            }
            for (int j = 0; j < *count - 1; ++j)
                if (strcmp((*out)[j].name, d->name) == 0) {
                    lpv_error(err, n, "%s: two cameras are named \"%s\"", where, d->name);
                    goto done;
                }
        }
    }
    rc = 0;
done:
    json_decref(def);
    if (rc != 0) {
        free(*out);
        *out = NULL;
        *count = 0;
    }
    return rc;
}

/* ---- the other lists ----------------------------------------------------------- */

static int parse_scene(const json_t *s, const char *where, lpvd_batch_scene *out, char *err, size_t n)
{
    static const char *const KEYS[] = {"name", "path", "cameras", "animation", "times", NULL};
    if (!json_is_object(s))
        return lpv_error(err, n, "%s: expected an object", where);
    if (only_keys(s, where, KEYS, err, n) != 0)
        return -1;
    const json_t *path = json_object_get(s, "path");
    char w[160];
    snprintf(w, sizeof w, "%s.path", where);
    if (path && take_path(path, w, &out->path, err, n) != 0)
        return -1;
    char deflt[LPVD_BATCH_NAME_MAX] = "cornell";
    if (out->path) { /* the file's name without its folder and extension */
        const char *b = strrchr(out->path, '/');
        b = b ? b + 1 : out->path;
        snprintf(deflt, sizeof deflt, "%.*s", (int)strcspn(b, "."), b);
    }
    if (take_name(s, where, deflt, out->name, err, n) != 0)
        return -1;
    const json_t *anim = json_object_get(s, "animation"), *times = json_object_get(s, "times");
    if (anim) {
        char buf[32];
        if (json_is_integer(anim) && json_integer_value(anim) >= 0 && json_integer_value(anim) < INT_MAX)
            snprintf(buf, sizeof buf, "%lld", (long long)json_integer_value(anim));
        else if (!json_is_string(anim) || json_string_length(anim) == 0)
            return lpv_error(err, n, "%s.animation: expected the animation's index or name", where);
        out->animation = dup_str(json_is_string(anim) ? json_string_value(anim) : buf);
        if (!times)
            return lpv_error(err, n, "%s.animation: needs times", where);
    }
    if (times) {
        if (!out->path)
            return lpv_error(err, n, "%s.times: the built-in scene has no animations", where);
        if (!json_is_array(times) || json_array_size(times) == 0 || json_array_size(times) > 100000)
            return lpv_error(err, n, "%s.times: expected a non-empty array of seconds", where);
        out->time_count = (int)json_array_size(times);
        out->times = calloc((size_t)out->time_count, sizeof *out->times);
        if (!out->times)
            return lpv_error(err, n, "out of memory");
        for (int i = 0; i < out->time_count; ++i) {
            const json_t *t = json_array_get(times, (size_t)i);
            double v = json_is_number(t) ? json_number_value(t) : -1.0;
            if (!(v >= 0.0 && v <= 1e9))
                return lpv_error(err, n, "%s.times[%d]: expected seconds, 0..1e9", where, i);
            if (i > 0 && !(v > out->times[i - 1]))
                return lpv_error(err, n, "%s.times[%d]: times must increase (each names its items)", where, i);
            out->times[i] = v;
        }
    }
    const json_t *cams = json_object_get(s, "cameras");
    if (cams)
        out->cameras = json_incref((json_t *)cams);
    return 0;
}

static int parse_lights(const json_t *l, const char *where, lpvd_batch_lights *out, char *err, size_t n)
{
    static const char *const KEYS[] = {"name", "lights", NULL};
    if (!json_is_object(l))
        return lpv_error(err, n, "%s: expected an object", where);
    if (only_keys(l, where, KEYS, err, n) != 0 || take_name(l, where, "file", out->name, err, n) != 0)
        return -1;
    const json_t *list = json_object_get(l, "lights");
    if (!list) {
        out->use_file = 1;
        return 0;
    }
    if (!json_is_array(list) || json_array_size(list) > 256)
        return lpv_error(err, n, "%s.lights: expected an array of at most 256 lights (LIGHT_SET bodies)", where);
    out->count = (int)json_array_size(list);
    out->lights = calloc((size_t)out->count + 1, sizeof *out->lights);
    if (!out->lights)
        return lpv_error(err, n, "out of memory");
    for (int i = 0; i < out->count; ++i) {
        char why[512];
        if (lpvd_light_from_json(json_array_get(list, (size_t)i), &out->lights[i], why, sizeof why) != 0)
            return lpv_error(err, n, "%s.lights[%d].%s", where, i, why);
    }
    return 0;
}

static int parse_settings(const json_t *s, const char *where, lpvd_batch_settings *out, char *err, size_t n)
{
    if (!json_is_object(s))
        return lpv_error(err, n, "%s: expected an object", where);
    if (take_name(s, where, "default", out->name, err, n) != 0)
        return -1;
    const char *key;
    json_t *v;
    json_object_foreach((json_t *)s, key, v)
    {
        (void)v;
        if (strcmp(key, "name") != 0 && strcmp(key, "preset") != 0 && strcmp(key, "technique") != 0 &&
            strcmp(key, "grid") != 0 && strcmp(key, "bounds") != 0 && !lpv_field_by_key(key))
            return lpv_error(err, n, "%s: unknown key \"%s\" (the settings are CONFIG's, docs/protocol.md)", where, key);
    }
    const lpvd_settings_limits none = {INT_MAX, INT_MAX};
    char why[512];
    memset(&out->settings, 0, sizeof out->settings);
    if (lpvd_settings_apply_json(s, &out->settings, &none, why, sizeof why) != LPVD_SETTINGS_OK)
        return lpv_error(err, n, "%s.%s", where, why);
    lpv_settings chk = out->settings;
    lpv_settings_resolve(&chk);
    if (lpv_settings_validate(&chk, why, sizeof why) != 0)
        return lpv_error(err, n, "%s: %s", where, why);
    out->json = json_deep_copy(s);
    json_object_del(out->json, "name");
    return 0;
}

static int parse_outputs(const json_t *o, lpvd_batch_job *job, char *err, size_t n)
{
    if (!o) {
        job->outputs = LPVD_OUT_PNG;
        return 0;
    }
    if (!json_is_array(o) || json_array_size(o) == 0)
        return lpv_error(err, n, "outputs: expected a non-empty array");
    for (size_t i = 0; i < json_array_size(o); ++i) {
        const json_t *v = json_array_get(o, i);
        if (json_is_object(v) && json_object_size(v) == 1 && json_object_get(v, "points")) {
            char w[64];
            snprintf(w, sizeof w, "outputs[%zu].points", i);
            free(job->points_path);
            job->points_path = NULL;
            if (take_path(json_object_get(v, "points"), w, &job->points_path, err, n) != 0)
                return -1;
            job->outputs |= LPVD_OUT_POINTS;
            continue;
        }
        const char *s = json_is_string(v) ? json_string_value(v) : "";
        if (strcmp(s, "png") == 0)
            job->outputs |= LPVD_OUT_PNG;
        else if (strcmp(s, "exr") == 0)
            job->outputs |= LPVD_OUT_EXR;
        else if (strcmp(s, "ao") == 0)
            job->outputs |= LPVD_OUT_AO;
        else if (strcmp(s, "volume") == 0)
            job->outputs |= LPVD_OUT_VOLUME;
        else
            return lpv_error(err, n, "outputs[%zu]: expected \"png\", \"exr\", \"ao\", \"volume\" or {\"points\": PATH}",
                        i);
    }
    return 0;
}

/* ---- the job --------------------------------------------------------------------- */

static int parse_list(const json_t *root, const char *key, size_t elem, void **out, int *count, char *err, size_t n,
                      int (*fn)(const json_t *, const char *, void *, char *, size_t), const char *deflt)
{
    const json_t *a = json_object_get(root, key);
    json_t *d = NULL;
    if (!a && deflt) {
        d = json_loads(deflt, 0, NULL);
        a = d;
    }
    int rc = -1;
    if (!json_is_array(a) || json_array_size(a) == 0 || json_array_size(a) > 100000) {
        lpv_error(err, n, "%s: expected a non-empty array", key);
        goto done;
    }
    *count = (int)json_array_size(a);
    *out = calloc((size_t)*count, elem);
    if (!*out) {
        lpv_error(err, n, "out of memory");
        goto done;
    }
    for (int i = 0; i < *count; ++i) {
        char w[64];
        snprintf(w, sizeof w, "%s[%d]", key, i);
        if (fn(json_array_get(a, (size_t)i), w, (char *)*out + (size_t)i * elem, err, n) != 0)
            goto done;
        for (int j = 0; j < i; ++j) /* every kind starts with its name */
            if (strcmp((char *)*out + (size_t)j * elem, (char *)*out + (size_t)i * elem) == 0) {
                lpv_error(err, n, "%s: two entries are named \"%s\"", key, (char *)*out + (size_t)i * elem);
                goto done;
            }
    }
    rc = 0;
done:
    json_decref(d);
    return rc;
}

static int scene_fn(const json_t *j, const char *w, void *o, char *e, size_t n) { return parse_scene(j, w, o, e, n); }
static int lights_fn(const json_t *j, const char *w, void *o, char *e, size_t n) { return parse_lights(j, w, o, e, n); }
static int settings_fn(const json_t *j, const char *w, void *o, char *e, size_t n)
{
    return parse_settings(j, w, o, e, n);
}

static int expand(lpvd_batch_job *job, char *err, size_t n)
{
    size_t total = 0;
    for (int s = 0; s < job->scene_count; ++s) {
        int times = job->scenes[s].time_count ? job->scenes[s].time_count : 1;
        total += (size_t)times * (size_t)job->camera_count[s] * (size_t)job->lights_count * (size_t)job->settings_count;
        if (total > LPVD_BATCH_MAX_ITEMS)
            return lpv_error(err, n, "the job expands to more than %d items", LPVD_BATCH_MAX_ITEMS);
    }
    job->items = calloc(total ? total : 1, sizeof *job->items);
    if (!job->items)
        return lpv_error(err, n, "out of memory");
    double pixels = (double)job->width * job->height;
    for (int s = 0; s < job->scene_count; ++s) {
        const lpvd_batch_scene *sc = &job->scenes[s];
        int times = sc->time_count ? sc->time_count : 1;
        for (int t = 0; t < times; ++t)
            for (int l = 0; l < job->lights_count; ++l)
                for (int q = 0; q < job->settings_count; ++q) {
                    lpv_settings st = job->settings[q].settings;
                    lpv_settings_resolve(&st);
                    lpv_tick_cost tc;
                    lpv_tick_cost_estimate(&st, &tc);
                    for (int c = 0; c < job->camera_count[s]; ++c) {
                        lpvd_batch_item *it = &job->items[job->item_count];
                        it->index = job->item_count++;
                        it->scene = s;
                        it->time = sc->time_count ? t : -1;
                        it->camera = c;
                        it->lights = l;
                        it->settings = q;
                        it->cost = tc.cell_steps + 16.0 * pixels;
                        char tb[48] = "";
                        if (sc->time_count)
                            snprintf(tb, sizeof tb, "@%.9g", sc->times[t]);
                        snprintf(it->id, sizeof it->id, "%s%s/%s/%s/%s", sc->name, tb, job->cameras[s][c].name,
                                 job->lights[l].name, job->settings[q].name);
                    }
                }
    }
    return 0;
}

int lpvd_batch_job_load(const char *path, lpvd_batch_job *job, char *err, size_t n)
{
    static const char *const KEYS[] = {"lpvd_batch", "size",    "scenes", "cameras",  "lights", "settings",
                                       "outputs",    "terms",   "exposure", "background", NULL};
    memset(job, 0, sizeof *job);
    lpv_display_default(&job->display);
    json_error_t je;
    json_t *root = json_load_file(path, JSON_REJECT_DUPLICATES, &je);
    if (!root)
        return lpv_error(err, n, "%s:%d: %s", path, je.line, je.text);
    int rc = -1;
    char why[512];
    const char *slash = strrchr(path, '/');
    job->dir = slash ? strndup(path, (size_t)(slash - path) + (slash == path)) : dup_str(".");
    if (!json_is_object(root)) {
        lpv_error(err, n, "%s: expected a JSON object", path);
        goto done;
    }
    if (only_keys(root, "job", KEYS, why, sizeof why) != 0) {
        lpv_error(err, n, "%s: %s", path, why);
        goto done;
    }
    int64_t version = 0, size[2] = {512, 512};
    if (lpvp_get_int(root, "lpvd_batch", 1, 1, 1, &version, why, sizeof why) != LPVP_FIELD_OK ||
        lpvp_get_ints(root, "size", 0, 2, 1, 8192, size, why, sizeof why) == LPVP_FIELD_BAD) {
        lpv_error(err, n, "%s: %s", path, why);
        goto done;
    }
    job->width = (int)size[0];
    job->height = (int)size[1];
    static const char *const TERMS[] = {"full", "indirect", "direct"};
    int terms = 0;
    if (lpvp_get_enum(root, "terms", 0, TERMS, 3, &terms, why, sizeof why) == LPVP_FIELD_BAD) {
        lpv_error(err, n, "%s: %s", path, why);
        goto done;
    }
    job->terms = terms == 0 ? LPV_TERMS_FULL : terms == 1 ? LPV_TERMS_INDIRECT_ONLY : LPV_TERMS_DIRECT_ONLY;
    const json_t *ex = json_object_get(root, "exposure");
    if (ex) {
        char buf[64];
        if (json_is_number(ex))
            snprintf(buf, sizeof buf, "%.9g", json_number_value(ex));
        else
            snprintf(buf, sizeof buf, "%s", json_is_string(ex) ? json_string_value(ex) : "?");
        if (lpv_exposure_parse(buf, &job->display, why, sizeof why) != 0) {
            lpv_error(err, n, "%s: exposure: %s", path, why);
            goto done;
        }
    }
    if (lpvp_get_floats(root, "background", 0, 3, 0.0, 1.0, job->display.background, why, sizeof why) ==
            LPVP_FIELD_BAD ||
        parse_outputs(json_object_get(root, "outputs"), job, why, sizeof why) != 0 ||
        parse_list(root, "scenes", sizeof(lpvd_batch_scene), (void **)&job->scenes, &job->scene_count, why,
                   sizeof why, scene_fn, "[{}]") != 0 ||
        parse_list(root, "lights", sizeof(lpvd_batch_lights), (void **)&job->lights, &job->lights_count, why,
                   sizeof why, lights_fn, "[{}]") != 0 ||
        parse_list(root, "settings", sizeof(lpvd_batch_settings), (void **)&job->settings, &job->settings_count, why,
                   sizeof why, settings_fn, "[{}]") != 0) {
        lpv_error(err, n, "%s: %s", path, why);
        goto done;
    }
    job->cameras = calloc((size_t)job->scene_count, sizeof *job->cameras);
    job->camera_count = calloc((size_t)job->scene_count, sizeof *job->camera_count);
    if (!job->cameras || !job->camera_count) {
        lpv_error(err, n, "out of memory");
        goto done;
    }
    for (int s = 0; s < job->scene_count; ++s) {
        const json_t *own = job->scenes[s].cameras;
        char w[64];
        snprintf(w, sizeof w, own ? "scenes[%d].cameras" : "cameras", s);
        if (expand_cameras(own ? own : json_object_get(root, "cameras"), w, &job->cameras[s], &job->camera_count[s],
                           why, sizeof why) != 0) {
            lpv_error(err, n, "%s: %s", path, why);
            goto done;
        }
    }
    if (expand(job, why, sizeof why) != 0) {
        lpv_error(err, n, "%s: %s", path, why);
        goto done;
    }
    rc = 0;
done:
    json_decref(root);
    if (rc != 0)
        lpvd_batch_job_free(job);
    return rc;
}

void lpvd_batch_job_free(lpvd_batch_job *job)
{
    for (int s = 0; s < job->scene_count; ++s) {
        free(job->scenes[s].path);
        free(job->scenes[s].animation);
        free(job->scenes[s].times);
        json_decref(job->scenes[s].cameras);
        if (job->cameras)
            free(job->cameras[s]);
    }
    for (int l = 0; l < job->lights_count; ++l)
        free(job->lights[l].lights);
    for (int q = 0; q < job->settings_count; ++q)
        json_decref(job->settings[q].json);
    free(job->scenes);
    free(job->cameras);
    free(job->camera_count);
    free(job->lights);
    free(job->settings);
    free(job->items);
    free(job->points_path);
    free(job->dir);
    memset(job, 0, sizeof *job);
}
