// area_shadow_blocks.comp - the area light samples' visibility once per
// block of area_shadow_step x area_shadow_step pixels (shading.glsl,
// area_visibility; run by frame_blocks.c before a frame that has area light
// samples when the step is above 1): the shadowed over the unshadowed
// irradiance of the samples at the mean point and normal of the block's
// pixels on its plane (block_surface), stored with the plane for the frame's
// upsampling (blocks_upsampled). Soft shadows vary over many pixels, while
// each sample's shadow map costs the frame its filter taps at every pixel.
layout(local_size_x = LPV_WG_2D, local_size_y = LPV_WG_2D) in;

layout(binding = LPV_IMG_AREA_SHADOW, rgba32f) writeonly uniform image2D u_area_shadow_out;
layout(binding = LPV_IMG_AREA_SHADOW_PLANE, rgba32f) writeonly uniform image2D u_area_shadow_plane_out;

void main()
{
    ivec2 b = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(b, imageSize(u_area_shadow_out))))
        return;
    vec4 plane;
    vec3 p, n_sum;
    bool seen = block_surface(b, u_area_shadow_step, plane, p, n_sum);
    vec3 v = seen ? area_visibility(p, unit_or_zero(n_sum)) : vec3(1.0);
    imageStore(u_area_shadow_out, b, vec4(v, seen ? 1.0 : 0.0));
    imageStore(u_area_shadow_plane_out, b, plane);
}
