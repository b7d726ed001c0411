// shade_rest.comp - the second pass of the frame (shading.glsl,
// LPV_LOOKUP_SPLIT): the indirect light of the pixels shade.comp listed,
// whose normal is none of the technique's cheap ones, looked up in full and
// added to the frame. Dispatched indirectly from the list's own counts
// (pass_camera.c); each listed pixel once (an invocation takes every
// (groups x LPV_SHADE_REST_WG)-th pixel when the list outgrows
// LPV_SHADE_REST_MAX_GROUPS), so the order does not matter.
layout(local_size_x = LPV_SHADE_REST_WG) in;

layout(binding = LPV_IMG_FRAME, rgba32f) uniform image2D u_frame;

void main()
{
    uint stride = gl_NumWorkGroups.x * uint(LPV_SHADE_REST_WG);
    for (uint i = gl_GlobalInvocationID.x; i < rest_head.w; i += stride) {
        ivec2 px = rest_px[i];
        vec4 pos = texelFetch(u_gbuf_position, px, 0);
        vec4 nrm = texelFetch(u_gbuf_normal, px, 0);
        vec3 e = V.shading.x * lpv_reach(pos.xyz, nrm.xyz) * lpv_irradiance(pos.xyz, nrm.xyz);
        vec4 c = imageLoad(u_frame, px);
        imageStore(u_frame, px, vec4(c.rgb + diffuse_reflectance(px, nrm.w) * ambient_occlusion(px) * e, c.a));
    }
}
