/*
 * engine_technique.c - the technique the engine drives (technique.h): which
 * one runs (auto's choice from the scene's facts), its instance, the
 * programs that read its volume (shading, queries, glossy, media and the
 * frame's variants, built with its lookup includes), and where its volume is
 * placed and committed outside a tick. Below the engine's other files: it
 * calls none of them but engine_facts.c, so the scene, the tick and the
 * passes call it without a circle.
 */
#include <stdio.h>
#include <string.h>

#include "engine_internal.h"
#include "error.h"
#include "shader.h"

static const char *const INC_SHADE[] = {"lights.glsl", "shadow.glsl", "shading.glsl", NULL};
static const char *const INC_MEDIA[] = {"lights.glsl", "shadow.glsl", "medium.glsl", NULL};

/* out = grid.glsl (the SH basis and grid block every reader of a volume
 * uses, whatever the technique), the technique's lookup includes (a name
 * already in the list is not pasted twice), reach.glsl (the enclosed-light
 * mask every reader of the volume multiplies by), then the pass's own (both
 * NULL-terminated; own may be NULL). Returns -1 when they do not fit. */
static int includes(const char **out, size_t cap, const char *const *own, const char *const *lookup)
{
    size_t n = 0;
    out[n++] = "grid.glsl";
    for (const char *const *i = lookup; i && *i; ++i) {
        int dup = 0;
        for (size_t k = 0; k < n; ++k)
            dup |= strcmp(out[k], *i) == 0;
        if (dup)
            continue;
        if (n + 1 < cap)
            out[n++] = *i;
        else
            return -1;
    }
    if (n + 1 < cap)
        out[n++] = "reach.glsl";
    else
        return -1;
    for (const char *const *i = own; i && *i; ++i)
        if (n + 1 < cap)
            out[n++] = *i;
        else
            return -1;
    out[n] = NULL;
    return 0;
}

/* The frame programs built so far (lpv_engine_frame_program). */
void lpv_engine_free_frame_programs(lpv_engine *e)
{
    for (int v = 0; v < LPV_FRAME_VARIANTS; ++v)
        if (e->progs.frame[v]) {
            glDeleteProgram(e->progs.frame[v]);
            e->progs.frame[v] = 0;
        }
}

/* Makes technique id the engine's: creates its instance and builds the
 * passes that read its volume (shading, query, glossy, media) with its
 * lookup includes (technique.h). On failure the current technique stays. */
int lpv_engine_use_technique(lpv_engine *e, lpv_technique_id id, char *err, size_t err_size)
{
    const lpv_technique_class *cls = lpv_technique_class_of(id);
    if (!cls)
        return lpv_error(err, err_size, "technique %d has no implementation", (int)id);
    const char *const *lookup = cls->lookup_includes;
    const char *inc_shade[16], *inc_media[16], *inc_lookup[16];
    if (includes(inc_shade, 16, INC_SHADE, lookup) || includes(inc_media, 16, INC_MEDIA, lookup) ||
        includes(inc_lookup, 16, NULL, lookup))
        return lpv_error(err, err_size, "technique %s names too many lookup includes", cls->name);
    struct {
        GLuint *prog;
        const char *a, *b;
        const char *const *inc;
        const char *defines;
    } progs[] = {
        /* the frame's programs are built when first used (lpv_engine_frame_program) */
        {&e->progs.shade_rest, "shade_rest.comp", NULL, inc_shade,
         "#define LPV_LOOKUP_DAMPING 0\n#define LPV_LOOKUP_SPLIT 1"},
        {&e->progs.shade_rest_damped, "shade_rest.comp", NULL, inc_shade, "#define LPV_LOOKUP_SPLIT 1"},
        {&e->progs.area_shadow_blocks, "area_shadow_blocks.comp", NULL, inc_shade, "#define LPV_LOOKUP_DAMPING 0"},
        {&e->progs.area_shadow_rest, "area_shadow_rest.comp", NULL, inc_shade,
         "#define LPV_LOOKUP_DAMPING 0\n#define LPV_AREA_SHADOW_BLOCKS 1"},
        {&e->progs.lookup_blocks, "lookup_blocks.comp", NULL, inc_shade, "#define LPV_LOOKUP_DAMPING 0"},
        {&e->progs.lookup_blocks_damped, "lookup_blocks.comp", NULL, inc_shade, NULL},
        {&e->progs.query, "query.comp", NULL, inc_lookup},
        {&e->progs.glossy, "fullscreen.vert", "glossy.frag", inc_lookup},
        {&e->progs.media, "fullscreen.vert", "media.frag", inc_media},
    };
    enum { N = sizeof progs / sizeof progs[0] };
    GLuint built[N] = {0};
    for (size_t i = 0; i < N; ++i) {
        built[i] = lpv_program_build_defines(progs[i].a, NULL, progs[i].b, progs[i].defines, progs[i].inc, err,
                                             err_size);
        if (!built[i]) {
            for (size_t k = 0; k < i; ++k)
                glDeleteProgram(built[k]);
            return -1;
        }
    }
    lpv_technique *t = cls->create(err, err_size);
    if (!t) {
        for (size_t k = 0; k < N; ++k)
            glDeleteProgram(built[k]);
        return -1;
    }
    for (size_t i = 0; i < N; ++i) {
        if (*progs[i].prog)
            glDeleteProgram(*progs[i].prog);
        *progs[i].prog = built[i];
    }
    if (e->tech)
        e->tech->cls->destroy(e->tech);
    e->tech = t;
    e->tech_id = id;
    lpv_engine_free_frame_programs(e); /* they hold the previous technique's lookup */
    return 0;
}

GLuint lpv_engine_frame_program(lpv_engine *e, unsigned variant, char *err, size_t err_size)
{
    if (variant & LPV_FRAME_BLOCKS) /* the frame reads the blocks' irradiance: it looks nothing up */
        variant &= ~(unsigned)(LPV_FRAME_DAMPED | LPV_FRAME_SPLIT);
    if (e->progs.frame[variant])
        return e->progs.frame[variant];
    const char *inc_shade[16];
    if (includes(inc_shade, 16, INC_SHADE, e->tech->cls->lookup_includes)) {
        lpv_error(err, err_size, "technique %s names too many lookup includes", e->tech->cls->name);
        return 0;
    }
    char defines[384];
    snprintf(defines, sizeof defines, "%s%s%s%s%s%s%s",
             variant & LPV_FRAME_OCCLUSION ? "" : "#define LPV_FRAME_OCCLUSION 0\n",
             variant & LPV_FRAME_UNLIT ? "" : "#define LPV_FRAME_UNLIT 0\n",
             variant & LPV_FRAME_DIRECTIONAL ? "" : "#define LPV_SHADE_DIRECTIONAL 0\n",
             variant & LPV_FRAME_DAMPED ? "" : "#define LPV_LOOKUP_DAMPING 0\n",
             variant & LPV_FRAME_SPLIT ? "#define LPV_LOOKUP_SPLIT 1\n" : "",
             variant & LPV_FRAME_BLOCKS ? "#define LPV_LOOKUP_BLOCKS 1\n" : "",
             variant & LPV_FRAME_AREA_BLOCKS ? "#define LPV_AREA_SHADOW_BLOCKS 1\n" : "");
    e->progs.frame[variant] = lpv_program_build_defines("shade.comp", NULL, NULL, defines, inc_shade, err, err_size);
    return e->progs.frame[variant];
}

int lpv_engine_resolve_technique(lpv_engine *e, const lpv_settings *s, char *err, size_t err_size)
{
    lpv_plan_facts facts;
    lpv_engine_gather_facts(e, &facts);
    char why[sizeof e->tech_reason];
    const lpv_technique_id id = lpv_technique_choose(s, e->has_scene ? &facts : NULL, why, sizeof why);
    if (id != e->tech_id && lpv_engine_use_technique(e, id, err, err_size) != 0)
        return -1;
    e->tech->cls->configure(e->tech, s);
    memcpy(e->tech_reason, why, sizeof why);
    return 0;
}

int lpv_engine_place_volume(lpv_engine *e, char *err, size_t err_size)
{
    lpv_plan_facts f;
    lpv_engine_gather_facts(e, &f);
    lpv_technique_where w;
    lpv_engine_where(e, &f, &w);
    int reset = 0;
    if (e->tech->cls->place(e->tech, &w, NULL, err, err_size) != 0)
        return -1;
    int rc = e->tech->cls->commit(e->tech, &w, &reset, err, err_size);
    lpv_engine_committed(e, reset);
    return rc;
}

void lpv_engine_committed(lpv_engine *e, int reset)
{
    e->tech->cls->describe(e->tech, &e->desc);
    if (reset) { /* new storage holds nothing computed */
        e->ticked = 0;
        e->computed = 0;
    }
}
