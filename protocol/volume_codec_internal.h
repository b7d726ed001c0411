/*
 * volume_codec_internal.h - what the volume header's builder and parser
 * share (volume_header_build.c, volume_header_parse.c); not part of the
 * library's API (volume_codec.h).
 */
#ifndef LPVP_VOLUME_CODEC_INTERNAL_H
#define LPVP_VOLUME_CODEC_INTERNAL_H

#include "volume_codec.h"

/* The cascades a header builds and the totals use: vi's own (their count),
 * or one from the grid's dims, origin and cell size (1); -1 for a cascade
 * count outside 0..LPVP_MAX_CASCADES. */
int lpvp_cascades_of(const lpvp_volume_info *vi, lpvp_cascade_info *out);

#endif /* LPVP_VOLUME_CODEC_INTERNAL_H */
