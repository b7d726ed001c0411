/*
 * probes_math.h - the probes' per-ray and per-texel math, plain C (issue 34;
 * Majercik et al., "Dynamic Diffuse Global Illumination with Ray-Traced
 * Irradiance Fields", JCGT 2019): the ray directions a probe shoots in a
 * tick, the octahedral map its distance moments are stored in, the L1 SH
 * its irradiance is kept as (core/sh.h's basis), and the Chebyshev weight
 * with which a lookup discounts a probe a surface may be hidden from. The
 * CPU oracle of the probes' shaders, which will compute the same.
 */
#ifndef LPV_PROBES_MATH_H
#define LPV_PROBES_MATH_H

#include <stdint.h>

/* Direction i of n (0 <= i < n) of the spherical Fibonacci set: n points
 * of equal area on the unit sphere, the i-th at height z = 1 - (2i + 1) / n
 * and turned by the golden angle from the one before (Keinert et al.,
 * "Spherical Fibonacci Mapping", 2015). Stratified: every region of the
 * sphere gets rays in proportion to its area. */
void lpv_probes_fibonacci(uint32_t i, uint32_t n, float out[3]);

/* A rotation (row-major 3 x 3, orthonormal, determinant +1) drawn uniformly
 * from the tick's number and a seed (Shoemake's quaternion from three
 * uniform numbers): the probes turn their ray set by it each tick, so over
 * ticks their rays cover every direction rather than the same n. */
void lpv_probes_rotation(uint32_t tick, uint32_t seed, float m[9]);

/* The i-th ray of a tick: m times lpv_probes_fibonacci(i, n). */
void lpv_probes_ray(uint32_t i, uint32_t n, const float m[9], float out[3]);

/* The octahedral map (Cigolle et al., JCGT 2014): unit direction d to
 * uv in [-1, 1]^2, the upper hemisphere inside |u| + |v| <= 1 and the
 * lower one folded over the corners; decode is its inverse (a unit
 * vector). A probe's distance moments are stored per texel of this map. */
void lpv_probes_oct_encode(const float d[3], float uv[2]);
void lpv_probes_oct_decode(const float uv[2], float d[3]);

/* Adds radiance sample l (W/(m^2 sr), rgb) arriving from unit direction d,
 * one of n uniform directions over the sphere, to the L1 SH projection of
 * the radiance, sh[channel][4]: each sample stands for 4 pi / n sr. */
void lpv_probes_sh_add(float sh[3][4], const float d[3], const float l[3], uint32_t n);

/* The irradiance (W/m^2, rgb) on a surface of unit normal nrm from the
 * radiance's SH: the product's integral with the clamped cosine's lobe
 * (core/sh.h), exact for radiance of bands 0 and 1. */
void lpv_probes_sh_irradiance(const float sh[3][4], const float nrm[3], float e[3]);

/* How much a probe at mean distance `mean` (and mean square `mean2`) in
 * the direction of a surface at distance d can be trusted to see it: 1 when
 * d <= mean, else the one-sided Chebyshev bound var / (var + (d - mean)^2),
 * cubed as the paper does, to cut the long tail that leaks light through
 * thin walls. var is mean2 - mean^2 kept at least `min_var` (rounding makes
 * it negative). 0 for non-finite input. */
float lpv_probes_chebyshev(float mean, float mean2, float d, float min_var);

#endif /* LPV_PROBES_MATH_H */
