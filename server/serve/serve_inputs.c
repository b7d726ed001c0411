/*
 * serve_inputs.c - what a world computes from: the live scenes (shared by
 * hash, counted against --max-scenes-memory) and the immutable snapshots of
 * a session's inputs (sv_inputs) whose key identifies a world. Below the
 * GL thread (serve_gl.c, whose jobs hold inputs) and the worlds
 * (serve_world.c), so the GL side never calls into the world layer.
 */
#include "serve.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- small helpers ------------------------------------------------------ */
void sv_scene_unref(sv_server *s, sv_scene *sc)
{
    if (!sc || --sc->refs > 0)
        return;
    for (sv_scene **p = &s->scenes; *p; p = &(*p)->next)
        if (*p == sc) {
            *p = sc->next;
            break;
        }
    if (s->builtin == sc)
        s->builtin = NULL;
    sv_memory_sub(&s->mem, SV_MEM_SCENES, sc->bytes);
    lpv_scene_free(&sc->scene);
    free(sc->glb);
    free(sc->base_dir);
    free(sc->nodes);
    free(sc);
}

/* The live scene equal to sc (same bytes, folder and node overrides), or NULL. */
static sv_scene *scene_equal(sv_server *s, const sv_scene *sc)
{
    for (sv_scene *o = s->scenes; o; o = o->next)
        if (o->hash == sc->hash && o->glb_size == sc->glb_size &&
            (o->glb_size == 0 || (o->glb && sc->glb && memcmp(o->glb, sc->glb, o->glb_size) == 0)) &&
            ((!o->base_dir && !sc->base_dir) || (o->base_dir && sc->base_dir && !strcmp(o->base_dir, sc->base_dir))) &&
            o->node_count == sc->node_count &&
            (!o->node_count || memcmp(o->nodes, sc->nodes, sizeof *o->nodes * o->node_count) == 0))
            return o;
    return NULL;
}

int sv_scene_fits(sv_server *s, const sv_scene *sc, char *err, size_t n)
{
    if (scene_equal(s, sc))
        return 1;
    const uint64_t held = sv_memory_held(&s->mem, SV_MEM_SCENES);
    if (held + sc->bytes > s->cfg.max_scenes_memory) {
        snprintf(err, n, "the scene needs %llu bytes; the server's scenes take %llu of the %llu bytes all scenes may "
                 "take together (--max-scenes-memory): try again when sessions have let theirs go",
                 (unsigned long long)sc->bytes, (unsigned long long)held, (unsigned long long)s->cfg.max_scenes_memory);
        return 0;
    }
    if (!sv_memory_fits(&s->mem, SV_MEM_SCENES, sc->bytes)) { /* R7.6a */
        char budget[SV_MEMORY_DESCRIBE_SIZE];
        sv_memory_describe(&s->mem, budget, sizeof budget);
        snprintf(err, n, "the scene needs %llu bytes; %s: try again when sessions have let theirs go",
                 (unsigned long long)sc->bytes, budget);
        return 0;
    }
    return 1;
}

sv_scene *sv_scene_intern(sv_server *s, sv_scene *sc)
{
    sv_scene *o = scene_equal(s, sc);
    if (o) {
        o->refs++;
        /* sc was never listed: free it directly */
        lpv_scene_free(&sc->scene);
        free(sc->glb);
        free(sc->base_dir);
        free(sc->nodes);
        free(sc);
        return o;
    }
    sc->refs = 1;
    sc->next = s->scenes;
    s->scenes = sc;
    sv_memory_add(&s->mem, SV_MEM_SCENES, sc->bytes);
    return sc;
}

/* ---- inputs ------------------------------------------------------------- */
void sv_inputs_unref(sv_inputs *in)
{
    if (!in || --in->refs > 0)
        return;
    free(in->materials);
    free(in->lights);
    free(in->key);
    free(in);
}

static void key_put(uint8_t **k, size_t *len, size_t *cap, const void *d, size_t n)
{
    if (*len + n > *cap) {
        size_t nc = (*cap ? *cap * 2 : 1024);
        while (nc < *len + n)
            nc *= 2;
        uint8_t *p = realloc(*k, nc);
        if (!p)
            return;
        *k = p;
        *cap = nc;
    }
    memcpy(*k + *len, d, n);
    *len += n;
}

sv_inputs *sv_inputs_build(sv_conn *c)
{
    sv_inputs *in = calloc(1, sizeof *in);
    if (!in)
        return NULL;
    in->refs = 1;
    in->scene = c->scene;
    in->material_count = c->material_count;
    in->light_count = c->light_count;
    if (c->material_count) {
        in->materials = malloc(sizeof(lpv_material) * c->material_count);
        if (!in->materials)
            goto fail;
        memcpy(in->materials, c->materials, sizeof(lpv_material) * c->material_count);
    }
    if (c->light_count) {
        in->lights = malloc(sizeof(lpv_light) * c->light_count);
        if (!in->lights)
            goto fail;
        memcpy(in->lights, c->lights, sizeof(lpv_light) * c->light_count);
    }
    in->settings = c->settings;
    in->tick_rate = c->tick_rate;
    in->view = c->view;
    size_t cap = 0;
    uint64_t sh = c->scene ? c->scene->hash : 0;
    uintptr_t sp = (uintptr_t)c->scene; /* interned: one object per content */
    key_put(&in->key, &in->key_len, &cap, &sh, sizeof sh);
    key_put(&in->key, &in->key_len, &cap, &sp, sizeof sp);
    key_put(&in->key, &in->key_len, &cap, &in->material_count, sizeof in->material_count);
    if (in->material_count)
        key_put(&in->key, &in->key_len, &cap, in->materials, sizeof(lpv_material) * in->material_count);
    key_put(&in->key, &in->key_len, &cap, &in->light_count, sizeof in->light_count);
    if (in->light_count)
        key_put(&in->key, &in->key_len, &cap, in->lights, sizeof(lpv_light) * in->light_count);
    key_put(&in->key, &in->key_len, &cap, &in->settings, sizeof in->settings);
    key_put(&in->key, &in->key_len, &cap, &in->tick_rate, sizeof in->tick_rate);
    key_put(&in->key, &in->key_len, &cap, &in->view, sizeof in->view);
    if (!in->key)
        goto fail;
    in->key_hash = lpv_hash_bytes(LPV_HASH_INIT, in->key, in->key_len);
    if (in->scene)
        in->scene->refs++;
    return in;
fail:
    free(in->materials);
    free(in->lights);
    free(in->key);
    free(in);
    return NULL;
}

void sv_inputs_release(sv_server *s, sv_inputs *in)
{
    if (!in)
        return;
    if (in->refs == 1)
        sv_scene_unref(s, in->scene);
    sv_inputs_unref(in);
}
