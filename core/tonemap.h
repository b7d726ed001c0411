/*
 * tonemap.h - display encoding of linear radiance for 8-bit images:
 * scale by the exposure (default 1: no gain), Reinhard x / (1 + x) per
 * channel, then the sRGB transfer curve. EXR output skips this entirely.
 */
#ifndef LPV_TONEMAP_H
#define LPV_TONEMAP_H

#include <stddef.h>
#include <stdint.h>

/* n pixels of RGBA float -> RGBA8 (alpha copied, clamped to 0..1).
 * Non-finite values become 0. */
void lpv_tonemap_rgba8(const float *rgba, size_t n, float exposure, uint8_t *out);

/* The sRGB encoding of a linear value in [0, 1], and its inverse. */
float lpv_srgb_encode(float linear);
float lpv_srgb_decode(float encoded);

#endif
