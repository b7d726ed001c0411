/*
 * pt.h - the path-traced reference for lpvd's indirect light (issue 4,
 * docs/reference.md).
 *
 * Built on Embree from the same lpv_scene lpvd renders, in the same
 * radiometric units (W/m^2 irradiance, W/(m^2 sr) radiance). The quantity is
 *
 *   E_ind(p, n, b) = integral over the hemisphere of n of
 *                    L_o^b(hit(p, w), -w) cos(n, w) dw
 *   L_o^b(q)       = L_e(q) + albedo(q)/pi * (E_direct(q, n_q)
 *                                             + [b > 1] E_ind(q, n_q, b - 1))
 *
 * with E_direct the shadowed irradiance from the punctual lights (exactly the
 * KHR_lights_punctual falloffs of shaders/lights.glsl), L_e the material's
 * emission on the front side of an emissive triangle, and on its back too
 * when the material is double-sided (glTF doubleSided; core/emissive.c's and
 * core/area_lights.c's rule),
 * n_q the surface normal on the side the ray arrived from. b = 1 is the term
 * lpvd's LPV approximates with area lights off (`lpvd render --indirect-only
 * --area-lights off` = albedo/pi * E_lpv).
 *
 * With emitters_are_lights (lpvd's default, area lights on) the emissive
 * surfaces are light sources like the punctual lights: E_direct(q) also holds
 * their shadowed irradiance (next-event estimation on the emitters by power),
 * L_e is never counted when a path hits an emitter, and E_ind(p, n, b) is
 * b diffuse reflections of that direct light, without the direct light at p.
 * The full image (lpv_ref_render_full) is the same in both modes:
 *   L = L_e(p) + albedo/pi * (E_direct(p) + E_ind(p, n, b))   (emitters as lights)
 *
 * Monte Carlo: cosine-weighted hemisphere samples, E = pi * mean(L); every
 * estimate carries its standard error (sample std / sqrt(n)). Each pixel or
 * point draws from its own PCG32 stream seeded by (index, sample), so results
 * are bit-identical across runs and thread counts.
 */
#ifndef LPV_REFERENCE_PT_H
#define LPV_REFERENCE_PT_H

#include <stddef.h>
#include <stdint.h>

#include "scene.h"
#include "view.h"

typedef struct lpv_ref lpv_ref;

typedef struct lpv_ref_desc {
    int threads;       /* worker threads; 0 = the number of online cores */
    uint64_t seed;     /* mixed into every RNG stream; 0 = the default stream */
    float ray_epsilon; /* m; ray offset off surfaces; 0 = 1e-4 x bounds diagonal (>= 1e-6) */
    int emitters_are_lights; /* 1: emissive surfaces are lights (their direct light is not in E_ind),
                                the split lpvd makes with area lights on; 0: emission seen directly
                                is part of E_ind (area lights off) */
    int max_bounces;         /* the cap on a converged path's bounces (LPV_REF_BOUNCES_CONVERGED);
                                0 = LPV_REF_MAX_BOUNCES_DEFAULT; ignored by fixed bounce counts */
} lpv_ref_desc;

/* `bounces` value: converged light, i.e. every bounce until the path's
 * throughput is negligible. Paths run unchanged for LPV_REF_RR_START bounces,
 * then survive each further bounce with probability
 * q = min(0.95, max channel of the throughput) and divide by q (Russian
 * roulette: unbiased), up to lpv_ref_desc.max_bounces. Light that needs more
 * bounces than the cap is the only thing missing (a closed box of albedo a
 * loses a^cap of it: 0.8^64 = 6e-7). Fixed bounce counts never use roulette
 * and are bit-identical to what they always were. */
#define LPV_REF_BOUNCES_CONVERGED (-1)
#define LPV_REF_MAX_BOUNCES_DEFAULT 64
#define LPV_REF_RR_START 3

/* Builds the reference for a scene (copied: the scene may be freed after).
 * Triangles with out-of-range indices, non-finite corners or zero area are
 * skipped; a non-finite or zero vertex normal falls back to the geometric
 * one. desc may be NULL (defaults). Returns 0, or -1 with a message in err. */
int lpv_ref_create(const lpv_scene *scene, const lpv_ref_desc *desc, lpv_ref **out, char *err, size_t err_size);
void lpv_ref_destroy(lpv_ref *ref);

/* Triangles kept (after skipping the degenerate ones). */
uint32_t lpv_ref_triangle_count(const lpv_ref *ref);
/* The resolved thread count. */
int lpv_ref_threads(const lpv_ref *ref);

/* Shadowed irradiance (W/m^2, rgb) at p on a surface with normal n (need not
 * be unit) from the punctual lights only. Deterministic (no sampling): equals
 * sum over lights of colour * intensity * spot * window / d^2 * max(0, cos),
 * for each light whose shadow ray is unblocked. A non-finite p or degenerate n
 * gives 0. */
void lpv_ref_direct_irradiance(const lpv_ref *ref, const float p[3], const float n[3], float out_rgb[3]);

/* E_ind at n points (points, normals: 3 floats each), `bounces` >= 1 or
 * LPV_REF_BOUNCES_CONVERGED,
 * `samples` >= 1 per point. out_rgb and out_stderr_rgb (either may be NULL)
 * get 3 floats per point: the estimate and its standard error. A point with a
 * non-finite position or degenerate normal gets 0 and 0. Returns 0, or -1 on
 * bad arguments / allocation failure. */
int lpv_ref_irradiance(const lpv_ref *ref, const float *points, const float *normals, size_t n, int bounces,
                       int samples, float *out_rgb, float *out_stderr_rgb);

/* The indirect-only image: per pixel (width * height * 4 floats, top row
 * first) albedo/pi * E_ind(bounces) at the first surface the ray through the
 * pixel centre hits (normal turned towards the camera), alpha 1; background 0
 * (bounces >= 1 or LPV_REF_BOUNCES_CONVERGED)
 * with alpha 0. rgba_stderr (may be NULL) gets the standard error of each
 * channel (alpha: as the image). Returns 0, or -1 on bad arguments. */
int lpv_ref_render_indirect(const lpv_ref *ref, const lpv_view *view, int bounces, int samples_per_pixel,
                            float *rgba_radiance, float *rgba_stderr);

/* The full image: per pixel L_e (emitting side) + albedo/pi * (E_direct +
 * E_ind(bounces)) at the first surface, emitters as lights whatever the
 * desc says: bounces = diffuse reflections of direct light, punctual and
 * emitted alike (1 = what lpvd's full frame approximates; 0 = direct only;
 * LPV_REF_BOUNCES_CONVERGED = every bounce, what a user sees).
 * Punctual light is exact, the emitters' direct light and the bounces are
 * sampled (samples_per_pixel each); rgba_stderr (may be NULL) as in
 * lpv_ref_render_indirect. Returns 0, or -1 on bad arguments. */
int lpv_ref_render_full(const lpv_ref *ref, const lpv_view *view, int bounces, int samples_per_pixel,
                        float *rgba_radiance, float *rgba_stderr);

/* The emissive surfaces' shadowed direct irradiance (W/m^2, rgb) at n points
 * (normals need not be unit), by next-event estimation with `samples`
 * samples each; out_stderr_rgb (may be NULL) its standard error. Returns 0,
 * or -1 on bad arguments. */
int lpv_ref_emitter_irradiance(const lpv_ref *ref, const float *points, const float *normals, size_t n, int samples,
                               float *out_rgb, float *out_stderr_rgb);

/* The primary ray of pixel (x, y) through its centre, the inverse of
 * lpv_view_project: origin, unit direction, and the [tmin, tmax] range the
 * view's znear/zfar allow (0 / INFINITY when unset). */
void lpv_ref_pixel_ray(const lpv_view *view, int x, int y, float org[3], float dir[3], float *tmin, float *tmax);

/* The first surface along a ray (dir need not be unit) within [tmin, tmax]:
 * returns 1 and its distance t and point p (either may be NULL), or 0. */
int lpv_ref_first_hit(const lpv_ref *ref, const float org[3], const float dir[3], float tmin, float tmax, float *t,
                      float p[3]);

/* As lpv_ref_first_hit, and n (may be NULL) gets the unit shading normal
 * there, turned towards the side the ray came from (the normal
 * lpv_ref_direct_irradiance wants for the surface the ray sees). */
int lpv_ref_first_surface(const lpv_ref *ref, const float org[3], const float dir[3], float tmin, float tmax,
                          float *t, float p[3], float n[3]);

/* Mean relative standard error of an image: the mean of se / value over the
 * rgb channels of covered pixels (alpha > 0) whose value is > 0; 0 if none. */
double lpv_ref_mean_relative_stderr(const float *rgba, const float *rgba_stderr, int width, int height);

#endif /* LPV_REFERENCE_PT_H */
