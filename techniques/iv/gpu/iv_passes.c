/*
 * iv_passes.c - the imperfect volume's passes on one tick's inputs
 * (technique_iv.c's header lists them; docs/imperfect-volumes.md).
 */
#include <stdint.h>
#include <string.h>

#include "iv_internal.h"

_Static_assert(LPV_IV_MAX_BOUNCES < LPV_IV_TAIL_RATIO_SLOT, "a total per bounce below the ratio's slot");

static GLuint groups(const lpv_iv_gpu *v) { return lpv_div_up(v->cells, LPV_IV_WG); }

void lpv_iv_clear_buffer(GLuint b)
{
    static const float zero = 0.0f;
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, b);
    glClearBufferData(GL_SHADER_STORAGE_BUFFER, GL_R32F, GL_RED, GL_FLOAT, &zero);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
}

/* iv_points: each voxel gathers its own points of the sorted cloud into its
 * atlas texels (iv_points.comp), every texel of the volume written, in
 * dispatches of whole voxels with a yield point between them. Returns
 * whether it wrote the atlas (else the caller clears it). */
static int gather_points(lpv_iv_gpu *v, const lpv_technique_inputs *in)
{
    if (!in->plan->pass[LPV_PASS_IV_POINTS].run || !v->cloud.points || !v->chunk_count ||
        memcmp(&v->grid, &v->cloud_grid, sizeof v->grid) != 0)
        return 0;
    lpv_timer_begin(in->timer, "iv_points");
    const GLuint prog = v->prog_points;
    glUseProgram(prog);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, v->grid_ubo);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_LIGHT, in->light_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_POINTS, v->points);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_POINT_STARTS, v->point_starts);
    glActiveTexture(GL_TEXTURE0 + 5);
    glBindTexture(GL_TEXTURE_2D_ARRAY, in->rsm_position);
    glActiveTexture(GL_TEXTURE0 + 6);
    glBindTexture(GL_TEXTURE_2D_ARRAY, in->rsm_albedo);
    glActiveTexture(GL_TEXTURE0);
    for (int i = 0; i < IV_ATTACHMENTS; ++i)
        glBindImageTexture((GLuint)i, v->atlas.tex[i], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glUniform1f(glGetUniformLocation(prog, "u_emission"), in->settings->area_lights == LPV_SWITCH_OFF ? 1.0f : 0.0f);
    glUniform1i(glGetUniformLocation(prog, "u_tiles_x"), v->atlas.tiles_x);
    const GLint loc_first = glGetUniformLocation(prog, "u_cell_first");
    const GLint loc_end = glGetUniformLocation(prog, "u_cell_end");
    size_t first = 0;
    for (size_t k = 0; k < v->chunk_count && !lpv_timer_abandoned(in->timer); ++k) {
        const size_t end = v->chunk_ends[k];
        glUniform1i(loc_first, (GLint)first);
        glUniform1i(loc_end, (GLint)end);
        glDispatchCompute(lpv_div_up(end - first, LPV_IV_WG), 1, 1);
        lpv_timer_count(in->timer, 1);
        first = end;
        if (k + 1 < v->chunk_count)
            lpv_timer_yield(in->timer);
    }
    for (int i = 0; i < IV_ATTACHMENTS; ++i)
        glBindImageTexture((GLuint)i, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    /* the reprojection blends into these texels, the resolve fetches them */
    glMemoryBarrier(GL_FRAMEBUFFER_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    lpv_timer_end(in->timer);
    return 1;
}

/* iv_reproject's first half: the camera's sampled pixels lit and summed per
 * block and voxel into v->splats (iv_reproject.comp). Returns the slots to
 * splat, 0 when there are none (or no memory for them). */
static size_t reproject_pixels(lpv_iv_gpu *v, const lpv_technique_inputs *in)
{
    int stride = 1;
    while ((size_t)((in->gbuffer_w + stride - 1) / stride) * (size_t)((in->gbuffer_h + stride - 1) / stride) >
           LPV_IV_REPROJECT_POINTS)
        ++stride;
    const int bx = lpv_div_up((size_t)((in->gbuffer_w + stride - 1) / stride), LPV_IV_REPROJECT_BLOCK);
    const int by = lpv_div_up((size_t)((in->gbuffer_h + stride - 1) / stride), LPV_IV_REPROJECT_BLOCK);
    const size_t slots = (size_t)bx * (size_t)by * LPV_IV_REPROJECT_BLOCK * LPV_IV_REPROJECT_BLOCK;
    if (slots > v->splat_slots) {
        lpv_gl_delete_buffer(&v->splats);
        v->splat_slots = 0;
        v->splats = lpv_gl_new_ssbo(slots * sizeof(struct IvSplat));
        if (glGetError() != GL_NO_ERROR) { /* no splat this tick; the cloud's points stand */
            lpv_gl_delete_buffer(&v->splats);
            return 0;
        }
        v->splat_slots = slots;
    }
    const GLuint prog = v->prog_reproject;
    glUseProgram(prog);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, v->grid_ubo);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_LIGHT, in->light_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_SPLATS, v->splats);
    for (int i = 0; i < 4; ++i) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glBindTexture(GL_TEXTURE_2D, in->gbuffer[i]);
    }
    glActiveTexture(GL_TEXTURE0 + 5);
    glBindTexture(GL_TEXTURE_2D_ARRAY, in->rsm_position);
    glActiveTexture(GL_TEXTURE0 + 6);
    glBindTexture(GL_TEXTURE_2D_ARRAY, in->rsm_albedo);
    glActiveTexture(GL_TEXTURE0);
    glUniform2i(glGetUniformLocation(prog, "u_gbuf_size"), in->gbuffer_w, in->gbuffer_h);
    glUniform1i(glGetUniformLocation(prog, "u_stride"), stride);
    glUniform2i(glGetUniformLocation(prog, "u_blocks"), bx, by);
    glUniform1i(glGetUniformLocation(prog, "u_tiles_x"), v->atlas.tiles_x);
    glUniform1f(glGetUniformLocation(prog, "u_emission"), in->settings->area_lights == LPV_SWITCH_OFF ? 1.0f : 0.0f);
    glDispatchCompute(lpv_div_up((size_t)bx * (size_t)by, LPV_IV_WG), 1, 1);
    lpv_timer_count(in->timer, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    return slots;
}

/* iv_points and iv_reproject: the points into the atlas. */
void lpv_iv_create_volume(lpv_iv_gpu *v, const lpv_technique_inputs *in)
{
    const lpv_plan *p = in->plan;
    const int kept = gather_points(v, in);
    const int reproject = p->pass[LPV_PASS_IV_REPROJECT].run && in->gbuffer_w > 0 && in->gbuffer_h > 0;
    size_t slots = 0;
    if (reproject) {
        lpv_timer_begin(in->timer, "iv_reproject");
        slots = reproject_pixels(v, in);
    }
    GLuint prog = v->prog_splat;
    if (kept)
        lpv_atlas_begin_keep(&v->atlas, prog, v->grid_ubo, v->empty_vao);
    else
        lpv_atlas_begin(&v->atlas, prog, v->grid_ubo, v->empty_vao);
    for (GLuint i = IV_ATTACHMENT_MAX; i < IV_ATTACHMENTS; ++i)
        glBlendEquationi(i, GL_MAX); /* the points' extent (LPV_IV_COVER) */
    if (slots) {
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_SPLATS, v->splats);
        glDrawArrays(GL_POINTS, 0, (GLsizei)slots);
        lpv_timer_count(in->timer, 1);
    }
    lpv_atlas_end();
    if (reproject)
        lpv_timer_end(in->timer);

    lpv_timer_begin(in->timer, "iv_resolve");
    lpv_iv_clear_buffer(v->occupancy); /* all bits 0 */
    glUseProgram(v->prog_resolve);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, v->grid_ubo);
    for (int i = 0; i < IV_ATTACHMENTS; ++i) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glBindTexture(GL_TEXTURE_2D, v->atlas.tex[i]);
    }
    glActiveTexture(GL_TEXTURE0);
    glUniform1i(glGetUniformLocation(v->prog_resolve, "u_tiles_x"), v->atlas.tiles_x);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_VOXELS, v->voxels);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_OCCUPANCY, v->occupancy);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glDispatchCompute(groups(v), 1, 1);
    lpv_timer_count(in->timer, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    lpv_timer_end(in->timer);
}


/* One march over the volume: radiance from the emission (ao 0) into out, or
 * visibility into the AO volume (ao 1). */
void lpv_iv_march_volume(lpv_iv_gpu *v, const lpv_settings *s, GLuint out, int ao, lpv_timer *timer)
{
    GLuint prog = v->prog_gather;
    glUseProgram(prog);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, v->grid_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_OCCUPANCY, v->occupancy);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_VOXELS, v->voxels);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_EMIT, v->emit);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_OUT, out);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_AO, v->ao);
    glUniform1i(glGetUniformLocation(prog, "u_rays"), s->iv.rays);
    glUniform1ui(glGetUniformLocation(prog, "u_seed"), (GLuint)s->iv.seed);
    glUniform1i(glGetUniformLocation(prog, "u_ao"), ao);
    const float reach = s->iv.ao_distance > 0.0f ? s->iv.ao_distance / v->grid.cell_size : LPV_IV_AO_VOXELS;
    glUniform1f(glGetUniformLocation(prog, "u_ao_reach"), reach);
    /* in chunks of about LPV_IV_MARCH_CHUNK_RAYS rays, a yield point between
     * them (timer.h): one dispatch of a fine volume with many rays took
     * seconds; the cells are independent, so the result is the same */
    const GLint loc_first = glGetUniformLocation(prog, "u_cell_first");
    size_t chunk = LPV_IV_MARCH_CHUNK_RAYS / (size_t)(s->iv.rays > 0 ? s->iv.rays : 1);
    chunk = chunk < LPV_IV_WG ? LPV_IV_WG : chunk / LPV_IV_WG * LPV_IV_WG;
    for (size_t first = 0; first < v->cells && !lpv_timer_abandoned(timer);) {
        const size_t n = v->cells - first < chunk ? v->cells - first : chunk;
        glUniform1i(loc_first, (GLint)first);
        glDispatchCompute(lpv_div_up(n, LPV_IV_WG), 1, 1);
        lpv_timer_count(timer, 1);
        first += n;
        if (first < v->cells)
            lpv_timer_yield(timer);
    }
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

/* iv_tail.comp: mode 0 sums `last` into slot k (one workgroup), mode 1
 * adds the tail to `last` from `before` (I_{K-2}). */
static void tail_pass(lpv_iv_gpu *v, int mode, int k, GLuint last, GLuint before, lpv_timer *timer)
{
    glUseProgram(v->prog_tail);
    glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, v->grid_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_OUT, last);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_ACC, mode ? before : last);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_TAIL, v->tail);
    glUniform1i(glGetUniformLocation(v->prog_tail, "u_mode"), mode);
    glUniform1i(glGetUniformLocation(v->prog_tail, "u_bounce"), k);
    glDispatchCompute(mode ? lpv_div_up(v->cells, LPV_IV_TAIL_WG) : 1, 1, 1);
    lpv_timer_count(timer, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

/* Bounces 1..K: emission from the previous gather, then a march; then the
 * tail (iv_tail on, K >= 3): the totals of the last four gathers and the
 * series they set, from I_K and I_{K-2} (kept in v->tail_base before the last
 * gather overwrites it); then iv_filter (LPV_IV_FILTER) into the other
 * volume. */
void lpv_iv_gather_bounces(lpv_iv_gpu *v, const lpv_technique_inputs *in)
{
    const lpv_settings *s = in->settings;
    lpv_timer_begin(in->timer, "iv_gather");
    int prev = 0, cur = 0;
    const int tail = s->iv.tail == LPV_SWITCH_ON && s->iv.bounces >= 3;
    if (tail)
        lpv_iv_clear_buffer(v->tail); /* S_0 = 0 */
    for (int k = 1; k <= s->iv.bounces && !lpv_timer_abandoned(in->timer); ++k) {
        cur = k == 1 ? 0 : 1 - prev;
        glUseProgram(v->prog_emit);
        glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, v->grid_ubo);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_VOXELS, v->voxels);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_EMIT, v->emit);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_ACC, v->radiance[prev]);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_AO, v->ao);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_OCCUPANCY, v->occupancy);
        glUniform1i(glGetUniformLocation(v->prog_emit, "u_bounce"), k);
        glUniform1i(glGetUniformLocation(v->prog_emit, "u_iv_neighbours"), s->iv.neighbours);
        glDispatchCompute(groups(v), 1, 1);
        lpv_timer_count(in->timer, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        if (tail && k == s->iv.bounces) { /* radiance[cur] holds I_{K-2} until this march */
            glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
            glCopyNamedBufferSubData(v->radiance[cur], v->tail_base, 0, 0,
                                     (GLsizeiptr)(v->cells * sizeof(struct LpvCell)));
        }
        lpv_iv_march_volume(v, s, v->radiance[cur], 0, in->timer);
        if (tail && k >= s->iv.bounces - 3)
            tail_pass(v, 0, k, v->radiance[cur], 0, in->timer);
        prev = cur;
    }
    if (tail)
        tail_pass(v, 1, s->iv.bounces, v->radiance[cur], v->tail_base, in->timer);
    v->filter_run = s->iv.filter == LPV_SWITCH_ON && !lpv_timer_abandoned(in->timer);
    if (v->filter_run) { /* LPV_IV_FILTER: into the other volume, which then holds the result */
        glUseProgram(v->prog_filter);
        glBindBufferBase(GL_UNIFORM_BUFFER, LPV_UBO_GRID, v->grid_ubo);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_OCCUPANCY, v->occupancy);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_IV_VOXELS, v->voxels);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_ACC, v->radiance[cur]);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_OUT, v->radiance[1 - cur]);
        glDispatchCompute(groups(v), 1, 1);
        lpv_timer_count(in->timer, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        cur = 1 - cur;
    }
    v->result = cur;
    v->bounces_run = s->iv.bounces;
    v->tail_run = tail;
    lpv_timer_end(in->timer);
}

/* Called from the tick's stats, after lpv_timer_collect has waited on the
 * tick's timer queries, iv_gather's (and so the tail pass's) among them:
 * the 12 bytes are ready and reading them stalls nothing further. */
void lpv_iv_gpu_tail_ratio(const lpv_iv_gpu *v, float rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    if (!v->tail_run)
        return;
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, v->tail);
    glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 3 * LPV_IV_TAIL_RATIO_SLOT * sizeof(float), 3 * sizeof(float), rgb);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
}

