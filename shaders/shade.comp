// shade.comp - the final frame (shading.glsl), one invocation per pixel,
// written into the frame texture.
layout(local_size_x = LPV_WG_2D, local_size_y = LPV_WG_2D) in;

layout(binding = LPV_IMG_FRAME, rgba32f) writeonly uniform image2D u_frame;
uniform int u_row_first; // this dispatch's first row (the frame goes in bands)
uniform int u_col_first; // its first column (the translucent layer shades only where its surfaces can be)

void main()
{
    ivec2 px = ivec2(u_col_first + int(gl_GlobalInvocationID.x), u_row_first + int(gl_GlobalInvocationID.y));
    if (any(greaterThanEqual(px, imageSize(u_frame))))
        return;
    imageStore(u_frame, px, shade_pixel(px));
}
