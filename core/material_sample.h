/*
 * material_sample.h - a material's inputs where the CPU needs them at a
 * point of a surface, read from its textures as the GPU reads them (uv set
 * and KHR_texture_transform, REPEAT, bilinear, sRGB colour decoded): the
 * emissive VPLs and area lights (core/emissive.c, core/area_lights.c), the
 * imperfect volume's point cloud (techniques/iv/core/iv_points.c) and the reference path
 * tracer use the same rules as the G-buffer and RSM shaders
 * (shaders/material.glsl), so the accuracy comparison stays like for like.
 *
 * glTF's metallic-roughness model on a diffuse-only transport: the diffuse
 * albedo is base colour x (1 - metallic) (a metal reflects specularly or not
 * at all), base colour = baseColorFactor x baseColorTexture, metallic =
 * metallicFactor x metallicRoughnessTexture.B; emission = emission x
 * emissiveTexture.
 */
#ifndef LPV_MATERIAL_SAMPLE_H
#define LPV_MATERIAL_SAMPLE_H

#include "scene.h"

/* The scene texture index if `index` names one of the right kind (linear
 * data, or sRGB colour), else -1: a material built with memset's 0, or a
 * colour texture given as data, reads as no texture. */
int lpv_material_texture(const lpv_scene *s, int index, int linear);

/* Texture t at uv (REPEAT, bilinear between texel centres), as linear values:
 * sRGB colour decoded, alpha and linear data / 255. */
void lpv_texture_sample(const lpv_texture *t, float u, float v, float out[4]);

/* The uv a material's texture reads: uv0 or uv1 by the transform's set,
 * then the transform. */
void lpv_material_uv(const lpv_uv_transform *t, const float uv0[2], const float uv1[2], float out[2]);

/* A material's alpha at a surface point: baseColorFactor.a x the base
 * colour texture's alpha x color_alpha (COLOR_0's alpha, 1 without one). */
float lpv_material_alpha_at(const lpv_scene *s, const lpv_material *m, const float uv0[2], const float uv1[2],
                            float color_alpha);

/* Whether a material's surface is there at a surface point for a draw u in
 * [0, 1): lpv_alpha_covers (shaders/lpv_shared.h) of its alpha, as the
 * shaders cut (material.glsl): always for OPAQUE, where alpha >= cutoff for
 * MASK, for the fraction alpha of draws for BLEND (alpha is coverage).
 * Where it is not there, it neither blocks, reflects nor shows. */
int lpv_material_covers_at(const lpv_scene *s, const lpv_material *m, const float uv0[2], const float uv1[2],
                           float color_alpha, float u);

/* Metallic at a surface point (factor x texture B), clamped to [0, 1]. */
float lpv_material_metallic_at(const lpv_scene *s, const lpv_material *m, const float uv0[2], const float uv1[2]);

/* The diffuse albedo at a surface point: base colour (x color, the point's
 * COLOR_0, where not NULL) x (1 - metallic), each channel clamped to [0, 1];
 * 0 for an unlit material (KHR_materials_unlit: it reflects no light). */
void lpv_material_albedo_at(const lpv_scene *s, const lpv_material *m, const float uv0[2], const float uv1[2],
                            const float *color, float out[3]);

/* The factor the frame's indirect (ambient) light takes at a surface point
 * from the occlusionTexture: 1 + strength x (R - 1), in [0, 1]; 1 without
 * one. Not applied to the GI (the bounces), only where a camera looks. */
float lpv_material_occlusion_at(const lpv_scene *s, const lpv_material *m, const float uv0[2], const float uv1[2]);

/* What a camera sees of an unlit material (KHR_materials_unlit) at a
 * surface point, W/(m^2 sr): its base colour (factor x texture x color
 * where not NULL) as luminance in nits, / LPV_LUMENS_PER_WATT, which the
 * display at EV 0 shows as the colour itself (docs/units.md), as three.js
 * and the Khronos viewer show it. 0 for a lit material. */
void lpv_material_unlit_radiance_at(const lpv_scene *s, const lpv_material *m, const float uv0[2],
                                    const float uv1[2], const float *color, float out[3]);

/* The emitted radiance at a surface point, W/(m^2 sr). */
void lpv_material_emission_at(const lpv_scene *s, const lpv_material *m, const float uv0[2], const float uv1[2],
                              float out[3]);

/* The mean emitted radiance over triangle v[0..2], W/(m^2 sr): the emission
 * alone without a texture, else the mean of the texture at four points per
 * texel the triangle covers (LPV_TRIANGLE_EMISSION_SAMPLES to _MAX points). */
#define LPV_TRIANGLE_EMISSION_SAMPLES 64
#define LPV_TRIANGLE_EMISSION_SAMPLES_MAX 4096
void lpv_triangle_emission(const lpv_scene *s, const lpv_material *m, const lpv_vertex *const v[3], float out[3]);

#endif
