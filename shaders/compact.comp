// compact.comp - the VPLs that carry light (marked by their producers in
// compact.glsl's bits) copied into a dense buffer in their order, with the
// count as a draw command for glDrawArraysIndirect. The down-sampled RSM
// leaves most of its blocks' slots empty (block_groups.glsl: a block has room
// for as many groups as texels), and llvmpipe runs the splats' vertex stage on
// one thread, per point drawn, empty or not. The order is kept, so additive
// splats sum the same values in the same order: the volumes are
// bit-identical to drawing every slot.
//   LPV_COMPACT_PHASE 1: one workgroup turns the chunks' live counts into
//     their first places (exclusive prefix sums) and writes the total into
//     the draw command;
//   2: each chunk copies its live samples from its first place on.
layout(local_size_x = LPV_COMPACT_PHASE == 1 ? LPV_COMPACT_SCAN_WG : LPV_COMPACT_WG) in;

layout(std430, binding = LPV_SSBO_VPLS) readonly buffer Src { LpvVpl src[]; };
layout(std430, binding = LPV_SSBO_COMPACT_DST) writeonly buffer Dst { LpvVpl dst[]; };

uniform int u_chunks; // chunks of LPV_COMPACT_CHUNK samples

#if LPV_COMPACT_PHASE == 1
shared uint s_sum[LPV_COMPACT_SCAN_WG];
#endif

void main()
{
#if LPV_COMPACT_PHASE == 1
    // invocation t counts a run of chunks, the workgroup scans the counts
    // (Hillis-Steele), then t writes its run's first places
    int t = int(gl_LocalInvocationID.x);
    int per = (u_chunks + LPV_COMPACT_SCAN_WG - 1) / LPV_COMPACT_SCAN_WG;
    int lo = min(t * per, u_chunks), hi = min(lo + per, u_chunks);
    uint own = 0u;
    for (int c = lo; c < hi; ++c)
        own += uint(bitCount(compact_words[c]));
    s_sum[t] = own;
    barrier();
    for (int d = 1; d < LPV_COMPACT_SCAN_WG; d *= 2) {
        uint add = t >= d ? s_sum[t - d] : 0u;
        barrier();
        s_sum[t] += add;
        barrier();
    }
    uint first = s_sum[t] - own;
    for (int c = lo; c < hi; ++c) {
        compact_words[u_chunks + c] = first;
        first += uint(bitCount(compact_words[c]));
    }
    if (t == LPV_COMPACT_SCAN_WG - 1) {
        compact_draw[0] = s_sum[t];
        compact_draw[2] = 0u;
        compact_draw[3] = 0u;
    }
#else
    int c = int(gl_GlobalInvocationID.x);
    if (c >= u_chunks)
        return;
    uint bits = compact_words[c];
    uint j = compact_words[u_chunks + c];
    while (bits != 0u) {
        int k = findLSB(bits);
        dst[j++] = src[c * LPV_COMPACT_CHUNK + k];
        bits &= bits - 1u;
    }
#endif
}
