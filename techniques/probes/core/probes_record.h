/*
 * probes_record.h - a probe's record, the one layout the engine reads back
 * (lpv_engine_read_visibility), the CPU lookup reads (probes_lookup.c) and
 * SPEC R5.15 sends (protocol/volume_layout.c, volume_header_parse.c). Header
 * only, so the protocol's codec, which links no engine code (its fuzzer
 * compiles it alone), shares it.
 *
 * Floats: the probe's offset from its cell's centre (m, 3), active (1, or
 * 0: off), the irradiance map (irradiance_side^2 texels of rgb, W/m^2),
 * then the distance map (distance_side^2 texels of mean and mean square hit
 * distance, m and m^2); each map row by row on the octahedral map
 * (probes_math.h).
 */
#ifndef LPV_PROBES_RECORD_H
#define LPV_PROBES_RECORD_H

#include <stddef.h>

#define LPV_PROBES_RECORD_OFFSET 0
#define LPV_PROBES_RECORD_ACTIVE 3
#define LPV_PROBES_RECORD_IRRADIANCE 4

/* Where the distance map starts. */
static inline size_t lpv_probes_record_distance_at(int irradiance_side)
{
    return LPV_PROBES_RECORD_IRRADIANCE + 3 * (size_t)irradiance_side * (size_t)irradiance_side;
}

/* Floats a record: 4 + 3 irradiance_side^2 + 2 distance_side^2. */
static inline size_t lpv_probes_record_values(int irradiance_side, int distance_side)
{
    return lpv_probes_record_distance_at(irradiance_side) + 2 * (size_t)distance_side * (size_t)distance_side;
}

#endif
