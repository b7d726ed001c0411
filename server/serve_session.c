/*
 * serve_session.c - one session per connection (SPEC section 7): its state
 * (scene, materials, lights, camera, config, revision, subscriptions), and
 * the dispatch of its requests, strictly one at a time in arrival order
 * (R3.2). Requests that need the GL thread (TICK, GET_FRAME,
 * QUERY_IRRADIANCE) or a worker (SCENE_LOAD, SCENE_UPDATE of nodes) mark the
 * session busy; its next request waits until the reply has been queued.
 */
#include "serve_session_internal.h"
#include "scene_defaults.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "gltf_load.h"
#include "settings_json.h"
#include "stats_json.h"
#include "settings_fields.h"
#include "volume_codec.h"

#define SV_MAX_LIGHTS 256
#define SV_MAX_VIEW_SIDE 4096

/* The names of formats, compressions, terms and streams are the protocol
 * library's (volume_codec.h), indexed by its enums. */

/* ---- replies ------------------------------------------------------------ */
void sv_reply_err(sv_conn *c, uint32_t rid, int code, int noclose, const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    sv_send(c, LPVP_ERROR, rid, lpvp_error_body(code, "%s", msg), NULL, 0, SV_STREAM_NONE);
    if (!noclose && lpvp_error_closes(code))
        sv_conn_close_after_write(c);
}

void sv_reply(sv_conn *c, uint16_t type, uint32_t rid, json_t *body)
{
    sv_send(c, LPVP_REPLY(type), rid, body ? body : json_object(), NULL, 0, SV_STREAM_NONE);
}

json_t *sv_rev_body(sv_conn *c)
{
    return json_pack("{s:I}", "revision", (json_int_t)c->revision);
}

/* ---- session state ------------------------------------------------------ */
static void name_lights(lpv_light *l, uint32_t n)
{
    for (uint32_t i = 0; i < n; ++i) {
        int dup = 0;
        for (uint32_t k = 0; k < i; ++k)
            if (strcmp(l[k].name, l[i].name) == 0)
                dup = 1;
        if (!l[i].name[0] || dup)
            snprintf(l[i].name, sizeof l[i].name, "light%u", i);
    }
}

static void default_view(sv_conn *c)
{
    const lpv_scene *sc = &c->scene->scene;
    int w = c->view_w ? c->view_w : SV_DEFAULT_VIEW_SIDE, h = c->view_h ? c->view_h : SV_DEFAULT_VIEW_SIDE;
    memset(&c->view, 0, sizeof c->view);
    if (c->view_camera >= 0 && (uint32_t)c->view_camera < sc->camera_count)
        lpv_view_from_camera(&sc->cameras[c->view_camera], w, h, &c->view);
    else if (sc->camera_count)
        lpv_view_from_camera(&sc->cameras[0], w, h, &c->view);
    else
        lpv_view_frame_bounds(sc, w, h, &c->view);
}

lpv_light *sv_named_lights(const lpv_scene *sc, int *fail)
{
    *fail = 0;
    if (!sc->light_count)
        return NULL;
    lpv_light *l = calloc(sc->light_count, sizeof *l);
    if (!l) {
        *fail = 1;
        return NULL;
    }
    memcpy(l, sc->lights, sizeof *l * sc->light_count);
    for (uint32_t i = 0; i < sc->light_count; ++i) { /* zero the name padding: lights are keys */
        char nm[LPV_NAME_MAX];
        snprintf(nm, sizeof nm, "%s", l[i].name);
        memset(l[i].name, 0, sizeof l[i].name);
        memcpy(l[i].name, nm, strlen(nm));
    }
    name_lights(l, sc->light_count);
    return l;
}

int sv_session_set_scene(sv_conn *c, sv_scene *sc)
{
    lpv_material *m = NULL;
    lpv_light *l = NULL;
    if (sc->scene.material_count) {
        m = malloc(sizeof *m * sc->scene.material_count);
        if (!m)
            return -1;
        memcpy(m, sc->scene.materials, sizeof *m * sc->scene.material_count);
    }
    int lfail = 0;
    l = sv_named_lights(&sc->scene, &lfail);
    if (lfail) {
        free(m);
        return -1;
    }
    if (c->scene)
        sv_scene_unref(c->srv, c->scene);
    c->scene = sc;
    free(c->materials);
    free(c->lights);
    c->materials = m;
    c->material_count = sc->scene.material_count;
    c->lights = l;
    c->light_count = sc->scene.light_count;
    if (!c->view_explicit) {
        if (c->view_camera >= 0 && (uint32_t)c->view_camera >= sc->scene.camera_count)
            c->view_camera = -1;
        default_view(c);
    }
    return 0;
}

void sv_session_changed(sv_conn *c)
{
    c->revision++;
    sv_inputs *in = sv_inputs_build(c);
    if (in)
        sv_world_attach(c, in);
}

void sv_session_init(sv_conn *c)
{
    sv_server *s = c->srv;
    c->view_camera = -1;
    c->settings = s->cfg.settings;
    c->tick_rate = s->cfg.tick_rate;
    c->subs[0].fp16 = 1;
    s->builtin->refs++;
    if (sv_session_set_scene(c, s->builtin) != 0) {
        sv_conn_close(c);
        return;
    }
    sv_inputs *in = sv_inputs_build(c);
    if (in)
        sv_world_attach(c, in);
}

void sv_session_free(sv_conn *c)
{
    sv_world_detach(c);
    if (c->scene)
        sv_scene_unref(c->srv, c->scene);
    c->scene = NULL;
    free(c->materials);
    free(c->lights);
    c->materials = NULL;
    c->lights = NULL;
    for (int i = 0; i < 2; ++i)
        sv_sub_clear(&c->subs[i]);
}

/* ---- stats -------------------------------------------------------------- */
/* The tick's stats in the one shape of lpvd_tick_stats_json (stats_json.h). */
static json_t *tick_stats(const sv_result *r)
{
    int one = r->cascade_count < 1;
    return lpvd_tick_stats_json(&r->stats, &r->plan, one ? &r->grid : r->cascades, one ? 1 : r->cascade_count,
                                r->tick_ms);
}

json_t *sv_config_json(sv_conn *c)
{
    lpv_settings s = c->settings;
    lpv_settings_resolve(&s);
    json_t *bounds;
    int auto_bounds = !lpv_settings_bounds_given(&s);
    if (auto_bounds && c->world && c->world->latest && c->world->latest->gen == c->world_gen) {
        const lpv_grid *g = &c->world->latest->grid;
        bounds = json_pack("[f,f,f,f,f,f]", (double)g->origin[0], (double)g->origin[1], (double)g->origin[2],
                           g->origin[0] + (double)g->cell_size * g->dims[0],
                           g->origin[1] + (double)g->cell_size * g->dims[1],
                           g->origin[2] + (double)g->cell_size * g->dims[2]);
    } else if (auto_bounds) {
        bounds = json_null(); /* the scene's, placed at the next tick */
    } else {
        bounds = json_pack("[f,f,f,f,f,f]", (double)s.bounds_min[0], (double)s.bounds_min[1], (double)s.bounds_min[2],
                           (double)s.bounds_max[0], (double)s.bounds_max[1], (double)s.bounds_max[2]);
    }
    const char *preset = lpv_preset_name(s.preset); /* CONFIG validated it, so never NULL */
    json_t *o = json_pack("{s:s, s:[i,i,i], s:o, s:b}", "preset", preset ? preset : "", "grid", s.grid_dims[0],
                          s.grid_dims[1], s.grid_dims[2], "bounds", bounds, "bounds_auto", auto_bounds);
    /* every knob of the field table (core/settings_fields.h), resolved: iterations, rsm_size, occlusion, ... */
    size_t nf;
    const lpv_field *fields = lpv_fields(&nf);
    for (size_t i = 0; o && i < nf; ++i) {
        double v = lpv_field_get(&s, &fields[i]);
        json_object_set_new(o, fields[i].key,
                            fields[i].kind == LPV_FIELD_INT      ? json_integer((json_int_t)v)
                            : fields[i].kind == LPV_FIELD_SWITCH ? json_boolean(v > 0.0)
                                                                 : json_real(v));
    }
    if (o)
        json_object_set_new(o, "tick_rate_hz", json_real(c->tick_rate));
    return o;
}

/* ---- lights, camera, config ---------------------------------------------- */
void sv_do_light_set(sv_conn *c, sv_request *r, json_t *j)
{
    static const char *const TYPES[] = {"directional", "point", "spot"}; /* = lpv_light_type */
    char err[512];
    const char *id = NULL;
    size_t idlen = 0;
    int type = 0;
    lpv_light l;
    memset(&l, 0, sizeof l);
    l.color[0] = l.color[1] = l.color[2] = 1.0f;
    l.direction[1] = -1.0f;
    l.outer_cone = (float)(M_PI / 4.0);
    if (lpvp_get_string(j, "id", 1, LPV_NAME_MAX - 1, &id, &idlen, err, sizeof err) != LPVP_FIELD_OK ||
        lpvp_get_enum(j, "type", 1, TYPES, 3, &type, err, sizeof err) != LPVP_FIELD_OK ||
        lpvp_get_floats(j, "color", 0, 3, 0.0, 1e30, l.color, err, sizeof err) == LPVP_FIELD_BAD ||
        lpvp_get_float(j, "intensity", 1, 0.0, 1e30, &l.intensity, err, sizeof err) != LPVP_FIELD_OK ||
        lpvp_get_floats(j, "position", 0, 3, -1e30, 1e30, l.position, err, sizeof err) == LPVP_FIELD_BAD ||
        lpvp_get_floats(j, "direction", 0, 3, -1e30, 1e30, l.direction, err, sizeof err) == LPVP_FIELD_BAD ||
        lpvp_get_float(j, "range", 0, 0.0, 1e30, &l.range, err, sizeof err) == LPVP_FIELD_BAD ||
        lpvp_get_float(j, "inner_cone", 0, 0.0, M_PI / 2.0, &l.inner_cone, err, sizeof err) == LPVP_FIELD_BAD ||
        lpvp_get_float(j, "outer_cone", 0, 0.0, M_PI / 2.0, &l.outer_cone, err, sizeof err) == LPVP_FIELD_BAD) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
        return;
    }
    if (idlen == 0) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "id: must not be empty");
        return;
    }
    float dl = sqrtf(l.direction[0] * l.direction[0] + l.direction[1] * l.direction[1] +
                     l.direction[2] * l.direction[2]);
    if (!(dl > 1e-12f) || !isfinite(dl)) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "direction: must be a non-zero vector");
        return;
    }
    for (int i = 0; i < 3; ++i)
        l.direction[i] /= dl;
    if (type == LPV_LIGHT_SPOT && l.inner_cone > l.outer_cone) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "inner_cone: must not exceed outer_cone");
        return;
    }
    if (type != LPV_LIGHT_SPOT)
        l.inner_cone = l.outer_cone = 0.0f;
    l.type = (lpv_light_type)type;
    memcpy(l.name, id, idlen);
    uint32_t i = 0;
    while (i < c->light_count && strcmp(c->lights[i].name, l.name) != 0)
        ++i;
    if (i == c->light_count) {
        if (c->light_count >= SV_MAX_LIGHTS) {
            sv_reply_err(c, r->request_id, LPVP_E_LIMIT, 0, "a session has at most %d lights", SV_MAX_LIGHTS);
            return;
        }
        lpv_light *nl = realloc(c->lights, sizeof *nl * (c->light_count + 1));
        if (!nl) {
            sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "out of memory");
            return;
        }
        c->lights = nl;
        c->light_count++;
    }
    c->lights[i] = l;
    sv_session_changed(c);
    sv_reply(c, LPVP_LIGHT_SET, r->request_id, sv_rev_body(c));
}

void sv_do_light_remove(sv_conn *c, sv_request *r, json_t *j)
{
    char err[512];
    const char *id = NULL;
    if (lpvp_get_string(j, "id", 1, 4096, &id, NULL, err, sizeof err) != LPVP_FIELD_OK) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
        return;
    }
    uint32_t i = 0;
    while (i < c->light_count && strcmp(c->lights[i].name, id) != 0)
        ++i;
    if (i == c->light_count) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "id: no light \"%s\" in this session", id);
        return;
    }
    memmove(&c->lights[i], &c->lights[i + 1], sizeof *c->lights * (c->light_count - i - 1));
    c->light_count--;
    sv_session_changed(c);
    sv_reply(c, LPVP_LIGHT_REMOVE, r->request_id, sv_rev_body(c));
}

void sv_do_camera_set(sv_conn *c, sv_request *r, json_t *j)
{
    char err[512];
    int64_t w = c->view_w ? c->view_w : SV_DEFAULT_VIEW_SIDE, h = c->view_h ? c->view_h : SV_DEFAULT_VIEW_SIDE;
    if (lpvp_get_int(j, "width", 0, 1, SV_MAX_VIEW_SIDE, &w, err, sizeof err) == LPVP_FIELD_BAD ||
        lpvp_get_int(j, "height", 0, 1, SV_MAX_VIEW_SIDE, &h, err, sizeof err) == LPVP_FIELD_BAD) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
        return;
    }
    const json_t *cam = json_object_get(j, "camera");
    const lpv_scene *sc = &c->scene->scene;
    lpv_view v;
    if (cam) {
        char key[64];
        if (json_is_integer(cam))
            snprintf(key, sizeof key, "%lld", (long long)json_integer_value(cam));
        else if (json_is_string(cam))
            snprintf(key, sizeof key, "%s", json_string_value(cam));
        else {
            sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "camera: expected an index or a name");
            return;
        }
        int idx = lpv_view_find_camera(sc, key);
        if (idx < 0) {
            sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "camera: the scene has %u camera(s) and none is \"%s\"",
                      sc->camera_count, key);
            return;
        }
        lpv_view_from_camera(&sc->cameras[idx], (int)w, (int)h, &v);
        c->view_camera = idx;
        c->view_explicit = 0;
    } else {
        float eye[3], target[3], up[3] = {0, 1, 0}, fov = 45.0f;
        int has_up;
        if (lpvp_get_floats(j, "eye", 1, 3, -1e30, 1e30, eye, err, sizeof err) != LPVP_FIELD_OK ||
            lpvp_get_floats(j, "target", 1, 3, -1e30, 1e30, target, err, sizeof err) != LPVP_FIELD_OK ||
            (has_up = lpvp_get_floats(j, "up", 0, 3, -1e30, 1e30, up, err, sizeof err)) == LPVP_FIELD_BAD ||
            lpvp_get_float(j, "fov_deg", 0, 0.01, 179.0, &fov, err, sizeof err) == LPVP_FIELD_BAD) {
            sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
            return;
        }
        if (lpv_view_look_at(eye, target, fov * (float)(M_PI / 180.0), (int)w, (int)h, &v) != 0) {
            sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "target: must differ from eye");
            return;
        }
        if (has_up == LPVP_FIELD_OK) { /* up, made orthogonal to forward */
            float d = up[0] * v.forward[0] + up[1] * v.forward[1] + up[2] * v.forward[2];
            float u[3] = {up[0] - d * v.forward[0], up[1] - d * v.forward[1], up[2] - d * v.forward[2]};
            float ul = sqrtf(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
            if (!(ul > 1e-6f) || !isfinite(ul)) {
                sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "up: must not be parallel to target - eye");
                return;
            }
            for (int i = 0; i < 3; ++i)
                v.up[i] = u[i] / ul;
        }
        c->view_explicit = 1;
        c->view_camera = -1;
    }
    c->view_w = (int)w;
    c->view_h = (int)h;
    c->view = v;
    sv_session_changed(c);
    sv_reply(c, LPVP_CAMERA_SET, r->request_id, sv_rev_body(c));
}


/* CONFIG's "preset": resets grid / iterations / rsm_size / occlusion to the
 * preset's (by clearing them, so resolve fills them in), before the message's
 * other fields override them. Returns LPVP_FIELD_OK or _ABSENT, LPVP_FIELD_BAD
 * (message in err), or -2 when the preset is over a server limit (ERROR LIMIT
 * already sent: --max-grid and --max-texture bound presets as well). */
static int config_preset(sv_conn *c, sv_request *r, const json_t *j, lpv_settings *st, char *err, size_t n)
{
    /* the choices are core's preset table (lpv_preset_name), in its order */
    const char *names[LPV_PRESET_COUNT_];
    int count = 0, idx = 0;
    for (int q = LPV_PRESET_DEFAULT + 1; q < LPV_PRESET_COUNT_; ++q)
        names[count++] = lpv_preset_name((lpv_preset)q);
    int rc = lpvp_get_enum(j, "preset", 0, names, (size_t)count, &idx, err, n);
    if (rc != LPVP_FIELD_OK)
        return rc;
    lpv_settings p;
    lpv_preset_settings((lpv_preset)(LPV_PRESET_DEFAULT + 1 + idx), &p);
    const sv_server *s = c->srv;
    if (p.grid_dims[0] > s->cfg.max_grid || p.rsm_size > s->cfg.max_texture) {
        sv_reply_err(c, r->request_id, LPVP_E_LIMIT, 0,
                  "preset: %s (grid %d, rsm_size %d) is over the server's limits (--max-grid %d, --max-texture %d)",
                  names[idx], p.grid_dims[0], p.rsm_size, s->cfg.max_grid, s->cfg.max_texture);
        return -2;
    }
    st->preset = p.preset;
    memset(st->grid_dims, 0, sizeof st->grid_dims);
    st->iterations = 0;
    st->rsm_size = 0;
    st->occlusion = LPV_SWITCH_DEFAULT;
    return LPVP_FIELD_OK;
}

/* CONFIG's scalar knobs, one per entry of the field table (core/settings_fields.h):
 * ints as JSON integers, floats as JSON numbers, switches as JSON booleans, each
 * within the table's range. Returns 0, or -1 with a message naming the key. */
static int config_fields(const json_t *j, lpv_settings *st, char *err, size_t n)
{
    size_t nf;
    const lpv_field *fields = lpv_fields(&nf);
    for (size_t i = 0; i < nf; ++i) {
        const lpv_field *f = &fields[i];
        int64_t iv;
        double dv;
        int bv, rc;
        char why[160];
        if (f->kind == LPV_FIELD_SWITCH) {
            if ((rc = lpvp_get_bool(j, f->key, 0, &bv, err, n)) == LPVP_FIELD_OK)
                lpv_field_set_bool(st, f, bv);
        } else if (f->kind == LPV_FIELD_INT) {
            if ((rc = lpvp_get_int(j, f->key, 0, (int64_t)f->min, (int64_t)f->max, &iv, err, n)) == LPVP_FIELD_OK)
                lpv_field_set_number(st, f, (double)iv, NULL, 0);
        } else if ((rc = lpvp_get_number(j, f->key, 0, f->min, f->max, &dv, err, n)) == LPVP_FIELD_OK &&
                   lpv_field_set_number(st, f, dv, why, sizeof why) != 0) { /* an exclusive minimum */
            snprintf(err, n, "%s: %s", f->key, why);
            return -1;
        }
        if (rc == LPVP_FIELD_BAD)
            return -1;
    }
    return 0;
}

void sv_do_config(sv_conn *c, sv_request *r, json_t *j)
{
    sv_server *s = c->srv;
    char err[512];
    lpv_settings st = c->settings;
    double rate = c->tick_rate;
    int64_t grid[3];
    float bounds[6];
    int gst;
    double lim_rate = s->cfg.max_tick_rate;
    int pst = config_preset(c, r, j, &st, err, sizeof err);
    if (pst == LPVP_FIELD_BAD)
        goto bad;
    if (pst < 0)
        return; /* over a limit: already answered */
    const json_t *gj = json_object_get(j, "grid");
    if (gj && json_is_integer(gj)) { /* a single N is accepted as NxNxN */
        gst = lpvp_get_int(j, "grid", 1, 1, INT32_MAX, &grid[0], err, sizeof err);
        grid[1] = grid[2] = grid[0];
    } else {
        gst = lpvp_get_ints(j, "grid", 0, 3, 1, INT32_MAX, grid, err, sizeof err);
    }
    if (gst == LPVP_FIELD_BAD)
        goto bad;
    if (gst == LPVP_FIELD_OK) {
        for (int i = 0; i < 3; ++i)
            if (grid[i] > s->cfg.max_grid) {
                sv_reply_err(c, r->request_id, LPVP_E_LIMIT, 0,
                          "grid: %lld cells on an axis is over the server's limit of %d (--max-grid)",
                          (long long)grid[i], s->cfg.max_grid);
                return;
            }
        for (int i = 0; i < 3; ++i)
            st.grid_dims[i] = (int)grid[i];
    }
    int bst = lpvp_get_floats(j, "bounds", 0, 6, -1e30, 1e30, bounds, err, sizeof err);
    if (bst == LPVP_FIELD_BAD)
        goto bad;
    if (bst == LPVP_FIELD_OK) {
        if (!(bounds[3] > bounds[0] && bounds[4] > bounds[1] && bounds[5] > bounds[2])) {
            snprintf(err, sizeof err, "bounds: expected [x0, y0, z0, x1, y1, z1] with max > min");
            goto bad;
        }
        memcpy(st.bounds_min, bounds, sizeof st.bounds_min);
        memcpy(st.bounds_max, bounds + 3, sizeof st.bounds_max);
    }
    int ist;
    if (config_fields(j, &st, err, sizeof err) != 0) /* iterations, rsm_size, occlusion, ..., planner */
        goto bad;
    if (json_object_get(j, "rsm_size") && st.rsm_size > s->cfg.max_texture) {
        sv_reply_err(c, r->request_id, LPVP_E_LIMIT, 0,
                  "rsm_size: %d is over the server's texture limit of %d (--max-texture)", st.rsm_size,
                  s->cfg.max_texture);
        return;
    }
    if (json_object_get(j, "shadow_size") && st.shadow_size > s->cfg.max_texture) {
        sv_reply_err(c, r->request_id, LPVP_E_LIMIT, 0,
                  "shadow_size: %d is over the server's texture limit of %d (--max-texture)", st.shadow_size,
                  s->cfg.max_texture);
        return;
    }
    double rv;
    if ((ist = lpvp_get_number(j, "tick_rate_hz", 0, 0.0, 1e9, &rv, err, sizeof err)) == LPVP_FIELD_BAD)
        goto bad;
    if (ist == LPVP_FIELD_OK) {
        if (rv > lim_rate) {
            sv_reply_err(c, r->request_id, LPVP_E_LIMIT, 0,
                      "tick_rate_hz: %g is over the server's limit of %g Hz (--max-tick-rate)", rv, lim_rate);
            return;
        }
        rate = rv;
    }
    lpv_settings chk = st;
    lpv_settings_resolve(&chk);
    if (lpv_settings_validate(&chk, err, sizeof err) != 0)
        goto bad;
    c->settings = st;
    c->tick_rate = rate;
    sv_session_changed(c);
    json_t *b = sv_rev_body(c);
    json_object_set_new(b, "config", sv_config_json(c));
    sv_reply(c, LPVP_CONFIG, r->request_id, b);
    return;
bad:
    sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
}

/* ---- ticks, volumes, frames, queries -------------------------------------- */
static int world_current(sv_conn *c)
{
    return c->world && c->world->latest && c->world->latest->gen == c->world_gen;
}

static void submit(sv_conn *c, sv_job *j)
{
    j->conn = c;
    c->refs++;
    c->busy = 1;
    sv_job_submit(c->srv, j);
}

void sv_do_tick(sv_conn *c, sv_request *r)
{
    if (c->world && sv_world_join_tick(c->world, c, r->request_id)) { /* shared with a queued tick (R7.2) */
        c->busy = 1;
        return;
    }
    sv_job *j = c->world ? sv_job_new(SV_JOB_TICK, c->world) : NULL;
    if (!j) {
        sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "out of memory");
        return;
    }
    j->request_id = r->request_id;
    j->terms_mask = sv_world_terms_mask(c->world);
    c->world->queued_tick = j;
    submit(c, j);
}

/* GET_FRAME's and SUBSCRIBE frame's "exposure" ("auto" or an EV number) and
 * "transparent" (SPEC R6.4). Returns LPVP_FIELD_BAD with err on a bad value. */
int sv_get_display(const json_t *j, lpv_display *d, char *err, size_t n)
{
    lpv_display_default(d);
    const json_t *e = json_object_get(j, "exposure");
    if (e) {
        char v[64];
        if (json_is_string(e))
            snprintf(v, sizeof v, "%s", json_string_value(e));
        else if (json_is_number(e))
            snprintf(v, sizeof v, "%.9g", json_number_value(e));
        else
            snprintf(v, sizeof v, "(not a string or number)");
        if (lpv_exposure_parse(v, d, err, n) != 0)
            return LPVP_FIELD_BAD;
    }
    return lpvp_get_bool(j, "transparent", 0, &d->transparent, err, n) == LPVP_FIELD_BAD ? LPVP_FIELD_BAD
                                                                                         : LPVP_FIELD_OK;
}

void sv_do_subscribe(sv_conn *c, sv_request *r, json_t *j, int on)
{
    char err[512];
    int stream = 0, fmt = -1, comp = -1, delta = 0, terms = 0;
    lpv_display display;
    lpv_display_default(&display);
    if (lpvp_get_enum(j, "stream", 1, lpvp_stream_names, LPVP_STREAM_COUNT, &stream, err, sizeof err) != LPVP_FIELD_OK)
        goto bad;
    sv_sub *sub = &c->subs[stream];
    if (!on) {
        sub->on = 0;
        sv_sub_clear(sub);
        sv_reply(c, LPVP_UNSUBSCRIBE, r->request_id, json_object());
        return;
    }
    if (lpvp_get_enum(j, "format", 0, stream ? lpvp_frame_format_names : lpvp_volume_format_names,
                      stream ? LPVP_FRAME_FORMAT_COUNT : 2, &fmt, err, sizeof err) ==
            LPVP_FIELD_BAD ||
        lpvp_get_enum(j, "compression", 0, lpvp_compression_names, 2, &comp, err, sizeof err) == LPVP_FIELD_BAD ||
        lpvp_get_bool(j, "delta", 0, &delta, err, sizeof err) == LPVP_FIELD_BAD ||
        (stream && lpvp_get_enum(j, "terms", 0, lpvp_frame_terms_names, LPVP_TERMS_COUNT, &terms, err, sizeof err) == LPVP_FIELD_BAD) ||
        (stream && sv_get_display(j, &display, err, sizeof err) == LPVP_FIELD_BAD))
        goto bad;
    if (stream && delta) {
        snprintf(err, sizeof err, "delta: only the volume stream has deltas");
        goto bad;
    }
    sv_sub_clear(sub);
    sub->on = 1;
    if (stream == SV_STREAM_VOLUME) {
        sub->fp16 = fmt != LPVP_FMT_FP32;
        sub->zstd = comp != LPVP_COMP_NONE; /* default zstd */
        sub->delta = delta;
    } else {
        sub->fmt = fmt < 0 ? LPVP_FRAME_PNG : fmt; /* default png */
        sub->zstd = comp == LPVP_COMP_ZSTD;         /* default none (rgba8 only) */
        sub->terms = terms;
        sub->display = display;
    }
    sv_reply(c, LPVP_SUBSCRIBE, r->request_id, json_object());
    return;
bad:
    sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
}

void sv_do_get_volume(sv_conn *c, sv_request *r, json_t *j)
{
    char err[512];
    int fmt = LPVP_FMT_FP16, comp = LPVP_COMP_ZSTD;
    if (lpvp_get_enum(j, "format", 0, lpvp_volume_format_names, 2, &fmt, err, sizeof err) == LPVP_FIELD_BAD ||
        lpvp_get_enum(j, "compression", 0, lpvp_compression_names, 2, &comp, err, sizeof err) == LPVP_FIELD_BAD) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
        return;
    }
    if (!world_current(c)) {
        sv_reply_err(c, r->request_id, LPVP_E_NOT_READY, 0,
                  "no volume yet for this session's current scene, lights, camera and config: send TICK first");
        return;
    }
    json_t *b = NULL;
    uint8_t *att = NULL;
    size_t alen = 0;
    if (sv_encode_volume(c->world->latest, fmt == LPVP_FMT_FP16, comp == LPVP_COMP_ZSTD, NULL, c->revision, &b, &att, &alen, err,
                         sizeof err) != 0) {
        sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "%s", err);
        return;
    }
    sv_send(c, LPVP_REPLY(LPVP_GET_VOLUME), r->request_id, b, att, alen, SV_STREAM_NONE);
}

static void send_frame_reply(sv_conn *c, uint32_t rid, const float *rgba, int w, int h, int fmt, int zstd, int terms,
                             const lpv_display *display, uint64_t tick)
{
    /* the plan of the tick shown, when it is still the world's latest */
    const lpv_plan *plan = c->world && c->world->latest && c->world->latest->tick == tick ? &c->world->latest->plan
                                                                                          : NULL;
    char err[512];
    json_t *b = NULL;
    uint8_t *att = NULL;
    size_t alen = 0;
    if (sv_encode_frame(rgba, w, h, fmt, zstd, terms, display, c->revision, tick, plan, &b, &att, &alen, err,
                        sizeof err) != 0) {
        sv_reply_err(c, rid, LPVP_E_INTERNAL, 0, "%s", err);
        return;
    }
    sv_send(c, LPVP_REPLY(LPVP_GET_FRAME), rid, b, att, alen, SV_STREAM_NONE);
}

void sv_do_get_frame(sv_conn *c, sv_request *r, json_t *j)
{
    char err[512];
    int fmt = LPVP_FRAME_PNG, comp = LPVP_COMP_NONE, terms = LPVP_TERMS_FULL;
    lpv_display display;
    if (lpvp_get_enum(j, "format", 0, lpvp_frame_format_names, LPVP_FRAME_FORMAT_COUNT, &fmt, err, sizeof err) == LPVP_FIELD_BAD ||
        lpvp_get_enum(j, "compression", 0, lpvp_compression_names, 2, &comp, err, sizeof err) == LPVP_FIELD_BAD ||
        lpvp_get_enum(j, "terms", 0, lpvp_frame_terms_names, LPVP_TERMS_COUNT, &terms, err, sizeof err) == LPVP_FIELD_BAD ||
        sv_get_display(j, &display, err, sizeof err) == LPVP_FIELD_BAD) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
        return;
    }
    if (!world_current(c)) {
        sv_reply_err(c, r->request_id, LPVP_E_NOT_READY, 0,
                  "no tick yet for this session's current scene, lights, camera and config: send TICK first");
        return;
    }
    const sv_result *res = c->world->latest;
    if (res->frames[terms]) { /* rendered with the tick already */
        send_frame_reply(c, r->request_id, res->frames[terms], res->width, res->height, fmt, comp == LPVP_COMP_ZSTD, terms,
                         &display, res->tick);
        return;
    }
    sv_job *jb = sv_job_new(SV_JOB_RENDER, c->world);
    if (!jb) {
        sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "out of memory");
        return;
    }
    jb->request_id = r->request_id;
    jb->terms = terms;
    jb->display = display;
    jb->count = (size_t)fmt | ((size_t)(comp == LPVP_COMP_ZSTD) << 4); /* encoding choice, read back in job_done */
    submit(c, jb);
}

void sv_do_query(sv_conn *c, sv_request *r, json_t *j)
{
    char err[512];
    int64_t count = 0;
    if (lpvp_get_int(j, "count", 1, 0, (int64_t)(c->srv->cfg.max_message / 24), &count, err, sizeof err) !=
        LPVP_FIELD_OK) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
        return;
    }
    if (r->att_len != (size_t)count * 24) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0,
                  "attachment: expected count x 24 = %lld bytes (px py pz nx ny nz float32 per point), got %zu",
                  (long long)count * 24, r->att_len);
        return;
    }
    if (!world_current(c)) {
        sv_reply_err(c, r->request_id, LPVP_E_NOT_READY, 0,
                  "no tick yet for this session's current scene, lights, camera and config: send TICK first");
        return;
    }
    sv_job *jb = sv_job_new(SV_JOB_QUERY, c->world);
    float *pts = malloc(count ? (size_t)count * 24 : 1);
    if (!jb || !pts) {
        free(pts);
        sv_job_free(jb);
        sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "out of memory");
        return;
    }
    for (int64_t i = 0; i < count * 6; ++i) { /* little-endian float32 */
        uint32_t u = lpvp_get_u32(r->att + i * 4);
        float f;
        memcpy(&f, &u, 4);
        pts[i] = f;
    }
    jb->points = pts;
    jb->count = (size_t)count;
    jb->request_id = r->request_id;
    submit(c, jb);
}

void sv_do_stats(sv_conn *c, sv_request *r)
{
    sv_server *s = c->srv;
    json_t *stages = json_array(), *plan = json_object();
    if (c->world && c->world->latest) {
        const sv_result *res = c->world->latest;
        json_decref(plan);
        plan = tick_stats(res);
        json_decref(stages); /* STATS keeps a top-level copy of the tick's stages (SPEC section 4) */
        stages = json_deep_copy(json_object_get(plan, "stages"));
        if (!plan || !stages) { /* out of memory: answer with what is left */
            json_decref(stages);
            stages = json_array();
            if (!plan)
                plan = json_object();
        }
        json_object_set_new(plan, "tick", json_integer((json_int_t)res->tick));
        json_object_set_new(plan, "current", json_boolean(res->gen == c->world_gen));
    }
    json_object_set_new(plan, "backend", json_string(s->gl_backend));
    json_object_set_new(plan, "gl_renderer", json_string(s->gl_renderer));
    json_object_set_new(plan, "config", sv_config_json(c));
    size_t pend = 0, wq = 0, drops = 0;
    int sessions = 0;
    for (sv_conn *o = s->conns; o; o = o->next) {
        pend += o->pending_count;
        wq += o->wq_bytes;
        drops += o->stream_dropped;
        if (o->hello)
            sessions++;
    }
    int shared = 0;
    if (c->world)
        shared = c->world->refs;
    json_t *b = json_pack(
        "{s:o, s:o, s:i, s:i, s:i, s:{s:I, s:I, s:I, s:I, s:I, s:I}, s:I, s:I, s:I, s:I, s:i, s:I}", "stages", stages,
        "plan", plan, "clients", s->conn_count, "sessions", sessions, "worlds", s->world_count, "queues", "gl_jobs",
        (json_int_t)sv_jobs_queued(s), "requests_pending", (json_int_t)pend, "write_bytes", (json_int_t)wq,
        "session_requests_pending", (json_int_t)c->pending_count, "session_write_bytes", (json_int_t)c->wq_bytes,
        "stream_dropped", (json_int_t)drops, "bytes_sent", (json_int_t)s->bytes_sent, "session_bytes_sent",
        (json_int_t)c->bytes_sent, "ticks", (json_int_t)s->ticks, "world_ticks",
        (json_int_t)(c->world && c->world->latest ? c->world->latest->tick : 0), "world_sessions", shared,
        "revision", (json_int_t)c->revision);
    /* tick coalescing (R7.2): computed ticks vs TICK requests answered by a tick queued for another */
    json_object_set_new(b, "ticks_computed", json_integer((json_int_t)s->ticks));
    json_object_set_new(b, "ticks_coalesced", json_integer((json_int_t)s->ticks_coalesced));
    json_object_set_new(b, "world_ticks_computed", json_integer((json_int_t)(c->world ? c->world->ticks_computed : 0)));
    json_object_set_new(b, "world_ticks_coalesced",
                        json_integer((json_int_t)(c->world ? c->world->ticks_coalesced : 0)));
    sv_reply(c, LPVP_STATS, r->request_id, b);
}

void sv_do_ack(sv_conn *c, sv_request *r, json_t *j)
{
    char err[512];
    int stream = 0;
    int64_t tick = 0;
    if (lpvp_get_enum(j, "stream", 1, lpvp_stream_names, 1, &stream, err, sizeof err) != LPVP_FIELD_OK ||
        lpvp_get_int(j, "tick", 1, 0, INT64_MAX, &tick, err, sizeof err) != LPVP_FIELD_OK) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err); /* ACK has no reply, but a bad one is an error */
        return;
    }
    sv_sub_ack(&c->subs[SV_STREAM_VOLUME], (uint64_t)tick);
}

/* ---- completions of GL jobs ---------------------------------------------- */
void sv_session_job_done(sv_job *j, sv_conn *c, uint32_t request_id)
{
    c->busy = 0;
    if (c->closing || c->close_after_write)
        return;
    if (j->status) {
        sv_reply_err(c, request_id, j->status, 0, "%s", j->err);
    } else if (j->kind == SV_JOB_TICK) {
        json_t *b = sv_rev_body(c);
        json_object_set_new(b, "tick", json_integer((json_int_t)j->result->tick));
        json_object_set_new(b, "stats", tick_stats(j->result));
        sv_reply(c, LPVP_TICK, request_id, b);
    } else if (j->kind == SV_JOB_RENDER) {
        send_frame_reply(c, request_id, j->rgba, j->width, j->height, (int)(j->count & 15), (int)(j->count >> 4),
                         j->terms, &j->display, j->tick);
    } else if (j->kind == SV_JOB_QUERY) {
        uint8_t *att = malloc(j->count ? j->count * 12 : 1);
        if (!att) {
            sv_reply_err(c, request_id, LPVP_E_INTERNAL, 0, "out of memory");
        } else {
            for (size_t i = 0; i < j->count * 3; ++i) {
                uint32_t u;
                memcpy(&u, &j->out[i], 4);
                lpvp_put_u32(att + i * 4, u);
            }
            json_t *b = json_pack("{s:I, s:I, s:I}", "revision", (json_int_t)c->revision, "tick", (json_int_t)j->tick,
                                  "count", (json_int_t)j->count);
            sv_send(c, LPVP_REPLY(LPVP_QUERY_IRRADIANCE), request_id, b, att, j->count * 12, SV_STREAM_NONE);
        }
    }
    sv_session_pump(c);
}

/* ---- streams ---------------------------------------------------------------- */
void sv_session_stream(sv_conn *c, sv_result *r)
{
    if (!c->hello || c->close_after_write || c->world_gen != r->gen)
        return;
    char err[512];
    sv_sub *vs = &c->subs[SV_STREAM_VOLUME];
    if (vs->on) {
        json_t *b = NULL;
        uint8_t *att = NULL;
        size_t alen = 0;
        if (sv_encode_volume(r, vs->fp16, vs->zstd, vs, c->revision, &b, &att, &alen, err, sizeof err) == 0)
            sv_send(c, LPVP_VOLUME, 0, b, att, alen, SV_STREAM_VOLUME);
        else
            fprintf(stderr, "lpvd serve: client %llu: volume: %s\n", (unsigned long long)c->id, err);
    }
    sv_sub *fs = &c->subs[SV_STREAM_FRAME];
    if (fs->on && r->frames[fs->terms] && !c->closing) {
        json_t *b = NULL;
        uint8_t *att = NULL;
        size_t alen = 0;
        if (sv_encode_frame(r->frames[fs->terms], r->width, r->height, fs->fmt, fs->zstd, fs->terms, &fs->display,
                            c->revision,
                            r->tick, &r->plan, &b, &att, &alen, err, sizeof err) == 0)
            sv_send(c, LPVP_FRAME, 0, b, att, alen, SV_STREAM_FRAME);
        else
            fprintf(stderr, "lpvd serve: client %llu: frame: %s\n", (unsigned long long)c->id, err);
    }
}

/* ---- dispatch ---------------------------------------------------------------- */
static void dispatch(sv_conn *c, sv_request *r)
{
    sv_server *s = c->srv;
    s->requests++;
    if (!lpvp_type_is_request(r->type)) {
        sv_reply_err(c, r->request_id, LPVP_E_UNKNOWN_TYPE, 0, "message type 0x%04x is not a request this server knows",
                  r->type);
        return;
    }
    char err[512];
    json_t *j = lpvp_body_parse(r->json, r->json_len, err, sizeof err);
    if (!j) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_JSON, 0, "%s", err);
        return;
    }
    if (s->stopping) {
        sv_reply_err(c, r->request_id, LPVP_E_SHUTTING_DOWN, 0, "the server is stopping");
    } else if (r->type == LPVP_HELLO) {
        sv_do_hello(c, r, j);
    } else if (!c->hello) {
        sv_reply_err(c, r->request_id, LPVP_E_HELLO_REQUIRED, 0, "%s before HELLO: send HELLO first",
                  lpvp_type_name(r->type));
    } else {
        switch (r->type) {
        case LPVP_SCENE_LOAD: sv_do_scene_load(c, r, j); break;
        case LPVP_SCENE_UPDATE: sv_do_scene_update(c, r, j); break;
        case LPVP_LIGHT_SET: sv_do_light_set(c, r, j); break;
        case LPVP_LIGHT_REMOVE: sv_do_light_remove(c, r, j); break;
        case LPVP_CAMERA_SET: sv_do_camera_set(c, r, j); break;
        case LPVP_CONFIG: sv_do_config(c, r, j); break;
        case LPVP_TICK: sv_do_tick(c, r); break;
        case LPVP_SUBSCRIBE: sv_do_subscribe(c, r, j, 1); break;
        case LPVP_UNSUBSCRIBE: sv_do_subscribe(c, r, j, 0); break;
        case LPVP_GET_VOLUME: sv_do_get_volume(c, r, j); break;
        case LPVP_GET_FRAME: sv_do_get_frame(c, r, j); break;
        case LPVP_QUERY_IRRADIANCE: sv_do_query(c, r, j); break;
        case LPVP_STATS: sv_do_stats(c, r); break;
        case LPVP_BYE:
            sv_reply(c, LPVP_BYE, r->request_id, json_object());
            sv_conn_close_after_write(c);
            break;
        case LPVP_ACK: sv_do_ack(c, r, j); break;
        default:
            sv_reply_err(c, r->request_id, LPVP_E_UNKNOWN_TYPE, 0, "message type 0x%04x is not handled", r->type);
        }
    }
    json_decref(j);
}

void sv_session_pump(sv_conn *c)
{
    if (c->closed)
        return;
    c->refs++;
    while (!c->busy && !c->closing && !c->close_after_write && c->pending_head) {
        sv_request *r = c->pending_head;
        c->pending_head = r->next;
        if (!c->pending_head)
            c->pending_tail = NULL;
        c->pending_count--;
        c->pending_bytes -= r->json_len + r->att_len;
        dispatch(c, r);
        free(r->json);
        free(r->att);
        free(r);
    }
    if (!c->closing)
        sv_net_resume_reading(c);
    sv_conn_unref(c);
}
