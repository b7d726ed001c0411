// iv_lookup.glsl - the imperfect volume's lookup (technique.h's contract):
// the gathered radiance (LpvCell per voxel, W/(m^2 sr), as a function of the
// direction light travels) reconstructed at surfaces by iv_blend, and the
// ambient occlusion volume.
layout(std430, binding = LPV_SSBO_LPV_ACC) readonly buffer AccLookup { LpvCell lpv[]; };
layout(std430, binding = LPV_SSBO_IV_AO) readonly buffer AoLookup { vec4 iv_ao[]; };
uniform float u_damping; // the LPV's; the imperfect volume has none

#define LPV_HAS_AO 1

// The irradiance e the 2-band reconstruction gives, any sign per channel, as
// light: one rule for the whole colour (techniques/iv/core/oracle_iv.c, physical). Near a
// surface the voxels a point reads hold its own bright light arriving from
// behind it, which the 2-band cosine lobe weighs negatively: a channel can
// fall below 0 while another stays positive. Clamping each channel at 0
// then left exactly 0 in red and green and kept blue (dark blue floors in
// the courtyard). Instead the luminance y decides: none at y <= 0; else the
// colour keeps y and its chroma shrinks by y / (y - 2 m), m its most
// negative channel (1 where no channel is negative; every channel stays
// above 0 and the colour stays continuous). No gain: y is the linear
// estimate's own luminance.
vec3 iv_physical(vec3 e)
{
    float y = dot(e, vec3(LPV_IV_LUMA_R, LPV_IV_LUMA_G, LPV_IV_LUMA_B));
    if (!(y > 0.0))
        return vec3(0.0);
    float m = min(min(e.r, e.g), e.b);
    if (m >= 0.0)
        return e;
    return vec3(y) + (e - vec3(y)) * (y / (y - 2.0 * m));
}

vec3 lpv_irradiance(vec3 p, vec3 n_in)
{
    float len = length(n_in);
    if (!(len > 1e-8) || isinf(len) || !finite3(p))
        return vec3(0.0);
    vec3 n = n_in / len;
    ivec3 cell[8];
    float w[8];
    float sum = iv_blend(p, n, cell, w);
    if (!(sum > 0.0))
        return vec3(0.0);
    vec4 r = vec4(0.0), g = vec4(0.0), b = vec4(0.0);
    for (int k = 0; k < 8; ++k) {
        if (w[k] == 0.0)
            continue;
        LpvCell c = lpv[cell_index(cell[k])];
        r += w[k] * c.r;
        g += w[k] * c.g;
        b += w[k] * c.b;
    }
    vec4 lobe = sh_lobe(-n) / sum; // irradiance: the incoming light travels along -n
    return iv_physical(vec3(dot(r, lobe), dot(g, lobe), dot(b, lobe)));
}

// Ambient occlusion at a surface (paper 3.5): the visible directions'
// cosine-weighted fraction, 1 = open, 0 = enclosed.
float lpv_ao(vec3 p, vec3 n_in)
{
    float len = length(n_in);
    if (!(len > 1e-8) || isinf(len) || !finite3(p))
        return 1.0;
    vec3 n = n_in / len;
    ivec3 cell[8];
    float w[8];
    float sum = iv_blend(p, n, cell, w);
    if (!(sum > 0.0))
        return 1.0;
    vec4 v = vec4(0.0);
    for (int k = 0; k < 8; ++k)
        if (w[k] != 0.0)
            v += w[k] * iv_ao[cell_index(cell[k])];
    return clamp(dot(v, sh_lobe(-n)) / (sum * LPV_PI), 0.0, 1.0);
}

// The radiance at x dotted with v (trilinear over voxel centres), for the
// glossy march and the media: the volume holds radiance, so no / cell^2;
// never negative.
vec3 lpv_project(vec3 x, vec4 v)
{
    vec3 u = cascade_coords(0, x) - 0.5;
    vec3 b = floor(u), f = u - b;
    vec3 e = vec3(0.0);
    for (int k = 0; k < 8; ++k) {
        ivec3 o = ivec3(k & 1, (k >> 1) & 1, k >> 2);
        ivec3 c = ivec3(b) + o;
        if (!cell_inside(c))
            continue;
        vec3 t = mix(1.0 - f, f, vec3(o));
        LpvCell l = lpv[cell_index(c)];
        e += t.x * t.y * t.z * vec3(dot(l.r, v), dot(l.g, v), dot(l.b, v));
    }
    return max(e, 0.0); // radiance: the 2-band SH's ringing below zero is not light
}

float lpv_cell_at(vec3 x) { return grid_cell_size(); }

// Every normal is cheap here: no second pass (technique.h).
vec3 lpv_irradiance_listed(vec3 p, vec3 n, out bool done)
{
    done = true;
    return lpv_irradiance(p, n);
}
