/*
 * probes_update.h - one tick of the probes on the CPU: each probe shoots
 * its rays (probes_math.h's set, turned by the tick's rotation) through the
 * scene's BVH (probes_bvh.h), and what comes back becomes its irradiance
 * (L1 SH of the radiance its rays saw), its distance moments (mean and mean
 * square of the hit distance per texel of an octahedral map, each ray
 * weighted by how close its direction is to the texel's) and the share of
 * its rays that hit a back face (a probe inside geometry sees mostly back
 * faces: the relocation and deactivation of issue 34 item 4 read it).
 *
 * The oracle of the probes' update shader; the radiance leaving a hit is
 * the caller's (lpv_probes_shade_fn), so this file knows rays and
 * statistics only, not lights or materials.
 */
#ifndef LPV_PROBES_UPDATE_H
#define LPV_PROBES_UPDATE_H

#include <stddef.h>
#include <stdint.h>

#include "probes_bvh.h"

/* Most texels per side of a probe's distance map (DDGI uses 16). */
#define LPV_PROBES_OCT_MAX 32

/* The radiance (W/(m^2 sr), rgb) leaving triangle tri at point p toward the
 * probe, the ray having come along unit direction d and travelled t. */
typedef void (*lpv_probes_shade_fn)(void *ctx, uint32_t tri, const float p[3], const float d[3], float t, float l[3]);

typedef struct lpv_probes_update_desc {
    const lpv_probes_bvh *bvh;
    const float *positions; /* xyz per probe */
    size_t probe_count;
    uint32_t rays;          /* per probe, >= 1 */
    uint32_t tick, seed;    /* the rotation of the ray set (lpv_probes_rotation) */
    float max_distance;     /* m: a ray that hits nothing counts as this far (and rays stop there) */
    int oct_size;           /* texels per side of the distance map, 1..LPV_PROBES_OCT_MAX */
    float sharpness;        /* the moments' weight max(0, cos)^sharpness of a ray about a texel's direction */
    lpv_probes_shade_fn shade; /* NULL: every hit sends 0 */
    void *ctx;
    const float *sky;       /* rgb radiance of a ray that hits nothing; NULL: 0 */
} lpv_probes_update_desc;

/* What one probe keeps. moments: oct_size^2 texels of (mean, mean square)
 * distance, m and m^2, texel (x, y) at 2 (y oct_size + x); a texel no ray
 * weighted holds max_distance. */
typedef struct lpv_probe_result {
    float sh[3][4];
    float *moments;
    float backface_share; /* of its rays, those that hit a triangle's back (its winding's normal facing the ray) */
} lpv_probe_result;

/* The direction a texel of the octahedral map stands for (its centre). */
void lpv_probes_texel_dir(int x, int y, int oct_size, float d[3]);

/* Updates every probe into out[0 .. probe_count) (each moments array
 * oct_size^2 x 2 floats, the caller's). Returns 0, or -1 (nothing written)
 * for a description it cannot run: no BVH or positions, no rays, an
 * oct_size outside 1..LPV_PROBES_OCT_MAX, a max_distance not > 0. */
int lpv_probes_update_cpu(const lpv_probes_update_desc *d, lpv_probe_result *out);

#endif /* LPV_PROBES_UPDATE_H */
