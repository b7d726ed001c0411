// lookup_blocks.comp - the technique's irradiance once per block of
// lookup_step x lookup_step pixels (shading.glsl, "The lookup step"; run by
// pass_camera.c before the frame when the step is above 1). A block's first
// covered pixel in raster order fixes its plane; the irradiance is looked up
// at the mean point and normal of the block's pixels on that plane (its
// centre when the block is all one surface, where the frame's bilinear
// weights put it), and stored with the plane for the frame's upsampling.
layout(local_size_x = LPV_WG_2D, local_size_y = LPV_WG_2D) in;

layout(binding = LPV_IMG_BLOCK_IRRADIANCE, rgba32f) writeonly uniform image2D u_block_irradiance_out;
layout(binding = LPV_IMG_BLOCK_PLANE, rgba32f) writeonly uniform image2D u_block_plane_out;

void main()
{
    ivec2 b = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(b, imageSize(u_block_irradiance_out))))
        return;
    int step = u_lookup_step, count = step * step;
    ivec2 first = b * step, size = textureSize(u_gbuf_normal, 0);
    // one pass in raster order: the first covered pixel fixes the plane, and
    // it and every later pixel on that plane join the mean
    vec4 plane = vec4(0.0);
    bool seen = false;
    vec3 p_sum = vec3(0.0), n_sum = vec3(0.0);
    float on = 0.0;
    for (int k = 0; k < count; ++k) {
        ivec2 px = first + ivec2(k % step, k / step);
        ivec2 at = min(px, size - 1);
        vec4 nrm = texelFetch(u_gbuf_normal, at, 0);
        vec3 p = texelFetch(u_gbuf_position, at, 0).xyz;
        vec3 nk = unit_or_zero(nrm.xyz);
        bool covered = nrm.w >= 0.5 && all(lessThan(px, size));
        if (covered && !seen) {
            plane = vec4(nk, dot(nk, p));
            seen = true;
        }
        bool same = covered && dot(nk, plane.xyz) >= LPV_BLOCK_NORMAL_COS && plane_offset(plane, p) < 1.0;
        p_sum += same ? p : vec3(0.0);
        n_sum += same ? nrm.xyz : vec3(0.0);
        on += same ? 1.0 : 0.0;
    }
    vec3 e = seen ? lpv_irradiance(p_sum / max(on, 1.0), n_sum) : vec3(0.0);
    imageStore(u_block_irradiance_out, b, vec4(e, seen ? 1.0 : 0.0));
    imageStore(u_block_plane_out, b, plane);
}
