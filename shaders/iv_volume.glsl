// iv_volume.glsl - the imperfect volume's voxels (grid.glsl's one cascade of
// cubic voxels) and the irradiance reconstruction's weights (paper 3.4),
// shared by the lookup and the bounces. core/oracle_iv.c is the reference.
uniform int u_iv_neighbours; // the nearest this many of the 8 voxels around the shifted point

ivec3 iv_cell_of(vec3 p) { return ivec3(floor(cascade_coords(0, p))); }
vec3 iv_centre(ivec3 c) { return (vec3(c) + 0.5 + cascade_origin_cells(0)) * grid_cell_size(); }

// The reconstruction at a surface point p facing unit n: move half a voxel
// along n to q, take the 8 voxels whose centres surround q (trilinear
// weights), keep the u_iv_neighbours nearest to q, never the voxel holding p
// itself (its radiance saw its own surface), and weight each by the cosine
// between n and the direction from p to its centre (0 behind the surface).
// Returns the sum of the weights; cell[k], w[k] the voxels and weights.
float iv_blend(vec3 p, vec3 n, out ivec3 cell[8], out float w[8])
{
    vec3 q = p + 0.5 * grid_cell_size() * n;
    ivec3 own = iv_cell_of(p);
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
        if (cell[k] == own || !cell_inside(cell[k]) || !(len > 0.0))
            w[k] = 0.0;
        else
            w[k] *= max(0.0, dot(n, dir / len));
        sum += w[k];
    }
    return sum;
}
