// lights.glsl - punctual lights (KHR_lights_punctual semantics, radiometric
// units) and area light samples (docs/area-lights.md): the power each light
// delivers, shared by the RSMs and direct shading.
layout(std140, binding = LPV_UBO_LIGHT) uniform LightUBO { LpvLightBlock L; };

// glTF's recommended smooth cone falloff: (clamp((cos - cos_outer) / (cos_inner - cos_outer)))^2.
float spot_factor(LpvLightGpu li, vec3 travel_dir)
{
    if (int(li.position_type.w) != LPV_LIGHT_TYPE_SPOT)
        return 1.0;
    float cd = dot(travel_dir, li.direction_range.xyz);
    float scale = 1.0 / max(1e-3, li.cone_faces.x - li.cone_faces.y);
    float t = clamp((cd - li.cone_faces.y) * scale, 0.0, 1.0);
    return t * t;
}

// glTF's range window clamp(1 - (d / range)^4, 0, 1)^2 (the 1/d^2 is separate).
float range_window(LpvLightGpu li, float dist)
{
    float r = li.direction_range.w;
    if (!(r > 0.0))
        return 1.0;
    float q = dist / r;
    float w = clamp(1.0 - q * q * q * q, 0.0, 1.0);
    return w * w;
}

// Irradiance (W/m^2, rgb) on a surface perpendicular to the light at p, and
// the unit direction from p towards the light.
vec3 light_irradiance_normal(LpvLightGpu li, vec3 p, out vec3 to_light)
{
    if (int(li.position_type.w) == LPV_LIGHT_TYPE_DIRECTIONAL) {
        to_light = -li.direction_range.xyz;
        return li.intensity.rgb;
    }
    vec3 d = li.position_type.xyz - p;
    float dist2 = max(dot(d, d), 1e-12);
    float dist = sqrt(dist2);
    to_light = d / dist;
    if (int(li.position_type.w) == LPV_LIGHT_TYPE_AREA) // cosine emission; a disc of area A on its axis
        return li.intensity.rgb * max(0.0, dot(-to_light, li.direction_range.xyz)) / (dist2 + li.intensity.a);
    return li.intensity.rgb * spot_factor(li, -to_light) * range_window(li, dist) / dist2;
}

// Whether light li reaches a surface at p facing n, before any shadowing:
// false behind the surface, outside a spot's cone, behind an area light
// sample (no shadow lookup is needed there; pass_shadow.c draws no depth
// for it). When true, e_cos is the unshadowed irradiance (W/m^2, rgb) on the
// surface and to_light the unit direction towards the light.
bool light_arrives(LpvLightGpu li, vec3 p, vec3 n, out vec3 e_cos, out vec3 to_light)
{
    vec3 e = light_irradiance_normal(li, p, to_light);
    float cos_i = dot(n, to_light);
    e_cos = e * cos_i;
    return cos_i > 0.0 && any(greaterThan(e, vec3(0.0)));
}

// The face of light `li` whose shadow map covers p: the single face, or the
// cube face of the major axis of p - light (faces ordered +x -x +y -y +z -z).
int light_face_for(LpvLightGpu li, vec3 p)
{
    int first = int(li.cone_faces.z);
    if (int(li.position_type.w) == LPV_LIGHT_TYPE_AREA) { // the face whose axis is nearest p's direction
        vec3 d = p - li.position_type.xyz;
        int best = first;
        for (int k = 1; k < int(li.cone_faces.w); ++k)
            if (dot(d, L.faces[first + k].axis.xyz) > dot(d, L.faces[best].axis.xyz))
                best = first + k;
        return best;
    }
    if (int(li.cone_faces.w) < 6)
        return first;
    vec3 d = p - li.position_type.xyz;
    vec3 a = abs(d);
    if (a.x >= a.y && a.x >= a.z)
        return first + (d.x >= 0.0 ? 0 : 1);
    if (a.y >= a.z)
        return first + (d.y >= 0.0 ? 2 : 3);
    return first + (d.z >= 0.0 ? 4 : 5);
}
