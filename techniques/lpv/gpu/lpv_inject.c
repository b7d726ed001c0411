/*
 * pass_inject.c - VPL injection. Each VPL (from the RSMs and from emissive
 * surfaces) is one point rendered with additive blending into a 2D atlas of
 * the grid's z slices (fp32, three attachments for r, g, b): the paper's
 * point-splatting injection, portable because it needs no float atomics and
 * deterministic because blending follows primitive order. A compute pass
 * then copies the atlas into the LPV buffer layout. The VPLs are the
 * engine's (its RSMs and the emissive surfaces'), handed in as inputs.
 */
#include "lpv_internal.h"

void lpv_pass_inject_run(lpv_cascaded *c, const lpv_technique_inputs *in, int rsm_vpls, int emissive_vpls)
{
    lpv_timer *timer = in->timer;
    /* a point per VPL and level, or with the far field one per VPL into the
     * finest level holding it (inject_vpl.vert) */
    const int spread = c->settings.lpv.smooth_injection == LPV_SWITCH_ON; /* four corners a VPL */
    const int instances = (c->cascades.handoff ? 1 : c->cascades.count) * (spread ? 4 : 1);
    lpv_timer_begin(timer, "inject");
    lpv_atlas_begin(&c->lpv_atlas, c->prog_inject_vpl, c->grid_ubo, c->empty_vao);
    glUniform1i(glGetUniformLocation(c->prog_inject_vpl, "u_spread"), spread);
    if (rsm_vpls)
        lpv_atlas_splat_indirect(c->prog_inject_vpl, LPV_SSBO_VPLS, in->rsm_vpls, in->rsm_vpl_draw, instances, timer);
    lpv_atlas_end();
    lpv_timer_end(timer);
    /* Emissive surfaces are their own stage, so the plan's "emissive" pass
     * shows its cost (and its absence). */
    if (emissive_vpls) {
        lpv_timer_begin(timer, "emissive");
        lpv_atlas_begin_keep(&c->lpv_atlas, c->prog_inject_vpl, c->grid_ubo, c->empty_vao);
        glUniform1i(glGetUniformLocation(c->prog_inject_vpl, "u_spread"), spread);
        lpv_atlas_splat(c->prog_inject_vpl, LPV_SSBO_VPLS, in->emissive_vpls, 0, in->emissive_vpl_count, instances,
                        timer);
        lpv_atlas_end();
        lpv_timer_end(timer);
    }

    lpv_timer_begin(timer, "pack");

    glUseProgram(c->prog_pack);
    glUniform1i(glGetUniformLocation(c->prog_pack, "u_tiles_x"), c->lpv_atlas.tiles_x);
    for (int i = 0; i < 3; ++i) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glBindTexture(GL_TEXTURE_2D, c->lpv_atlas.tex[i]);
    }
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, c->grid_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_OUT, c->lpv_injected);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_ACC, c->lpv_acc);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_SENT_OUT, c->sent[0]);
    glDispatchCompute(lpv_div_up((size_t)c->grid.dims[0], LPV_WG_2D), lpv_div_up((size_t)c->grid.dims[1], LPV_WG_2D),
                      (GLuint)(c->grid.dims[2] * lpv_volumes(c)));
    lpv_timer_count(timer, 1);
    /* propagation reads the packed grid and flux limits as buffer textures */
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
    lpv_timer_end(timer);
}

void lpv_pass_clear_run(lpv_cascaded *c)
{
    GLuint bufs[] = {c->lpv_injected, c->lpv_acc};
    for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; ++i) {
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, bufs[i]);
        glClearBufferData(GL_SHADER_STORAGE_BUFFER, GL_RGBA32F, GL_RGBA, GL_FLOAT, NULL);
    }
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}
