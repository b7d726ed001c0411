// medium.glsl - the participating medium (docs/effects.md, "Media"): scattering
// and absorption coefficients (1/m at density 1) times a density that is 1
// everywhere (fog), 1 inside a box, or a 3D texture over the box.
uniform int u_medium;            // bit 0: a medium; bit 1: bounded by the box; bit 2: density texture
uniform vec3 u_medium_sigma_s;   // 1/m
uniform vec3 u_medium_sigma_a;   // 1/m
uniform vec3 u_medium_box_min;   // m
uniform vec3 u_medium_box_max;   // m
layout(binding = LPV_TEX_DENSITY) uniform sampler3D u_medium_density;

float medium_density(vec3 p)
{
    if ((u_medium & 1) == 0)
        return 0.0;
    if ((u_medium & 2) == 0)
        return 1.0;
    vec3 uvw = (p - u_medium_box_min) / (u_medium_box_max - u_medium_box_min);
    if (any(lessThan(uvw, vec3(0.0))) || any(greaterThan(uvw, vec3(1.0))))
        return 0.0;
    return (u_medium & 4) != 0 ? max(texture(u_medium_density, uvw).r, 0.0) : 1.0;
}

vec3 medium_sigma_t(vec3 p) { return (u_medium_sigma_s + u_medium_sigma_a) * medium_density(p); }
