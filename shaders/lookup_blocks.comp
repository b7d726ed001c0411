// lookup_blocks.comp - the technique's irradiance once per block of
// lookup_step x lookup_step pixels (shading.glsl, "The lookup step"; run by
// frame_blocks.c before the frame when the step is above 1). The irradiance
// is looked up at the mean point and normal of the block's pixels on its
// plane (shading.glsl, block_surface: its centre when the block is all one
// surface, where the frame's bilinear weights put it), and stored with the
// plane for the frame's upsampling (blocks_upsampled).
layout(local_size_x = LPV_WG_2D, local_size_y = LPV_WG_2D) in;

layout(binding = LPV_IMG_BLOCK_IRRADIANCE, rgba32f) writeonly uniform image2D u_block_irradiance_out;
layout(binding = LPV_IMG_BLOCK_PLANE, rgba32f) writeonly uniform image2D u_block_plane_out;

void main()
{
    ivec2 b = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(b, imageSize(u_block_irradiance_out))))
        return;
    vec4 plane;
    vec3 p, n_sum;
    bool seen = block_surface(b, u_lookup_step, plane, p, n_sum);
    vec3 e = seen ? lpv_reach(p, normalize(n_sum)) * lpv_irradiance(p, n_sum) : vec3(0.0);
    imageStore(u_block_irradiance_out, b, vec4(e, seen ? 1.0 : 0.0));
    imageStore(u_block_plane_out, b, plane);
}
