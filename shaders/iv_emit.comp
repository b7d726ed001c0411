// iv_emit.comp - what every occupied voxel sends out in bounce u_bounce:
// its direct light, plus from the second bounce on its albedo times the
// irradiance the previous gather reconstructs at its centre (facing its mean
// normal) over the hemisphere of that normal (paper 3.3: the two volumes
// alternate). Empty voxels send nothing.
layout(local_size_x = LPV_IV_WG) in;

layout(std430, binding = LPV_SSBO_IV_VOXELS) readonly buffer Voxels { IvVoxel voxels[]; };
layout(std430, binding = LPV_SSBO_IV_EMIT) writeonly buffer Emit { LpvCell emit[]; };
uniform int u_bounce; // 1: direct light only

void main()
{
    int i = int(gl_GlobalInvocationID.x);
    if (i >= grid_cells())
        return;
    IvVoxel v = voxels[i];
    LpvCell o;
    o.r = o.g = o.b = vec4(0.0);
    if (v.normal.w > 0.0) {
        o.r = v.r;
        o.g = v.g;
        o.b = v.b;
        vec3 m = v.normal.xyz;
        float len = length(m);
        if (u_bounce > 1 && len > 1e-3) {
            ivec3 d = grid_dims();
            ivec3 c = ivec3(i % d.x, (i / d.x) % d.y, i / (d.x * d.y));
            vec3 e = lpv_irradiance(iv_centre(c), m / len) * v.albedo.rgb;
            vec4 h = vec4(LPV_IV_HEMI0, LPV_IV_HEMI1 * m.y, LPV_IV_HEMI1 * m.z, LPV_IV_HEMI1 * m.x);
            o.r += e.r * h;
            o.g += e.g * h;
            o.b += e.b * h;
        }
    }
    emit[i] = o;
}
