// compact.glsl - the bits by which the RSMs' VPL producers (vpl_extract.comp,
// vpl_blocks.comp) mark the VPLs that carry light, and the places
// compact.comp copies them to (gpu/compact.h): after the draw command, a
// 32-bit word of live bits per chunk of LPV_COMPACT_CHUNK (32) samples, then
// each chunk's first place in the dense copy.
layout(std430, binding = LPV_SSBO_COMPACT_HEAD) buffer CompactHead
{
    uint compact_draw[4]; // DrawArraysIndirectCommand: count, instances, first, base instance
    uint compact_words[]; // [0, chunks): live bits; [chunks, 2 chunks): first places
};

// Sample i carries light: integer OR, so the bits do not depend on the order
// the invocations run in.
void compact_mark_live(int i)
{
    atomicOr(compact_words[i >> 5], 1u << uint(i & 31));
}
