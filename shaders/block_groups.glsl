// block_groups.glsl - down-sampling a buffer's samples (camera pixels, RSM
// texels) in blocks without moving their light or blocking between cells:
// each block's samples are grouped by the cell (VPLs) or geometry-volume
// point (surfels) they land in, in every cascade, and by normal bin (so the
// two faces of a thin wall, whose normals would cancel, stay apart), and
// one sample per group carries the group's sum at its weighted centroid
// (camera_surfels.comp, vpl_blocks.comp). Since a centroid of points in one
// cell lies in that cell, every cell or point receives what the samples gave
// it one by one. With smooth injection a VPL group is the samples of one
// 2 x 2 stencil (grid.glsl vpl_stencil_at), spread from its centroid: each
// axis's weights are linear in the position, so a cell receives what the
// samples gave it but for the two axes' cross term (the members'
// covariance within the block), and a sample that crosses into the next
// stencil does so where its weight on the cells it leaves is 0. The means are sums of differences from the group's first
// sample, so a group of samples at one position (a plane on a cell's
// border: the grid's half-cell margin puts the scene's walls there) keeps
// that position to the bit, and the injection puts it where it put them.
//
// The groups live in LPV_BLOCK_SLOTS slots, written as macros over four sets
// of scalars rather than arrays: llvmpipe keeps arrays in per-invocation
// scratch memory, which costs even a shader that never indexes them. Slot k
// holds its group's key and tag (what must match too: the object size), its
// first sample's position and normal, the summed weight w, the w-weighted
// sums of the position's and normal's differences from the first, and the
// summed value. A shader declares BG_DECL_ALL, runs BG_STEP for each sample
// with key g, tag, weight w > 0, position x, unit normal n and value val,
// defines block_emit(i, w_sum, x_mean, n_mean, val_sum, tag) (w_sum 0 for an
// empty slot; n_mean the w-weighted mean of unit normals, not normalised)
// and ends with BG_EMIT_ALL (base). A sample of a group that finds no free slot joins the
// slot of the nearest finest cell or point: nothing is dropped.

uniform vec4 u_group_grid[LPV_MAX_CASCADES]; // each cascade: lower corner in cells, cell (m)
uniform int u_group_levels;                  // cascades; 0: no grid, one group per block
uniform int u_group_spread;                  // VPLs key on their smooth-injection stencil (grid.glsl)

// 9 bits per axis (index + 1, clamped to 0..511: a grid has at most 257
// points a side) and 3 bits for the normal bin.
uint group_pack(ivec3 c, int bin)
{
    uvec3 u = uvec3(clamp(c + 1, ivec3(0), ivec3(511)));
    return u.x | (u.y << 9) | (u.z << 18) | (uint(bin) << 27);
}

ivec3 group_unpack(uint k) { return ivec3(int(k & 511u), int((k >> 9) & 511u), int((k >> 18) & 511u)) - 1; }

// Cascade c's part of the key of a sample at x with unit normal n: the GV
// point nearest x (points, inject_gv.vert), or the cell holding x + half a
// cell along n (cells, inject_vpl.vert; with u_group_spread the lower cell
// of its stencil), with the normal's bin (-1: none);
// computed as those shaders compute it (grid.glsl cascade_coords), so a
// sample on a cell's border falls on the same side.
uint group_code(int c, vec3 x, vec3 n, bool points, int bin)
{
    vec4 g = u_group_grid[c];
    vec3 f;
    ivec3 q = points ? gv_point_at(x, n, g.w, g.xyz)
                     : u_group_spread != 0 ? vpl_stencil_at(x, n, g.w, g.xyz, f) : vpl_cell_at(x, n, g.w, g.xyz);
    return group_pack(q, max(bin, 0));
}

// A loop to the cascades in use (llvmpipe computes every branch of an
// unrolled one).
uvec4 group_key(vec3 x, vec3 n, bool points, int bin)
{
    uvec4 key = uvec4(0u);
    for (int c = 0; c < u_group_levels; ++c)
        key[c] = group_code(c, x, n, points, bin);
    return key;
}

// A group (block_emit's arguments) as the surfel or VPL it becomes. The mean
// normal stays unnormalised: its lobe is the sum of the members' lobes
// (lpv_mean_direction). An empty or broken group gives area 0 / position.w
// 0, which the splats skip.
bool group_ok(float w, vec3 pos, vec3 nrm)
{
    return w > 0.0 && !isinf(w) && finite3(pos) && finite3(nrm) && length(nrm) > 1e-8;
}

LpvSurfel group_surfel(float area, vec3 pos, vec3 nrm, vec3 albedo_sum, float size)
{
    bool ok = group_ok(area, pos, nrm);
    LpvSurfel s;
    s.position = vec4(ok ? pos : vec3(0.0), ok ? area : 0.0);
    s.normal = vec4(ok ? nrm : vec3(0.0, 0.0, 1.0), size);
    s.albedo = vec4(ok ? albedo_sum / area : vec3(0.0), 0.0);
    return s;
}

LpvVpl group_vpl(float w, vec3 pos, vec3 nrm, vec3 flux, float size)
{
    bool ok = group_ok(w, pos, nrm);
    LpvVpl v;
    v.position = vec4(ok ? pos : vec3(0.0), ok ? 1.0 : 0.0);
    v.normal = vec4(ok ? nrm : vec3(0.0, 0.0, 1.0), size); // w: object size
    v.flux = vec4(ok ? flux : vec3(0.0), 0.0);
    return v;
}

#define BG_DECL(k) uvec4 bg_key##k = uvec4(0u); float bg_w##k = 0.0, bg_tag##k = 0.0; \
    vec3 bg_x0##k = vec3(0.0), bg_n0##k = vec3(0.0), bg_pos##k = vec3(0.0), bg_nrm##k = vec3(0.0), bg_val##k = vec3(0.0);
#define BG_MATCH(k) if (bg_slot < 0 && bg_used > k && bg_key##k == g && bg_tag##k == tag) bg_slot = k;
#define BG_NEAR(k) if (bg_used > k) { ivec3 d = abs(group_unpack(bg_key##k.x) - g0); \
    if (d.x + d.y + d.z < bg_best) { bg_best = d.x + d.y + d.z; bg_slot = k; } }
#define BG_ADD(k) if (bg_slot == k) { if (bg_w##k == 0.0) { bg_key##k = g; bg_tag##k = tag; bg_x0##k = x; bg_n0##k = n; } \
    bg_w##k += w; bg_pos##k += w * (x - bg_x0##k); bg_nrm##k += w * (n - bg_n0##k); bg_val##k += val; }
#define BG_OUT(k) if (u_slots > k) block_emit(base + k, bg_w##k, bg_x0##k + bg_pos##k / max(bg_w##k, 1e-30), \
    bg_n0##k + bg_nrm##k / max(bg_w##k, 1e-30), bg_val##k, bg_tag##k);

// BG_SLOTS slots (4, or 8 where the includer defines BG_SLOTS 8 first; at
// most LPV_BLOCK_SLOTS): one macro call per slot below.
#ifndef BG_SLOTS
#define BG_SLOTS 4
#endif
#if BG_SLOTS == 8
#define BG_EACH(M) M(0) M(1) M(2) M(3) M(4) M(5) M(6) M(7)
#else
#define BG_EACH(M) M(0) M(1) M(2) M(3)
#endif
#define BG_DECL_ALL int bg_used = 0; BG_EACH(BG_DECL)
#define BG_STEP { int bg_slot = -1; \
    BG_EACH(BG_MATCH) \
    if (bg_slot < 0 && bg_used < min(u_slots, BG_SLOTS)) bg_slot = bg_used++; \
    if (bg_slot < 0) { int bg_best = 1 << 30; ivec3 g0 = group_unpack(g.x); BG_EACH(BG_NEAR) } \
    BG_EACH(BG_ADD) }
#define BG_EMIT_ALL BG_EACH(BG_OUT)
