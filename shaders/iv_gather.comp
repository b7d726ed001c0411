// iv_gather.comp - radiance caching (paper 3.3): every voxel that a lookup
// can read (one with an occupied voxel among its 27) marches u_rays
// stratified rays (lpv_iv_ray) through the occupancy, starting
// LPV_IV_START voxels out (occupied voxels; empty ones at their centre) and
// visiting every voxel the ray crosses, until an occupied voxel or the
// volume's edge. A hit sees what that voxel emits towards the ray's
// origin; a ray that leaves the volume sees nothing (lpvd has no environment
// light: the path-traced reference sees black there too). The Monte-Carlo
// projection 4 pi / N sum L Y stores the arriving radiance as SH of the
// direction it travels. With u_ao 1 the march returns visibility instead
// (1 past u_ao_reach metres or out of the volume, 0 at a hit; paper 3.5).
layout(local_size_x = LPV_IV_WG) in;

layout(std430, binding = LPV_SSBO_IV_OCCUPANCY) readonly buffer Occupancy { uint occupancy[]; };
layout(std430, binding = LPV_SSBO_IV_EMIT) readonly buffer Emit { LpvCell emit[]; };
layout(std430, binding = LPV_SSBO_LPV_OUT) writeonly buffer Out { LpvCell gathered[]; };
layout(std430, binding = LPV_SSBO_IV_AO) writeonly buffer Ao { vec4 ao[]; };

uniform int u_rays;
uniform uint u_seed;
uniform int u_ao;
uniform float u_ao_reach; // voxels

bool occupied(ivec3 c) { int i = cell_index(c); return (occupancy[i >> 5] & (1u << uint(i & 31))) != 0u; }

// The radiance one channel of a voxel's emission e sends along unit t
// (core/oracle_iv.c, emitted): e is the SH of the Lambertian hemispheres of
// the voxel's surfaces, so it is read back as the two hemispheres it is the
// projection of, B_f / pi along its dipole d and B_b / pi against it
// (B_f + B_b = e0 / HEMI0, (B_f - B_b) d = e1 / HEMI1), not as the 2-band
// SH's own value: that one is 1.25 B / pi along the normal, 0.5 B / pi at
// grazing and below 0 behind, and the gathered light of a floor, peaked
// straight up, then read at the floor itself as -B / 16 per channel.
float emitted(vec4 e, vec3 t)
{
    float sum = e.x / LPV_IV_HEMI0;
    vec3 v = vec3(e.w, e.y, e.z) / LPV_IV_HEMI1;
    float diff = min(length(v), sum);
    return max(dot(v, t) > 0.0 ? sum + diff : sum - diff, 0.0) * (0.5 / LPV_PI);
}

bool needed(ivec3 c)
{
    for (int z = -1; z <= 1; ++z)
        for (int y = -1; y <= 1; ++y)
            for (int x = -1; x <= 1; ++x) {
                ivec3 q = c + ivec3(x, y, z);
                if (cell_inside(q) && occupied(q))
                    return true;
            }
    return false;
}

void main()
{
    int i = int(gl_GlobalInvocationID.x);
    if (i >= grid_cells())
        return;
    ivec3 d = grid_dims();
    ivec3 c = ivec3(i % d.x, (i / d.x) % d.y, i / (d.x * d.y));
    const float sphere = 4.0 * LPV_PI;
    if (!needed(c)) {
        if (u_ao != 0)
            ao[i] = vec4(sphere * LPV_SH_C0, 0.0, 0.0, 0.0); // open: visibility 1 everywhere
        else
            gathered[i] = LpvCell(vec4(0.0), vec4(0.0), vec4(0.0));
        return;
    }
    vec3 centre = vec3(c) + 0.5; // in voxels
    // The paper starts every ray sqrt(3)/2 voxels out so that it leaves the
    // surface in its own voxel. An empty voxel has none: skipping would let
    // its rays start beyond a surface passing close by and see through it,
    // more so the closer its centre lies to the surface (bands along tilted
    // walls); its rays start at the centre.
    const float start = occupied(c) ? LPV_IV_START : 0.0;
    vec4 r = vec4(0.0), g = vec4(0.0), b = vec4(0.0), vis = vec4(0.0);
    int max_steps = d.x + d.y + d.z + 3;
    for (int j = 0; j < u_rays; ++j) {
        vec3 w;
        lpv_iv_ray(u_seed, uint(i), uint(j), uint(u_rays), w);
        vec4 y = sh_basis(-w); // the light arrives travelling along -w
        // walk every voxel the ray crosses (Amanatides & Woo), from
        // LPV_IV_START voxels out: a fixed one-voxel step would skip voxels
        // the ray only clips and leak through tilted surfaces' staircases
        vec3 o = centre + start * w;
        ivec3 q = ivec3(floor(o));
        ivec3 st = ivec3(sign(w));
        vec3 inv = vec3(abs(w.x) > 1e-12 ? 1.0 / abs(w.x) : 1e30, abs(w.y) > 1e-12 ? 1.0 / abs(w.y) : 1e30,
                        abs(w.z) > 1e-12 ? 1.0 / abs(w.z) : 1e30);
        vec3 cross_at = mix(o - vec3(q), vec3(q) + 1.0 - o, greaterThan(w, vec3(0.0))) * inv; // next faces
        float t = start; // where the ray enters q
        int hit = -1;
        bool out_of_reach = false;
        for (int s = 0; s < max_steps; ++s) {
            if (u_ao != 0 && t > u_ao_reach) {
                out_of_reach = true;
                break;
            }
            if (!cell_inside(q))
                break;
            if (q != c && occupied(q)) {
                hit = cell_index(q);
                break;
            }
            int a = cross_at.x < cross_at.y ? (cross_at.x < cross_at.z ? 0 : 2) : (cross_at.y < cross_at.z ? 1 : 2);
            t = start + cross_at[a];
            q[a] += st[a];
            cross_at[a] += inv[a];
        }
        if (u_ao != 0) {
            if (hit < 0 || out_of_reach)
                vis += y;
            continue;
        }
        if (hit < 0)
            continue;
        LpvCell e = emit[hit];
        r += emitted(e.r, -w) * y;
        g += emitted(e.g, -w) * y;
        b += emitted(e.b, -w) * y;
    }
    float k = sphere / float(u_rays);
    if (u_ao != 0)
        ao[i] = vis * k;
    else
        gathered[i] = LpvCell(r * k, g * k, b * k);
}
