/* scene_gpu.c - see scene_gpu.h. */
#include "scene_gpu.h"

#include <stdint.h>

#include "scene.h"

GLuint lpv_scene_gpu_program(const lpv_scene_gpu *g, GLuint full, GLuint plain)
{
    return g->materials_plain ? plain : full;
}

/* The draws of `list` in `set` with their materials' uniforms and textures
 * (lpv_scene_gpu_draw, lpv_scene_gpu_draw_wires); u_wire tells gbuffer.frag
 * which kind it draws. */
static void draw_list(const lpv_scene_gpu *g, GLuint prog, const lpv_gpu_draw *list, uint32_t count, int cull_single_sided,
                      lpv_draw_set set, int wire, lpv_timer *timer)
{
    GLint loc_color = glGetUniformLocation(prog, "u_base_color");
    GLint loc_has_tex = glGetUniformLocation(prog, "u_has_texture");
    GLint loc_emission = glGetUniformLocation(prog, "u_emission");
    GLint loc_roughness = glGetUniformLocation(prog, "u_roughness");
    GLint loc_metallic = glGetUniformLocation(prog, "u_metallic");
    GLint loc_size = glGetUniformLocation(prog, "u_object_size");
    GLint loc_cutoff = glGetUniformLocation(prog, "u_alpha_cutoff");
    GLint loc_blend = glGetUniformLocation(prog, "u_alpha_blend");
    glUniform1i(glGetUniformLocation(prog, "u_wire"), wire);
    GLint loc_base_set = glGetUniformLocation(prog, "u_base_uv_set");
    GLint loc_base_row0 = glGetUniformLocation(prog, "u_base_uv_row0");
    GLint loc_base_row1 = glGetUniformLocation(prog, "u_base_uv_row1");
    GLint loc_has_normal = glGetUniformLocation(prog, "u_has_normal_texture");
    GLint loc_normal_scale = glGetUniformLocation(prog, "u_normal_scale");
    GLint loc_normal_set = glGetUniformLocation(prog, "u_normal_uv_set");
    GLint loc_normal_row0 = glGetUniformLocation(prog, "u_normal_uv_row0");
    GLint loc_normal_row1 = glGetUniformLocation(prog, "u_normal_uv_row1");
    GLint loc_vertex_color = glGetUniformLocation(prog, "u_vertex_color");
    GLint loc_unlit = glGetUniformLocation(prog, "u_unlit");
    GLint loc_has_mr = glGetUniformLocation(prog, "u_has_mr_texture");
    GLint loc_mr_set = glGetUniformLocation(prog, "u_mr_uv_set");
    GLint loc_mr_row0 = glGetUniformLocation(prog, "u_mr_uv_row0");
    GLint loc_mr_row1 = glGetUniformLocation(prog, "u_mr_uv_row1");
    GLint loc_has_emissive = glGetUniformLocation(prog, "u_has_emissive_texture");
    GLint loc_emissive_set = glGetUniformLocation(prog, "u_emissive_uv_set");
    GLint loc_emissive_row0 = glGetUniformLocation(prog, "u_emissive_uv_row0");
    GLint loc_emissive_row1 = glGetUniformLocation(prog, "u_emissive_uv_row1");
    GLint loc_has_occlusion = glGetUniformLocation(prog, "u_has_occlusion_texture");
    GLint loc_occlusion_strength = glGetUniformLocation(prog, "u_occlusion_strength");
    GLint loc_occlusion_set = glGetUniformLocation(prog, "u_occlusion_uv_set");
    GLint loc_occlusion_row0 = glGetUniformLocation(prog, "u_occlusion_uv_row0");
    GLint loc_occlusion_row1 = glGetUniformLocation(prog, "u_occlusion_uv_row1");
    glBindVertexArray(g->vao);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW); /* glTF's front faces; the loader rewinds mirrored nodes */
    for (uint32_t i = 0; i < count; ++i) {
        const lpv_gpu_draw *d = &list[i];
        static const lpv_gpu_material fallback = {
            .base_color = {1, 1, 1, 1}, .roughness = 1.0f, .texture = -1, .double_sided = 1,
            .base_uv = {1, 0, 0, 0, 1, 0}, .normal_texture = -1, .normal_uv = {1, 0, 0, 0, 1, 0},
            .mr_texture = -1, .mr_uv = {1, 0, 0, 0, 1, 0}, .emissive_texture = -1, .emissive_uv = {1, 0, 0, 0, 1, 0},
            .occlusion_texture = -1, .occlusion_strength = 1.0f, .occlusion_uv = {1, 0, 0, 0, 1, 0}};
        const lpv_gpu_material *m =
            (d->material >= 0 && (uint32_t)d->material < g->material_count) ? &g->materials[d->material] : &fallback;
        if ((set == LPV_DRAWS_NOT_BLEND && m->blend) || (set == LPV_DRAWS_BLEND && !m->blend))
            continue;
        glUniform4fv(loc_color, 1, m->base_color);
        glUniform3fv(loc_emission, 1, m->emission);
        glUniform1f(loc_roughness, m->roughness);
        glUniform1f(loc_metallic, m->metallic);
        glUniform1f(loc_size, d->size);
        glUniform1f(loc_cutoff, m->alpha_cutoff);
        glUniform1i(loc_blend, m->blend);
        glUniform1i(loc_has_tex, m->texture >= 0);
        glUniform1i(loc_base_set, m->base_uv_set);
        glUniform3fv(loc_base_row0, 1, &m->base_uv[0]);
        glUniform3fv(loc_base_row1, 1, &m->base_uv[3]);
        glUniform1i(loc_has_normal, m->normal_texture >= 0);
        glUniform1f(loc_normal_scale, m->normal_scale);
        glUniform1i(loc_normal_set, m->normal_uv_set);
        glUniform3fv(loc_normal_row0, 1, &m->normal_uv[0]);
        glUniform3fv(loc_normal_row1, 1, &m->normal_uv[3]);
        glUniform1i(loc_vertex_color, d->vertex_color);
        glUniform1i(loc_unlit, m->unlit);
        glUniform1i(loc_has_mr, m->mr_texture >= 0);
        glUniform1i(loc_mr_set, m->mr_uv_set);
        glUniform3fv(loc_mr_row0, 1, &m->mr_uv[0]);
        glUniform3fv(loc_mr_row1, 1, &m->mr_uv[3]);
        glUniform1i(loc_has_emissive, m->emissive_texture >= 0);
        glUniform1i(loc_emissive_set, m->emissive_uv_set);
        glUniform3fv(loc_emissive_row0, 1, &m->emissive_uv[0]);
        glUniform3fv(loc_emissive_row1, 1, &m->emissive_uv[3]);
        glUniform1i(loc_has_occlusion, m->occlusion_texture >= 0);
        glUniform1f(loc_occlusion_strength, m->occlusion_strength);
        glUniform1i(loc_occlusion_set, m->occlusion_uv_set);
        glUniform3fv(loc_occlusion_row0, 1, &m->occlusion_uv[0]);
        glUniform3fv(loc_occlusion_row1, 1, &m->occlusion_uv[3]);
        /* material.glsl's units: base colour, normal, metallic-roughness, emissive, occlusion */
        const int unit_texture[5] = {m->texture, m->normal_texture, m->mr_texture, m->emissive_texture,
                                     m->occlusion_texture};
        for (int u = 0; u < 5; ++u) {
            glActiveTexture(GL_TEXTURE0 + (GLenum)u);
            glBindTexture(GL_TEXTURE_2D, unit_texture[u] >= 0 ? g->textures[unit_texture[u]] : 0);
        }
        glActiveTexture(GL_TEXTURE0);
        if (cull_single_sided && !m->double_sided)
            glEnable(GL_CULL_FACE);
        else
            glDisable(GL_CULL_FACE);
        const GLenum mode = d->mode == LPV_DRAW_POINTS ? GL_POINTS : d->mode == LPV_DRAW_LINES ? GL_LINES : GL_TRIANGLES;
        if (d->index_count)
            glDrawElements(mode, (GLsizei)d->index_count, GL_UNSIGNED_INT,
                           (void *)(uintptr_t)(d->first_index * sizeof(uint32_t)));
        if (timer)
            lpv_timer_count(timer, 1);
    }
    glDisable(GL_CULL_FACE);
    glBindVertexArray(0);
}

void lpv_scene_gpu_draw(const lpv_scene_gpu *g, GLuint prog, int cull_single_sided, lpv_draw_set set,
                        lpv_timer *timer)
{
    draw_list(g, prog, g->draws, g->draw_count, cull_single_sided, set, 0, timer);
}

void lpv_scene_gpu_draw_wires(const lpv_scene_gpu *g, GLuint prog, lpv_timer *timer)
{
    if (g->wire_draw_count)
        draw_list(g, prog, g->wire_draws, g->wire_draw_count, 0, LPV_DRAWS_ALL, 1, timer);
}
