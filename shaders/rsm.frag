// rsm.frag - reflective shadow map: for every texel the light sees, the
// surfel's position and area, its normal (facing the light) and the flux it
// reflects (W), so each texel becomes one VPL and one blocking surfel.
// Alpha-masked texels are cut away: they neither block light (no depth, so no
// shadow) nor reflect it; a BLEND surface of alpha a keeps a of its texels
// (material_covers_texel), so it reflects a of the light and the surfaces
// behind it get the rest. Normal maps are not applied here: an RSM texel is
// far larger than a normal map's detail, and the reflected flux below does
// not depend on the normal (docs/scenes.md, "Materials").
in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv;
in vec2 v_uv1;
in vec4 v_tangent;
in vec4 v_color;

uniform int u_face;

layout(location = 0) out vec4 o_position; // xyz world (m); w surfel area (m^2)
layout(location = 1) out vec4 o_normal;   // xyz unit normal facing the light; w 1 = covered
layout(location = 2) out vec4 o_flux;     // rgb reflected flux (W); a object size (m)
layout(location = 3) out vec4 o_albedo;   // rgb diffuse albedo (for bounces); a 1 = occluder

// Grazing surfels would get unbounded areas; their blocking saturates anyway.
const float MIN_COS = 0.05;

void main()
{
    LpvFaceGpu F = L.faces[u_face];
    LpvLightGpu li = L.lights[int(F.info.x)];
    vec3 p = v_position;

    vec3 to_light;
    vec3 e_perp = light_irradiance_normal(li, p, to_light);
    float side;
    vec3 n = surface_normal(v_normal, p, to_light, side);
    float cos_s = max(dot(n, to_light), MIN_COS);

    // Power arriving through this texel: irradiance x footprint for an
    // orthographic face; I x solid angle for a perspective one (octree thesis
    // 3.3: Omega = 4 cos^3(theta) tan^2(fov/2) / N^2). e_perp already holds
    // I * falloff / d^2, so multiply back by d^2.
    float texel_area_perp; // m^2, perpendicular to the light's rays
    if (F.info.y == 0.0) {
        texel_area_perp = F.info.z;
    } else {
        vec3 d = p - li.position_type.xyz;
        float dist2 = dot(d, d);
        float cos_t = max(dot(normalize(d), F.axis.xyz), 0.0);
        float n_texels = F.info.w;
        float omega = 4.0 * cos_t * cos_t * cos_t * F.info.z * F.info.z / (n_texels * n_texels);
        texel_area_perp = omega * dist2;
    }
    vec3 power = e_perp * texel_area_perp;
    vec4 base = material_albedo(v_uv, v_uv1, v_color);
    // diffuse (an unlit material reflects nothing)
    vec3 albedo = u_unlit != 0 ? vec3(0.0) : base.rgb * (1.0 - material_metallic_roughness(v_uv, v_uv1).x);
    if (LPV_MATERIAL_PLAIN == 0 && !material_covers_texel(base.a)) // after every derivative
        discard;

    o_position = vec4(p, texel_area_perp / cos_s);
    o_normal = vec4(n, 1.0);
    o_flux = vec4(albedo * power, u_object_size);
    // a: 1 = blocks light in the geometry volume; emitters do not (they are
    // light sources, and the planner counts only non-emissive triangles), nor
    // do surfaces seen from a face marked so (F.axis.w: another area light
    // sample already brings them)
    o_albedo = vec4(albedo, any(greaterThan(u_emission, vec3(0.0))) || F.axis.w != 0.0 ? 0.0 : 1.0);
}
