/*
 * metrics.h - how far an lpvd frame is from a path-traced reference
 * (docs/accuracy.md). Plain C, no GL: usable by the sweep driver and tests.
 *
 * Images are linear RGBA float, width*height*4, top row first, radiance in
 * W/(m^2 sr). A pixel takes part when its alpha is > 0.5 in BOTH the lpvd
 * frame and the reference ("seen by both"). All averages are over those
 * pixels and over the three colour channels R, G, B with equal weight (per
 * channel, not luminance-weighted):
 *
 *   mean(X)   = sum_{p,c} X[p,c] / (3 N)
 *   rel_rmse  = sqrt(mean((L - R)^2)) / mean(R)
 *   rel_bias  = (mean(L) - mean(R)) / mean(R)
 *   ref_noise = sqrt(mean(S^2)) / mean(R)          S = the reference's standard error
 *   rel_rmse_excess = sqrt(max(0, mean((L - R)^2) - mean(S^2))) / mean(R)
 *   rel_mae   = mean(|L - R|) / mean(R)            (less dominated by hot spots)
 *
 * rel_rmse^2 ~= rel_rmse_excess^2 + ref_noise^2 when the reference's noise is
 * independent of lpvd's error, so ref_noise tells how much of the measured
 * error is the reference's own noise, and rel_rmse_excess is the rest.
 */
#ifndef LPV_ACCURACY_METRICS_H
#define LPV_ACCURACY_METRICS_H

#include <stddef.h>
#include <stdint.h>

typedef struct lpv_acc_metrics {
    size_t pixels;          /* pixels seen by both (alpha > 0.5 in both) */
    double mean_lpv;        /* mean(L), W/(m^2 sr) */
    double mean_ref;        /* mean(R), W/(m^2 sr) */
    double rel_rmse;        /* sqrt(mean((L-R)^2)) / mean(R) */
    double rel_bias;        /* (mean(L) - mean(R)) / mean(R) */
    double ref_noise;       /* sqrt(mean(S^2)) / mean(R); 0 without a stderr image */
    double rel_rmse_excess; /* the part of rel_rmse above the reference's noise */
    double rel_mae;         /* mean(|L-R|) / mean(R) */
} lpv_acc_metrics;

/* Compares lpv against ref (both RGBA). ref_stderr may be NULL (no noise
 * estimate): RGBA, its alpha is ignored. Returns 0, or -1 when no pixel is
 * seen by both or mean(R) <= 0 (then the relative metrics are undefined; out
 * still gets pixels and the means, the rest NaN). */
int lpv_acc_compare(const float *lpv, const float *ref, const float *ref_stderr, int width, int height,
                    lpv_acc_metrics *out);

/* What a rel_rmse is worth, over the pixels seen by both: the rel_rmse an
 * all-black image would score (sqrt(mean(R^2)) / mean(R)) and an image
 * holding mean(R) everywhere (the reference's own spread, std(R) / mean(R)).
 * An LPV scoring above `constant` places its light worse than no placement
 * at all. NaN when no pixel is seen by both or mean(R) <= 0. */
void lpv_acc_baselines(const float *lpv, const float *ref, int width, int height, double *black, double *constant);

/* Regions of the image by the facing of the surface a pixel sees (from the
 * reference's primary rays): up-facing (floors, tops), down-facing (ceilings)
 * and the rest (walls). */
enum { LPV_ACC_REGION_FLOOR = 0, LPV_ACC_REGION_CEILING = 1, LPV_ACC_REGION_WALLS = 2, LPV_ACC_REGIONS = 3,
       LPV_ACC_REGION_NONE = 255 };
/* The region of a unit normal: n.y > 0.7 floor, n.y < -0.7 ceiling, else walls. */
int lpv_acc_region_of(const float n[3]);

/* Per region r: share[r] = the region's part of the squared error (sum of
 * (L-R)^2 over its pixels / the sum over all pixels seen by both), rmse[r] =
 * sqrt(mean over its pixels of (L-R)^2) / the global mean(R) (so the regions'
 * rmse^2 weighted by their pixel fractions add up to rel_rmse^2), and
 * ratio[r] = mean(L) / mean(R) over its pixels. NaN where a region has no
 * pixel. region: one byte per pixel (LPV_ACC_REGION_*). */
void lpv_acc_region_errors(const float *lpv, const float *ref, const uint8_t *region, int width, int height,
                           double share[LPV_ACC_REGIONS], double rmse[LPV_ACC_REGIONS],
                           double ratio[LPV_ACC_REGIONS]);

/* The signed relative error of one pixel, as the error image shows it:
 *   e = (l - r) / max(r, floor_frac * mean(R))
 * with l, r the pixel's mean over R, G, B, so dark reference pixels do not
 * blow up (floor_frac: LPV_ACC_ERROR_FLOOR). */
#define LPV_ACC_ERROR_FLOOR 0.1
double lpv_acc_pixel_error(const float *lpv_px, const float *ref_px, double mean_ref);

/* The diverging colour map: e <= -1 blue (0,0,255) (lpvd too dark), 0 white,
 * e >= +1 red (255,0,0) (lpvd too bright), linear in between; NaN -> black. */
void lpv_acc_error_colour(double e, uint8_t rgb[3]);

/* Fills rgb (width*height*3 bytes) with the error image: each pixel seen by
 * both coloured by lpv_acc_error_colour(lpv_acc_pixel_error(...)), the other
 * pixels black (0,0,0). mean_ref as lpv_acc_compare computed it. */
void lpv_acc_error_image(const float *lpv, const float *ref, int width, int height, double mean_ref,
                         uint8_t *rgb);

/* Writes the error image as a PNG (image_io.h). Returns 0 or -1 (err). */
int lpv_acc_write_error_png(const char *path, const float *lpv, const float *ref, int width, int height,
                            double mean_ref, char *err, size_t err_size);

/* Marks the Pareto front of n points minimising both cost[i] and error[i]:
 * front[i] = 1 when no other point is at most as costly and at most as wrong
 * and strictly better in one of them; NaN points are never on the front.
 * Returns the number of points on the front. */
size_t lpv_acc_pareto(const double *cost, const double *error, size_t n, int *front);

/* The median of n values (sorts a copy; NaN for n == 0). */
double lpv_acc_median(const double *v, size_t n);

#endif
