// lpv_handoff.comp - the far field's hand-off (docs/propagation.md section
// 5b): the light in flight in every cascade moves on to the next coarser one,
// whose cells are unions of 2^3 cells of it, so from here it travels twice as
// far per step. Flux moves exactly (a coarse cell's intensity is the sum of
// its eight children's: the flux of a cell is its c0 times sqrt(4 pi), and a
// coarse step carries it twice the distance, so what a surface accumulates
// from a passing wave stays the same). The finest cascade is left empty, the
// coarsest keeps its own light as well. Nothing is accumulated here: the
// light only changes the grid it lives in. Writes what the cells send next
// (flux_limit.glsl, limited).
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = LPV_TEX_LPV_IN) uniform samplerBuffer u_in; // LpvCell as 3 texels
layout(std430, binding = LPV_SSBO_LPV_OUT) writeonly buffer Out { LpvCell cout[]; };
layout(std430, binding = LPV_SSBO_SENT_OUT) writeonly buffer SentOut { LpvCell sent_out[]; };

void add_cell(inout LpvCell o, int j)
{
    o.r += texelFetch(u_in, 3 * j);
    o.g += texelFetch(u_in, 3 * j + 1);
    o.b += texelFetch(u_in, 3 * j + 2);
}

void main()
{
    ivec3 c;
    int v = volume_of_invocation(ivec3(gl_GlobalInvocationID), c);
    if (!cell_inside(c) || v >= volume_count())
        return;
    int k = volume_cascade(v), bin = v - k * bin_count();
    LpvCell o;
    o.r = o.g = o.b = vec4(0.0);
    if (k == cascade_count() - 1)
        add_cell(o, v * grid_cells() + cell_index(c));
    if (k > 0) {
        // cell c of cascade k covers cells 2c + off + {0,1}^3 of cascade k - 1
        ivec3 off = ivec3(round(2.0 * cascade_origin_cells(k) - cascade_origin_cells(k - 1)));
        int fine = ((k - 1) * bin_count() + bin) * grid_cells();
        for (int j = 0; j < 8; ++j) {
            ivec3 ch = 2 * c + off + ivec3(j & 1, (j >> 1) & 1, (j >> 2) & 1);
            if (cell_inside(ch))
                add_cell(o, fine + cell_index(ch));
        }
    }
    int i = v * grid_cells() + cell_index(c);
    cout[i] = o;
    sent_out[i] = limited(o);
}
