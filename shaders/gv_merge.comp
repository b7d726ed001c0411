// gv_merge.comp - merges one buffer's geometry volume (an RSM's or the
// camera's, from the atlas) into the total: per GV point the total keeps the
// SH vector with the larger DC term, so a surface two buffers both saw is not
// counted twice (the paper's max-merge, without mixing coefficients of
// different surfaces), and the winner's mean albedo with it. All cascades in
// one dispatch; the total holds two vec4 per point: blocking SH, albedo.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform sampler2D u_atlas_gv;
layout(binding = 1) uniform sampler2D u_atlas_albedo;
layout(std430, binding = LPV_SSBO_GV_TOTAL) buffer GvTotal { vec4 gv_total[]; };

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
    if (v.x > gv_total[2 * i].x) {
        vec4 a = texelFetch(u_atlas_albedo, t, 0);
        gv_total[2 * i] = v;
        gv_total[2 * i + 1] = a.w > 0.0 ? vec4(a.rgb / a.w, 1.0) : vec4(0.0);
    }
}
