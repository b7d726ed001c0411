// shade.frag - the final frame in linear radiance, W/(m^2 sr):
//   L = albedo / pi * (E_direct + gain * E_lpv) + emission
// with E_direct from the lights through their shadow maps and E_lpv the
// irradiance looked up in the accumulated LPV. Switches in the view block
// select the terms (e.g. --indirect-only keeps only the LPV term).
in vec2 v_uv;

layout(binding = 0) uniform sampler2D u_gbuf_position;
layout(binding = 1) uniform sampler2D u_gbuf_normal;
layout(binding = 2) uniform sampler2D u_gbuf_albedo;
layout(binding = 3) uniform sampler2D u_gbuf_emission;
layout(binding = 4) uniform sampler2DArrayShadow u_shadow;

layout(std140, binding = LPV_UBO_VIEW) uniform ViewUBO { LpvViewBlock V; };

layout(location = 0) out vec4 o_radiance;

// Shadow test for light l at p with normal n. The receiver is offset along
// its normal by about two shadow-map texels, and the face (of a point light's
// cube) is chosen for the *offset* point: near a cube edge the offset can
// cross into the neighbouring face, whose frustum is the one that holds it.
float shadow_visibility(int l, vec3 p, vec3 n)
{
    LpvLightGpu li = L.lights[l];
    LpvFaceGpu F0 = L.faces[light_face_for(li, p)];
    float texel;
    if (F0.info.y == 0.0)
        texel = sqrt(F0.info.z);
    else // every face of one light shares its fov and size
        texel = 2.0 * F0.info.z * length(p - li.position_type.xyz) / F0.info.w;
    vec3 q = p + n * 2.0 * texel;
    int face = light_face_for(li, q);
    LpvFaceGpu F = L.faces[face];
    vec4 clip = F.view_proj * vec4(q, 1.0);
    if (!(clip.w > 0.0))
        return 0.0;
    vec3 ndc = clip.xyz / clip.w;
    if (any(greaterThan(abs(ndc.xy), vec2(1.0))))
        return F.info.y == 0.0 ? 1.0 : 0.0;
    vec3 uvz = ndc * 0.5 + 0.5;
    return texture(u_shadow, vec4(uvz.xy, float(face), uvz.z - 1e-4));
}

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 pos = texelFetch(u_gbuf_position, px, 0);
    vec4 nrm = texelFetch(u_gbuf_normal, px, 0);
    if (nrm.w < 0.5) {
        o_radiance = vec4(0.0, 0.0, 0.0, 0.0);
        return;
    }
    vec3 p = pos.xyz;
    vec3 n = nrm.xyz;
    vec3 albedo = texelFetch(u_gbuf_albedo, px, 0).rgb;
    vec3 emission = texelFetch(u_gbuf_emission, px, 0).rgb;

    vec3 e_direct = vec3(0.0);
    if (V.shading.y != 0.0) {
        int count = int(L.counts.x);
        for (int l = 0; l < count; ++l) {
            LpvLightGpu li = L.lights[l];
            vec3 to_light;
            vec3 e = light_irradiance_normal(li, p, to_light);
            float cos_i = dot(n, to_light);
            if (cos_i <= 0.0)
                continue;
            e_direct += e * cos_i * shadow_visibility(l, p, n);
        }
    }
    vec3 e_indirect = V.shading.z != 0.0 ? V.shading.x * lpv_irradiance(p, n) : vec3(0.0);
    vec3 radiance = albedo / LPV_PI * (e_direct + e_indirect);
    if (V.shading.w != 0.0)
        radiance += emission;
    o_radiance = vec4(radiance, 1.0);
}
