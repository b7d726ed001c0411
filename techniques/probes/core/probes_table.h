/*
 * probes_table.h - a batch's ray table: what every probe of a batch shares
 * (one rotation of the ray set per batch), made once on the CPU and read
 * by the update and blend shaders (lpv_shared.h's LPV_SSBO_PROBES_RAY_DIRS
 * and LPV_SSBO_PROBES_TAPS): each ray's direction, and for the distance
 * moments each octahedral texel's rays with their weights
 * max(0, cos)^sharpness normalised to sum 1. Weights below
 * LPV_PROBES_TAP_FLOOR of the texel's largest are left out: at the
 * paper's sharpness a texel keeps a handful of its rays, not half of them.
 */
#ifndef LPV_PROBES_TABLE_H
#define LPV_PROBES_TABLE_H

#include <stddef.h>
#include <stdint.h>

#define LPV_PROBES_TAP_FLOOR 1e-5f

/* The irradiance map's taps: each texel's rays with cos > 0, weighted pi
 * cos / (their cos sum), so a texel's irradiance is the sum of its rays'
 * radiance times their weights (uniform rays: E(n) = int L max(0, n.w) dw,
 * the cosine normalised over the rays that land). */
typedef struct lpv_probes_table {
    float *dirs;     /* 4 floats a ray: xyz, 0 */
    uint32_t *taps;  /* 2 a texel (first, count): the distance map's oct^2, then the irradiance map's
                        irr_oct^2; then 2 a tap (ray, weight's float bits) */
    size_t tap_words; /* uint32s in taps */
} lpv_probes_table;

/* Makes the table for `rays` rays turned by lpv_probes_rotation(tick, seed),
 * an oct x oct distance map and an irr_oct x irr_oct irradiance map; 0, or
 * -1 (out of memory, or rays < 1, oct < 1, irr_oct < 1).
 * Frees t's arrays first, so a table can be made again in place. */
int lpv_probes_table_make(lpv_probes_table *t, uint32_t tick, uint32_t seed, uint32_t rays, int oct,
                          float sharpness, int irr_oct);

void lpv_probes_table_free(lpv_probes_table *t);

#endif
