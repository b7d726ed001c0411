// shadow.glsl - shadow-map visibility of the lights (RSM depth layers),
// shared by the shading and the media's in-scattering.
layout(binding = 4) uniform sampler2DArrayShadow u_shadow;

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
    // F.tile: the face's square of its layer (area light faces are tiles),
    // kept half a texel inside so the filter never reads a neighbouring tile
    float half_texel = 0.5 * F.tile.z / F.info.w;
    vec2 uv = clamp(F.tile.xy + uvz.xy * F.tile.z, F.tile.xy + half_texel, F.tile.xy + F.tile.z - half_texel);
    return texture(u_shadow, vec4(uv, F.tile.w, uvz.z - 1e-4));
}

