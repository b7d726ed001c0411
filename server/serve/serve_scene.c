/*
 * serve_scene.c - SCENE_LOAD (SPEC R4.3-R4.5) and SCENE_UPDATE. A load reads
 * and parses the .glb on a libuv worker thread (load_run) so a large scene
 * never stalls the loop, then takes it as the session's on the loop
 * (load_done); the session stays busy in between (R3.2). SCENE_UPDATE of
 * materials applies at once; of nodes, it rebuilds the scene from its bytes
 * with the node overrides through the same worker.
 */
#include "serve_session_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "gltf_load.h"
#include "open_beneath.h"
#include "scene_defaults.h"

/* The SCENE_LOAD reply's "scene". */
static json_t *scene_json(const lpv_scene *sc)
{
    return json_pack("{s:I, s:i, s:i, s:i, s:b, s:b, s:[f,f,f,f,f,f], s:s}", "triangles",
                     (json_int_t)(sc->index_count / 3), "materials", (int)sc->material_count, "lights",
                     (int)sc->light_count, "cameras", (int)sc->camera_count, "default_light", sc->default_light_added,
                     "default_camera", sc->default_camera_added, "bounds", (double)sc->bounds_min[0],
                     (double)sc->bounds_min[1], (double)sc->bounds_min[2], (double)sc->bounds_max[0],
                     (double)sc->bounds_max[1], (double)sc->bounds_max[2], "source", sc->source);
}

typedef struct load_work {
    uv_work_t req;
    struct load_work *next_wait; /* in the server's queue of loads waiting for a worker */
    int started;                 /* on a worker (counted in loads_running) */
    sv_conn *c;
    uint32_t request_id;
    uint16_t type;
    /* in */
    char *sent;            /* the path as the client sent it (relative to the root), or NULL for an attachment:
                              the only path messages name (never the root's) */
    int root_fd;           /* the server's root descriptor (not owned) */
    uint64_t max_file;     /* --max-message: a path load reads no more than an attachment may carry */
    lpv_gltf_limits limits; /* the per-scene budgets */
    uint8_t *glb;          /* attachment or the session scene's bytes (owned copy) */
    size_t glb_size;
    char *base_dir;        /* the scene's folder (external URIs) relative to the root, absolute only for
                              the operator's --scene; or NULL */
    lpv_gltf_node_override *nodes;
    size_t node_count;
    sv_pose pose;          /* the animation time to pose at (SCENE_UPDATE) */
    int pose_given;        /* this request set it: its failures name "animation" */
    uint64_t base_hash;
    /* out */
    int status;
    char err[1024];
    sv_scene *scene;
    lpv_gltf_warnings warnings; /* the loader's, for the SCENE_LOAD reply */
} load_work;

static char *dir_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    size_t n = slash ? (size_t)(slash - path) : 0;
    char *d = malloc(n + 2);
    if (!d)
        return NULL;
    if (n == 0) {
        strcpy(d, slash ? "/" : ".");
    } else {
        memcpy(d, path, n);
        d[n] = '\0';
    }
    return d;
}

static int contains(const uint8_t *hay, size_t n, const char *needle)
{
    size_t k = strlen(needle);
    for (size_t i = 0; i + k <= n; ++i)
        if (hay[i] == (uint8_t)needle[0] && memcmp(hay + i, needle, k) == 0)
            return 1;
    return 0;
}

/* Why a path could not be opened beneath the root, as the client's error. */
static void path_error(load_work *w, int e)
{
    w->status = LPVP_E_SCENE_INVALID;
    if (e == ELOOP || e == EXDEV) {
        w->status = LPVP_E_PATH_REFUSED;
        snprintf(w->err, sizeof w->err,
                 "path %s: goes through a symbolic link (refused: only files and folders under the scene root "
                 "are opened, never links)", w->sent);
    } else if (e == ENOENT) {
        snprintf(w->err, sizeof w->err, "path %s: no such file under the scene root", w->sent);
    } else if (e == ENOTDIR) {
        snprintf(w->err, sizeof w->err, "path %s: one of its folders is not a folder", w->sent);
    } else {
        snprintf(w->err, sizeof w->err, "path %s: %s", w->sent, strerror(e));
    }
}

/* Reads the scene file w->sent, opened beneath the root in one step (no
 * window between the check and the open: a file swapped for a link is never
 * followed), only a regular file, at most max_file bytes. 0, or -1 with
 * w->status and w->err set. */
static int read_scene_file(load_work *w)
{
    int fd = lpv_open_beneath(w->root_fd, w->sent, O_RDONLY);
    if (fd < 0) {
        path_error(w, errno);
        return -1;
    }
    struct stat st;
    w->status = LPVP_E_SCENE_INVALID;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        snprintf(w->err, sizeof w->err, "path %s: %s", w->sent,
                 S_ISDIR(st.st_mode) ? "is a folder, not a scene file" : "not a regular file");
    } else if ((uint64_t)st.st_size > w->max_file) {
        w->status = LPVP_E_LIMIT;
        snprintf(w->err, sizeof w->err,
                 "path %s: %llu bytes, over the server's limit of %llu bytes per message (--max-message)", w->sent,
                 (unsigned long long)st.st_size, (unsigned long long)w->max_file);
    } else {
        w->glb_size = (size_t)st.st_size;
        w->glb = malloc(w->glb_size ? w->glb_size : 1);
        size_t got = 0;
        while (w->glb && got < w->glb_size) {
            ssize_t n = read(fd, w->glb + got, w->glb_size - got);
            if (n < 0 && errno == EINTR)
                continue;
            if (n <= 0)
                break;
            got += (size_t)n;
        }
        if (w->glb && got == w->glb_size && (w->base_dir = dir_of(w->sent)))
            w->status = 0;
        else
            snprintf(w->err, sizeof w->err, "path %s: cannot read", w->sent);
    }
    close(fd);
    return w->status ? -1 : 0;
}

/* The flag of the budget a loader code names (lpv_gltf_load_at). */
static const char *budget_flag(int rc)
{
    return rc == LPV_GLTF_OVER_TEXTURE ? "--max-texture"
           : rc == LPV_GLTF_OVER_TEXELS ? "--max-scene-texels"
                                        : "--max-scene-bytes";
}

static void load_run(uv_work_t *req)
{
    load_work *w = req->data;
    if (w->sent && read_scene_file(w) != 0)
        return;
    /* an absolute folder is only ever the operator's --scene (serve.c); a
     * client's scene folder is relative to the root and opens beneath it */
    int base_fd = !w->base_dir ? -1
                  : w->base_dir[0] == '/' ? open(w->base_dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC)
                                          : lpv_open_beneath(w->root_fd, w->base_dir, O_RDONLY | O_DIRECTORY);
    if (w->base_dir && base_fd < 0) {
        /* not named: for the operator's --scene it is an absolute path of the machine */
        snprintf(w->err, sizeof w->err, "the scene's folder (for its external files): %s", strerror(errno));
        w->status = LPVP_E_SCENE_INVALID;
        return;
    }
    sv_scene *sc = calloc(1, sizeof *sc);
    if (!sc) {
        w->status = LPVP_E_INTERNAL;
        snprintf(w->err, sizeof w->err, "out of memory");
        return;
    }
    const char *label = w->sent ? w->sent : "attachment";
    const lpv_gltf_animation_time at = {w->pose.animation, w->pose.time};
    int rc = lpv_gltf_load_at_posed(w->glb, w->glb_size, base_fd, label, w->pose.set ? &at : NULL, w->nodes,
                                    w->node_count, &w->limits, &sc->scene, &w->warnings, w->err, sizeof w->err);
    if (base_fd >= 0)
        close(base_fd);
    char why[256];
    if (rc == LPV_GLTF_OK && lpv_scene_check_ranges(&sc->scene, why, sizeof why) != 0) {
        /* a file, or node transforms (SCENE_UPDATE: BAD_FIELD "nodes: ..."),
         * that puts the scene where float math breaks: refused, not ticked */
        snprintf(w->err, sizeof w->err, "%s: %s", label, why);
        lpv_scene_free(&sc->scene);
        rc = LPV_GLTF_DEFECT;
    }
    if (rc != LPV_GLTF_OK) {
        free(sc);
        w->status = rc == LPV_GLTF_DEFECT ? LPVP_E_SCENE_INVALID : LPVP_E_LIMIT;
        if (rc != LPV_GLTF_DEFECT) {
            size_t n = strlen(w->err);
            snprintf(w->err + n, sizeof w->err - n, " (%s)", budget_flag(rc));
        }
        return;
    }
    if (lpv_scene_add_defaults(&sc->scene, w->err, sizeof w->err) != 0) {
        lpv_scene_free(&sc->scene);
        free(sc);
        w->status = LPVP_E_INTERNAL;
        return;
    }
    if (w->base_dir && !contains(w->glb, w->glb_size, "\"uri\"")) {
        /* self-contained: the folder plays no part, so a path load and an
         * attachment of the same bytes are the same scene (and share worlds) */
        free(w->base_dir);
        w->base_dir = NULL;
    }
    uint64_t h = lpv_hash_bytes(LPV_HASH_INIT, w->glb, w->glb_size);
    if (w->base_dir)
        h = lpv_hash_bytes(h, w->base_dir, strlen(w->base_dir));
    if (w->node_count)
        h = lpv_hash_bytes(h, w->nodes, sizeof *w->nodes * w->node_count);
    if (w->pose.set)
        h = lpv_hash_bytes(h, &w->pose, sizeof w->pose);
    sc->hash = h ? h : 1;
    sc->pose = w->pose;
    sc->bytes = lpv_scene_bytes(&sc->scene) + w->glb_size;
    sc->glb = w->glb;
    sc->glb_size = w->glb_size;
    sc->base_dir = w->base_dir;
    sc->nodes = w->nodes;
    sc->node_count = w->node_count;
    w->glb = NULL;
    w->base_dir = NULL;
    w->nodes = NULL;
    w->node_count = 0;
    w->scene = sc;
}

static int scene_over_limits(sv_server *s, const lpv_scene *sc, char *err, size_t n)
{
    uint64_t tris = sc->index_count / 3;
    if (tris > s->cfg.max_triangles) {
        snprintf(err, n, "%s has %llu triangles, over the server's limit of %llu (--max-triangles)", sc->source,
                 (unsigned long long)tris, (unsigned long long)s->cfg.max_triangles);
        return 1;
    }
    for (uint32_t i = 0; i < sc->texture_count; ++i)
        if (sc->textures[i].width > s->cfg.max_texture || sc->textures[i].height > s->cfg.max_texture) {
            snprintf(err, n, "%s: texture %u is %dx%d, over the server's limit of %d texels per side (--max-texture)",
                     sc->source, i, sc->textures[i].width, sc->textures[i].height, s->cfg.max_texture);
            return 1;
        }
    return 0;
}

static void free_sv_scene_unlisted(sv_scene *sc)
{
    lpv_scene_free(&sc->scene);
    free(sc->glb);
    free(sc->base_dir);
    free(sc->nodes);
    free(sc);
}

static void start_waiting_loads(sv_server *s);

static void load_done(uv_work_t *req, int status)
{
    load_work *w = req->data;
    sv_conn *c = w->c;
    sv_server *s = c->srv;
    if (w->started)
        s->loads_running--;
    if (status == UV_ECANCELED && !w->status) { /* never ran: its session went or the server is stopping */
        w->status = s->stopping ? LPVP_E_SHUTTING_DOWN : LPVP_E_INTERNAL;
        snprintf(w->err, sizeof w->err, "the load could not start");
    }
    if (!c->closing && !c->close_after_write) {
        char err[1024];
        if (w->status == LPVP_E_SCENE_INVALID && w->type == LPVP_SCENE_UPDATE) {
            /* the file loaded before: the new pose or node transforms are at fault */
            sv_reply_err(c, w->request_id, LPVP_E_BAD_FIELD, 0, "%s: %s", w->pose_given ? "animation" : "nodes",
                         w->err);
        } else if (w->status) {
            sv_reply_err(c, w->request_id, w->status, 0, "%s", w->err);
        } else if (scene_over_limits(s, &w->scene->scene, err, sizeof err) ||
                   !sv_scene_fits(s, w->scene, err, sizeof err)) {
            free_sv_scene_unlisted(w->scene);
            w->scene = NULL;
            sv_reply_err(c, w->request_id, LPVP_E_LIMIT, 0, "%s", err);
        } else {
            sv_scene *sc = sv_scene_intern(s, w->scene);
            w->scene = NULL;
            /* SCENE_UPDATE of nodes keeps the session's material edits and lights */
            lpv_material *keep_m = NULL;
            lpv_light *keep_l = NULL, *old_file = NULL;
            uint32_t keep_mn = 0, keep_ln = 0, old_n = 0;
            int ofail = 0;
            if (w->type == LPVP_SCENE_UPDATE) {
                old_file = sv_named_lights(&c->scene->scene, &ofail);
                old_n = c->scene->scene.light_count;
                keep_m = c->materials;
                keep_mn = c->material_count;
                keep_l = c->lights;
                keep_ln = c->light_count;
                c->materials = NULL;
                c->lights = NULL;
            }
            if (sv_session_set_scene(c, sc) != 0) {
                sv_scene_unref(s, sc);
                if (w->type == LPVP_SCENE_UPDATE) { /* the session keeps what it had */
                    c->materials = keep_m;
                    c->lights = keep_l;
                }
                sv_reply_err(c, w->request_id, LPVP_E_INTERNAL, 0, "out of memory");
            } else {
                if (w->type == LPVP_SCENE_UPDATE) {
                    if (keep_mn == c->material_count) {
                        free(c->materials);
                        c->materials = keep_m;
                    } else {
                        free(keep_m);
                    }
                    /* file lights the session did not edit follow their nodes */
                    for (uint32_t i = 0; i < keep_ln && old_file && !ofail && c->lights; ++i)
                        for (uint32_t k = 0; k < old_n && k < c->light_count; ++k)
                            if (strcmp(keep_l[i].name, old_file[k].name) == 0 &&
                                memcmp(&keep_l[i], &old_file[k], sizeof keep_l[i]) == 0 &&
                                strcmp(c->lights[k].name, old_file[k].name) == 0) {
                                keep_l[i] = c->lights[k];
                                break;
                            }
                    free(c->lights);
                    c->lights = keep_l;
                    c->light_count = keep_ln;
                } else {
                    free(keep_m);
                    free(keep_l);
                }
                sv_session_changed(c);
                json_t *b = sv_rev_body(c);
                if (w->type == LPVP_SCENE_LOAD) {
                    json_t *sj = scene_json(&sc->scene), *wa = json_array();
                    for (int i = 0; wa && i < w->warnings.count; ++i)
                        json_array_append_new(wa, json_string(w->warnings.line[i]));
                    if (sj && wa)
                        json_object_set_new(sj, "warnings", wa);
                    else
                        json_decref(wa);
                    json_object_set_new(b, "scene", sj);
                }
                sv_reply(c, w->type, w->request_id, b);
            }
            free(old_file);
        }
    }
    if (w->scene)
        free_sv_scene_unlisted(w->scene);
    free(w->sent);
    free(w->glb);
    free(w->base_dir);
    free(w->nodes);
    c->busy = 0;
    sv_session_work_end(c);
    free(w);
    sv_session_go_on(c);
    sv_conn_unref(c);
    start_waiting_loads(s);
}

/* Starts waiting loads while fewer than SV_MAX_LOADS run; one whose session
 * has gone ends at once, unrun. */
static void start_waiting_loads(sv_server *s)
{
    while (s->loads_wait_head && s->loads_running < SV_MAX_LOADS) {
        load_work *w = s->loads_wait_head;
        s->loads_wait_head = w->next_wait;
        if (!s->loads_wait_head)
            s->loads_wait_tail = NULL;
        if (w->c->closing || w->c->close_after_write || s->stopping ||
            uv_queue_work(s->loop, &w->req, load_run, load_done) != 0) {
            load_done(&w->req, UV_ECANCELED);
            continue;
        }
        w->started = 1;
        s->loads_running++;
    }
}

void sv_scene_loads_drop(sv_server *s)
{
    while (s->loads_wait_head) {
        load_work *w = s->loads_wait_head;
        s->loads_wait_head = w->next_wait;
        if (!s->loads_wait_head)
            s->loads_wait_tail = NULL;
        load_done(&w->req, UV_ECANCELED);
    }
}

static int start_load(sv_conn *c, load_work *w)
{
    w->req.data = w;
    w->c = c;
    w->root_fd = c->srv->root_fd;
    w->max_file = c->srv->cfg.max_message;
    w->limits.max_texture = c->srv->cfg.max_texture;
    w->limits.max_texels = c->srv->cfg.max_scene_texels;
    w->limits.max_bytes = c->srv->cfg.max_scene_bytes;
    c->refs++;
    c->busy = 1;
    sv_server *s = c->srv;
    if (s->loads_running < SV_MAX_LOADS) {
        if (uv_queue_work(s->loop, &w->req, load_run, load_done) != 0) {
            c->busy = 0;
            c->refs--;
            return -1;
        }
        w->started = 1;
        s->loads_running++;
    } else { /* waits its turn for a worker (start_waiting_loads) */
        w->next_wait = NULL;
        if (s->loads_wait_tail)
            s->loads_wait_tail->next_wait = w;
        else
            s->loads_wait_head = w;
        s->loads_wait_tail = w;
    }
    sv_session_work_begin(c, w->request_id);
    return 0;
}

/* R4.3, the checks that need no file system: a path, a root, relative, no
 * ".." (the open itself refuses links: read_scene_file). 0, or the error
 * code with its message. */
static int check_scene_path(sv_server *s, const char *p, char *err, size_t n)
{
    if (!p[0]) {
        snprintf(err, n, "path: empty; give a file's path relative to the scene root");
        return LPVP_E_BAD_FIELD;
    }
    if (s->root_fd < 0) {
        snprintf(err, n, "path %s: this server has no --scene-root; send the .glb as an attachment", p);
        return LPVP_E_PATH_REFUSED;
    }
    if (p[0] == '/') {
        snprintf(err, n, "path %s: absolute paths are refused; give a path relative to the scene root", p);
        return LPVP_E_PATH_REFUSED;
    }
    if (lpv_path_stays_beneath(p) != 0) {
        snprintf(err, n, "path %s: \"..\" components are refused", p);
        return LPVP_E_PATH_REFUSED;
    }
    return 0;
}

void sv_do_scene_load(sv_conn *c, sv_request *r, json_t *j)
{
    char err[1024];
    const char *path = NULL;
    int pst = lpvp_get_string(j, "path", 0, 4096, &path, NULL, err, sizeof err);
    if (pst == LPVP_FIELD_BAD) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
        return;
    }
    load_work *w = calloc(1, sizeof *w);
    if (!w) {
        sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "out of memory");
        return;
    }
    w->request_id = r->request_id;
    w->type = LPVP_SCENE_LOAD;
    if (pst == LPVP_FIELD_OK) {
        if (r->att_len) {
            free(w);
            sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0,
                      "path: give either \"path\" or a .glb attachment, not both");
            return;
        }
        int code = check_scene_path(c->srv, path, err, sizeof err);
        if (code == 0 && !(w->sent = strdup(path))) {
            code = LPVP_E_INTERNAL;
            snprintf(err, sizeof err, "out of memory");
        }
        if (code != 0) {
            free(w);
            sv_reply_err(c, r->request_id, code, 0, "%s", err);
            return;
        }
    } else {
        if (!r->att_len) {
            free(w);
            sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0,
                      "path: required (a path under --scene-root), or send the .glb as the attachment");
            return;
        }
        w->glb = r->att; /* take the attachment */
        w->glb_size = r->att_len;
        r->att = NULL;
        r->att_len = 0;
    }
    if (start_load(c, w) != 0) {
        free(w->sent);
        free(w->glb);
        free(w);
        sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "cannot queue the scene load");
    }
}

/* SCENE_UPDATE "animation": {"name"?: string or index, "time": seconds}
 * into *p; 0, 1 absent, -1 with a message (SPEC R4.4c). */
static int parse_pose(const json_t *j, sv_pose *p, char *err, size_t n)
{
    const json_t *a = json_object_get(j, "animation");
    if (!a)
        return 1;
    if (!json_is_object(a))
        return snprintf(err, n, "animation: expected an object {\"name\"?, \"time\"}"), -1;
    const char *k;
    json_t *v;
    json_object_foreach((json_t *)a, k, v) {
        if (strcmp(k, "name") && strcmp(k, "time")) {
            snprintf(err, n, "animation: unknown field (only \"name\" and \"time\")");
            return -1;
        }
    }
    memset(p, 0, sizeof *p);
    const json_t *t = json_object_get(a, "time"), *name = json_object_get(a, "name");
    if (!json_is_number(t) || !isfinite(json_number_value(t)) || json_number_value(t) < 0.0 ||
        json_number_value(t) > 1e9)
        return snprintf(err, n, "animation.time: expected seconds, a number in 0..1e9"), -1;
    p->time = json_number_value(t);
    if (json_is_string(name)) {
        if (strlen(json_string_value(name)) >= sizeof p->animation)
            return snprintf(err, n, "animation.name: longer than %zu bytes", sizeof p->animation - 1), -1;
        snprintf(p->animation, sizeof p->animation, "%s", json_string_value(name));
    } else if (json_is_integer(name) && json_integer_value(name) >= 0 && json_integer_value(name) <= 65535) {
        snprintf(p->animation, sizeof p->animation, "%lld", (long long)json_integer_value(name));
    } else if (name) {
        return snprintf(err, n, "animation.name: expected the animation's name or index"), -1;
    }
    p->set = 1;
    return 0;
}

void sv_do_scene_update(sv_conn *c, sv_request *r, json_t *j)
{
    char err[512];
    const json_t *nodes = NULL, *mats = NULL;
    sv_pose pose;
    int pose_rc;
    if (lpvp_get_array(j, "nodes", 0, 65536, &nodes, err, sizeof err) == LPVP_FIELD_BAD ||
        lpvp_get_array(j, "materials", 0, 65536, &mats, err, sizeof err) == LPVP_FIELD_BAD ||
        (pose_rc = parse_pose(j, &pose, err, sizeof err)) < 0) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
        return;
    }
    if (pose_rc == 0 && !c->scene->glb) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0,
                     "animation: the built-in scene has no animations; SCENE_LOAD a .glb first");
        return;
    }
    /* materials: validated into a copy, applied only if all are good */
    lpv_material *m = NULL;
    if (mats && json_array_size(mats)) {
        m = malloc(sizeof *m * (c->material_count ? c->material_count : 1));
        if (!m) {
            sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "out of memory");
            return;
        }
        if (c->material_count)
            memcpy(m, c->materials, sizeof *m * c->material_count);
        for (size_t i = 0; i < json_array_size(mats); ++i) {
            const json_t *e = json_array_get(mats, i);
            int64_t idx;
            int bad = 0;
            if (!json_is_object(e)) {
                snprintf(err, sizeof err, "materials[%zu]: expected an object", i);
                bad = 1;
            } else if (lpvp_get_int(e, "material", 1, 0, (int64_t)c->material_count - 1, &idx, err, sizeof err) !=
                       LPVP_FIELD_OK) {
                if (c->material_count == 0)
                    snprintf(err, sizeof err, "material: the scene has no materials");
                bad = 1;
            } else {
                lpv_material *t = &m[idx];
                if (lpvp_get_floats(e, "base_color", 0, 4, 0.0, 1.0, t->base_color, err, sizeof err) ==
                        LPVP_FIELD_BAD ||
                    lpvp_get_floats(e, "emission", 0, 3, 0.0, 1e30, t->emission, err, sizeof err) == LPVP_FIELD_BAD ||
                    lpvp_get_float(e, "metallic", 0, 0.0, 1.0, &t->metallic, err, sizeof err) == LPVP_FIELD_BAD ||
                    lpvp_get_float(e, "roughness", 0, 0.0, 1.0, &t->roughness, err, sizeof err) == LPVP_FIELD_BAD)
                    bad = 1;
            }
            if (bad) {
                if (strncmp(err, "materials[", 10) != 0)
                    lpvp_err_prefix(err, sizeof err, "materials[%zu].", i);
                free(m);
                sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
                return;
            }
        }
    }
    /* nodes: parsed into overrides; the scene is rebuilt from its bytes */
    lpv_gltf_node_override *ov = NULL;
    size_t nov = 0;
    if (nodes && json_array_size(nodes)) {
        if (!c->scene->glb) {
            free(m);
            sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0,
                      "nodes: the built-in scene has no glTF nodes; SCENE_LOAD a .glb first");
            return;
        }
        nov = json_array_size(nodes);
        ov = calloc(nov, sizeof *ov);
        if (!ov) {
            free(m);
            sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "out of memory");
            return;
        }
        for (size_t i = 0; i < nov; ++i) {
            const json_t *e = json_array_get(nodes, i);
            lpv_gltf_node_override *o = &ov[i];
            int64_t idx;
            int st[4];
            if (!json_is_object(e)) {
                snprintf(err, sizeof err, "nodes[%zu]: expected an object", i);
                goto bad_node;
            }
            if (lpvp_get_int(e, "node", 1, 0, INT32_MAX, &idx, err, sizeof err) != LPVP_FIELD_OK)
                goto bad_node_prefix;
            o->node = (int)idx;
            if ((st[0] = lpvp_get_floats(e, "matrix", 0, 16, -1e30, 1e30, o->matrix, err, sizeof err)) ==
                    LPVP_FIELD_BAD ||
                (st[1] = lpvp_get_floats(e, "translation", 0, 3, -1e30, 1e30, o->translation, err, sizeof err)) ==
                    LPVP_FIELD_BAD ||
                (st[2] = lpvp_get_floats(e, "rotation", 0, 4, -1e30, 1e30, o->rotation, err, sizeof err)) ==
                    LPVP_FIELD_BAD ||
                (st[3] = lpvp_get_floats(e, "scale", 0, 3, -1e30, 1e30, o->scale, err, sizeof err)) ==
                    LPVP_FIELD_BAD)
                goto bad_node_prefix;
            o->has_matrix = st[0] == LPVP_FIELD_OK;
            o->has_translation = st[1] == LPVP_FIELD_OK;
            o->has_rotation = st[2] == LPVP_FIELD_OK;
            o->has_scale = st[3] == LPVP_FIELD_OK;
            if (o->has_matrix && (o->has_translation || o->has_rotation || o->has_scale)) {
                snprintf(err, sizeof err, "matrix: give either \"matrix\" or translation/rotation/scale");
                goto bad_node_prefix;
            }
            continue;
        bad_node_prefix:
            lpvp_err_prefix(err, sizeof err, "nodes[%zu].", i);
        bad_node:
            free(ov);
            free(m);
            sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
            return;
        }
    }
    if (!ov && pose_rc != 0) {
        if (m) {
            free(c->materials);
            c->materials = m;
        }
        sv_session_changed(c);
        sv_reply(c, LPVP_SCENE_UPDATE, r->request_id, sv_rev_body(c));
        return;
    }
    load_work *w = calloc(1, sizeof *w);
    uint8_t *glb = malloc(c->scene->glb_size ? c->scene->glb_size : 1);
    char *bd = c->scene->base_dir ? strdup(c->scene->base_dir) : NULL;
    if (!w || !glb || (c->scene->base_dir && !bd)) {
        free(w);
        free(glb);
        free(bd);
        free(ov);
        free(m);
        sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "out of memory");
        return;
    }
    memcpy(glb, c->scene->glb, c->scene->glb_size);
    /* materials: apply now (the rebuilt scene keeps the session's material list) */
    if (m) {
        free(c->materials);
        c->materials = m;
    }
    w->request_id = r->request_id;
    w->type = LPVP_SCENE_UPDATE;
    w->glb = glb;
    w->glb_size = c->scene->glb_size;
    w->base_dir = bd;
    w->nodes = ov;
    w->node_count = nov;
    /* the pose asked for, else the one the scene has (a node update keeps it) */
    w->pose = pose_rc == 0 ? pose : c->scene->pose;
    w->pose_given = pose_rc == 0;
    /* the overrides the scene already has come first (later ones win) */
    if (c->scene->node_count) {
        lpv_gltf_node_override *all = calloc(c->scene->node_count + nov, sizeof *all);
        if (!all) {
            free(w->glb);
            free(w->base_dir);
            free(w->nodes);
            free(w);
            sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "out of memory");
            return;
        }
        memcpy(all, c->scene->nodes, sizeof *all * c->scene->node_count);
        if (nov)
            memcpy(all + c->scene->node_count, ov, sizeof *all * nov);
        free(w->nodes);
        w->nodes = all;
        w->node_count = c->scene->node_count + nov;
    }
    if (start_load(c, w) != 0) {
        free(w->glb);
        free(w->base_dir);
        free(w->nodes);
        free(w);
        sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "cannot queue the scene rebuild");
    }
}
