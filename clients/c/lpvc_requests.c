/*
 * lpvc_requests.c - the C client's requests (SPEC section 4): each builds
 * its JSON body and goes through lpvci_request (lpvc_transport.c); the
 * knob accessors read the HELLO description kept on the connection.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lpvc_internal.h"
#include "volume_codec.h"

size_t lpvc_knobs(const lpvc *c, const lpvc_knob **knobs)
{
    if (knobs)
        *knobs = c ? c->knobs.knobs : NULL;
    return c ? c->knobs.count : 0;
}

const lpvc_knob *lpvc_knob_find(const lpvc *c, const char *name)
{
    return c ? lpvc_knobset_find(&c->knobs, name) : NULL;
}

const char *const *lpvc_presets(const lpvc *c, size_t *count)
{
    if (count)
        *count = c ? c->knobs.preset_count : 0;
    return c ? c->knobs.presets : NULL;
}

const char *const *lpvc_techniques(const lpvc *c, size_t *count)
{
    if (count)
        *count = c ? c->knobs.technique_count : 0;
    return c ? c->knobs.techniques : NULL;
}

/* ---- requests -------------------------------------------------------------- */

static json_t *vec(const float *v, int n)
{
    json_t *a = json_array();
    for (int i = 0; i < n; i++)
        json_array_append_new(a, json_real(v[i]));
    return a;
}

json_t *lpvci_parse_object(lpvc *c, const char *text, const char *what)
{
    if (!text)
        text = "{}";
    char err[256];
    json_t *o = lpvp_body_parse(text, strlen(text), err, sizeof err);
    if (!o)
        lpvci_fail(c, LPVC_ERR_USAGE, "%s: %s", what, err);
    return o;
}

int lpvc_scene_load_file(lpvc *c, const char *path)
{
    if (!c || !path)
        return c ? lpvci_fail(c, LPVC_ERR_USAGE, "scene path is NULL") : -1;
    return lpvci_simple(c, LPVP_SCENE_LOAD, json_pack("{s:s}", "path", path));
}

int lpvc_scene_load_glb(lpvc *c, const void *glb, size_t size)
{
    if (!c)
        return -1;
    if (!glb || size == 0)
        return lpvci_fail(c, LPVC_ERR_USAGE, "empty .glb");
    json_t *body = json_object();
    int rc = lpvci_request(c, LPVP_SCENE_LOAD, body, glb, size, NULL, NULL, NULL);
    json_decref(body);
    return rc;
}

int lpvc_scene_update(lpvc *c, const char *json)
{
    if (!c)
        return -1;
    json_t *o = lpvci_parse_object(c, json, "scene update");
    return o ? lpvci_simple(c, LPVP_SCENE_UPDATE, o) : -1;
}

int lpvc_light_set(lpvc *c, const lpvc_light *l)
{
    if (!c)
        return -1;
    if (!l || !l->id)
        return lpvci_fail(c, LPVC_ERR_USAGE, "light id is required");
    json_t *o = json_pack("{s:s, s:s, s:f}", "id", l->id, "type", l->type ? l->type : "point", "intensity",
                          (double)l->intensity);
    if (!o)
        return lpvci_fail(c, LPVC_ERR_USAGE, "out of memory");
    if (l->color)
        json_object_set_new(o, "color", vec(l->color, 3));
    if (l->position)
        json_object_set_new(o, "position", vec(l->position, 3));
    if (l->direction)
        json_object_set_new(o, "direction", vec(l->direction, 3));
    if (l->range != 0.0f)
        json_object_set_new(o, "range", json_real(l->range));
    if (l->inner_cone != 0.0f)
        json_object_set_new(o, "inner_cone", json_real(l->inner_cone));
    if (l->outer_cone != 0.0f)
        json_object_set_new(o, "outer_cone", json_real(l->outer_cone));
    return lpvci_simple(c, LPVP_LIGHT_SET, o);
}

int lpvc_light_remove(lpvc *c, const char *id)
{
    if (!c)
        return -1;
    if (!id)
        return lpvci_fail(c, LPVC_ERR_USAGE, "light id is required");
    return lpvci_simple(c, LPVP_LIGHT_REMOVE, json_pack("{s:s}", "id", id));
}

int lpvc_camera_set(lpvc *c, const lpvc_camera *cam)
{
    if (!c)
        return -1;
    if (!cam)
        return lpvci_fail(c, LPVC_ERR_USAGE, "camera is NULL");
    json_t *o;
    if (cam->scene_camera_name)
        o = json_pack("{s:s}", "camera", cam->scene_camera_name);
    else if (cam->scene_camera > 0)
        o = json_pack("{s:i}", "camera", cam->scene_camera - 1);
    else {
        if (!cam->eye || !cam->target)
            return lpvci_fail(c, LPVC_ERR_USAGE, "camera needs eye and target, or a scene camera");
        o = json_object();
        json_object_set_new(o, "eye", vec(cam->eye, 3));
        json_object_set_new(o, "target", vec(cam->target, 3));
        if (cam->up)
            json_object_set_new(o, "up", vec(cam->up, 3));
        if (cam->fov_deg != 0.0f)
            json_object_set_new(o, "fov_deg", json_real(cam->fov_deg));
        if (cam->width > 0)
            json_object_set_new(o, "width", json_integer(cam->width));
        if (cam->height > 0)
            json_object_set_new(o, "height", json_integer(cam->height));
    }
    return lpvci_simple(c, LPVP_CAMERA_SET, o);
}

int lpvc_config_set(lpvc *c, const lpvc_config *cfg)
{
    if (!c)
        return -1;
    lpvc_config z = {0};
    if (!cfg)
        cfg = &z;
    json_t *o = json_object();
    if (cfg->technique)
        json_object_set_new(o, "technique", json_string(cfg->technique));
    if (cfg->preset)
        json_object_set_new(o, "preset", json_string(cfg->preset));
    if (cfg->grid[0] || cfg->grid[1] || cfg->grid[2])
        json_object_set_new(o, "grid", json_pack("[i,i,i]", cfg->grid[0], cfg->grid[1], cfg->grid[2]));
    if (cfg->bounds)
        json_object_set_new(o, "bounds", vec(cfg->bounds, 6));
    if (cfg->tick_rate_hz != 0.0f)
        json_object_set_new(o, "tick_rate_hz", json_real(cfg->tick_rate_hz));
    char err[512];
    if (lpvc_knobset_add(&c->knobs, o, cfg->settings, cfg->settings ? cfg->setting_count : 0, err, sizeof err) != 0) {
        json_decref(o);
        return lpvci_fail(c, LPVC_ERR_USAGE, "%s", err);
    }
    return lpvci_simple(c, LPVP_CONFIG, o);
}

int lpvc_config_json(lpvc *c, const char *json)
{
    if (!c)
        return -1;
    json_t *o = lpvci_parse_object(c, json, "config");
    return o ? lpvci_simple(c, LPVP_CONFIG, o) : -1;
}

int lpvc_tick(lpvc *c, int64_t *tick)
{
    if (!c)
        return -1;
    json_t *body = json_object(), *reply = NULL;
    int rc = lpvci_request(c, LPVP_TICK, body, NULL, 0, &reply, NULL, NULL);
    json_decref(body);
    if (rc == 0 && tick) {
        json_t *t = json_object_get(reply, "tick");
        *tick = json_is_integer(t) ? json_integer_value(t) : -1;
    }
    json_decref(reply);
    return rc;
}

static const char *stream_name(enum lpvc_stream s)
{
    return lpvp_stream_names[s == LPVC_STREAM_FRAME ? LPVP_STREAM_FRAME : LPVP_STREAM_VOLUME];
}

int lpvc_subscribe(lpvc *c, const lpvc_subscribe_desc *desc)
{
    if (!c)
        return -1;
    lpvc_subscribe_desc d = {0};
    if (desc)
        d = *desc;
    json_t *o = json_pack("{s:s}", "stream", stream_name(d.stream));
    if (d.format)
        json_object_set_new(o, "format", json_string(d.format));
    if (d.compression)
        json_object_set_new(o, "compression", json_string(d.compression));
    if (d.error_bound > 0.0)
        json_object_set_new(o, LPVP_SHQ_BOUND_KEY, json_real(d.error_bound));
    if (d.delta)
        json_object_set_new(o, "delta", json_true());
    return lpvci_simple(c, LPVP_SUBSCRIBE, o);
}

int lpvc_unsubscribe(lpvc *c, enum lpvc_stream stream)
{
    if (!c)
        return -1;
    return lpvci_simple(c, LPVP_UNSUBSCRIBE, json_pack("{s:s}", "stream", stream_name(stream)));
}

int lpvc_ack(lpvc *c, int64_t tick)
{
    if (!c)
        return -1;
    lpvci_clear_error(c);
    json_t *o = json_pack("{s:s, s:I}", "stream", lpvp_stream_names[LPVP_STREAM_VOLUME], "tick", (json_int_t)tick);
    if (!o)
        return lpvci_fail(c, LPVC_ERR_USAGE, "out of memory");
    uint32_t id = lpvci_send_frame(c, LPVP_ACK, o, NULL, 0);
    json_decref(o);
    return id ? 0 : -1;
}

/* ---- queries, stats, bye ------------------------------------------------------ */

int lpvc_query_irradiance(lpvc *c, const float *points, const float *normals, size_t n, float *rgb)
{
    if (!c)
        return -1;
    if (n && (!points || !normals || !rgb))
        return lpvci_fail(c, LPVC_ERR_USAGE, "points, normals and rgb must not be NULL");
    if (n > UINT32_MAX / 24)
        return lpvci_fail(c, LPVC_ERR_USAGE, "too many query points (%zu)", n);
    uint8_t *att = malloc(n ? n * 24 : 1);
    if (!att)
        return lpvci_fail(c, LPVC_ERR_IO, "out of memory");
    for (size_t i = 0; i < n; i++) {
        float v[6] = {points[3 * i], points[3 * i + 1], points[3 * i + 2],
                      normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]};
        for (int k = 0; k < 6; k++) {
            uint32_t u;
            memcpy(&u, &v[k], 4);
            lpvp_put_u32(att + 24 * i + 4 * k, u);
        }
    }
    json_t *o = json_pack("{s:I}", "count", (json_int_t)n);
    uint8_t *ratt = NULL;
    size_t ratt_len = 0;
    int rc = lpvci_request(c, LPVP_QUERY_IRRADIANCE, o, att, n * 24, NULL, &ratt, &ratt_len);
    json_decref(o);
    free(att);
    if (rc == 0) {
        if (ratt_len != n * 12) {
            rc = lpvci_fail(c, LPVC_ERR_PROTOCOL, "QUERY_IRRADIANCE answered %zu bytes for %zu points", ratt_len, n);
        } else {
            for (size_t i = 0; i < n * 3; i++) {
                uint32_t u = lpvp_get_u32(ratt + 4 * i);
                memcpy(&rgb[i], &u, 4);
            }
        }
    }
    free(ratt);
    return rc;
}

int lpvc_stats(lpvc *c, char **json)
{
    if (!c)
        return -1;
    if (json)
        *json = NULL;
    int rc = lpvci_simple(c, LPVP_STATS, json_object());
    if (rc == 0 && json) {
        *json = strdup(c->last_reply ? c->last_reply : "{}");
        if (!*json)
            return lpvci_fail(c, LPVC_ERR_IO, "out of memory");
    }
    return rc;
}

int lpvc_bye(lpvc *c)
{
    if (!c)
        return -1;
    int rc = lpvci_simple(c, LPVP_BYE, json_object());
    lpvci_close_fd(c);
    return rc;
}

int lpvc_request_raw(lpvc *c, uint16_t type, const char *json, const void *attachment, size_t att_len, void **att,
                     size_t *att_n)
{
    if (!c)
        return -1;
    json_t *o = lpvci_parse_object(c, json, "request body");
    if (!o)
        return -1;
    uint8_t *ratt = NULL;
    size_t rlen = 0;
    int rc;
    if (type == LPVP_ACK) {
        lpvci_clear_error(c);
        rc = lpvci_send_frame(c, type, o, attachment, att_len) ? 0 : -1;
    } else {
        rc = lpvci_request(c, type, o, attachment, att_len, NULL, &ratt, &rlen);
    }
    json_decref(o);
    if (att)
        *att = ratt;
    else
        free(ratt);
    if (att_n)
        *att_n = rlen;
    return rc;
}
