/*
 * pass_propagate.c - the propagation iterations: ping-pong between two
 * buffers, each step's output also added into the accumulated volume (which
 * the injection pass initialised with the injected grid). Occlusion is
 * skipped on the first step (the paper's rule against self-shadowing).
 */
#include "lpv_internal.h"

void lpv_pass_propagate_run(lpv_cascaded *c, const lpv_technique_inputs *in, int occlusion_on, int bounce)
{
    lpv_timer *timer = in->timer;
    lpv_timer_begin(timer, "propagate");
    /* the variant without the bounce and medium terms unless one is on */
    const int media = in->plan->pass[LPV_PASS_MEDIA].run;
    const GLuint prog = bounce || lpv_medium_active(in->medium, in->settings, media) ? c->prog_propagate_effects
                                                                                     : c->prog_propagate;
    glUseProgram(prog);
    GLint loc_occ = glGetUniformLocation(prog, "u_occlusion");
    GLint loc_write = glGetUniformLocation(prog, "u_write_coeffs");
    glUniform1i(glGetUniformLocation(prog, "u_bounce"), bounce);
    lpv_medium_bind(in->medium, in->settings, prog, media);
    glActiveTexture(GL_TEXTURE0 + LPV_TEX_REFLECT);
    glBindTexture(GL_TEXTURE_BUFFER, c->tbo_reflect);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, c->grid_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_ACC, c->lpv_acc);
    glActiveTexture(GL_TEXTURE0 + LPV_TEX_ACC_IN);
    glBindTexture(GL_TEXTURE_BUFFER, c->tbo_acc);
    glActiveTexture(GL_TEXTURE0 + LPV_TEX_TRANSMIT);
    glBindTexture(GL_TEXTURE_BUFFER, c->tbo_transmit);
    const int occlusion = occlusion_on;
    /* Step i reads (through buffer-texture views: on llvmpipe texel fetches
     * gather far faster than SSBO loads) what the cells step i - 1 wrote
     * send (sent[], their coefficients times their flux limits), written by
     * lpv_pack.comp first, then by each step and hand-off in turn; the
     * coefficients themselves go to ping and pong only where they are read
     * (by a hand-off, and the last step's by LPV_GRID_LAST_STEP). With the
     * far field on, each level but the coarsest takes far_field_steps steps,
     * then a hand-off moves the light in flight on to the next coarser
     * cascade (lpv_handoff.comp), as one more turn of the ping-pong; the
     * coarsest takes the rest. The schedule's start does not depend on the
     * iteration count, so more iterations only add steps at the coarsest
     * level: the accumulation can only grow (an even share per level moved
     * light out of the finer levels later as the count grew, and the Cornell
     * box got worse from 4 to 16 steps). */
    const int iterations = in->settings->lpv.iterations, levels = c->cascades.handoff ? c->cascades.count : 1;
    const int every = in->settings->lpv.far_field_steps > 0 ? in->settings->lpv.far_field_steps : 1;
    GLuint in_view = c->tbo_injected, cur = 0;
    int sent = 0; /* the buffer holding what the cells read next send (flux_limit.glsl, limited) */
    const GLuint groups[3] = {lpv_div_up((size_t)c->grid.dims[0], LPV_PROP_WG_X),
                              lpv_div_up((size_t)c->grid.dims[1], LPV_PROP_WG_Y),
                              (GLuint)(c->grid.dims[2] * lpv_volumes(c))};
    /* each step is a yield point: a long propagation lets other worlds'
     * work run between its steps (timer.h) */
    for (int i = 0; i < iterations && !lpv_timer_abandoned(timer); lpv_timer_yield(timer), ++i) {
        GLuint out = cur == c->lpv_ping ? c->lpv_pong : c->lpv_ping;
        const int handoff_next = (i + 1) % every == 0 && (i + 1) / every < levels && i + 1 < iterations;
        glUseProgram(prog);
        glActiveTexture(GL_TEXTURE0 + LPV_TEX_SENT_IN);
        glBindTexture(GL_TEXTURE_BUFFER, c->tbo_sent[sent]);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_OUT, out);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_SENT_OUT, c->sent[sent ^ 1]);
        glUniform1i(loc_occ, occlusion && i > 0);
        /* the coefficients are read only by a hand-off and by the read-back
         * of the last step (LPV_GRID_LAST_STEP) */
        glUniform1i(loc_write, handoff_next || i + 1 == iterations);
        glDispatchCompute(groups[0], groups[1], groups[2]);
        lpv_timer_count(timer, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
        cur = out;
        in_view = out == c->lpv_ping ? c->tbo_ping : c->tbo_pong;
        sent ^= 1;
        if (handoff_next) {
            out = cur == c->lpv_ping ? c->lpv_pong : c->lpv_ping;
            glUseProgram(c->prog_handoff);
            glActiveTexture(GL_TEXTURE0 + LPV_TEX_LPV_IN);
            glBindTexture(GL_TEXTURE_BUFFER, in_view);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_OUT, out);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_SENT_OUT, c->sent[sent ^ 1]);
            glDispatchCompute(lpv_div_up((size_t)c->grid.dims[0], LPV_WG_2D),
                              lpv_div_up((size_t)c->grid.dims[1], LPV_WG_2D), groups[2]);
            lpv_timer_count(timer, 1);
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
            cur = out;
            in_view = out == c->lpv_ping ? c->tbo_ping : c->tbo_pong;
            sent ^= 1;
        }
    }
    c->lpv_last = cur ? cur : c->lpv_injected;
    lpv_timer_end(timer);
}
