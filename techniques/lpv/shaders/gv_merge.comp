// gv_merge.comp - merges one buffer's geometry volume (an RSM's, the
// camera's or the scene surfels', from the atlas) into the total
// (LpvGvPoint): per GV point and travel direction d the total keeps the
// larger blocking potential B(-d) = dot(sh, Y(-d)), so a surface two buffers
// both saw blocks once, and a wall whose two sides two buffers saw (a lamp's
// RSM inside a box, the scene surfels outside) blocks light both ways; a
// whole-vector max would keep one side's lobe and let light through the
// other way. A NaN is kept and stays (transmit.comp blocks it fully). The
// total starts at 0, so a back face's negative lobe never lowers what
// another corner blocks. The albedo is that of the buffer with the larger DC
// term, the one that saw the most surface here. All cascades in one dispatch.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform sampler2D u_atlas_gv;
layout(binding = 1) uniform sampler2D u_atlas_albedo;
layout(std430, binding = LPV_SSBO_GV_TOTAL) buffer GvTotal { LpvGvPoint gv_total[]; };

void main()
{
    ivec3 id = ivec3(gl_GlobalInvocationID);
    ivec3 d = grid_dims() + 1;
    int k = id.z / d.z;
    ivec3 p = ivec3(id.xy, id.z % d.z);
    if (any(greaterThanEqual(p, d)) || k >= cascade_count())
        return;
    int i = k * d.x * d.y * d.z + p.x + d.x * (p.y + d.y * p.z);
    ivec2 t = atlas_texel(ivec3(p.xy, id.z), d.xy);
    vec4 v = texelFetch(u_atlas_gv, t, 0);
    for (int dir = 0; dir < LPV_DIR_COUNT; ++dir) {
        float b = dot(v, sh_basis(-dir_vector(dir)));
        if (b > gv_total[i].blocking[dir / 4][dir % 4] || isnan(b))
            gv_total[i].blocking[dir / 4][dir % 4] = b;
    }
    if (v.x > gv_total[i].albedo.w) {
        vec4 a = texelFetch(u_atlas_albedo, t, 0);
        gv_total[i].albedo = a.w > 0.0 ? vec4(a.rgb / a.w, v.x) : vec4(0.0);
    }
}
