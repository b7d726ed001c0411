// iv_direct.glsl - direct irradiance (W/m^2) at a point of the imperfect
// volume (paper 3.1: "the direct illumination is calculated using the
// interpolated normal"): every light of lights.glsl, shadowed through its
// reflective shadow map, the light's shadow map in this pipeline. The RSMs
// cover every surface the lights reach, where the camera's cascaded shadow
// maps cover only what the camera sees. A texel shadows p when its surface
// lies towards the light from p by more than the bias; texels of emitters
// (albedo.a 0 in the RSM) do not shadow, as in the geometry volume.
layout(binding = 5) uniform sampler2DArray u_rsm_position; // xyz world (m); w area, 0 = no surface
layout(binding = 6) uniform sampler2DArray u_rsm_albedo;   // a 1 = occluder

// Fraction of a 2x2 texel footprint around p that sees the light.
float iv_rsm_visibility(int face, vec3 p, vec3 n, vec3 to_light)
{
    LpvFaceGpu F = L.faces[face];
    vec4 clip = F.view_proj * vec4(p, 1.0);
    if (!(clip.w > 0.0))
        return 1.0;
    vec2 ndc = clip.xy / clip.w;
    if (any(greaterThan(abs(ndc), vec2(1.0))))
        return 1.0; // outside the face: nothing there casts a shadow the RSM saw
    ivec3 size = textureSize(u_rsm_position, 0);
    vec2 lo = F.tile.xy * vec2(size.xy), span = vec2(F.tile.z) * vec2(size.xy);
    vec2 st = lo + (ndc * 0.5 + 0.5) * span - 0.5;
    // texel side at p (m): orthographic info.z is m^2 per texel; perspective
    // info.z is tan(fov/2) over info.w texels, times the depth along the axis
    float texel_m = F.info.y == 0.0 ? sqrt(F.info.z)
                                    : 2.0 * F.info.z / F.info.w *
                                          max(dot(p - L.lights[int(F.info.x)].position_type.xyz, F.axis.xyz), 0.0);
    float cos_t = clamp(dot(n, to_light), 0.05, 1.0);
    float bias = texel_m * (LPV_SHADOW_NORMAL_OFFSET + min(sqrt(1.0 - cos_t * cos_t) / cos_t, LPV_SHADOW_MAX_SLOPE));
    ivec2 base = ivec2(floor(st));
    vec2 f = st - vec2(base);
    ivec2 tmin = ivec2(lo), tmax = ivec2(lo + span) - 1;
    float vis = 0.0;
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        ivec2 t = clamp(base + o, tmin, tmax);
        float w = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
        vec4 q = texelFetch(u_rsm_position, ivec3(t, int(F.tile.w)), 0);
        bool blocks = q.w > 0.0 && dot(q.xyz - p, to_light) > bias &&
                      texelFetch(u_rsm_albedo, ivec3(t, int(F.tile.w)), 0).a > 0.5;
        vis += blocks ? 0.0 : w;
    }
    return vis;
}

vec3 iv_direct_irradiance(vec3 p, vec3 n)
{
    vec3 e = vec3(0.0);
    int count = int(L.counts.x);
    for (int l = 0; l < count; ++l) {
        LpvLightGpu li = L.lights[l];
        vec3 e_cos, to_light;
        if (light_arrives(li, p, n, e_cos, to_light))
            e += e_cos * iv_rsm_visibility(light_face_for(li, p), p, n, to_light);
    }
    return e;
}
