// translucent.comp - the translucent layer laid over the frame
// (gpu/pass_camera.c, lpv_pass_translucent_run; docs/scenes.md, "Alpha"):
// where the nearest BLEND surface in front of the G-buffer's covers alpha a
// of the pixel, the frame becomes a x that surface's shading + (1 - a) x
// what lies behind it (glTF's alpha as coverage, the "over" operator; the
// reference path tracer's rays pass it with probability 1 - a). The pixel's
// alpha: a + (1 - a) x the frame's (its background stays 0 where nothing is).
layout(local_size_x = LPV_WG_2D, local_size_y = LPV_WG_2D) in;

layout(binding = LPV_IMG_FRAME, rgba32f) uniform image2D u_frame;
layout(binding = 0) uniform sampler2D u_layer_frame;    // the layer's pixels shaded (shading.glsl)
layout(binding = 1) uniform sampler2D u_layer_coverage; // the layer's alpha, 0 = no translucent surface
uniform ivec2 u_first; // the dispatch's first pixel (the layer's rectangle, pass_camera.c)

void main()
{
    ivec2 px = u_first + ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(u_frame))))
        return;
    float a = texelFetch(u_layer_coverage, px, 0).r;
    if (!(a > 0.0))
        return;
    vec4 behind = imageLoad(u_frame, px);
    vec4 layer = texelFetch(u_layer_frame, px, 0);
    imageStore(u_frame, px, vec4(mix(behind.rgb, layer.rgb, a), a + (1.0 - a) * behind.a));
}
