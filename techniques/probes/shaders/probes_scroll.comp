// probes_scroll.comp - one of the probes' buffers into the layout of
// cascades that moved by whole cells (one invocation a probe of the new
// layout): a probe whose world cell the old layout also held takes that
// probe's u_stride floats (its light, distances, state and offset move with
// the cell, not with the index); one the move brought in gets zeros (no
// light, not active, no offset) until its warmup (technique_probes.c). The
// rule is lpv_probes_scroll_source's (probes_plan.c), which lists the
// probes brought in for the warmup; test_plan checks it, test_probes_gpu
// checks this copy against an independent count.
layout(local_size_x = LPV_PROBES_WG) in;

layout(std430, binding = LPV_SSBO_PROBES_SCROLL_SRC) readonly buffer ScrollSrc { float scroll_src[]; };
layout(std430, binding = LPV_SSBO_PROBES_SCROLL_DST) writeonly buffer ScrollDst { float scroll_dst[]; };

uniform uint u_total;                       // probes of every cascade
uniform uint u_stride;                      // floats per probe
uniform ivec3 u_dims;                       // every cascade's
uniform ivec3 u_shift[LPV_MAX_CASCADES];    // a new cell's old cell is cell + shift

void main()
{
    uint p = gl_GlobalInvocationID.x;
    if (p >= u_total)
        return;
    int cells = u_dims.x * u_dims.y * u_dims.z;
    int k = int(p) / cells, cell = int(p) % cells;
    ivec3 c = ivec3(cell % u_dims.x, (cell / u_dims.x) % u_dims.y, cell / (u_dims.x * u_dims.y));
    ivec3 o = c + u_shift[k];
    bool kept = all(greaterThanEqual(o, ivec3(0))) && all(lessThan(o, u_dims));
    uint from = kept ? uint(k * cells + o.x + u_dims.x * (o.y + u_dims.y * o.z)) * u_stride : 0u, to = p * u_stride;
    for (uint i = 0u; i < u_stride; ++i)
        scroll_dst[to + i] = kept ? scroll_src[from + i] : 0.0;
}
