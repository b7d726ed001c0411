// material.glsl - the per-draw material and the surface normal, shared by the
// RSM and G-buffer fragment shaders (docs/scenes.md, "Materials").
// LPV_MATERIAL_PLAIN 1 compiles a scene pass's program for scenes whose
// materials all have no texture (base colour, normal, metallic-roughness,
// emissive) and no alpha cut (gpu/engine_scene.c, lpv_engine_material_program): llvmpipe runs the
// code of a branch under lane masks even when no lane takes it, so the
// texture fetches and the normal map's frame cost every pixel, and a
// discard keeps the depth-only shadow faces from its fast path.
#ifndef LPV_MATERIAL_PLAIN
#define LPV_MATERIAL_PLAIN 0
#endif
uniform vec4 u_base_color;      // linear RGBA factor
uniform int u_has_texture;      // base colour texture bound to unit 0 (sRGB, decoded by GL)
uniform int u_vertex_color;     // 1: the vertices' COLOR_0 multiplies the base colour (the draw's lpv_draw.vertex_color)
uniform vec3 u_emission;        // W/(m^2 sr)
uniform float u_roughness;      // glTF roughness (0 mirror .. 1 matte)
uniform float u_metallic;       // glTF metallic (0 dielectric .. 1 metal)
uniform int u_unlit;            // KHR_materials_unlit: shown as its base colour, lit by and lighting nothing
uniform float u_object_size;    // m, the draw's longest bounding-box side (cascade fading)
uniform float u_alpha_cutoff;   // MASK: alpha below it is cut away; 0 = no cutoff
uniform int u_alpha_blend;      // BLEND: alpha is coverage (lpv_alpha_covers)
// A texture's uv: set (0 TEXCOORD_0, 1 TEXCOORD_1) and the rows of its
// KHR_texture_transform matrix applied to (u, v, 1).
uniform int u_base_uv_set;
uniform vec3 u_base_uv_row0;
uniform vec3 u_base_uv_row1;
uniform int u_has_normal_texture; // tangent-space normal map bound to unit 1 (linear)
uniform float u_normal_scale;     // glTF normalTexture.scale
uniform int u_normal_uv_set;
uniform vec3 u_normal_uv_row0;
uniform vec3 u_normal_uv_row1;
// metallicRoughnessTexture on unit 2 (linear: G x roughness, B x metallic),
// emissiveTexture on unit 3 (sRGB, x the emission); their uv sets and rows
uniform int u_has_mr_texture;
uniform int u_mr_uv_set;
uniform vec3 u_mr_uv_row0;
uniform vec3 u_mr_uv_row1;
uniform int u_has_emissive_texture;
uniform int u_emissive_uv_set;
uniform vec3 u_emissive_uv_row0;
uniform vec3 u_emissive_uv_row1;
layout(binding = 0) uniform sampler2D u_base_texture;
layout(binding = 1) uniform sampler2D u_normal_texture;
layout(binding = 2) uniform sampler2D u_mr_texture;
layout(binding = 3) uniform sampler2D u_emissive_texture;
// occlusionTexture on unit 4 (linear R), its strength, uv set and rows
uniform int u_has_occlusion_texture;
uniform float u_occlusion_strength;
uniform int u_occlusion_uv_set;
uniform vec3 u_occlusion_uv_row0;
uniform vec3 u_occlusion_uv_row1;
layout(binding = 4) uniform sampler2D u_occlusion_texture;

vec2 texture_uv(int set, vec3 row0, vec3 row1, vec2 uv0, vec2 uv1)
{
    vec3 uv = vec3(set == 1 ? uv1 : uv0, 1.0);
    return vec2(dot(row0, uv), dot(row1, uv));
}

// the base colour: factor x texture x COLOR_0 (color: the vertex's, read
// where u_vertex_color is 1)
vec4 material_albedo(vec2 uv0, vec2 uv1, vec4 color)
{
    vec4 c = u_base_color;
    if (u_vertex_color != 0)
        c *= color;
    if (LPV_MATERIAL_PLAIN == 0 && u_has_texture != 0)
        c *= texture(u_base_texture, texture_uv(u_base_uv_set, u_base_uv_row0, u_base_uv_row1, uv0, uv1));
    return c;
}

// metallic (x) and roughness (y) at the surface: the factors x the
// metallicRoughnessTexture's B and G (glTF), each in [0, 1]
vec2 material_metallic_roughness(vec2 uv0, vec2 uv1)
{
    vec2 mr = vec2(u_metallic, u_roughness);
    if (LPV_MATERIAL_PLAIN == 0 && u_has_mr_texture != 0)
        mr *= texture(u_mr_texture, texture_uv(u_mr_uv_set, u_mr_uv_row0, u_mr_uv_row1, uv0, uv1)).bg;
    return clamp(mr, 0.0, 1.0);
}

// the emitted radiance at the surface, W/(m^2 sr): the emission x the
// emissiveTexture (glTF's emissiveFactor x emissiveTexture x strength)
vec3 material_emission(vec2 uv0, vec2 uv1)
{
    vec3 e = u_emission;
    if (LPV_MATERIAL_PLAIN == 0 && u_has_emissive_texture != 0)
        e *= texture(u_emissive_texture,
                     texture_uv(u_emissive_uv_set, u_emissive_uv_row0, u_emissive_uv_row1, uv0, uv1)).rgb;
    return e;
}

// the factor the frame's indirect light takes here: 1 + strength x (R - 1)
// (glTF's occlusionTexture; core/material_sample.h lpv_material_occlusion_at)
float material_occlusion(vec2 uv0, vec2 uv1)
{
    if (LPV_MATERIAL_PLAIN != 0 || u_has_occlusion_texture == 0)
        return 1.0;
    float r = texture(u_occlusion_texture,
                      texture_uv(u_occlusion_uv_set, u_occlusion_uv_row0, u_occlusion_uv_row1, uv0, uv1)).r;
    return clamp(1.0 + u_occlusion_strength * (r - 1.0), 0.0, 1.0);
}

#ifdef LPV_STAGE_FRAGMENT
// Whether the surface of alpha a is at this texel of a light's view (shadow
// maps, RSMs): MASK where a >= the cutoff; BLEND at the fraction a of the
// texels an ordered dither picks, so the light's filters and VPLs see 1 - a
// of it let through (lpv_alpha_covers, lpv_dither8 in lpv_shared.h).
bool material_covers_texel(float a)
{
    return lpv_alpha_covers(a, u_alpha_cutoff, u_alpha_blend,
                            lpv_dither8(uint(gl_FragCoord.x), uint(gl_FragCoord.y))) != 0;
}

// The interpolated normal (the face normal when the file's normal is
// zero-length or not finite), for the side of the surface seen from `toward`
// (a unit direction from the surface to the viewer or light): the side is
// told by the geometric normal from the position's derivatives, and the
// normal is flipped when the back of the surface (against the file's
// normals) is seen, as glTF does for double-sided back faces. side is +1 on
// the front, -1 on the back.
vec3 surface_normal(vec3 interpolated, vec3 position, vec3 toward, out float side)
{
    vec3 g = cross(dFdx(position), dFdy(position));
    float glen = length(g);
    bool g_ok = glen > 1e-20 && !isinf(glen);
    if (g_ok)
        g = dot(g, toward) < 0.0 ? -g / glen : g / glen;
    else
        g = toward;
    vec3 n = interpolated;
    float len = length(n);
    if (!(len > 1e-8) || isinf(len)) {
        side = 1.0;
        return g;
    }
    n /= len;
    side = dot(n, g) < 0.0 ? -1.0 : 1.0;
    return n * side;
}

// The normal map's normal (glTF: tangent space, +X along +u, +Y towards
// decreasing v, i.e. up in the image, +Z out of the surface; xy scaled by
// u_normal_scale) in world space. n is the front-side normal, tangent the
// file's TANGENT (xyz, w handedness; zero = none: then the frame comes from
// the derivatives of position and uv per pixel).
vec3 normal_mapped(vec3 n, vec3 position, vec4 tangent, vec2 uv)
{
    vec3 t = texture(u_normal_texture, uv).xyz * 2.0 - 1.0;
    t.xy *= u_normal_scale;
    vec3 T, B;
    float tlen = length(tangent.xyz);
    if (tlen > 1e-8 && !isinf(tlen)) {
        T = normalize(tangent.xyz - n * dot(n, tangent.xyz));
        B = cross(n, T) * (tangent.w < 0.0 ? -1.0 : 1.0);
    } else {
        // Schueler's cotangent frame (ShaderX5, "Normal mapping without
        // precomputed tangents"): T along +u; B along -v for glTF's +Y.
        vec3 dp1 = dFdx(position), dp2 = dFdy(position);
        vec2 duv1 = dFdx(uv), duv2 = dFdy(uv);
        vec3 dp2perp = cross(dp2, n), dp1perp = cross(n, dp1);
        T = dp2perp * duv1.x + dp1perp * duv2.x;
        B = -(dp2perp * duv1.y + dp1perp * duv2.y);
        float m = max(dot(T, T), dot(B, B));
        if (!(m > 1e-30) || isinf(m))
            return n; // no uv variation: nothing to map
        float inv = inversesqrt(m);
        T *= inv;
        B *= inv;
    }
    vec3 w = t.x * T + t.y * B + t.z * n;
    float wl = length(w);
    return wl > 1e-8 && !isinf(wl) ? w / wl : n;
}
#endif
