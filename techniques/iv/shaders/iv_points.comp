// iv_points.comp - the point cloud into the atlas, one invocation per voxel
// (paper 3.1): iv_cloud.c sorted the cloud by the voxel each point falls in
// (iv_volume.glsl's iv_cell_of, counted on the CPU), so a voxel loops over
// its own points, lights each (iv_direct.glsl), and stores their sums
// (iv_sums.glsl: the SH of B / pi over the normal's hemisphere, normal +
// count, albedo + area, folded normal + signed area, and the greatest place
// in the voxel and 1 - the least, LPV_IV_COVER). Every voxel's texel is written, so the atlas needs no
// clear; the camera's points (iv_reproject) are then blended on top. A
// gather instead of a scatter: no rasterised points, and the voxels run in
// parallel (llvmpipe runs a draw's vertex stage on one thread).
layout(local_size_x = LPV_IV_WG) in;

layout(std430, binding = LPV_SSBO_IV_POINTS) readonly buffer Points { IvPoint points[]; };
layout(std430, binding = LPV_SSBO_IV_POINT_STARTS) readonly buffer Starts { uint starts[]; }; // cells + 1
layout(rgba32f, binding = 0) uniform writeonly image2D u_sum_r;
layout(rgba32f, binding = 1) uniform writeonly image2D u_sum_g;
layout(rgba32f, binding = 2) uniform writeonly image2D u_sum_b;
layout(rgba32f, binding = 3) uniform writeonly image2D u_sum_n;
layout(rgba32f, binding = 4) uniform writeonly image2D u_sum_a;
layout(rgba32f, binding = 5) uniform writeonly image2D u_sum_f;
layout(rgba32f, binding = 6) uniform writeonly image2D u_max_hi;
layout(rgba32f, binding = 7) uniform writeonly image2D u_max_lo;

uniform float u_emission; // 1: emission counts (area lights off); 0: the area lights carry the emitters
uniform int u_cell_first;  // this dispatch's voxels: [u_cell_first, u_cell_end)
uniform int u_cell_end;

void main()
{
    int i = u_cell_first + int(gl_GlobalInvocationID.x);
    if (i >= u_cell_end || i >= grid_cells())
        return;
    ivec3 d = grid_dims();
    ivec3 c = ivec3(i % d.x, (i / d.x) % d.y, i / (d.x * d.y));
    IvSplat sum;
    sum.r = sum.g = sum.b = sum.n = sum.a = sum.f = sum.hi = sum.lo = sum.texel = vec4(0.0);
    for (uint k = starts[i]; k < starts[i + 1]; ++k) {
        IvPoint q = points[k];
        vec3 p = q.position.xyz, n = q.normal.xyz, albedo = q.albedo.rgb, emission = q.emission.rgb;
        float area = q.normal.w, len = length(n);
        if (q.position.w == 0.0 || !finite3(p) || !(len > 1e-8) || isinf(len) || !finite3(albedo) ||
            !finite3(emission))
            continue;
        n /= len;
        vec3 radiosity = albedo * iv_direct_irradiance(p, n) + LPV_PI * u_emission * emission;
        if (!finite3(radiosity))
            continue;
        if (!(area >= 0.0) || isinf(area))
            area = 0.0;
        // the place in the voxel the CPU counted it in (a point on a face may
        // round to the neighbour there: it is clamped to this voxel's face)
        iv_sum_point(sum, n, albedo, radiosity, area, clamp(iv_coords_of(p, n) - vec3(c), 0.0, 1.0));
    }
    ivec2 t = atlas_texel(c, d.xy);
    imageStore(u_sum_r, t, sum.r);
    imageStore(u_sum_g, t, sum.g);
    imageStore(u_sum_b, t, sum.b);
    imageStore(u_sum_n, t, sum.n);
    imageStore(u_sum_a, t, sum.a);
    imageStore(u_sum_f, t, sum.f);
    imageStore(u_max_hi, t, sum.hi);
    imageStore(u_max_lo, t, sum.lo);
}
