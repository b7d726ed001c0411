// iv_volume.glsl - the imperfect volume's voxels (grid.glsl's one cascade of
// cubic voxels) and the irradiance reconstruction's weights (paper 3.4),
// shared by the lookup and the bounces. techniques/iv/core/oracle_iv.c is the reference.
uniform int u_iv_neighbours; // the nearest this many of the 8 voxels around the shifted point
layout(std430, binding = LPV_SSBO_IV_OCCUPANCY) readonly buffer OccupancyLookup { uint iv_occupancy[]; };

bool iv_occupied(ivec3 c)
{
    int i = cell_index(c);
    return (iv_occupancy[i >> 5] & (1u << uint(i & 31))) != 0u;
}

// The voxel a surface point facing n belongs to (LPV_IV_BEHIND).
// p in voxels from the volume's corner, moved LPV_IV_BEHIND against n
vec3 iv_coords_of(vec3 p, vec3 n) { return cascade_coords(0, p) - LPV_IV_BEHIND * n; }
ivec3 iv_cell_of(vec3 p, vec3 n) { return ivec3(floor(iv_coords_of(p, n))); }
vec3 iv_centre(ivec3 c) { return (vec3(c) + 0.5 + cascade_origin_cells(0)) * grid_cell_size(); }

// The reconstruction at a surface point p facing unit n: move half a voxel
// along n to q, take the 8 voxels whose centres surround q (trilinear
// weights), keep the u_iv_neighbours nearest to q, and weight each by the
// cosine between n and the direction from p to its centre (0 behind the
// surface). The voxel holding p is one of them like any other: it holds p's
// surface, so it weighs LPV_IV_HELD_WEIGHT as below; cutting it out made a
// step wherever p crossed a voxel face (voxel blocks on curved surfaces).
// Voxels that hold a surface themselves weigh LPV_IV_HELD_WEIGHT as much:
// their rays start among the surface's own voxels and see its own light (the
// paper's "self intersections"), which the cosine alone lets through
// wherever p lies below its voxel's centre, a pattern at the voxel pitch. A
// factor rather than a cut keeps the blend continuous where a tilted
// surface's voxels come and go, and still answers where every neighbour
// holds a surface (a concave corner). Returns the sum of the weights; cell[k], w[k] the voxels and weights.
float iv_blend(vec3 p, vec3 n, out ivec3 cell[8], out float w[8])
{
    vec3 q = p + 0.5 * grid_cell_size() * n;
    vec3 u = cascade_coords(0, q) - 0.5;
    vec3 b = floor(u);
    vec3 f = u - b;
    float d[8];
    for (int k = 0; k < 8; ++k) {
        ivec3 o = ivec3(k & 1, (k >> 1) & 1, k >> 2);
        cell[k] = ivec3(b) + o;
        vec3 t = mix(1.0 - f, f, vec3(o));
        w[k] = t.x * t.y * t.z;
        d[k] = distance(q, iv_centre(cell[k]));
    }
    for (int drop = 0; drop < 8 - clamp(u_iv_neighbours, 1, 8); ++drop) { // the farthest; ties: the later corner
        int far = 0;
        for (int k = 1; k < 8; ++k)
            if (d[k] >= d[far])
                far = k;
        d[far] = -1.0;
        w[far] = 0.0;
    }
    float sum = 0.0;
    for (int k = 0; k < 8; ++k) {
        vec3 dir = iv_centre(cell[k]) - p;
        float len = length(dir);
        if (!cell_inside(cell[k]) || !(len > 0.0))
            w[k] = 0.0;
        else
            w[k] *= max(0.0, dot(n, dir / len)) *
                    (iv_occupied(cell[k]) ? LPV_IV_HELD_WEIGHT : 1.0);
        sum += w[k];
    }
    return sum;
}
