// probes_rays.comp - a batch of rays through the probes' BVH
// (probes_trace.glsl): per ray its closest hit. The GPU traversal's check
// against the CPU's (test_probes_trace_gpu.c); the probes' update pass will
// trace its rays with the same function.
layout(local_size_x = LPV_PROBES_WG) in;

layout(std430, binding = LPV_SSBO_PROBES_RAYS) readonly buffer Rays { vec4 rays[]; };  // origin (w: tmax), direction
layout(std430, binding = LPV_SSBO_PROBES_HITS) writeonly buffer Hits { uvec4 hits[]; }; // t bits, id, hit, 0
uniform uint u_ray_count;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_ray_count)
        return;
    vec4 o = rays[2u * i], d = rays[2u * i + 1u];
    float t;
    uint tri;
    bool hit = probes_closest_hit(o.xyz, d.xyz, o.w, t, tri);
    hits[i] = uvec4(floatBitsToUint(hit ? t : 0.0), hit ? tri : 0u, hit ? 1u : 0u, 0u);
}
