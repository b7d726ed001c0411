// material.glsl - the per-draw material and the surface normal, shared by the
// RSM and G-buffer fragment shaders.
uniform vec4 u_base_color;      // linear RGBA factor
uniform int u_has_texture;      // base colour texture bound to unit 0 (sRGB, decoded by GL)
uniform vec3 u_emission;        // W/(m^2 sr)
uniform float u_roughness;      // glTF roughness (0 mirror .. 1 matte)
uniform float u_metallic;       // glTF metallic (0 dielectric .. 1 metal)
uniform float u_object_size;    // m, the draw's longest bounding-box side (cascade fading)
layout(binding = 0) uniform sampler2D u_base_texture;

vec4 material_albedo(vec2 uv)
{
    vec4 c = u_base_color;
    if (u_has_texture != 0)
        c *= texture(u_base_texture, uv);
    return c;
}

#ifdef LPV_STAGE_FRAGMENT
// The interpolated normal, or the face normal when the file's normal is
// zero-length or not finite; oriented towards `toward` (a unit direction from
// the surface to the viewer or light), since lpvd treats surfaces as seen
// from the side they are lit or looked at.
vec3 surface_normal(vec3 interpolated, vec3 position, vec3 toward)
{
    vec3 n = interpolated;
    float len = length(n);
    if (!(len > 1e-8) || isinf(len)) {
        n = cross(dFdx(position), dFdy(position));
        len = length(n);
        if (!(len > 1e-20) || isinf(len))
            return toward;
    }
    n /= len;
    return dot(n, toward) < 0.0 ? -n : n;
}
#endif
