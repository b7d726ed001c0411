// octree_merge.comp - the octree's merge step (Olovsson's thesis, section
// 4.2, eq. 10): M(x) = O_I(x)(x / 2^I(x)) with I(x) the finest level whose
// accumulated cell over x holds light (I_i(x) = i wherever O_i is non-zero;
// l - 1 where no level is). Run once per level from the coarsest (u_level =
// l - 1, which writes every cell) to level 0, each overwriting where its
// level holds light, so the finest non-zero level wins. The grid block is
// level 0's. techniques/octree/core/oracle_octree.c is the reference.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(std430, binding = LPV_SSBO_VPLS) readonly buffer Level { LpvCell level[]; };
layout(std430, binding = LPV_SSBO_LPV_OUT) buffer Merged { LpvCell merged[]; };
layout(std430, binding = LPV_SSBO_SURFELS) buffer Index { int index_volume[]; };

uniform int u_level;        // i
uniform int u_coarsest;     // 1: i = l - 1 (writes every cell)
uniform ivec3 u_level_dims; // level i's dims

bool holds_light(LpvCell x) { return any(notEqual(x.r, vec4(0.0))) || any(notEqual(x.g, vec4(0.0))) || any(notEqual(x.b, vec4(0.0))); }

void main()
{
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (!cell_inside(c))
        return;
    ivec3 p = min(c >> u_level, u_level_dims - 1);
    LpvCell x = level[p.x + u_level_dims.x * (p.y + u_level_dims.y * p.z)];
    if (u_coarsest == 0 && !holds_light(x))
        return;
    int i = cell_index(c);
    merged[i] = x;
    index_volume[i] = u_level;
}
