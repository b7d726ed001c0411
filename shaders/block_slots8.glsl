// block_slots8.glsl - included before block_groups.glsl: 8 slots per block
// (vpl_blocks.comp: an RSM texel of an area light's wide face covers more
// cells than a camera pixel, so its blocks reach more cells).
#define BG_SLOTS 8
