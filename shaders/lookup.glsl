// lookup.glsl - irradiance from the accumulated LPV (core/oracle_lookup.c is
// the reference): trilinear interpolation between cell centres, clamped at
// the grid's edge, at half a cell in front of the surface, then E = max(0, c . lobe(-n) / cell^2) per channel: the
// stored intensity per cell cross-section read as radiance, integrated against
// the cosine over the hemisphere the surface faces.
layout(std430, binding = LPV_SSBO_LPV_ACC) readonly buffer AccLookup { LpvCell lpv[]; };

vec3 lpv_irradiance(vec3 p, vec3 n_in)
{
    float len = length(n_in);
    if (!(len > 1e-8) || isinf(len) || !finite3(p))
        return vec3(0.0);
    vec3 n = n_in / len;
    ivec3 dims = grid_dims();
    // half a cell in front of the surface, mirroring the injection offset
    vec3 q = (p + 0.5 * grid_cell_size() * n - grid_origin()) / grid_cell_size();
    q = clamp(q, vec3(0.5), vec3(dims) - 0.5) - 0.5;
    ivec3 c0 = min(ivec3(floor(q)), dims - 1);
    ivec3 c1 = min(c0 + 1, dims - 1);
    vec3 f = q - vec3(c0);
    vec4 r = vec4(0.0), g = vec4(0.0), b = vec4(0.0);
    for (int k = 0; k < 8; ++k) {
        ivec3 sel = ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
        ivec3 c = mix(c0, c1, bvec3(sel));
        vec3 w3 = mix(1.0 - f, f, vec3(sel));
        float w = w3.x * w3.y * w3.z;
        LpvCell cell = lpv[cell_index(c)];
        r += w * cell.r;
        g += w * cell.g;
        b += w * cell.b;
    }
    vec4 lobe = sh_lobe(-n);
    float inv_area = 1.0 / (grid_cell_size() * grid_cell_size());
    return max(vec3(dot(r, lobe), dot(g, lobe), dot(b, lobe)) * inv_area, 0.0);
}
