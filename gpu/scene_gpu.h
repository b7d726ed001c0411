/*
 * scene_gpu.h - the scene on the GPU as the passes draw it: one vertex and
 * index buffer, the draw list (triangles, then points and lines), the
 * materials' uniforms and the textures. The engine uploads it
 * (engine_scene.c, lpv_engine_set_scene); every pass that rasterises the
 * scene (light views, shadow maps, the camera's G-buffer and translucent
 * layer) draws it through lpv_scene_gpu_draw, knowing nothing else of the
 * engine.
 */
#ifndef LPV_SCENE_GPU_H
#define LPV_SCENE_GPU_H

#include <stddef.h>
#include <stdint.h>

#include "gl.h"
#include "timer.h"

typedef struct lpv_gpu_material {
    float base_color[4];
    float emission[3];
    float roughness, metallic;
    int texture; /* index into lpv_scene_gpu.textures, -1 none */
    float alpha_cutoff;   /* lpv_material_alpha_cutoff: MASK's cutoff, else 0 */
    int blend;            /* alphaMode BLEND: alpha is coverage, drawn in the translucent layer */
    int double_sided;     /* 0: the camera culls back faces */
    int base_uv_set;      /* 0 TEXCOORD_0, 1 TEXCOORD_1 */
    float base_uv[6];     /* lpv_uv_transform_matrix rows */
    int normal_texture;   /* index into lpv_scene_gpu.textures (linear), -1 none */
    float normal_scale;
    int normal_uv_set;
    float normal_uv[6];
    int mr_texture;       /* metallicRoughnessTexture: index into lpv_scene_gpu.textures (linear), -1 none */
    int mr_uv_set;
    float mr_uv[6];
    int emissive_texture; /* emissiveTexture: index into lpv_scene_gpu.textures (sRGB), -1 none */
    int emissive_uv_set;
    float emissive_uv[6];
    int unlit;             /* KHR_materials_unlit */
    int occlusion_texture; /* occlusionTexture: index into lpv_scene_gpu.textures (linear), -1 none */
    float occlusion_strength;
    int occlusion_uv_set;
    float occlusion_uv[6];
} lpv_gpu_material;

typedef struct lpv_gpu_draw {
    uint32_t first_index, index_count;
    int material;
    float size; /* m, longest side of the draw's bounding box (cascade fading) */
    int vertex_color; /* lpv_draw.vertex_color */
    float box_min[3], box_max[3]; /* m, its bounding box (min > max: no finite vertex); triangles only */
    int mode; /* lpv_draw_mode: LPV_DRAW_TRIANGLES, or a wire draw's POINTS or LINES */
} lpv_gpu_draw;

typedef struct lpv_scene_gpu {
    GLuint vao, vbo, ibo;
    lpv_gpu_draw *draws;
    uint32_t draw_count;
    lpv_gpu_draw *wire_draws; /* points and lines (lpv_scene.wire_draws), indices after the triangles' */
    uint32_t wire_draw_count;
    lpv_gpu_material *materials;
    uint32_t material_count;
    int materials_plain;      /* 1: no material has a texture, a normal map or an alpha cut */
    int materials_occlusion;  /* 1: some material has an occlusionTexture (LPV_FRAME_OCCLUSION) */
    int materials_unlit;      /* 1: some material is unlit (LPV_FRAME_UNLIT) */
    size_t blend_draws;       /* draws whose material is BLEND (the translucent layer, LPV_PASS_TRANSLUCENT) */
    GLuint *textures;
    uint32_t texture_count;
} lpv_scene_gpu;

/* Which draws lpv_scene_gpu_draw draws: every one (the light views, where
 * BLEND's alpha is coverage per texel), all but the BLEND ones (the camera's
 * G-buffer), or only those (its translucent layer). */
typedef enum lpv_draw_set { LPV_DRAWS_ALL = 0, LPV_DRAWS_NOT_BLEND, LPV_DRAWS_BLEND } lpv_draw_set;

/* Draws the draws of `set` with their material's uniforms and textures,
 * each counted as a call in timer's current stage (NULL: none).
 * cull_single_sided: back faces of materials that are not double-sided are
 * culled (the camera's view, as glTF says; light views pass 0 and see both
 * sides). */
void lpv_scene_gpu_draw(const lpv_scene_gpu *g, GLuint prog, int cull_single_sided, lpv_draw_set set,
                        lpv_timer *timer);
/* Draws the points and lines (one pixel wide) with their materials'
 * uniforms and u_wire 1: only the camera's G-buffer does. */
void lpv_scene_gpu_draw_wires(const lpv_scene_gpu *g, GLuint prog, lpv_timer *timer);
/* The program a scene pass draws with: plain (built with LPV_MATERIAL_PLAIN)
 * when the scene's materials are all plain, else full. */
GLuint lpv_scene_gpu_program(const lpv_scene_gpu *g, GLuint full, GLuint plain);

#endif
