// iv_surface.glsl - what the imperfect volume's passes ask of the voxels
// around one: whether a voxel holds a surface, the one surface beside an
// empty voxel (LPV_IV_SURFACE_GATHER) and the plane its gather starts on
// (iv_gather.comp marches from it, iv_filter.comp averages along it).
// techniques/iv/core/oracle_iv_internal.h holds the oracle's copies.
layout(std430, binding = LPV_SSBO_IV_OCCUPANCY) readonly buffer Occupancy { uint occupancy[]; };
layout(std430, binding = LPV_SSBO_IV_VOXELS) readonly buffer Voxels { IvVoxel voxels[]; };

bool occupied(ivec3 c) { int i = cell_index(c); return (occupancy[i >> 5] & (1u << uint(i & 31))) != 0u; }

// c's one occupied face neighbour qs (a floor's voxel under it), if it has
// exactly one; a the unit axis from qs to c. Else qs stays c and a 0: the
// march skips qs, and left at the last of two neighbours it let an edge
// voxel's rays through that wall.
bool surface_beside(ivec3 c, out ivec3 qs, out vec3 a)
{
    int n = 0;
    qs = c;
    a = vec3(0.0);
    for (int k = 0; k < 3; ++k)
        for (int sgn = -1; sgn <= 1; sgn += 2) {
            ivec3 q = c;
            q[k] += sgn;
            if (cell_inside(q) && occupied(q) && ++n == 1) {
                qs = q;
                a[k] = -float(sgn);
            }
        }
    if (n != 1) {
        qs = c;
        a = vec3(0.0);
    }
    return n == 1;
}

// Whether empty voxel c gathers on a surface (LPV_IV_SURFACE_GATHER): its
// one occupied face neighbour own holds a slab across the axis k between
// them; side the unit axis from own to c; plane where the slab's face
// towards c lies along k, in voxels. Else own is c, side 0 and k -1.
bool surface_plane(ivec3 c, out ivec3 own, out vec3 side, out int k, out float plane)
{
    k = -1;
    plane = 0.0;
    own = c;
    side = vec3(0.0);
    if (occupied(c) || !surface_beside(c, own, side))
        return false;
    int a = side.x != 0.0 ? 0 : side.y != 0.0 ? 1 : 2;
    vec4 slab = voxels[cell_index(own)].slab;
    if (slab.x != float(a)) {
        own = c;
        side = vec3(0.0);
        return false;
    }
    k = a;
    plane = float(own[k]) + (side[k] > 0.0 ? slab.z : slab.y);
    return true;
}
