// gv_merge.comp - merges one buffer's geometry volume (an RSM's or the
// camera's, from the atlas) into the total: per GV point the total keeps the
// SH vector with the larger DC term, so a surface two buffers both saw is not
// counted twice (the paper's max-merge, without mixing coefficients of
// different surfaces).
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform sampler2D u_atlas_gv;
layout(std430, binding = LPV_SSBO_GV_TOTAL) buffer GvTotal { vec4 gv_total[]; };

void main()
{
    ivec3 p = ivec3(gl_GlobalInvocationID);
    ivec3 d = grid_dims() + 1;
    if (any(greaterThanEqual(p, d)))
        return;
    int i = p.x + d.x * (p.y + d.y * p.z);
    vec4 v = texelFetch(u_atlas_gv, atlas_texel(p, d.xy), 0);
    if (v.x > gv_total[i].x)
        gv_total[i] = v;
}
