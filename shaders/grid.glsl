// grid.glsl - grid placement, cell indexing, the SH basis and the cosine lobe
// (the conventions of lpv_shared.h and core/grid.h, core/sh.c).
layout(std140, binding = LPV_UBO_GRID) uniform GridUBO { LpvGridParams G; };

ivec3 grid_dims() { return ivec3(G.dims.xyz); }
float grid_cell_size() { return G.origin_cell.w; }
vec3 grid_origin() { return G.origin_cell.xyz; }

int cell_index(ivec3 c)
{
    ivec3 d = grid_dims();
    return c.x + d.x * (c.y + d.y * c.z);
}

bool cell_inside(ivec3 c)
{
    return all(greaterThanEqual(c, ivec3(0))) && all(lessThan(c, grid_dims()));
}

vec4 sh_basis(vec3 d) { return vec4(LPV_SH_C0, LPV_SH_C1 * d.y, LPV_SH_C1 * d.z, LPV_SH_C1 * d.x); }
vec4 sh_lobe(vec3 n) { return vec4(LPV_SH_LOBE0, LPV_SH_LOBE1 * n.y, LPV_SH_LOBE1 * n.z, LPV_SH_LOBE1 * n.x); }

bool finite3(vec3 v) { return !any(isnan(v)) && !any(isinf(v)); }

// Injection renders points into a 2D atlas: slice z of a (w, h, depth)
// volume is the tile (z % tiles_x, z / tiles_x) of w x h texels.
uniform int u_tiles_x;

ivec2 atlas_texel(ivec3 c, ivec2 tile_size)
{
    return ivec2((c.z % u_tiles_x) * tile_size.x + c.x, (c.z / u_tiles_x) * tile_size.y + c.y);
}
