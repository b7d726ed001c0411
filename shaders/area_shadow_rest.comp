// area_shadow_rest.comp - after the frame at an area shadow step above 1
// (shading.glsl, LPV_AREA_SHADOW_BLOCKS): the area light of the pixels the
// frame listed because no block around them lies on their surface, through
// every sample's shadow map as at step 1, added to the frame. Dispatched
// indirectly from the list's own counts (pass_camera.c); each listed pixel
// once, as in shade_rest.comp.
layout(local_size_x = LPV_SHADE_REST_WG) in;

layout(binding = LPV_IMG_FRAME, rgba32f) uniform image2D u_frame;

void main()
{
    uint stride = gl_NumWorkGroups.x * uint(LPV_SHADE_REST_WG);
    for (uint i = gl_GlobalInvocationID.x; i < area_rest_head.w; i += stride) {
        ivec2 px = area_rest_px[i];
        vec3 p = texelFetch(u_gbuf_position, px, 0).xyz;
        vec4 nrm = texelFetch(u_gbuf_normal, px, 0);
        vec3 arrives;
        vec3 e = area_light_shadowed(p, nrm.xyz, arrives);
        vec4 c = imageLoad(u_frame, px);
        imageStore(u_frame, px, vec4(c.rgb + diffuse_reflectance(px, nrm.w) * e, c.a));
    }
}
