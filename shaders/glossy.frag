// glossy.frag - glossy reflections from the LPV (cascaded-LPV paper section 7,
// docs/effects.md): for a pixel whose material is rougher than nothing but
// below the glossy threshold, march the cascades along the reflection
// direction r over GLOSSY_STEPS cells and average the radiance travelling back
// toward the surface, I(-r) / cell^2, weighted by the inverse squared
// distance. Added (blending ONE, ONE) to the shaded frame as F0 x that
// radiance, F0 = mix(0.04, albedo, metallic); shading.glsl lowered the diffuse
// part of the same pixels by kd, so the pixel does not gain energy.
in vec2 v_uv;

layout(binding = 0) uniform sampler2D u_gbuf_position;
layout(binding = 1) uniform sampler2D u_gbuf_normal;  // w: 1 + metallic where covered
layout(binding = 2) uniform sampler2D u_gbuf_albedo;  // a: roughness

layout(std140, binding = LPV_UBO_VIEW) uniform ViewUBO { LpvViewBlock V; };

uniform float u_glossy_roughness;

layout(location = 0) out vec4 o_radiance;

const int GLOSSY_STEPS = 4;

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 nrm = texelFetch(u_gbuf_normal, px, 0);
    vec4 alb = texelFetch(u_gbuf_albedo, px, 0);
    o_radiance = vec4(0.0);
    if (nrm.w < 0.5 || lpv_gbuffer_unlit(nrm.w) || !(alb.a < u_glossy_roughness))
        return;
    vec3 p = texelFetch(u_gbuf_position, px, 0).xyz;
    vec3 n = normalize(nrm.xyz);
    vec3 to_eye = V.eye.w > 0.5 ? normalize(V.eye.xyz - p) : -V.forward.xyz;
    vec3 r = reflect(-to_eye, n);
    float cell = lpv_cell_at(p);
    vec3 start = p + 0.5 * cell * n; // out of the surface's own cell, like the lookup
    vec4 toward_surface = sh_basis(-r);
    vec3 sum = vec3(0.0);
    float wsum = 0.0;
    for (int j = 1; j <= GLOSSY_STEPS; ++j) {
        float d = float(j) * cell;
        float w = 1.0 / (d * d);
        sum += w * lpv_reach_point(start + d * r) * lpv_project(start + d * r, toward_surface);
        wsum += w;
    }
    float metallic = clamp(nrm.w - 1.0, 0.0, 1.0);
    vec3 f0 = mix(vec3(0.04), alb.rgb, metallic);
    o_radiance = vec4(f0 * sum / wsum, 0.0);
}
