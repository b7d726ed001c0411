// iv_resolve.comp - the atlas's sums into voxels (IvVoxel: the means over
// the points a voxel received) and the occupancy bits the march tests.
layout(local_size_x = LPV_IV_WG) in;

layout(binding = 0) uniform sampler2D u_sum_r;
layout(binding = 1) uniform sampler2D u_sum_g;
layout(binding = 2) uniform sampler2D u_sum_b;
layout(binding = 3) uniform sampler2D u_sum_n;
layout(binding = 4) uniform sampler2D u_sum_a;
layout(binding = 5) uniform sampler2D u_sum_f;
layout(std430, binding = LPV_SSBO_IV_VOXELS) writeonly buffer Voxels { IvVoxel voxels[]; };
layout(std430, binding = LPV_SSBO_IV_OCCUPANCY) buffer Occupancy { uint occupancy[]; };

void main()
{
    int i = int(gl_GlobalInvocationID.x);
    if (i >= grid_cells())
        return;
    ivec3 d = grid_dims();
    ivec3 c = ivec3(i % d.x, (i / d.x) % d.y, i / (d.x * d.y));
    ivec2 t = atlas_texel(c, d.xy);
    vec4 n = texelFetch(u_sum_n, t, 0);
    IvVoxel v;
    float k = n.w > 0.0 ? 1.0 / n.w : 0.0;
    v.r = texelFetch(u_sum_r, t, 0) * k;
    v.g = texelFetch(u_sum_g, t, 0) * k;
    v.b = texelFetch(u_sum_b, t, 0) * k;
    v.normal = vec4(n.xyz * k, n.w);
    v.albedo = texelFetch(u_sum_a, t, 0) * k;
    v.fold = texelFetch(u_sum_f, t, 0) * k;
    voxels[i] = v;
    if (n.w > 0.0)
        atomicOr(occupancy[i >> 5], 1u << uint(i & 31));
}
