/*
 * reach_volume.c - the engine's side of core/reach.h: the scene's air
 * spaces built when its geometry arrives, the lit ones found again when the
 * lights change, and the mask as an R8UI 3D texture that reach.glsl reads
 * in every pass that looks the technique's volume up (docs/propagation.md,
 * "Enclosed lights").
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "engine_internal.h"

void lpv_engine_reach_free(lpv_engine *e)
{
    lpv_reach_free(&e->reach);
    e->view_chord = 0.0f;
    if (e->reach_tex)
        glDeleteTextures(1, &e->reach_tex);
    e->reach_tex = 0;
}

int lpv_engine_reach_build(lpv_engine *e, const lpv_scene *scene, char *err, size_t err_size)
{
    lpv_engine_reach_free(e);
    if (lpv_reach_build(&e->reach, scene, 0, err, err_size) != 0) {
        lpv_reach_free(&e->reach); /* a scene without bounds: everything reads lit */
        return lpv_error(err, err_size, "%s: %s", scene->source, err);
    }
    lpv_engine_reach_view(e);
    return 0;
}

void lpv_engine_reach_view(lpv_engine *e)
{
    if (!e->has_view || !e->reach.label) {
        e->view_chord = 0.0f;
        return;
    }
    float d2 = 0.0f;
    for (int i = 0; i < 3; ++i)
        d2 += (e->view.eye[i] - e->view_chord_eye[i]) * (e->view.eye[i] - e->view_chord_eye[i]);
    if (e->view_chord != 0.0f && d2 < e->reach.voxel * e->reach.voxel)
        return;
    e->view_chord = lpv_reach_view_chord(&e->reach, e->view.eye);
    memcpy(e->view_chord_eye, e->view.eye, sizeof e->view_chord_eye);
}

void lpv_engine_reach_light(lpv_engine *e)
{
    if (!e->reach.mask)
        return;
    /* the lights light the same spaces as before (one moved in its room):
     * the texture holds the mask already */
    if (!lpv_reach_light(&e->reach, &e->geometry, e->lights, e->light_count) && e->reach_tex)
        return;
    if (!e->reach_tex) {
        glGenTextures(1, &e->reach_tex);
        glBindTexture(GL_TEXTURE_3D, e->reach_tex);
        glTexStorage3D(GL_TEXTURE_3D, 1, GL_R8UI, e->reach.dims[0], e->reach.dims[1], e->reach.dims[2]);
        glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    } else
        glBindTexture(GL_TEXTURE_3D, e->reach_tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, 0, e->reach.dims[0], e->reach.dims[1], e->reach.dims[2], GL_RED_INTEGER,
                    GL_UNSIGNED_BYTE, e->reach.mask);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glBindTexture(GL_TEXTURE_3D, 0);
}

int lpv_engine_reach_in_use(const lpv_engine *e)
{
    return e->reach_tex && !e->reach.unsure && e->settings.reach != LPV_SWITCH_OFF;
}

int lpv_engine_lit_region(const lpv_engine *e, float min[3], float max[3], float *free_path)
{
    double box = 1.0, bounds = 1.0;
    for (int k = 0; k < 3; ++k) {
        min[k] = e->reach.lit_min[k] > e->scene_min[k] ? e->reach.lit_min[k] : e->scene_min[k];
        max[k] = e->reach.lit_max[k] < e->scene_max[k] ? e->reach.lit_max[k] : e->scene_max[k];
        box *= fmax((double)max[k] - (double)min[k], 0.0);
        bounds *= (double)e->scene_max[k] - (double)e->scene_min[k];
    }
    /* the lit box pays where it is much smaller than the scene (a lit tunnel
     * under a wide hill); a room's lit air is most of its bounds, and a
     * grid a few per cent smaller only moves where its voxels fall */
    const int lit = lpv_engine_reach_in_use(e) && e->reach.lit_box && box <= LPV_REACH_LIT_BOX_SHARE * bounds;
    if (!lit) {
        memcpy(min, e->scene_min, sizeof e->scene_min);
        memcpy(max, e->scene_max, sizeof e->scene_max);
    }
    *free_path = lit ? e->reach.lit_free_path : e->reach.free_path;
    return lit;
}

/* A perspective camera standing in air a light reaches sees only surfaces
 * that face that air (solid geometry hides the rest; cut-out and blended
 * surfaces are not solid in the mask), where the mask is 1: the frame skips
 * its per-pixel fetches (13 % of the balanced tick on the built-in box). */
int lpv_engine_reach_per_pixel(const lpv_engine *e)
{
    return lpv_engine_reach_in_use(e) &&
           !(e->has_view && !e->view.orthographic && lpv_reach_lit_at(&e->reach, e->view.eye));
}

void lpv_engine_bind_lookup(const lpv_engine *e, GLuint prog, float damping)
{
    e->tech->cls->bind_lookup(e->tech, prog, damping);
    const int on = lpv_engine_reach_per_pixel(e);
    glActiveTexture(GL_TEXTURE0 + LPV_TEX_REACH);
    glBindTexture(GL_TEXTURE_3D, on ? e->reach_tex : 0);
    glActiveTexture(GL_TEXTURE0);
    glUniform4f(glGetUniformLocation(prog, "u_reach_grid"), e->reach.origin[0], e->reach.origin[1],
                e->reach.origin[2], on ? e->reach.voxel : 0.0f);
}
