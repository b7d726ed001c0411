// block_slots8.glsl - included before block_groups.glsl: 8 slots per block
// (camera_surfels.comp, and vpl_blocks.comp past 2 x 2 texels; without it
// block_groups.glsl has 4, as many as a 2 x 2 block has samples).
#define BG_SLOTS 8
