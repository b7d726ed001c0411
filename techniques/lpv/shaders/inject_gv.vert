// inject_gv.vert - one point per surfel and cascade (instance) into the geometry-volume atlas, at the
// nearest GV point (GV points sit on LPV cell corners), carrying the blocking
// potential (area / cell^2) * lobe(n).
layout(std430, binding = LPV_SSBO_SURFELS) readonly buffer Surfels { LpvSurfel surfels[]; };

uniform int u_first;
uniform vec2 u_atlas_size;

flat out vec4 v_gv;
flat out vec4 v_albedo;

void main()
{
    LpvSurfel s = surfels[u_first + gl_VertexID];
    int k = gl_InstanceID; // one instance per cascade
    gl_PointSize = 1.0;
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    v_gv = vec4(0.0);
    v_albedo = vec4(0.0);

    float len = length(s.normal.xyz);
    float area = s.position.w;
    if (!(area > 0.0) || isinf(area) || !finite3(s.position.xyz) || !(len > 1e-8) || isinf(len))
        return;
    float w = cascade_object_weight(k, s.normal.w);
    if (!(w > 0.0))
        return;
    vec3 n = s.normal.xyz / max(len, 1.0); // unit, or a down-sampled surfel's mean normal (core/sh.h lpv_mean_direction)
    float cell = cascade_cell(k);
    ivec3 p = cascade_gv_point(k, s.position.xyz, n);
    ivec3 gv_dims = grid_dims() + 1;
    if (any(lessThan(p, ivec3(0))) || any(greaterThanEqual(p, gv_dims)))
        return;

    v_gv = sh_lobe(n) * (w * area / (cell * cell));
    // albedo weighted by the blocking, so the merge can average it
    v_albedo = vec4(clamp(s.albedo.rgb, 0.0, 1.0), 1.0) * v_gv.x;
    vec2 texel = vec2(atlas_texel(ivec3(p.xy, k * gv_dims.z + p.z), gv_dims.xy)) + 0.5;
    gl_Position = vec4(texel / u_atlas_size * 2.0 - 1.0, 0.0, 1.0);
}
