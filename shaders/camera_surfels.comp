// camera_surfels.comp - the G-buffer's pixels as blocking surfels.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform sampler2D u_gbuf_position;
layout(binding = 1) uniform sampler2D u_gbuf_normal;
layout(binding = 2) uniform sampler2D u_gbuf_albedo;
layout(binding = 3) uniform sampler2D u_gbuf_emission; // a: object size
layout(std430, binding = LPV_SSBO_SURFELS) writeonly buffer Surfels { LpvSurfel surfels[]; };

uniform ivec2 u_size;

void main()
{
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (t.x >= u_size.x || t.y >= u_size.y)
        return;
    vec4 p = texelFetch(u_gbuf_position, t, 0);
    vec4 n = texelFetch(u_gbuf_normal, t, 0);
    int i = t.x + u_size.x * t.y;
    // emitters are light sources only: they do not block in the GV (the
    // planner counts only non-emissive triangles as occluders)
    bool emitter = any(greaterThan(texelFetch(u_gbuf_emission, t, 0).rgb, vec3(0.0)));
    surfels[i].position = vec4(p.xyz, n.w > 0.5 && !emitter ? p.w : 0.0);
    surfels[i].normal = vec4(n.xyz, texelFetch(u_gbuf_emission, t, 0).a);
    surfels[i].albedo = vec4(texelFetch(u_gbuf_albedo, t, 0).rgb, 0.0);
}
