/*
 * sh.h - two-band real spherical harmonics (4 coefficients), the basis and
 * lobe conventions of shaders/lpv_shared.h. Plain C, no GL.
 */
#ifndef LPV_SH_H
#define LPV_SH_H

/* Basis functions at unit direction d: out = (C0, C1 d.y, C1 d.z, C1 d.x). */
void lpv_sh_basis(const float d[3], float out[4]);

/* Coefficients of the clamped cosine max(0, <n, w>) around unit n. */
void lpv_sh_cosine_lobe(const float n[3], float out[4]);

/* Evaluates coefficients c at unit direction d. */
float lpv_sh_eval(const float c[4], const float d[3]);

/* Integral over the sphere of the function with coefficients c: c0 sqrt(4 pi). */
float lpv_sh_integral(const float c[4]);

/* Integral over the sphere of the product of two functions: dot(a, b). */
float lpv_sh_dot(const float a[4], const float b[4]);

/* A direction is usable when it is finite and longer than 1e-8 (length
 * computed in float, as in the shaders, so one whose length overflows is
 * rejected too); then out = in / |in| and 1 is returned, else 0. */
int lpv_unit_direction(const float in[3], float out[3]);
/* A VPL's or surfel's normal (docs/propagation.md section 3c): a unit
 * normal, or the weighted mean of the unit normals of the samples a
 * down-sampled VPL or surfel stands for (length <= 1, shorter where they
 * differ, so the lobe it injects is the sum of theirs). Longer vectors are
 * normalised. 0 for a non-finite or (nearly) zero vector, as
 * lpv_unit_direction. */
int lpv_mean_direction(const float in[3], float out[3]);

#endif /* LPV_SH_H */
