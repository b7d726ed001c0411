// iv_reproject.comp - the camera's visible pixels for the imperfect volume
// (paper 3.2), one invocation per block of LPV_IV_REPROJECT_BLOCK^2 sampled
// pixels (every u_stride-th in x and y). Each pixel is lit (iv_direct.glsl)
// and summed, as iv_points.comp sums the cloud's points, into its block's
// slot for the voxel that holds it: the SH of B / pi over its normal's
// hemisphere (B = albedo x E_direct + pi x emission), its normal and a count
// of 1, its albedo, its folded normal (LPV_IV_FOLD), and its place in the
// voxel (the greatest and 1 - the least). A pixel carries no area
// (LPV_IV_COVER: only the cloud's points stand for one). iv_splat.vert then
// blends one point per used slot into the atlas. Neighbouring pixels mostly
// share a voxel, so the draw blends a few points per block instead of one
// per pixel, and the lighting runs here on every core (llvmpipe runs a
// draw's vertex stage, and blends into a small atlas, on one thread).
// The pixels are taken in a fixed order, so the sums are the same each tick.
layout(local_size_x = LPV_IV_WG) in;

layout(binding = 0) uniform sampler2D u_gbuf_position;
layout(binding = 1) uniform sampler2D u_gbuf_normal;
layout(binding = 2) uniform sampler2D u_gbuf_albedo;
layout(binding = 3) uniform sampler2D u_gbuf_emission;
layout(std430, binding = LPV_SSBO_IV_SPLATS) buffer Splats { IvSplat splats[]; };

uniform ivec2 u_gbuf_size;
uniform int u_stride;      // every u_stride-th pixel in x and y
uniform ivec2 u_blocks;    // blocks across and down
uniform float u_emission;  // 1: emission counts (area lights off); 0: the area lights carry the emitters

#define BLOCK LPV_IV_REPROJECT_BLOCK

void main()
{
    int blk = int(gl_GlobalInvocationID.x);
    if (blk >= u_blocks.x * u_blocks.y)
        return;
    ivec2 origin = ivec2(blk % u_blocks.x, blk / u_blocks.x) * BLOCK;
    ivec2 samples = (u_gbuf_size + u_stride - 1) / u_stride;
    int base = blk * BLOCK * BLOCK, used = 0;
    int ids[BLOCK * BLOCK];
    for (int j = 0; j < BLOCK; ++j) {
        for (int i = 0; i < BLOCK; ++i) {
            ivec2 s = origin + ivec2(i, j);
            if (s.x >= samples.x || s.y >= samples.y)
                continue;
            ivec2 t = s * u_stride;
            vec4 gn = texelFetch(u_gbuf_normal, t, 0);
            if (gn.w < 0.5 || lpv_gbuffer_wire(gn.w))
                continue; // background, or a point's or line's pixel (no surface)
            vec3 p = texelFetch(u_gbuf_position, t, 0).xyz, n = gn.xyz;
            vec3 albedo = texelFetch(u_gbuf_albedo, t, 0).rgb * lpv_gbuffer_kd(gn.w); // diffuse
            // an unlit pixel's emission target is what the camera sees, not light
            vec3 emission = lpv_gbuffer_unlit(gn.w) ? vec3(0.0) : texelFetch(u_gbuf_emission, t, 0).rgb;
            float len = length(n);
            if (!finite3(p) || !(len > 1e-8) || isinf(len) || !finite3(albedo) || !finite3(emission))
                continue;
            n /= len;
            vec3 u = iv_coords_of(p, n);
            ivec3 c = ivec3(floor(u));
            if (!cell_inside(c))
                continue;
            vec3 radiosity = albedo * iv_direct_irradiance(p, n) + LPV_PI * u_emission * emission;
            if (!finite3(radiosity))
                continue;
            int id = cell_index(c), k = 0;
            while (k < used && ids[k] != id)
                ++k;
            IvSplat sum;
            if (k == used) { // the block's first pixel in this voxel
                ids[used++] = id;
                sum.r = sum.g = sum.b = sum.n = sum.a = sum.f = sum.hi = sum.lo = vec4(0.0);
                sum.texel = vec4(vec2(atlas_texel(c, grid_dims().xy)), 0.0, 1.0);
            } else {
                sum = splats[base + k];
            }
            iv_sum_point(sum, n, albedo, radiosity, 0.0, clamp(u - vec3(c), 0.0, 1.0));
            splats[base + k] = sum;
        }
    }
    for (int k = used; k < BLOCK * BLOCK; ++k)
        splats[base + k].texel = vec4(0.0);
}
