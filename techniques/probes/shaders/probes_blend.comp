// probes_blend.comp - a batch's rays into its probes (one invocation a
// probe): the L1 SH of the radiance the rays brought (each ray 4 pi / n sr
// of a uniform set), times cell^2 by travel direction as the lookup reads
// it; the mean and mean square of the hit distance per texel of the
// octahedral map, each ray weighted max(0, cos)^sharpness about the texel's
// direction (the batch's taps: the weights are the same for every probe, so
// the CPU lists each texel's rays that count and their normalised weights)
// and clamped at a few cells; and the share of rays that met a
// back face, which turns the probe off past a threshold, and on a fresh
// volume's first pass moves probes out of geometry and off surfaces
// (relocation; the next passes trace from where they moved to). The light is
// blended into the probe's old value with the hysteresis, lowered in the
// first sweeps after a change where the light changed by much, or by more
// than the batch's noise explains (Majercik et al. 2021: fast where light
// changed, slow where it is noise; lpv_probes_change_test_on); the distances with their own weight (a running
// mean over the warmup's passes, then the hysteresis: only geometry moves
// them, and a new scene starts the probes afresh). probes_update.c is the CPU oracle of the statistics.
layout(local_size_x = LPV_PROBES_WG) in;

layout(std430, binding = LPV_SSBO_PROBES_RAY_OUT) readonly buffer ProbesRayOut { vec4 ray_out[]; };
layout(std430, binding = LPV_SSBO_PROBES_SH) buffer ProbesSH { LpvCell probes_sh[]; };
layout(std430, binding = LPV_SSBO_PROBES_MOMENTS) buffer ProbesMoments { vec2 probes_moments[]; };
layout(std430, binding = LPV_SSBO_PROBES_STATE) buffer ProbesState { vec4 probes_state[]; };
layout(std430, binding = LPV_SSBO_PROBES_RAY_DIRS) readonly buffer ProbesRayDirs { vec4 probes_ray_dirs[]; };
layout(std430, binding = LPV_SSBO_PROBES_TAPS) readonly buffer ProbesTaps { uvec2 probes_taps[]; };
layout(std430, binding = LPV_SSBO_PROBES_IRRADIANCE) buffer ProbesIrradiance { float probes_irradiance[]; };

uniform uint u_rays;
uniform int u_oct;
uniform float u_hysteresis;    // 0: the rays replace the old value
uniform int u_change_test;     // 1: lower it where the light changed (the first sweeps after a change only)
uniform float u_moment_hysteresis; // the same for the distances, which only moving geometry changes
uniform float u_moment_cells;  // the moments clamp distances at this many of the probe's cells
uniform float u_backface_off;  // a probe whose share of back faces exceeds it is off
uniform int u_relocate;        // 1: move the probe (see the end of main)
uniform float u_min_front;     // cells
uniform float u_max_offset;    // cells
uniform float u_max_distance;  // m: a miss's distance

void main()
{
    uint j = gl_GlobalInvocationID.x;
    if (j >= u_batch)
        return;
    uint probe = probes_batch_probe(j);
    int k = int(probe) / grid_cells();
    float cell = cascade_cell(k), mmax = u_moment_cells * cell;
    uint first = j * u_rays;
    vec4 r = vec4(0.0), g = vec4(0.0), b = vec4(0.0);
    vec3 s2 = vec3(0.0); // the rays' radiance squared: the batch's own noise
    uint back = 0u;
    float t_back = 1e30, t_front = 1e30; // the closest back and front faces' distances, and directions
    vec3 d_back = vec3(0.0), d_front = vec3(0.0);
    for (uint i = 0u; i < u_rays; ++i) {
        vec4 o = ray_out[first + i];
        s2 += o.rgb * o.rgb;
        back += o.w < 0.0 ? 1u : 0u;
        if (o.w < 0.0 && -o.w < t_back) {
            t_back = -o.w;
            d_back = probes_ray_dirs[i].xyz;
        } else if (o.w >= 0.0 && o.w < u_max_distance && o.w < t_front) {
            t_front = o.w;
            d_front = probes_ray_dirs[i].xyz;
        }
        vec4 y = sh_basis(-probes_ray_dirs[i].xyz); // travel direction: from the hit to the probe
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
    if (h > 0.0 && u_change_test != 0) {
        // band 0 is w C0 x the sum of the rays' radiance: its change against
        // the old value, relative (over half of it) and in standard errors of
        // this batch's estimate (the rays' sample variance): a change the
        // rays' noise does not explain lowers the hysteresis
        vec3 a = vec3(old.r.x, old.g.x, old.b.x), c = vec3(r.x, g.x, b.x);
        vec3 rel = abs(c - a) / max(max(abs(a), abs(c)), vec3(1e-30));
        float n = float(u_rays), c0 = sh_basis(vec3(0.0, 0.0, 1.0)).x;
        vec3 s1 = c / max(w * c0, 1e-30); // the rays' radiance summed
        vec3 se = w * c0 * sqrt(n * max(s2 - s1 * s1 / n, vec3(0.0)) / max(n - 1.0, 1.0));
        vec3 z = abs(c - a) / max(se, max(max(abs(a), abs(c)) * 1e-3, vec3(1e-30)));
        float changed = max(smoothstep(0.5, 1.0, max(rel.x, max(rel.y, rel.z))),
                            smoothstep(LPV_PROBES_CHANGE_Z0, LPV_PROBES_CHANGE_Z1, max(z.x, max(z.y, z.z))));
        h *= 1.0 - changed;
    }
    probes_sh[probe] = LpvCell(mix(r, old.r, h), mix(g, old.g, h), mix(b, old.b, h));

    int texels = u_oct * u_oct;
    for (int t = 0; t < texels; ++t) {
        uvec2 range = probes_taps[t];
        vec2 m = vec2(0.0), fresh = vec2(mmax, mmax * mmax); // a texel no ray weighs: as far as the clamp
        for (uint k = range.x; k < range.x + range.y; ++k) {
            uvec2 tap = probes_taps[k];
            float d = min(abs(ray_out[first + tap.x].w), mmax);
            m += uintBitsToFloat(tap.y) * vec2(d, d * d);
        }
        if (range.y > 0u)
            fresh = m;
        uint at = probe * uint(texels) + uint(t);
        probes_moments[at] = mix(fresh, probes_moments[at], u_moment_hysteresis);
    }
    // the irradiance map: each texel's rays (cos > 0) weighted pi cos / sum cos
    const int irr = LPV_PROBES_IRR_OCT * LPV_PROBES_IRR_OCT;
    for (int t = 0; t < irr; ++t) {
        uvec2 range = probes_taps[texels + t];
        vec3 e = vec3(0.0);
        for (uint k = range.x; k < range.x + range.y; ++k) {
            uvec2 tap = probes_taps[k];
            e += uintBitsToFloat(tap.y) * ray_out[first + tap.x].rgb;
        }
        uint at = 3u * (probe * uint(irr) + uint(t));
        vec3 v = mix(e, vec3(probes_irradiance[at], probes_irradiance[at + 1u], probes_irradiance[at + 2u]), h);
        probes_irradiance[at] = v.r;
        probes_irradiance[at + 1u] = v.g;
        probes_irradiance[at + 2u] = v.b;
    }
    float share = float(back) / float(u_rays);
    vec3 offset = probes_state[2u * probe + 1u].xyz, moved = offset;
    if (u_relocate != 0) {
        // Relocation (Majercik et al. 2021): out through the closest back
        // face of what the probe is inside, or away from a surface too
        // near; only within its cell, else where it was
        float min_front = u_min_front * cell;
        if (share > u_backface_off)
            moved = offset + d_back * (t_back + 0.5 * min_front);
        else if (t_front < min_front)
            moved = offset - d_front * (min_front - t_front);
        if (any(greaterThan(abs(moved), vec3(u_max_offset * cell))))
            moved = offset;
    }
    probes_state[2u * probe] = vec4(share, share > u_backface_off ? 0.0 : 1.0, moved != offset ? 1.0 : 0.0, 0.0);
    probes_state[2u * probe + 1u] = vec4(moved, 0.0);
}
