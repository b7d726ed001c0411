// shading.glsl - the final frame in linear radiance, W/(m^2 sr):
//   L = albedo / pi * (E_direct + gain * E_lpv) + emission
// with E_direct from the lights through their shadow maps and E_lpv the
// irradiance looked up in the accumulated LPV. Switches in the view block
// select the terms (e.g. --indirect-only keeps only the LPV term).
// shade_pixel(px) is one pixel of it, from the G-buffer; shade.comp runs it
// for every pixel (pass_camera.c, lpv_pass_shade_run).
layout(binding = 0) uniform sampler2D u_gbuf_position;
layout(binding = 1) uniform sampler2D u_gbuf_normal;
layout(binding = 2) uniform sampler2D u_gbuf_albedo;
layout(binding = 3) uniform sampler2D u_gbuf_emission;
layout(binding = LPV_TEX_GBUF_OCCLUSION) uniform sampler2D u_gbuf_occlusion; // the material's occlusionTexture

// The factor the pixel's indirect light takes (glTF's occlusionTexture: an
// ambient term of the frame, not of the GI the bounces carry). Frames of
// scenes without one (LPV_FRAME_OCCLUSION 0) read nothing: llvmpipe would
// fetch for every pixel (gpu/pass_camera.c picks the variant).
#ifndef LPV_FRAME_OCCLUSION
#define LPV_FRAME_OCCLUSION 1
#endif
#ifndef LPV_FRAME_UNLIT
#define LPV_FRAME_UNLIT 1
#endif
float ambient_occlusion(ivec2 px) { return LPV_FRAME_OCCLUSION != 0 ? texelFetch(u_gbuf_occlusion, px, 0).r : 1.0; }

layout(std140, binding = LPV_UBO_VIEW) uniform ViewUBO { LpvViewBlock V; };

uniform float u_glossy_roughness; // materials below it are glossy; 0 when the glossy pass does not run

// The lookup step (docs/accuracy.md, "The lookup step"): with lookup_step N >
// 1 the technique's irradiance is looked up once per N x N block of pixels
// (lookup_blocks.comp) and each pixel takes it from the blocks around it that
// lie on its own plane. LPV_LOOKUP_BLOCKS 1 is the frame that reads the
// blocks (the engine's prog_shade_blocks), 0 the one that looks up every
// pixel itself.
#ifndef LPV_LOOKUP_BLOCKS
#define LPV_LOOKUP_BLOCKS 0
#endif
uniform int u_lookup_step;

// LPV_SHADE_DIRECTIONAL 0: the frame without the directional lights' loop
// (the engine's programs for scenes without one, gpu/engine.c): llvmpipe
// runs a loop's code at least once for every pixel, and the cascades'
// search cost a 512^2 frame 4 ms with no directional light in the scene.
#ifndef LPV_SHADE_DIRECTIONAL
#define LPV_SHADE_DIRECTIONAL 1
#endif

// The frame in two passes (LPV_LOOKUP_SPLIT 1, the engine's prog_shade):
// shade.comp looks up only what the technique finds cheaply
// (lpv_irradiance_listed: the lookup's own normals) and lists the other
// pixels; shade_rest.comp then adds their indirect light. On llvmpipe the
// full lookup's arithmetic would otherwise run for every pixel under lane
// masks. The list: a dispatch's workgroup counts (x grows by one per
// LPV_SHADE_REST_WG pixels, up to LPV_SHADE_REST_MAX_GROUPS), the pixel
// count, then the pixels.
#ifndef LPV_LOOKUP_SPLIT
#define LPV_LOOKUP_SPLIT 0
#endif
#if LPV_LOOKUP_SPLIT
layout(std430, binding = LPV_SSBO_SHADE_REST) buffer ShadeRest
{
    uvec4 rest_head; // x, y, z workgroups of shade_rest.comp; w pixels listed
    ivec2 rest_px[];
};
#endif

// Appends pixel px to a list of that layout (head: a uvec4, list: ivec2[]),
// a workgroup more in head.x per LPV_SHADE_REST_WG pixels.
#define LPV_LIST_PIXEL(head, list, px)                                                                     \
    {                                                                                                      \
        uint listed_ = atomicAdd(head.w, 1u);                                                              \
        if (listed_ % uint(LPV_SHADE_REST_WG) == 0u && listed_ / uint(LPV_SHADE_REST_WG) < uint(LPV_SHADE_REST_MAX_GROUPS)) \
            atomicAdd(head.x, 1u);                                                                         \
        list[listed_] = px;                                                                                \
    }

// The width (m) of a block of `step` pixels at p: 2 tan(yfov / 2) times the
// depth per image height (orthographic: 2 ymag).
float block_width_at(vec3 p, int step)
{
    float depth = V.eye.w != 0.0 ? max(dot(p - V.eye.xyz, V.forward.xyz), 0.0) : 1.0;
    return 2.0 * V.forward.w * depth / V.viewport.y * float(step);
}

// v / |v|, or 0 for a zero normal (a pixel no surface covers).
vec3 unit_or_zero(vec3 v)
{
    float len = length(v);
    return len > 1e-8 ? v / len : vec3(0.0);
}

// How far p lies off a block's plane (xyz unit normal, w distance from the
// origin), in LPV_BLOCK_PLANE_PIXELS widths at p of a block of `step`
// pixels: below 1, the same surface.
float plane_offset(vec4 plane, vec3 p, int step)
{
    return abs(dot(plane.xyz, p) - plane.w) / (LPV_BLOCK_PLANE_PIXELS * block_width_at(p, step));
}

// How alike point p with unit normal n is to a block's plane, 0..1: 1 on the
// plane facing its way, falling with cos^8 of the angle between the normals
// and to 0 at plane_offset 1 (another surface).
float plane_likeness(vec4 plane, vec3 p, vec3 n, int step)
{
    float wn = max(dot(n, plane.xyz), 0.0);
    wn *= wn;
    wn *= wn;
    wn *= wn;
    return wn * clamp(1.0 - plane_offset(plane, p, step), 0.0, 1.0);
}

// The surface of block b of step x step pixels, for the passes that work per
// block (lookup_blocks.comp, area_shadow_blocks.comp): the block's first
// covered pixel in raster order fixes its plane (xyz unit normal, w distance
// from the origin), and it and every later pixel on that plane join the mean
// point and the normals' sum. False when no pixel of the block is covered.
bool block_surface(ivec2 b, int step, out vec4 plane, out vec3 p_mean, out vec3 n_sum)
{
    ivec2 first = b * step, size = textureSize(u_gbuf_normal, 0);
    bool seen = false;
    vec3 p_sum = vec3(0.0);
    float on = 0.0;
    plane = vec4(0.0);
    n_sum = vec3(0.0);
    for (int k = 0; k < step * step; ++k) {
        ivec2 px = first + ivec2(k % step, k / step);
        ivec2 at = min(px, size - 1);
        vec4 nrm = texelFetch(u_gbuf_normal, at, 0);
        vec3 p = texelFetch(u_gbuf_position, at, 0).xyz;
        vec3 nk = unit_or_zero(nrm.xyz);
        bool covered = nrm.w >= 0.5 && !lpv_gbuffer_wire(nrm.w) && all(lessThan(px, size));
        if (covered && !seen) {
            plane = vec4(nk, dot(nk, p));
            seen = true;
        }
        bool same = covered && dot(nk, plane.xyz) >= LPV_BLOCK_NORMAL_COS && plane_offset(plane, p, step) < 1.0;
        p_sum += same ? p : vec3(0.0);
        n_sum += same ? nrm.xyz : vec3(0.0);
        on += same ? 1.0 : 0.0;
    }
    p_mean = p_sum / max(on, 1.0);
    return seen;
}

// The value at pixel px (point p, normal n) of the blocks of step x step
// pixels whose values (rgb; a 1 = the block saw a surface) and planes the two
// samplers hold: bilinear between the four blocks' centres around px, each
// weighted by how alike its plane is (plane_likeness), so nothing crosses an
// edge between surfaces; where no block around is alike (weights 0: a
// surface thinner than the blocks), the most alike one's.
vec3 blocks_upsampled(sampler2D values, sampler2D planes, int step, vec3 p, vec3 n_in, ivec2 px, out float weights)
{
    vec3 n = unit_or_zero(n_in);
    vec2 u = (vec2(px) + 0.5) / float(step) - 0.5; // block centres at integers
    ivec2 i0 = ivec2(floor(u));
    vec2 f = u - vec2(i0);
    ivec2 last = textureSize(values, 0) - 1;
    vec3 sum = vec3(0.0), most_alike = vec3(0.0);
    float best = -1.0;
    weights = 0.0;
    for (int j = 0; j < 4; ++j) {
        ivec2 b = clamp(i0 + ivec2(j & 1, j >> 1), ivec2(0), last);
        vec4 e = texelFetch(values, b, 0);
        float like = e.a * plane_likeness(texelFetch(planes, b, 0), p, n, step);
        float w = ((j & 1) != 0 ? f.x : 1.0 - f.x) * ((j >> 1) != 0 ? f.y : 1.0 - f.y) * like;
        sum += w * e.rgb;
        weights += w;
        if (like > best) {
            best = like;
            most_alike = e.rgb;
        }
    }
    return weights > 0.0 ? sum / weights : most_alike;
}

#if LPV_LOOKUP_BLOCKS
layout(binding = LPV_TEX_BLOCK_IRRADIANCE) uniform sampler2D u_block_irradiance;
layout(binding = LPV_TEX_BLOCK_PLANE) uniform sampler2D u_block_plane;
#endif

// The area light samples' irradiance at p (unit normal n) through their
// shadow maps (W/m^2, rgb); `arrives` the same without the shadows.
vec3 area_light_shadowed(vec3 p, vec3 n, out vec3 arrives)
{
    vec3 lit = vec3(0.0);
    arrives = vec3(0.0);
    for (int l = int(L.counts.z); l < int(L.counts.x); ++l) {
        vec3 e, to_light;
        if (light_arrives(L.lights[l], p, n, e, to_light)) {
            arrives += e;
            lit += e * shadow_visibility(l, p, n, SHADOW_AREA_SAMPLE);
        }
    }
    return lit;
}

// The area light samples' visibility at p (unit normal n), per channel: the
// shadowed over the unshadowed irradiance of all samples, so that the
// samples weigh by the light each brings; 1 where none arrives.
// area_shadow_blocks.comp evaluates it once per block of u_area_shadow_step
// pixels (the area shadow step, docs/area-lights.md); the frame multiplies
// each pixel's own unshadowed irradiance by it, spread by blocks_upsampled.
vec3 area_visibility(vec3 p, vec3 n)
{
    vec3 arrives;
    vec3 lit = area_light_shadowed(p, n, arrives);
    return mix(vec3(1.0), lit / max(arrives, vec3(1e-30)), greaterThan(arrives, vec3(0.0)));
}

// LPV_AREA_SHADOW_BLOCKS 1: the frame that reads the area light samples'
// visibility from area_shadow_blocks.comp's blocks (the engine's frame
// variant LPV_FRAME_AREA_BLOCKS); 0 the one that reads every sample's shadow
// map at every pixel. A lit pixel that no block around is alike to (a
// surface thinner than the blocks, seen edge-on or far away) gets no area
// light from the frame and is listed instead (the layout of ShadeRest):
// area_shadow_rest.comp adds its area light through every sample's shadow
// map, as at step 1.
#ifndef LPV_AREA_SHADOW_BLOCKS
#define LPV_AREA_SHADOW_BLOCKS 0
#endif
uniform int u_area_shadow_step;
#if LPV_AREA_SHADOW_BLOCKS
layout(binding = LPV_TEX_AREA_SHADOW) uniform sampler2D u_area_shadow;
layout(binding = LPV_TEX_AREA_SHADOW_PLANE) uniform sampler2D u_area_shadow_plane;
layout(std430, binding = LPV_SSBO_AREA_REST) buffer AreaRest
{
    uvec4 area_rest_head; // x, y, z workgroups of area_shadow_rest.comp; w pixels listed
    ivec2 area_rest_px[];
};
#endif

// The diffuse albedo / pi at pixel px (metallic_w: the G-buffer normal's
// w): base x (1 - metallic) (lpv_gbuffer_kd). With the glossy pass on, a
// glossy surface's diffuse part gives way to its specular part too
// (glossy.frag adds F0 x the LPV's radiance along the reflection): x (1 - 0.04).
vec3 diffuse_reflectance(ivec2 px, float metallic_w)
{
    vec4 a = texelFetch(u_gbuf_albedo, px, 0);
    float kd = lpv_gbuffer_kd(metallic_w) * (a.a < u_glossy_roughness ? 1.0 - 0.04 : 1.0);
    return kd * a.rgb / LPV_PI;
}

vec4 shade_pixel(ivec2 px)
{
    vec4 pos = texelFetch(u_gbuf_position, px, 0);
    vec4 nrm = texelFetch(u_gbuf_normal, px, 0);
    if (nrm.w < 0.5)
        return vec4(0.0);
    vec3 p = pos.xyz;
    vec3 n = nrm.xyz;
#ifdef LPV_HAS_AO
    if (V.viewport.w != 0.0) // the technique's ambient occlusion, 1 = open
        return vec4(vec3(lpv_ao(p, n)), 1.0);
#endif
    vec3 emission = texelFetch(u_gbuf_emission, px, 0).rgb;
    if (LPV_FRAME_UNLIT != 0 && lpv_gbuffer_unlit(nrm.w)) // KHR_materials_unlit: its colour as it is, no light
        return vec4(V.shading.w != 0.0 ? emission : vec3(0.0), 1.0);

    vec3 e_direct = vec3(0.0);
    if (V.shading.y != 0.0) {
        // the directional lights, the points and spots, then the area light
        // samples (lights.glsl, gpu/light_faces.c): apart, so that each loop
        // holds only its kind's shadow lookup
        int directional = int(L.counts.w), punctual = int(L.counts.z), count = int(L.counts.x);
#if LPV_SHADE_DIRECTIONAL
        for (int l = 0; l < directional; ++l) {
            vec3 e, to_light;
            if (light_arrives(L.lights[l], p, n, e, to_light))
                e_direct += e * shadow_visibility(l, p, n, SHADOW_DIRECTIONAL);
        }
#endif
        for (int l = directional; l < punctual; ++l) {
            vec3 e, to_light;
            if (light_arrives(L.lights[l], p, n, e, to_light))
                e_direct += e * shadow_visibility(l, p, n, SHADOW_PERSPECTIVE);
        }
#if LPV_AREA_SHADOW_BLOCKS
        vec3 e_area = vec3(0.0);
        for (int l = punctual; l < count; ++l) {
            vec3 e, to_light;
            if (light_arrives(L.lights[l], p, n, e, to_light))
                e_area += e;
        }
        float alike;
        vec3 v = blocks_upsampled(u_area_shadow, u_area_shadow_plane, u_area_shadow_step, p, n, px, alike);
        if (alike > 0.0)
            e_direct += e_area * v;
        else if (any(greaterThan(e_area, vec3(0.0))))
            LPV_LIST_PIXEL(area_rest_head, area_rest_px, px)
#else
        vec3 arrives;
        e_direct += area_light_shadowed(p, n, arrives);
#endif
    }
#if LPV_LOOKUP_BLOCKS
    float alike;
    vec3 e_indirect = V.shading.z != 0.0 ? V.shading.x * blocks_upsampled(u_block_irradiance, u_block_plane,
                                                                           u_lookup_step, p, n, px, alike)
                                         : vec3(0.0);
#elif LPV_LOOKUP_SPLIT
    vec3 e_indirect = vec3(0.0);
    if (V.shading.z != 0.0) {
        bool done;
        e_indirect = V.shading.x * lpv_reach(p, n) * lpv_irradiance_listed(p, n, done);
        if (!done)
            LPV_LIST_PIXEL(rest_head, rest_px, px)
    }
#else
    vec3 e_indirect = V.shading.z != 0.0 ? V.shading.x * lpv_reach(p, n) * lpv_irradiance(p, n) : vec3(0.0);
#endif
    vec3 radiance = diffuse_reflectance(px, nrm.w) * (e_direct + ambient_occlusion(px) * e_indirect);
    if (V.shading.w != 0.0)
        radiance += emission;
    return vec4(radiance, 1.0);
}
