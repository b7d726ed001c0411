/*
 * probes_lookup.h - the probes' lookup on the CPU: each probe's record of
 * what the lookup needs (the layout the engine reads back and SPEC R5.15
 * sends), and the irradiance at a surface point from the probes around it,
 * weighted by their visibility (Majercik et al. 2019, section 4). The
 * oracle of shaders/probes_lookup.glsl's lpv_irradiance, step for step; the
 * clients' R5.15 lookup (protocol/volume_lookup.c) is this code.
 */
#ifndef LPV_PROBES_LOOKUP_H
#define LPV_PROBES_LOOKUP_H

#include <stddef.h>

#include "lpv_shared.h" /* the lookup's weights, LPV_PROBES_FACING_FLOOR .. LPV_PROBES_UNSEEN */
#include "probes_record.h" /* a probe's record: its layout and size */

/* One level of probes (a cascade): a probe at each cell's centre. */
typedef struct lpv_probes_level {
    int dims[3];           /* probes per axis, each >= 1 */
    float origin[3];       /* m, the lower corner of the cells */
    float cell_size;       /* m, > 0 */
    const float *records;  /* dims' product records, x fastest */
} lpv_probes_level;

typedef struct lpv_probes_field {
    int levels; /* 1..4, finest first */
    lpv_probes_level level[4];
    int irradiance_side, distance_side; /* each >= 1 */
    float bias_cells;                   /* the point moves this far along the normal (cells) */
} lpv_probes_field;

/* Bilinear weights w over the four texel centres around unit d's place
 * on a side x side octahedral map, clamped at its edge: texel indices in i
 * (row * side + column). */
void lpv_probes_oct_bilinear(int side, const float d[3], int i[4], float w[4]);

/* The irradiance (W/m^2, rgb) at p on a surface of normal n (of a length
 * in (1e-8, 1e18); else, or for a non-finite p or n, no light) from level
 * k's probes alone;
 * returns how much of them sees p (0 when every probe around it is off or
 * hidden from it). */
float lpv_probes_irradiance_in(const lpv_probes_field *f, int k, const float p[3], const float n[3], float e[3]);

/* The irradiance (W/m^2, rgb) at p on a surface of normal n from every
 * level: the finest whose probes surround p, the next coarser where none of
 * its probes sees p, blended into the next coarser over two cells before
 * its last probes. Returns 0, or -1 (zero light) for a field that is not
 * usable (levels outside 1..4, no records, dims < 1, a cell size <= 0, a
 * map side < 1). */
int lpv_probes_irradiance(const lpv_probes_field *f, const float p[3], const float n[3], float e[3]);

#endif /* LPV_PROBES_LOOKUP_H */
