/*
 * serve_session.c - one session per connection (SPEC section 7): its state
 * (scene, materials, lights, camera, config, revision, subscriptions), what
 * changes it for every handler, its requests on worker threads, and its
 * shutdown. Its requests are dispatched by serve_dispatch.c, above the
 * handlers (listed in serve_session_internal.h); this file is below them.
 */
#include "serve_session_internal.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
    c->subs[SV_STREAM_VOLUME].vol = (sv_volume_coding){.fp16 = 1, .comp = LPVP_COMP_ZSTD};
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

/* ---- requests on worker threads, and shutdown ------------------------------ */
void sv_session_work_begin(sv_conn *c, uint32_t request_id)
{
    c->work_inflight = 1;
    c->work_request_id = request_id;
    c->srv->works_inflight++;
}

void sv_session_work_end(sv_conn *c)
{
    c->work_inflight = 0;
    c->srv->works_inflight--;
}

void sv_session_answered(sv_conn *c)
{
    c->busy = 0;
    c->idle_since_ms = sv_now_ms();
}

void sv_session_shutdown(sv_conn *c)
{
    if (c->closing || c->close_after_write)
        return;
    /* A load on a worker cannot be stopped: it is answered now and its
     * result dropped when it ends (the connection is closing by then). */
    if (c->work_inflight)
        sv_reply_err(c, c->work_request_id, LPVP_E_SHUTTING_DOWN, 1, "the server is stopping");
    for (sv_request *r = c->pending_head; r; r = r->next)
        if (lpvp_type_has_reply(r->type))
            sv_reply_err(c, r->request_id, LPVP_E_SHUTTING_DOWN, 1, "the server is stopping");
    sv_send(c, LPVP_BYE_REPLY, 0, json_object(), NULL, 0, SV_STREAM_NONE);
    sv_conn_close_after_write(c);
}
