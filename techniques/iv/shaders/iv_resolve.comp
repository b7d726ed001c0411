// iv_resolve.comp - the atlas's sums into voxels (IvVoxel: the means over
// the points a voxel received) and the occupancy bits the march tests.
layout(local_size_x = LPV_IV_WG) in;

layout(binding = 0) uniform sampler2D u_sum_r;
layout(binding = 1) uniform sampler2D u_sum_g;
layout(binding = 2) uniform sampler2D u_sum_b;
layout(binding = 3) uniform sampler2D u_sum_n;
layout(binding = 4) uniform sampler2D u_sum_a;
layout(binding = 5) uniform sampler2D u_sum_f;
layout(binding = 6) uniform sampler2D u_max_hi;
layout(binding = 7) uniform sampler2D u_max_lo;
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
    // LPV_IV_COVER: the cloud's area over a voxel face's, plain and signed; the extent
    float face = 1.0 / (grid_cell_size() * grid_cell_size());
    vec4 a = texelFetch(u_sum_a, t, 0), f = texelFetch(u_sum_f, t, 0);
    v.albedo = vec4(a.rgb * k, a.w * face);
    v.fold = vec4(f.xyz * k, f.w * face);
    vec3 hi = texelFetch(u_max_hi, t, 0).xyz, lo = 1.0 - texelFetch(u_max_lo, t, 0).xyz, span = hi - lo;
    float widen = n.w >= 2.0 ? (n.w + 1.0) / (n.w - 1.0) : 0.0;
    v.extent = vec4(clamp(span * widen, 0.0, 1.0), 0.0);
    // LPV_IV_SLAB: across the axis the points' folded normals agree on, if they lie thin on it
    vec3 af = abs(v.fold.xyz);
    int axis = af.x >= af.y && af.x >= af.z ? 0 : af.y >= af.z ? 1 : 2;
    v.slab = n.w > 0.0 && af[axis] >= LPV_IV_FLAT && span[axis] <= LPV_IV_SLAB_MAX
                 ? vec4(float(axis), lo[axis], hi[axis], 0.0)
                 : vec4(-1.0, 0.0, 0.0, 0.0);
    voxels[i] = v;
    if (n.w > 0.0)
        atomicOr(occupancy[i >> 5], 1u << uint(i & 31));
}
