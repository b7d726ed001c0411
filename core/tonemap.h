/*
 * tonemap.h - display encoding of linear radiance for 8-bit images
 * (docs/units.md, "PNG: exposure, tone curve, background").
 *
 * A pixel's radiance L (W/(m^2 sr)) is shown as
 *   d = s * L,  s = LPV_LUMENS_PER_WATT * 2^EV   (683 lm/W: d is in nits x 2^EV)
 * then Reinhard's curve d / (1 + d) per channel and the sRGB transfer curve.
 * EV 0 shows a glTF file at the brightness three.js and the Khronos sample
 * viewer give it at their exposure 1 (they read candela and nits as display
 * values). The exposure is automatic unless fixed: the frame is metered like
 * a camera (lpv_exposure_meter_ev). Pixels the camera sees no geometry in get
 * the background colour, opaque unless transparent is asked for. EXR output
 * skips all of this: it stays radiometric.
 */
#ifndef LPV_TONEMAP_H
#define LPV_TONEMAP_H

#include <stddef.h>
#include <stdint.h>

#define LPV_MIDDLE_GREY 0.18f        /* the metered key maps to this display value */
#define LPV_METER_PERCENTILE 0.98f   /* the meter's bright end: this percentile of luminance */
#define LPV_METER_STOPS 6.0f         /* pixels darker than the bright end by more count as this many stops */
#define LPV_BACKGROUND_SRGB 0.25f    /* default background, sRGB grey (Blender's default world, linear 0.05) */

typedef struct lpv_display {
    int exposure_auto;     /* 1 (default): metered from the frame; 0: exposure_ev */
    float exposure_ev;     /* fixed EV when exposure_auto is 0 (s = 683 * 2^EV) */
    int transparent;       /* 1: background pixels get alpha 0 (and no colour) */
    float background[3];   /* sRGB 0..1 of pixels without geometry (default LPV_BACKGROUND_SRGB) */
} lpv_display;

/* The defaults: automatic exposure, opaque background of LPV_BACKGROUND_SRGB. */
void lpv_display_default(lpv_display *d);

/* Parses an --exposure value: "auto" or an EV (a finite number, -64..64).
 * Returns 0, or -1 with a message in err (d untouched). */
int lpv_exposure_parse(const char *value, lpv_display *d, char *err, size_t n);

/* The EV the automatic exposure picks for a frame: the key is the geometric
 * mean of the Rec. 709 luminance of the covered pixels (alpha > 0.5), each
 * clamped to [p / 2^LPV_METER_STOPS, p] with p the LPV_METER_PERCENTILE
 * percentile; EV = log2(LPV_MIDDLE_GREY / (683 * key)). 0 when nothing
 * covered is lit (nothing to meter). Scaling every radiance by k shifts the
 * EV by -log2(k) exactly, so the image does not change. */
float lpv_exposure_meter_ev(const float *rgba, size_t n);

/* n pixels of RGBA float radiance -> RGBA8 for display: the exposure (metered
 * or fixed), Reinhard, sRGB, then the background where alpha < 1 (added in
 * linear display space, alpha 255) or, when transparent, alpha = the frame's.
 * Non-finite values become 0. Returns the EV used. */
float lpv_display_rgba8(const float *rgba, size_t n, const lpv_display *d, uint8_t *out);

/* A fraction (the ambient occlusion, 1 = open) as a grey picture: each
 * channel 255 x the pixel's red value clamped to 0..1 (NaN: 0), alpha 255; no
 * exposure, tone or sRGB curve (it is not light). What `lpvd render --ao` and
 * lpvd batch's ao output write. */
void lpv_fraction_gray8(const float *rgba, size_t n, uint8_t *out);

/* Lower level, for tools comparing images at one explicit linear factor:
 * scale by `factor` (no 683), Reinhard, sRGB; alpha copied, clamped to 0..1. */
void lpv_tonemap_rgba8(const float *rgba, size_t n, float factor, uint8_t *out);

/* The sRGB encoding of a linear value in [0, 1], and its inverse. */
float lpv_srgb_encode(float linear);
float lpv_srgb_decode(float encoded);

#endif
