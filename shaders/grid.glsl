// grid.glsl - cascade placement, cell indexing, the SH basis and the cosine
// lobe (the conventions of lpv_shared.h and core/grid.h, core/sh.c).
// Buffers hold the cascades one after another: cell c of cascade k is at
// k * cells_per_cascade + cell_index(c).
layout(std140, binding = LPV_UBO_GRID) uniform GridUBO { LpvGridParams G; };

ivec3 grid_dims() { return ivec3(G.dims.xyz); }
int grid_cells() { return int(G.dims.w); }
int cascade_count() { return int(G.info.x); }
float cascade_cell(int k) { return G.cascade[k].w; }
vec3 cascade_origin_cells(int k) { return G.cascade[k].xyz; }
vec3 cascade_origin(int k) { return G.cascade[k].xyz * G.cascade[k].w; }
// The finest cascade: what a single grid used to be.
float grid_cell_size() { return cascade_cell(0); }
vec3 grid_origin() { return cascade_origin(0); }

int cell_index(ivec3 c)
{
    ivec3 d = grid_dims();
    return c.x + d.x * (c.y + d.y * c.z);
}

bool cell_inside(ivec3 c)
{
    return all(greaterThanEqual(c, ivec3(0))) && all(lessThan(c, grid_dims()));
}

// Continuous cell coordinates of world point p in cascade k (cell centres at
// integer + 0.5): p / cell - origin, so whole-cell moves of a snapped cascade
// shift every point by exactly whole cells.
vec3 cascade_coords(int k, vec3 p) { return p / cascade_cell(k) - cascade_origin_cells(k); }

// The cell of a VPL at x with normal n and the GV point of a surfel there, in
// a grid of `cell` m with its lower corner at origin_cells (lpv_shared.h,
// LPV_VPL_SHIFT_CELLS and LPV_TIE_CELLS); the cascade's, and the down-sampling
// keys' (block_groups.glsl), are these.
ivec3 vpl_cell_at(vec3 x, vec3 n, float cell, vec3 origin_cells)
{
    return ivec3(floor((x + LPV_VPL_SHIFT_CELLS * cell * n) / cell - origin_cells));
}
ivec3 gv_point_at(vec3 x, vec3 n, float cell, vec3 origin_cells)
{
    return ivec3(floor((x + LPV_TIE_CELLS * cell * n) / cell - origin_cells + 0.5));
}
ivec3 cascade_vpl_cell(int k, vec3 x, vec3 n) { return vpl_cell_at(x, n, cascade_cell(k), cascade_origin_cells(k)); }
ivec3 cascade_gv_point(int k, vec3 x, vec3 n) { return gv_point_at(x, n, cascade_cell(k), cascade_origin_cells(k)); }

// A compute invocation over every cascade: z runs over dims.z * cascades.
// Returns the cascade and sets c to the cell within it.
int cascade_of_invocation(ivec3 id, out ivec3 c)
{
    int dz = grid_dims().z;
    c = ivec3(id.x, id.y, id.z % dz);
    return id.z / dz;
}

// Volumes: with normal bins on, each cascade holds bin_count() volumes (one
// per dominant axis of the emitting surface's normal); LPV buffers hold
// volume v = cascade * bin_count() + bin at v * grid_cells(). The geometry
// volume and the transmittances stay per cascade.
int bin_count() { return max(int(G.info.z), 1); }
int volume_count() { return cascade_count() * bin_count(); }
int volume_cascade(int v) { return v / bin_count(); }
int transport() { return int(G.info.w); }
// Far field (docs/propagation.md section 5b): cascade k + 1 carries on the
// light of cascade k; a point's light is the sum over the cascades holding it.
bool far_field() { return G.mode.x != 0.0; }

// The bin of a unit normal: its dominant axis and sign, in the direction
// order +x -x +y -y +z -z (ties go to the lower axis).
int normal_bin(vec3 n)
{
    vec3 a = abs(n);
    int axis = (a.x >= a.y && a.x >= a.z) ? 0 : (a.y >= a.z ? 1 : 2);
    return 2 * axis + (n[axis] < 0.0 ? 1 : 0);
}

// Smooth injection (settings lpv.smooth_injection): a VPL at x with normal n
// spreads its light bilinearly over the 2 x 2 cells around x + half a cell
// along n, in the two axes but the normal's dominant one (normal_bin's),
// and along that axis lands in the cell vpl_cell_at gives. A light that
// moves slides its RSM texels over the surfaces, so the volume then changes
// smoothly instead of by a texel's whole flux where one crosses a cell's
// border; light still never lands behind the surface along the normal.
// Returns the stencil's lower cell and sets f, the upper cells' weights
// per axis (0 along the dominant one); corner j (0..3) is the lower cell
// plus j & 1 along the first other axis and j >> 1 along the second.
ivec3 vpl_stencil_at(vec3 x, vec3 n, float cell, vec3 origin_cells, out vec3 f)
{
    vec3 q = (x + LPV_VPL_SHIFT_CELLS * cell * n) / cell - origin_cells;
    int ax = normal_bin(n) / 2;
    vec3 b = floor(q - 0.5);
    f = q - 0.5 - b;
    b[ax] = floor(q[ax]);
    f[ax] = 0.0;
    return ivec3(b);
}
ivec3 vpl_stencil_corner(ivec3 b, vec3 n, int j)
{
    int ax = normal_bin(n) / 2;
    ivec3 o = ivec3(0);
    o[ax == 0 ? 1 : 0] = j & 1;
    o[ax == 2 ? 1 : 2] = j >> 1;
    return b + o;
}
float vpl_stencil_weight(vec3 f, vec3 n, int j)
{
    int ax = normal_bin(n) / 2;
    int a0 = ax == 0 ? 1 : 0, a1 = ax == 2 ? 1 : 2;
    return ((j & 1) != 0 ? f[a0] : 1.0 - f[a0]) * ((j >> 1) != 0 ? f[a1] : 1.0 - f[a1]);
}

// The unit vector of direction d in the order +x -x +y -y +z -z.
vec3 dir_vector(int d)
{
    vec3 e = vec3(0.0);
    e[d / 2] = (d & 1) == 0 ? 1.0 : -1.0;
    return e;
}

// Bins follow the direction order.
vec3 bin_axis(int b) { return dir_vector(b); }

// A compute invocation over every LPV volume: z runs over dims.z * volumes.
int volume_of_invocation(ivec3 id, out ivec3 c) { return cascade_of_invocation(id, c); }

// Weight of an object of size `size` (m) in cascade k: the finest cascade
// takes everything; a coarser one fades out objects smaller than two of its
// cells and drops those smaller than one (paper section 4), so an object
// moving between sizes fades instead of popping. 0 = unknown size: kept.
float cascade_object_weight(int k, float size)
{
    if (k == 0 || G.info.y == 0.0 || !(size > 0.0))
        return 1.0;
    return clamp(size / cascade_cell(k) - 1.0, 0.0, 1.0);
}

vec4 sh_basis(vec3 d) { return vec4(LPV_SH_C0, LPV_SH_C1 * d.y, LPV_SH_C1 * d.z, LPV_SH_C1 * d.x); }
vec4 sh_lobe(vec3 n) { return vec4(LPV_SH_LOBE0, LPV_SH_LOBE1 * n.y, LPV_SH_LOBE1 * n.z, LPV_SH_LOBE1 * n.x); }

bool finite3(vec3 v) { return !any(isnan(v)) && !any(isinf(v)); }

// Injection renders points into a 2D atlas: slice z of a (w, h, depth)
// volume is the tile (z % tiles_x, z / tiles_x) of w x h texels. Cascades
// stack their slices: slice k * depth + z.
uniform int u_tiles_x;

ivec2 atlas_texel(ivec3 c, ivec2 tile_size)
{
    return ivec2((c.z % u_tiles_x) * tile_size.x + c.x, (c.z / u_tiles_x) * tile_size.y + c.y);
}
