// camera_surfels.comp - the G-buffer's pixels as blocking surfels, down-sampled
// (seed 000: the camera's buffers are down-sampled before surfel injection;
// the geometry volume resolves a cell, not a pixel). Each block of u_step x
// u_step pixels (settings.camera_surfel_step) gives up to u_slots surfels,
// one per set of geometry-volume points its blocking pixels snap to
// (block_groups.glsl): the group's total area at its area-weighted
// centroid, with its area-weighted mean normal (normalised) and albedo, so
// every GV point receives the blocking its pixels gave it one by one,
// exactly on a plane. u_step = 1 is one surfel per pixel. Surfel i of block
// b is surfels[b * u_slots + i]; unused slots have area 0.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform sampler2D u_gbuf_position;
layout(binding = 1) uniform sampler2D u_gbuf_normal;
layout(binding = 2) uniform sampler2D u_gbuf_albedo;
layout(binding = 3) uniform sampler2D u_gbuf_emission; // a: object size
layout(std430, binding = LPV_SSBO_SURFELS) writeonly buffer Surfels { LpvSurfel surfels[]; };

uniform ivec2 u_size;     // G-buffer pixels
uniform int u_step;       // pixels per block along each axis
uniform ivec2 u_out_size; // blocks: ceil(u_size / u_step)
uniform int u_slots;      // surfels per block: min(LPV_BLOCK_SLOTS, u_step^2)

void block_emit(int i, float area, vec3 pos_mean, vec3 nrm_mean, vec3 albedo_sum, float size)
{
    surfels[i] = group_surfel(area, pos_mean, nrm_mean, albedo_sum, size);
}

void main()
{
    ivec2 s = ivec2(gl_GlobalInvocationID.xy);
    if (s.x >= u_out_size.x || s.y >= u_out_size.y)
        return;
    ivec2 lo = s * u_step, hi = min(lo + u_step, u_size);
    BG_DECL_ALL
    for (int py = lo.y; py < hi.y; ++py)
        for (int px = lo.x; px < hi.x; ++px) {
            ivec2 t = ivec2(px, py);
            vec4 nt = texelFetch(u_gbuf_normal, t, 0);
            vec4 em = texelFetch(u_gbuf_emission, t, 0);
            vec4 p = texelFetch(u_gbuf_position, t, 0);
            // emitters are light sources only: they do not block in the GV
            // (the planner counts only non-emissive triangles as occluders)
            if (!(nt.w > 0.5) || (any(greaterThan(em.rgb, vec3(0.0))) && !lpv_gbuffer_unlit(nt.w)) || !(p.w > 0.0) ||
                isinf(p.w) ||
                !finite3(p.xyz) || !finite3(nt.xyz))
                continue;
            vec3 x = p.xyz, n = nt.xyz;
            float w = p.w, tag = em.a; // tag: object size
            vec3 val = p.w * texelFetch(u_gbuf_albedo, t, 0).rgb * lpv_gbuffer_kd(nt.w); // diffuse
            uvec4 g = group_key(x, n, true, normal_bin(n)); // the bin: opposite faces never cancel
            BG_STEP
        }
    int base = (s.x + u_out_size.x * s.y) * u_slots;
    BG_EMIT_ALL
}
