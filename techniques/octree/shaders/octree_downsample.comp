// octree_downsample.comp - the octree's downsampling step (Olovsson's thesis,
// section 4.2, eq. 11): each cell of level i is the mean of its eight
// children in level i - 1, written as the level's injected grid and initial
// accumulation, with what its cells send on the first step (as
// lpv_pack.comp does for level 0). The grid block is level i's; u_fine_dims
// are level i - 1's. techniques/octree/core/oracle_octree.c is the reference.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(std430, binding = LPV_SSBO_VPLS) readonly buffer Fine { LpvCell fine[]; };
layout(std430, binding = LPV_SSBO_LPV_OUT) writeonly buffer Injected { LpvCell injected[]; };
layout(std430, binding = LPV_SSBO_LPV_ACC) writeonly buffer Acc { LpvCell acc[]; };
layout(std430, binding = LPV_SSBO_SENT_OUT) writeonly buffer SentOut { LpvCell sent_out[]; };

uniform ivec3 u_fine_dims;

void main()
{
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (!cell_inside(c))
        return;
    LpvCell m;
    m.r = m.g = m.b = vec4(0.0);
    for (int j = 0; j < 8; ++j) {
        ivec3 f = 2 * c + ivec3(j & 1, (j >> 1) & 1, (j >> 2) & 1);
        if (any(greaterThanEqual(f, u_fine_dims)))
            continue;
        LpvCell x = fine[f.x + u_fine_dims.x * (f.y + u_fine_dims.y * f.z)];
        m.r += x.r;
        m.g += x.g;
        m.b += x.b;
    }
    m.r *= 0.125;
    m.g *= 0.125;
    m.b *= 0.125;
    int i = cell_index(c);
    injected[i] = m;
    acc[i] = m;
    sent_out[i] = limited(m);
}
