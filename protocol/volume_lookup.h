/*
 * volume_lookup.h - irradiance from a decoded volume, for clients.
 *
 * R5.7 (the LPV's cascades): the cascade to read at a point and the blend
 * across cascade borders. The SH lookup inside one cascade is core's
 * reference lookup (techniques/lpv/core/oracle.h lpv_oracle_irradiance: the half-cell
 * offset, trilinear filtering clamped at the edge, the cosine lobe, /
 * cell_size^2), so the client's answer and the oracle tests' are the same
 * code; this file adds only what the SPEC defines on top of it.
 *
 * R5.14 (technique iv's voxels): the imperfect volume's reconstruction, core's
 * reference (techniques/iv/core/oracle_iv.h lpv_iv_irradiance_held) on the volume and its
 * index of surface-holding voxels.
 *
 * R5.15 (technique probes with their visibility): the probes' weighted
 * lookup, core's reference (techniques/probes/core/probes_lookup.h
 * lpv_probes_irradiance) on the records the visibility carries.
 *
 * Part of the lpv_protocol library, which therefore links lpv_core
 * (protocol -> core; core never includes protocol).
 */
#ifndef LPVP_VOLUME_LOOKUP_H
#define LPVP_VOLUME_LOOKUP_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* One cascade of a decoded volume (R5.6). */
typedef struct lpvp_lookup_cascade {
    int dims[3];          /* cells per axis, each >= 1 */
    float origin[3];      /* m, lower corner */
    float cell_size;      /* m, > 0 */
    const float *cells;   /* dims' product x 12 floats in the wire order (R5.1), 16-byte aligned
                             (malloc'd buffers are; each cascade starts a multiple of 48 bytes in) */
} lpvp_lookup_cascade;

/* Irradiance (W/m^2, rgb) at p for a surface with normal n from one cascade
 * (lpv_oracle_irradiance). Returns 0, or -1 (rgb zero) for a cascade that
 * is not usable: no cells, misaligned cells, dims < 1 or a cell size <= 0. */
int lpvp_cascade_irradiance(const lpvp_lookup_cascade *cs, const float p[3], const float n[3], float rgb[3]);

/* R5.7 over count (1..4) cascades, finest first: the finest cascade whose
 * box contains p (the coarsest when none does); within 3 of its cells of its
 * border, blended with the next coarser one containing p,
 * E = lerp(E_coarser, E_fine, clamp((d - 1) / 2, 0, 1)), d the distance to
 * the border in the finer cascade's cells. Returns 0, or -1 as above. */
int lpvp_volume_irradiance(const lpvp_lookup_cascade *cs, int count, const float p[3], const float n[3],
                           float rgb[3]);

/* An iv volume (SPEC R5.14): one level of cubic voxels, the radiance
 * arriving at each voxel's centre (W/(m^2 sr)) as 12 SH values, and which
 * voxels hold a surface. */
typedef struct lpvp_lookup_iv {
    int dims[3];           /* voxels per axis, each >= 1 */
    float origin[3];       /* m, lower corner */
    float cell_size;       /* m, > 0: the voxels' side */
    const float *cells;    /* dims' product x 12 floats in the wire order (R5.1), 16-byte aligned */
    const uint32_t *held;  /* dims' product flags, the description's index: non-zero = holds a surface */
    int neighbours;        /* 1..8: the description's iv_neighbours */
} lpvp_lookup_iv;

/* Irradiance (W/m^2, rgb) at p for a surface with normal n by R5.14's
 * reconstruction (lpv_iv_irradiance_held). Returns 0, or -1 (rgb zero) for a
 * volume that is not usable: no cells or flags, misaligned cells, dims < 1, a
 * cell size <= 0, neighbours outside 1..8. */
int lpvp_iv_irradiance(const lpvp_lookup_iv *v, const float p[3], const float n[3], float rgb[3]);

/* A probes' volume with its visibility (SPEC R5.15): the levels'
 * placement and every probe's record (the description's values_per_probe
 * floats each, level 0's probes first, x fastest). */
typedef struct lpvp_lookup_probes {
    int count;                         /* levels, 1..4, finest first */
    lpvp_lookup_cascade levels[4];     /* dims, origin, cell_size (cells unused) */
    const float *records;              /* the visibility's probes x values_per_probe floats */
    int irradiance_side, distance_side; /* the description's */
    float bias_cells;
} lpvp_lookup_probes;

/* Irradiance (W/m^2, rgb) at p for a surface with normal n by R5.15's
 * visibility-weighted lookup (techniques/probes/core/probes_lookup.c
 * lpv_probes_irradiance, the oracle of the server's). Returns 0, or -1
 * (rgb zero) for a volume that is not usable: no records, levels outside
 * 1..4, dims < 1, a cell size <= 0, a map side < 1. */
int lpvp_probes_irradiance(const lpvp_lookup_probes *v, const float p[3], const float n[3], float rgb[3]);

#ifdef __cplusplus
}
#endif

#endif /* LPVP_VOLUME_LOOKUP_H */
