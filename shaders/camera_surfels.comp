// camera_surfels.comp - the G-buffer's pixels as blocking surfels, down-sampled
// (seed 000: the camera's buffers are down-sampled before surfel injection;
// the geometry volume resolves a cell, not a pixel). Each block of u_step x
// u_step pixels (settings.camera_surfel_step) gives up to LPV_CAMERA_SLOTS
// surfels, one per set of geometry-volume points (one in each cascade) its
// blocking pixels snap to (the points inject_gv.vert splats them to): each
// carries the total area of its pixels at their area-weighted centroid, with
// their area-weighted mean normal (normalised) and albedo. The centroid
// snaps to the same points, so every GV point receives the per-pixel sum of
// blocking wherever its pixels lie on one plane. A block touching more point
// sets than it has slots (a depth discontinuity) adds the rest to the slot
// of the nearest point in the finest cascade, so no area is lost. u_step = 1 is one surfel per pixel, as before the
// down-sampling. Surfel i of block b is surfels[b * u_slots + i]; unused
// slots have area 0.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform sampler2D u_gbuf_position;
layout(binding = 1) uniform sampler2D u_gbuf_normal;
layout(binding = 2) uniform sampler2D u_gbuf_albedo;
layout(binding = 3) uniform sampler2D u_gbuf_emission; // a: object size
layout(std430, binding = LPV_SSBO_SURFELS) writeonly buffer Surfels { LpvSurfel surfels[]; };

uniform ivec2 u_size;     // G-buffer pixels
uniform int u_step;       // pixels per block along each axis
uniform ivec2 u_out_size; // blocks: ceil(u_size / u_step)
uniform int u_slots;      // surfels per block: min(LPV_CAMERA_SLOTS, u_step^2)
uniform vec4 u_gv_grid[LPV_MAX_CASCADES]; // each cascade: origin (m), cell (m)
uniform int u_gv_levels;  // cascades; 0 = no grid (one slot)

bool finite_vec(vec3 v) { return !any(isnan(v)) && !any(isinf(v)); }

void main()
{
    ivec2 s = ivec2(gl_GlobalInvocationID.xy);
    if (s.x >= u_out_size.x || s.y >= u_out_size.y)
        return;
    ivec2 lo = s * u_step, hi = min(lo + u_step, u_size);
    ivec3 key[LPV_CAMERA_SLOTS * LPV_MAX_CASCADES]; // slot k, cascade c: key[k * LPV_MAX_CASCADES + c]
    float area[LPV_CAMERA_SLOTS];
    vec3 pos[LPV_CAMERA_SLOTS], nrm[LPV_CAMERA_SLOTS], alb[LPV_CAMERA_SLOTS];
    float size[LPV_CAMERA_SLOTS];
    for (int k = 0; k < LPV_CAMERA_SLOTS * LPV_MAX_CASCADES; ++k)
        key[k] = ivec3(0);
    for (int k = 0; k < LPV_CAMERA_SLOTS; ++k) {
        area[k] = 0.0;
        pos[k] = nrm[k] = alb[k] = vec3(0.0);
        size[k] = 0.0;
    }
    int used = 0;
    ivec2 first = lo; // where an empty block's surfel stands (area 0)
    for (int y = lo.y; y < hi.y; ++y)
        for (int x = lo.x; x < hi.x; ++x) {
            ivec2 t = ivec2(x, y);
            vec4 n = texelFetch(u_gbuf_normal, t, 0);
            vec4 em = texelFetch(u_gbuf_emission, t, 0);
            // emitters are light sources only: they do not block in the GV
            // (the planner counts only non-emissive triangles as occluders)
            if (!(n.w > 0.5) || any(greaterThan(em.rgb, vec3(0.0))))
                continue;
            vec4 p = texelFetch(u_gbuf_position, t, 0);
            if (!(p.w > 0.0) || isinf(p.w) || !finite_vec(p.xyz) || !finite_vec(n.xyz))
                continue;
            ivec3 g[LPV_MAX_CASCADES];
            for (int c = 0; c < LPV_MAX_CASCADES; ++c)
                g[c] = c < u_gv_levels ? ivec3(floor((p.xyz - u_gv_grid[c].xyz) / u_gv_grid[c].w + 0.5)) : ivec3(0);
            int slot = -1;
            for (int k = 0; k < used && slot < 0; ++k) {
                bool same = true;
                for (int c = 0; c < LPV_MAX_CASCADES; ++c)
                    same = same && key[k * LPV_MAX_CASCADES + c] == g[c];
                if (same)
                    slot = k;
            }
            if (slot < 0 && used < u_slots) {
                slot = used++;
                for (int c = 0; c < LPV_MAX_CASCADES; ++c)
                    key[slot * LPV_MAX_CASCADES + c] = g[c];
                size[slot] = em.a;
            }
            if (slot < 0) { // more point sets than slots: the nearest finest point's slot
                int best = 1 << 30;
                for (int k = 0; k < used; ++k) {
                    ivec3 d = abs(key[k * LPV_MAX_CASCADES] - g[0]);
                    int dist = d.x + d.y + d.z;
                    if (dist < best) {
                        best = dist;
                        slot = k;
                    }
                }
            }
            area[slot] += p.w;
            pos[slot] += p.w * p.xyz;
            nrm[slot] += p.w * n.xyz;
            alb[slot] += p.w * texelFetch(u_gbuf_albedo, t, 0).rgb;
        }
    int base = (s.x + u_out_size.x * s.y) * u_slots;
    for (int k = 0; k < u_slots; ++k) {
        float a = area[k];
        float len = length(nrm[k]);
        bool ok = a > 0.0 && !isinf(a) && len > 0.0;
        vec3 p = ok ? pos[k] / a : texelFetch(u_gbuf_position, first, 0).xyz;
        surfels[base + k].position = vec4(p, ok ? a : 0.0);
        surfels[base + k].normal = vec4(ok ? nrm[k] / len : vec3(0.0, 0.0, 1.0), size[k]);
        surfels[base + k].albedo = vec4(ok ? alb[k] / a : vec3(0.0), 0.0);
    }
}
