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

layout(std140, binding = LPV_UBO_VIEW) uniform ViewUBO { LpvViewBlock V; };

uniform float u_glossy_roughness; // materials below it are glossy; 0 when the glossy pass does not run

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
    vec3 albedo = texelFetch(u_gbuf_albedo, px, 0).rgb;
    vec3 emission = texelFetch(u_gbuf_emission, px, 0).rgb;

    vec3 e_direct = vec3(0.0);
    if (V.shading.y != 0.0) {
        // the punctual lights, then the area light samples (lights.glsl):
        // apart, so that each loop holds only its kind's shadow lookup
        int punctual = int(L.counts.z), count = int(L.counts.x);
        for (int l = 0; l < punctual; ++l) {
            vec3 e, to_light;
            if (light_arrives(L.lights[l], p, n, e, to_light))
                e_direct += e * shadow_visibility(l, p, n, SHADOW_PUNCTUAL);
        }
        for (int l = punctual; l < count; ++l) {
            vec3 e, to_light;
            if (light_arrives(L.lights[l], p, n, e, to_light))
                e_direct += e * shadow_visibility(l, p, n, SHADOW_AREA_SAMPLE);
        }
    }
    vec3 e_indirect = V.shading.z != 0.0 ? V.shading.x * lpv_irradiance(p, n) : vec3(0.0);
    // With the glossy pass on, a glossy surface's diffuse part gives way to
    // its specular part (glossy.frag adds F0 x the LPV's radiance along the
    // reflection): kd = (1 - metallic)(1 - 0.04).
    float roughness = texelFetch(u_gbuf_albedo, px, 0).a;
    float metallic = clamp(nrm.w - 1.0, 0.0, 1.0);
    float kd = roughness < u_glossy_roughness ? (1.0 - metallic) * (1.0 - 0.04) : 1.0;
    vec3 radiance = kd * albedo / LPV_PI * (e_direct + e_indirect);
    if (V.shading.w != 0.0)
        radiance += emission;
    return vec4(radiance, 1.0);
}
