// vpl_blocks.comp - the RSM texels of every face as VPLs and surfels,
// down-sampled in blocks of u_step x u_step texels (settings.rsm_vpl_step,
// block_groups.glsl; vpl_extract.comp is u_step = 1): each block gives up to
// u_slots VPLs, one per injection cell (in every cascade) and normal bin its
// texels reach, carrying the group's summed flux at its flux-weighted
// centroid with its flux-weighted mean normal, and as many surfels, one per
// set of geometry-volume points, carrying the summed area at the
// area-weighted centroid. Every cell and point so receives what the texels
// gave it one by one (exactly on a plane). Sample i of block b of layer
// u_layer0 + l is [u_base + (l * u_blocks^2 + b) * u_slots + i]; unused
// slots have position.w = 0 (VPL) / area 0 (surfel).
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform sampler2DArray u_rsm_position;
layout(binding = 1) uniform sampler2DArray u_rsm_normal;
layout(binding = 2) uniform sampler2DArray u_rsm_flux;
layout(binding = 3) uniform sampler2DArray u_rsm_albedo;

layout(std430, binding = LPV_SSBO_VPLS) writeonly buffer Vpls { LpvVpl vpls[]; };
layout(std430, binding = LPV_SSBO_SURFELS) writeonly buffer Surfels { LpvSurfel surfels[]; };

uniform int u_size;   // texels per layer side
uniform int u_step;   // texels per block side
uniform int u_blocks; // blocks per layer side: ceil(u_size / u_step)
uniform int u_slots;  // samples per block: min(LPV_BLOCK_SLOTS, u_step^2)
uniform int u_layer0; // the first layer of this dispatch
uniform int u_base;   // its first element

// LPV_BLOCKS_VPLS_ONLY 1: VPLs only, for layers whose surfels the geometry
// volume leaves out (pass_rsm.c); their surfel slots are not written.
#ifndef LPV_BLOCKS_VPLS_ONLY
#define LPV_BLOCKS_VPLS_ONLY 0
#endif

bool g_vpls; // what block_emit writes: VPLs, else surfels

void block_emit(int i, float w, vec3 pos_mean, vec3 nrm_mean, vec3 val, float size)
{
    if (g_vpls) {
        LpvVpl v = group_vpl(w, pos_mean, nrm_mean, val, size);
        vpls[i] = v;
        if (v.position.w != 0.0)
            compact_mark_live(i);
    } else
        surfels[i] = group_surfel(w, pos_mean, nrm_mean, val, size);
}

// The block's texels as VPLs: grouped by injection cell and normal bin,
// weighted by their flux summed over r, g, b.
void block_vpls(ivec2 lo, ivec2 hi, int layer, int base)
{
    g_vpls = true;
    BG_DECL_ALL
    for (int py = lo.y; py < hi.y; ++py)
        for (int px = lo.x; px < hi.x; ++px) {
            ivec3 t = ivec3(px, py, layer);
            vec4 nt = texelFetch(u_rsm_normal, t, 0);
            vec4 f = texelFetch(u_rsm_flux, t, 0);
            vec4 p = texelFetch(u_rsm_position, t, 0);
            float w = f.r + f.g + f.b;
            float len = length(nt.xyz);
            if (!(nt.w > 0.5) || !(w > 0.0) || isinf(w) || !finite3(p.xyz) || !(len > 1e-8) || isinf(len))
                continue;
            vec3 x = p.xyz, n = nt.xyz / len, val = f.rgb;
            float tag = f.a; // object size
            // the bin always: VPLs of opposite faces never cancel in one mean
            uvec4 g = group_key(x, n, false, normal_bin(n));
            BG_STEP
        }
    BG_EMIT_ALL
}

// ... and as blocking surfels: grouped by geometry-volume point, weighted by
// their area.
void block_surfels(ivec2 lo, ivec2 hi, int layer, int base)
{
    g_vpls = false;
    BG_DECL_ALL
    for (int py = lo.y; py < hi.y; ++py)
        for (int px = lo.x; px < hi.x; ++px) {
            ivec3 t = ivec3(px, py, layer);
            vec4 nt = texelFetch(u_rsm_normal, t, 0);
            vec4 albedo = texelFetch(u_rsm_albedo, t, 0);
            vec4 p = texelFetch(u_rsm_position, t, 0);
            // emitters do not block (see rsm.frag)
            if (!(nt.w > 0.5) || !(albedo.a > 0.5) || !(p.w > 0.0) || isinf(p.w) || !finite3(p.xyz) ||
                !finite3(nt.xyz))
                continue;
            vec3 x = p.xyz, n = nt.xyz, val = p.w * albedo.rgb;
            float w = p.w, tag = texelFetch(u_rsm_flux, t, 0).a;
            uvec4 g = group_key(x, n, true, normal_bin(n));
            BG_STEP
        }
    BG_EMIT_ALL
}

void main()
{
    ivec3 b = ivec3(gl_GlobalInvocationID);
    if (b.x >= u_blocks || b.y >= u_blocks)
        return;
    ivec2 lo = b.xy * u_step, hi = min(lo + u_step, ivec2(u_size));
    int base = u_base + ((b.z * u_blocks + b.y) * u_blocks + b.x) * u_slots;
    block_vpls(lo, hi, b.z + u_layer0, base);
#if !LPV_BLOCKS_VPLS_ONLY
    block_surfels(lo, hi, b.z + u_layer0, base);
#endif
}
