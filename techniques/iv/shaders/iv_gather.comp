// iv_gather.comp - radiance caching (paper 3.3): every voxel that a lookup
// can read (one with an occupied voxel among its 27) marches u_rays
// stratified rays (lpv_iv_ray) through the occupancy and visits every voxel
// each crosses, until an occupied voxel whose slab it meets
// (LPV_IV_SLAB_MARCH; any occupied voxel for the AO) or the volume's edge.
// An occupied voxel's rays start LPV_IV_START voxels out; an empty one's at
// its centre, or on the surface beside it (LPV_IV_SURFACE_GATHER). A hit
// sees what that voxel emits towards the ray's origin (a corner reached
// past a surface: what the surfaces beside it emit, LPV_IV_CORNER_READ); a
// ray that leaves the
// volume sees nothing (lpvd has no environment light: the path-traced
// reference sees black there too). The Monte-Carlo projection
// 4 pi / N sum L Y stores the arriving radiance as SH of the direction it
// travels, its L0 term set from the exact cosine sums along the voxel's
// axis (LPV_IV_AXIS_L0). With u_ao 1 the march returns visibility instead
// (1 past u_ao_reach metres or out of the volume, 0 at a hit; paper 3.5),
// from the centre as the paper's.
layout(local_size_x = LPV_IV_WG) in;

layout(std430, binding = LPV_SSBO_IV_EMIT) readonly buffer Emit { LpvCell emit[]; };
layout(std430, binding = LPV_SSBO_LPV_OUT) writeonly buffer Out { LpvCell gathered[]; };
layout(std430, binding = LPV_SSBO_IV_AO) writeonly buffer Ao { vec4 ao[]; };

uniform int u_rays;
uniform int u_cell_first; // this dispatch's first cell (the march goes in chunks)
uniform uint u_seed;
uniform int u_ao;
uniform float u_ao_reach; // voxels

// The radiance one channel of a voxel's emission e sends along unit t
// (techniques/iv/core/oracle_iv.c, emitted): e is the SH of the Lambertian hemispheres of
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

// Whether a ray's stretch through occupied voxel q, from
// o + t_in w to o + t_out w (in voxels), meets its surface: passes through
// the slab its points lie in where they lie thin along an axis
// (LPV_IV_SLAB), else anywhere in it (techniques/iv/core/oracle_iv_gather.c, meets).
bool meets(ivec3 q, vec3 o, vec3 w, float t_in, float t_out)
{
    vec4 slab = voxels[cell_index(q)].slab;
    if (slab.x < 0.0)
        return true;
    int k = int(slab.x);
    float x_in = o[k] - float(q[k]) + t_in * w[k], x_out = o[k] - float(q[k]) + t_out * w[k];
    return max(x_in, x_out) >= slab.y - LPV_IV_SLAB_PAD && min(x_in, x_out) <= slab.z + LPV_IV_SLAB_PAD;
}

vec3 emitted3(int v, vec3 t)
{
    LpvCell e = emit[v];
    return vec3(emitted(e.r, t), emitted(e.g, t), emitted(e.b, t));
}

// What a ray that hit voxel v at q sees along -t (LPV_IV_CORNER_READ): with
// axis >= 0 (it came through the face across that axis straight from a
// surface it passed) and no slab in v, the mean of v's face neighbours that
// hold a slab across axis; else v's own light (techniques/iv/core/oracle_iv_gather.c, corner_read).
vec3 corner_read(ivec3 q, int v, int axis, vec3 t)
{
    if (axis >= 0 && voxels[v].slab.x < 0.0) {
        vec3 sum = vec3(0.0);
        float n = 0.0;
        for (int k = 0; k < 3; ++k) {
            if (k == axis)
                continue;
            for (int sg = -1; sg <= 1; sg += 2) {
                ivec3 p = q;
                p[k] += sg;
                if (!cell_inside(p) || !occupied(p) || voxels[cell_index(p)].slab.x != float(axis))
                    continue;
                sum += emitted3(cell_index(p), t);
                n += 1.0;
            }
        }
        if (n > 0.0)
            return sum / n;
    }
    return emitted3(v, t);
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
    int i = u_cell_first + int(gl_GlobalInvocationID.x);
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
    // walls); its rays start at the centre, or on the surface beside it.
    const float start = occupied(c) ? LPV_IV_START : 0.0;
    vec4 r = vec4(0.0), g = vec4(0.0), b = vec4(0.0), vis = vec4(0.0);
    vec3 e_plus = vec3(0.0), e_minus = vec3(0.0); // sum L max(0, +-axis.w) per channel
    ivec3 own = c; // LPV_IV_SURFACE_GATHER: the surface's voxel, its side towards c
    vec3 side = vec3(0.0), axis = vec3(0.0); // axis: LPV_IV_AXIS_L0
    bool surf = false;
    vec3 origin = centre;
    int plane_axis;
    float plane;
    // a corner, a curved or tilted piece (no slab across the axis): from the centre, as any
    if (u_ao == 0 && surface_plane(c, own, side, plane_axis, plane)) {
        surf = true;
        origin[plane_axis] = plane + LPV_IV_SLAB_PAD * side[plane_axis];
        axis = side;
    }
    int max_steps = d.x + d.y + d.z + 3;
    for (int j = 0; j < u_rays; ++j) {
        vec3 w;
        lpv_iv_ray(u_seed, uint(i), uint(j), uint(u_rays), w);
        vec4 y = sh_basis(-w); // the light arrives travelling along -w
        int hit = -1;
        ivec3 hit_q = ivec3(0);
        int hit_axis = -1;
        bool out_of_reach = false;
        if (surf && dot(w, side) <= 0.0) {
            hit = cell_index(own); // into the surface: its own light
            hit_q = own;           // (hit_axis -1: corner_read reads it as it is)
        } else {
            // walk every voxel the ray crosses (Amanatides & Woo): a fixed
            // one-voxel step would skip voxels the ray only clips and leak
            // through tilted surfaces' staircases
            vec3 o = surf ? origin : centre + start * w;
            ivec3 q = ivec3(floor(o));
            ivec3 st = ivec3(sign(w));
            vec3 inv = vec3(abs(w.x) > 1e-12 ? 1.0 / abs(w.x) : 1e30, abs(w.y) > 1e-12 ? 1.0 / abs(w.y) : 1e30,
                            abs(w.z) > 1e-12 ? 1.0 / abs(w.z) : 1e30);
            vec3 cross_at = mix(o - vec3(q), vec3(q) + 1.0 - o, greaterThan(w, vec3(0.0))) * inv; // next faces
            float t = 0.0; // where the ray enters q, from o
            int entered = -1;     // the axis of the face the ray entered q through (-1: it starts in q)
            bool passed = false;  // the voxel before q holds a surface whose slab the ray ran clear of
            for (int s = 0; s < max_steps; ++s) {
                if (u_ao != 0 && start + t > u_ao_reach) {
                    out_of_reach = true;
                    break;
                }
                if (!cell_inside(q))
                    break;
                int a = cross_at.x < cross_at.y ? (cross_at.x < cross_at.z ? 0 : 2) : (cross_at.y < cross_at.z ? 1 : 2);
                bool held = q != c && q != own && occupied(q);
                // LPV_IV_SLAB_MARCH: radiance rays pass the slabs they run clear of; AO keeps blocks
                if (held && (u_ao != 0 || meets(q, o, w, t, cross_at[a]))) {
                    hit = cell_index(q);
                    hit_q = q;
                    hit_axis = passed ? entered : -1;
                    break;
                }
                passed = held;
                entered = a;
                t = cross_at[a];
                q[a] += st[a];
                cross_at[a] += inv[a];
            }
        }
        if (u_ao != 0) {
            if (hit < 0 || out_of_reach)
                vis += y;
            continue;
        }
        if (hit < 0)
            continue;
        vec3 L = corner_read(hit_q, hit, hit_axis, -w);
        r += L.r * y;
        g += L.g * y;
        b += L.b * y;
        float up = dot(axis, w);
        e_plus += L * max(up, 0.0);
        e_minus += L * max(-up, 0.0);
    }
    float k = sphere / float(u_rays);
    if (u_ao != 0) {
        ao[i] = vis * k;
        return;
    }
    if (axis != vec3(0.0)) { // LPV_IV_AXIS_L0: exact E(axis) and E(-axis)
        vec3 l0 = (e_plus + e_minus) / (2.0 * LPV_SH_LOBE0);
        r.x = l0.r;
        g.x = l0.g;
        b.x = l0.b;
    }
    gathered[i] = LpvCell(r * k, g * k, b * k);
}
