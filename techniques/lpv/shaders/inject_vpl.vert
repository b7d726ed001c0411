// inject_vpl.vert - one point per VPL and cascade (instance) into the LPV
// atlas (the volume of its normal's bin when normal bins are on), at the cell
// holding position + half a cell along the normal, carrying lobe(n) * flux / pi
// per channel. With the far field, one point per VPL (a single instance),
// into the finest level holding it (docs/propagation.md §5b): llvmpipe runs
// the vertex stage on one thread, and an instance per level whose points all
// but one level drop cost the splat a third of its time at the default.
// Additive blending sums VPLs in array order: portable, no float atomics,
// deterministic. With u_spread (settings lpv.smooth_injection) each VPL is
// four points, the corners of its 2 x 2 stencil along its surface, each
// carrying its bilinear weight (grid.glsl vpl_stencil_at): instance
// i = 4 * (cascade or 0) + corner.
layout(std430, binding = LPV_SSBO_VPLS) readonly buffer Vpls { LpvVpl vpls[]; };

uniform int u_first;
uniform vec2 u_atlas_size;
uniform int u_spread;

flat out vec4 v_r;
flat out vec4 v_g;
flat out vec4 v_b;

void main()
{
    LpvVpl v = vpls[u_first + gl_VertexID];
    int corner = u_spread != 0 ? gl_InstanceID % 4 : 0;
    int k = u_spread != 0 ? gl_InstanceID / 4 : gl_InstanceID; // one instance per cascade (and corner)
    gl_PointSize = 1.0;
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0); // outside the clip volume: dropped
    v_r = v_g = v_b = vec4(0.0);

    float len = length(v.normal.xyz);
    if (v.position.w == 0.0 || !finite3(v.position.xyz) || !finite3(v.flux.rgb) || !(len > 1e-8) || isinf(len))
        return;
    vec3 n = v.normal.xyz / max(len, 1.0); // unit, or a down-sampled VPL's mean normal (core/sh.h lpv_mean_direction)
    // far field: a VPL lives in the finest level holding it; coarser ones
    // receive its light through the hand-off (the levels nest: each cell is
    // 2^3 of the finer level's)
    if (far_field()) {
        k = -1;
        for (int j = cascade_count() - 1; j >= 0; --j) {
            bool inside;
            if (u_spread != 0) { /* the whole stencil: a level holds all of a VPL or none of it */
                vec3 f;
                ivec3 b = vpl_stencil_at(v.position.xyz, n, cascade_cell(j), cascade_origin_cells(j), f);
                inside = cell_inside(b) && cell_inside(vpl_stencil_corner(b, n, 3));
            } else {
                inside = cell_inside(cascade_vpl_cell(j, v.position.xyz, n));
            }
            if (inside)
                k = j;
        }
        if (k < 0 && u_spread != 0)
            k = cascade_count() - 1; /* no level holds the whole stencil: the coarsest keeps the corners inside it */
        if (k < 0)
            return;
    }
    float w = cascade_object_weight(k, v.normal.w);
    if (!(w > 0.0))
        return;
    ivec3 c;
    if (u_spread != 0) {
        vec3 f;
        ivec3 b = vpl_stencil_at(v.position.xyz, n, cascade_cell(k), cascade_origin_cells(k), f);
        c = vpl_stencil_corner(b, n, corner);
        w *= vpl_stencil_weight(f, n, corner);
        if (!(w > 0.0))
            return;
    } else {
        c = cascade_vpl_cell(k, v.position.xyz, n);
    }
    if (!cell_inside(c))
        return;

    vec4 lobe = sh_lobe(n) * (w / LPV_PI);
    v_r = lobe * v.flux.r;
    v_g = lobe * v.flux.g;
    v_b = lobe * v.flux.b;
    ivec3 d = grid_dims();
    int vol = k * bin_count() + (bin_count() > 1 ? normal_bin(n) : 0);
    vec2 texel = vec2(atlas_texel(ivec3(c.xy, vol * d.z + c.z), d.xy)) + 0.5;
    gl_Position = vec4(texel / u_atlas_size * 2.0 - 1.0, 0.0, 1.0);
}
