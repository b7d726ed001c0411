/*
 * serve_controls.c - the requests that change a session's inputs other than
 * its scene: LIGHT_SET, LIGHT_REMOVE, CAMERA_SET and CONFIG (SPEC R4.6,
 * R4.10, R4.11).
 * Each validates the whole message before it changes anything, then bumps
 * the revision and moves the session to the world of its new inputs
 * (sv_session_changed).
 */
#include "serve_session_internal.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cascades.h"
#include "settings_fields.h"
#include "light_json.h"
#include "settings_json.h"
#include "tick_cost.h"

#define SV_MAX_LIGHTS 256
#define SV_MAX_VIEW_SIDE 4096

void sv_do_light_set(sv_conn *c, sv_request *r, json_t *j)
{
    char err[512];
    lpv_light l;
    if (lpvd_light_from_json(j, &l, err, sizeof err) != 0) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
        return;
    }
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
    { /* a frame one world can never hold would fail every tick (issue 31, item 11) */
        const lpv_memory_need need = {.image_w = (int)w, .image_h = (int)h};
        if (lpv_memory_check(&need, &c->srv->gl_limits, err, sizeof err) != 0) {
            sv_reply_err(c, r->request_id, LPVP_E_LIMIT, 0, "width x height %lldx%lld: %s", (long long)w, (long long)h,
                         err);
            return;
        }
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
        if (lpvp_get_floats(j, "eye", 1, 3, -LPV_MAX_COORD, LPV_MAX_COORD, eye, err, sizeof err) != LPVP_FIELD_OK ||
            lpvp_get_floats(j, "target", 1, 3, -LPV_MAX_COORD, LPV_MAX_COORD, target, err, sizeof err) !=
                LPVP_FIELD_OK ||
            (has_up = lpvp_get_floats(j, "up", 0, 3, -1e30, 1e30, up, err, sizeof err)) == LPVP_FIELD_BAD ||
            lpvp_get_float(j, "fov_deg", 0, 0.01, 179.0, &fov, err, sizeof err) == LPVP_FIELD_BAD) {
            sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
            return;
        }
        int look = lpv_view_look_at(eye, target, fov * (float)(M_PI / 180.0), (int)w, (int)h, &v);
        if (look != 0) { /* the ranges above leave only eye == target (the other codes: a defect here) */
            sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s",
                         look == LPV_VIEW_EYE_IS_TARGET ? "target: must differ from eye (by more than 1e-9 m)"
                         : look == LPV_VIEW_BAD_FOV     ? "fov_deg: must be above 0 and below 180"
                                                        : "eye, target: must be finite");
            return;
        }
        if (has_up == LPVP_FIELD_OK) { /* up, made orthogonal to forward */
            /* in double, relative to |up|: components up to 1e30 square beyond float */
            double d = 0.0, u[3], ul = 0.0, upl = 0.0;
            for (int i = 0; i < 3; ++i) {
                d += (double)up[i] * v.forward[i];
                upl += (double)up[i] * up[i];
            }
            for (int i = 0; i < 3; ++i) {
                u[i] = up[i] - d * v.forward[i];
                ul += u[i] * u[i];
            }
            ul = sqrt(ul);
            if (!(ul > 1e-6 * sqrt(upl))) {
                sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0,
                             "up: must be non-zero and not parallel to target - eye");
                return;
            }
            for (int i = 0; i < 3; ++i)
                v.up[i] = (float)(u[i] / ul);
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


void sv_do_config(sv_conn *c, sv_request *r, json_t *j)
{
    sv_server *s = c->srv;
    char err[512];
    lpv_settings st = c->settings;
    double rate = c->tick_rate;
    double lim_rate = s->cfg.max_tick_rate;
    const lpvd_settings_limits lim = {s->cfg.max_grid, s->cfg.max_texture};
    int sst = lpvd_settings_apply_json(j, &st, &lim, err, sizeof err);
    if (sst == LPVD_SETTINGS_LIMIT) {
        sv_reply_err(c, r->request_id, LPVP_E_LIMIT, 0, "%s", err);
        return;
    }
    if (sst != 0)
        goto bad;
    int ist;
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
    /* explicit cascades must be placeable over the scene (the planner falls
     * back to one grid for its own choice, and says so in the plan) */
    char why[320];
    const lpv_scene *sc = &c->scene->scene;
    if (chk.lpv.cascades > 1 && !lpv_settings_bounds_given(&chk) &&
        !lpv_cascades_fit(&chk, sc->bounds_min, sc->bounds_max, 0.0f, why, sizeof why)) {
        snprintf(err, sizeof err, "cascade_size: %s", why);
        goto bad;
    }
    if (sv_tick_cost_check(&s->cfg, &chk, err, sizeof err) != 0 || /* R4.6a: the settings as a whole */
        sv_memory_floor_check(s, &chk, (int)c->light_count, err, sizeof err) != 0) {
        sv_reply_err(c, r->request_id, LPVP_E_LIMIT, 0, "%s", err);
        return;
    }
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

int sv_tick_cost_check(const sv_config *cfg, const lpv_settings *s, char *err, size_t n)
{
    lpv_tick_cost tc;
    lpv_tick_cost_estimate(s, &tc);
    if (tc.cell_steps <= (double)cfg->max_tick_cost)
        return 0;
    snprintf(err, n, "tick cost: %s = %.0f cell-steps, over the server's budget of %llu a tick (--max-tick-cost); "
             "lower %s", tc.terms, tc.cell_steps, (unsigned long long)cfg->max_tick_cost, tc.lower);
    return -1;
}

int sv_memory_floor_check(const sv_server *s, const lpv_settings *st, int light_faces, char *err, size_t n)
{
    lpv_memory_need need;
    lpv_memory_need_floor(st, light_faces, &need);
    return lpv_memory_check(&need, &s->gl_limits, err, n);
}

int sv_grid_that_fits(const sv_server *s, int n)
{
    lpv_settings base = s->cfg.settings; /* the sessions' default RSM and shadow sizes, one point light */
    lpv_settings_resolve(&base);
    for (; n > 1; --n) {
        lpv_settings st = {.technique = LPV_TECHNIQUE_ID_LPV, .grid_dims = {n, n, n}, .rsm_size = base.rsm_size,
                           .shadow_size = base.shadow_size};
        st.lpv.cascades = 1; /* and no far field */
        if (sv_memory_floor_check(s, &st, 6, NULL, 0) == 0) /* a point light's six faces */
            break;
    }
    return n;
}

/* CONFIG's reply and STATS' "config": the session's settings, resolved. */
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
    const char *technique = lpv_technique_name(s.technique);
    json_t *o = json_pack("{s:s, s:s, s:[i,i,i], s:o, s:b}", "technique", technique ? technique : "", "preset",
                          preset ? preset : "", "grid", s.grid_dims[0], s.grid_dims[1], s.grid_dims[2], "bounds",
                          bounds, "bounds_auto", auto_bounds);
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
