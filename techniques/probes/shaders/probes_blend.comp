// probes_blend.comp - a batch's rays into its probes (one invocation a
// probe): the L1 SH of the radiance the rays brought (each ray 4 pi / n sr
// of a uniform set), times cell^2 by travel direction as the lookup reads
// it; the mean and mean square of the hit distance per texel of the
// octahedral map, each ray weighted max(0, cos)^sharpness about the texel's
// direction and clamped at a few cells; and the share of rays that met a
// back face, which turns the probe off past a threshold. The light is
// blended into the probe's old value with the hysteresis, lowered where the
// light changed by much (Majercik et al. 2021: fast where light changed,
// slow where it is noise); the distances with their own weight (a running
// mean over the warmup's passes, then the hysteresis: only geometry moves
// them, and a new scene starts the probes afresh). probes_update.c is the CPU oracle of the statistics.
layout(local_size_x = LPV_PROBES_WG) in;

layout(std430, binding = LPV_SSBO_PROBES_RAY_OUT) readonly buffer ProbesRayOut { vec4 ray_out[]; };
layout(std430, binding = LPV_SSBO_PROBES_SH) buffer ProbesSH { LpvCell probes_sh[]; };
layout(std430, binding = LPV_SSBO_PROBES_MOMENTS) buffer ProbesMoments { vec2 probes_moments[]; };
layout(std430, binding = LPV_SSBO_PROBES_STATE) buffer ProbesState { vec4 probes_state[]; };

uniform uint u_first, u_batch, u_total, u_rays;
uniform int u_oct;
uniform float u_hysteresis;    // 0: the rays replace the old value
uniform float u_moment_hysteresis; // the same for the distances, which only moving geometry changes
uniform float u_sharpness;
uniform float u_moment_cells;  // the moments clamp distances at this many of the probe's cells
uniform float u_backface_off;  // a probe whose share of back faces exceeds it is off

vec3 probes_texel_dir(int x, int y, int s)
{
    vec2 uv = (vec2(x, y) + 0.5) / float(s) * 2.0 - 1.0;
    vec3 d = vec3(uv, 1.0 - abs(uv.x) - abs(uv.y));
    if (d.z < 0.0)
        d.xy = (1.0 - abs(d.yx)) * vec2(d.x >= 0.0 ? 1.0 : -1.0, d.y >= 0.0 ? 1.0 : -1.0);
    return normalize(d);
}

void main()
{
    uint j = gl_GlobalInvocationID.x;
    if (j >= u_batch)
        return;
    uint probe = (u_first + j) % u_total;
    int k = int(probe) / grid_cells();
    float cell = cascade_cell(k), mmax = u_moment_cells * cell;
    uint first = j * u_rays;
    vec4 r = vec4(0.0), g = vec4(0.0), b = vec4(0.0);
    uint back = 0u;
    for (uint i = 0u; i < u_rays; ++i) {
        vec4 o = ray_out[first + i];
        back += o.w < 0.0 ? 1u : 0u;
        vec4 y = sh_basis(-probes_ray_dir(i, u_rays)); // travel direction: from the hit to the probe
        r += o.r * y;
        g += o.g * y;
        b += o.b * y;
    }
    float w = 4.0 * LPV_PI / float(u_rays) * cell * cell;
    r *= w;
    g *= w;
    b *= w;
    LpvCell old = probes_sh[probe];
    float h = u_hysteresis;
    if (h > 0.0) {
        // band 0 is the mean radiance: its relative change, over the channels
        vec3 a = vec3(old.r.x, old.g.x, old.b.x), c = vec3(r.x, g.x, b.x);
        vec3 rel = abs(c - a) / max(max(abs(a), abs(c)), vec3(1e-30));
        h *= 1.0 - smoothstep(0.25, 0.75, max(rel.x, max(rel.y, rel.z)));
    }
    probes_sh[probe] = LpvCell(mix(r, old.r, h), mix(g, old.g, h), mix(b, old.b, h));

    int s = u_oct;
    for (int ty = 0; ty < s; ++ty)
        for (int tx = 0; tx < s; ++tx) {
            vec3 td = probes_texel_dir(tx, ty, s);
            vec3 m = vec3(0.0); // weighted t, t^2, weight
            for (uint i = 0u; i < u_rays; ++i) {
                float c = dot(td, probes_ray_dir(i, u_rays));
                if (c <= 0.0)
                    continue;
                float wt = pow(c, u_sharpness), t = min(abs(ray_out[first + i].w), mmax);
                m += wt * vec3(t, t * t, 1.0);
            }
            vec2 fresh = m.z > 0.0 ? m.xy / m.z : vec2(mmax, mmax * mmax);
            uint at = probe * uint(s * s) + uint(ty * s + tx);
            probes_moments[at] = mix(fresh, probes_moments[at], u_moment_hysteresis);
        }
    float share = float(back) / float(u_rays);
    probes_state[probe] = vec4(share, share > u_backface_off ? 0.0 : 1.0, 0.0, 0.0);
}
