// lpv_pack.comp - copies the injection atlas into the LPV buffer layout
// (LpvCell per cell, x fastest, volumes - cascades x normal bins - one after
// another) as both the injected grid and the initial accumulation, with the
// what the cells send on the first step (flux_limit.glsl, limited).
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform sampler2D u_atlas_r;
layout(binding = 1) uniform sampler2D u_atlas_g;
layout(binding = 2) uniform sampler2D u_atlas_b;

layout(std430, binding = LPV_SSBO_LPV_OUT) writeonly buffer Injected { LpvCell injected[]; };
layout(std430, binding = LPV_SSBO_LPV_ACC) writeonly buffer Acc { LpvCell acc[]; };
layout(std430, binding = LPV_SSBO_SENT_OUT) writeonly buffer SentOut { LpvCell sent_out[]; };

void main()
{
    ivec3 id = ivec3(gl_GlobalInvocationID);
    ivec3 c;
    int k = volume_of_invocation(id, c);
    if (!cell_inside(c) || k >= volume_count())
        return;
    ivec2 t = atlas_texel(id, grid_dims().xy);
    LpvCell cell;
    cell.r = texelFetch(u_atlas_r, t, 0);
    cell.g = texelFetch(u_atlas_g, t, 0);
    cell.b = texelFetch(u_atlas_b, t, 0);
    int i = k * grid_cells() + cell_index(c);
    injected[i] = cell;
    acc[i] = cell;
    sent_out[i] = limited(cell);
}
