// iv_emit.comp - what every occupied voxel sends out in bounce u_bounce:
// its direct light, plus from the second bounce on its albedo times the
// irradiance the previous gather reconstructs at its centre over the
// hemisphere it arrives on, for each side of its mean normal in proportion
// to the points facing that way (a thin wall's voxel holds both sides;
// core/oracle_iv.h, lpv_iv_emit). The two volumes alternate (paper 3.3).
// Empty voxels send nothing.
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
            vec3 nh = m / len;
            float front = 0.5 * (1.0 + min(len, 1.0)), back = 1.0 - front;
            vec3 ef = lpv_irradiance(iv_centre(c), nh) * v.albedo.rgb * front;
            vec3 eb = back > 0.0 ? lpv_irradiance(iv_centre(c), -nh) * v.albedo.rgb * back : vec3(0.0);
            vec4 hf = vec4(LPV_IV_HEMI0, LPV_IV_HEMI1 * nh.y, LPV_IV_HEMI1 * nh.z, LPV_IV_HEMI1 * nh.x);
            vec4 hb = vec4(LPV_IV_HEMI0, -hf.yzw);
            o.r += ef.r * hf + eb.r * hb;
            o.g += ef.g * hf + eb.g * hb;
            o.b += ef.b * hf + eb.b * hb;
        }
    }
    emit[i] = o;
}
