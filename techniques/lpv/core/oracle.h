/*
 * oracle.h - the plain-C reference implementation of the LPV pipeline.
 *
 * Straightforward loops, no GL, sharing only shaders/lpv_shared.h with the
 * shaders. The tests feed the same VPLs and surfels (read back from the GPU)
 * to both and compare grids. docs/propagation.md states the algorithm; every
 * function here follows it literally so the GLSL can be checked against it.
 */
#ifndef LPV_ORACLE_H
#define LPV_ORACLE_H

#include <stddef.h>
#include "lpv_shared.h"
#include "grid.h"

typedef struct LpvCell lpv_cell;
typedef struct LpvVpl lpv_vpl;
typedef struct LpvSurfel lpv_surfel;
typedef struct LpvGvPoint lpv_gv_point;

/* Adds each valid VPL (position.w != 0, finite, unit-able normal) to the cell
 * containing position + 0.5 * cell_size * normal, as lobe(normal) * flux / pi
 * per channel, in array order. VPLs landing outside the grid are dropped.
 * Returns the number injected. */
size_t lpv_oracle_inject_vpls(const lpv_grid *g, const lpv_vpl *vpls, size_t n, lpv_cell *cells);
/* Smooth injection (settings lpv.smooth_injection, grid.glsl
 * vpl_stencil_at): each valid VPL spread over the 2 x 2 cells around
 * position + 0.5 * cell_size * normal in the two axes but the normal's
 * dominant one, with bilinear weights, and along that axis into the cell
 * lpv_oracle_inject_vpls would use. Corners outside the grid are dropped.
 * Returns the number of VPLs that gave a cell light. */
size_t lpv_oracle_inject_vpls_spread(const lpv_grid *g, const lpv_vpl *vpls, size_t n, lpv_cell *cells);

/* Adds each valid surfel (area > 0, finite, unit-able normal) to its nearest
 * GV point as (area / cell_size^2) * lobe(normal). gv has lpv_grid_gv_count
 * entries. Returns the number injected. */
size_t lpv_oracle_inject_surfels(const lpv_grid *g, const lpv_surfel *surfels, size_t n, vec4 *gv);

/* Merges one buffer's GV (SH per point, as lpv_oracle_inject_surfels builds
 * it) into the total: per GV point and travel direction d (+x -x +y -y +z -z)
 * the total keeps the larger of its blocking and B(-d) = dot(src, Y(-d)); a
 * NaN wins and stays. So a surface seen by two buffers is not counted twice,
 * and a wall two buffers saw from opposite sides blocks both ways. A zeroed
 * total is the empty one. Only the blocking is merged: the oracle has no
 * albedo, the total's albedo is left as it is. */
void lpv_oracle_gv_merge(const lpv_grid *g, const vec4 *src, lpv_gv_point *dst);

/* Per cell and direction (order +x -x +y -y +z -z, the direction light
 * travels), the transmittance 1 - clamp(B / LPV_GV_PEAK, 0, 1) of the face
 * through which light from the neighbour at cell - d enters, with B the
 * total's blocking for d averaged over the face's four corners (a non-finite
 * B gives 0). t has 6 * cell_count floats. */
void lpv_oracle_transmittance(const lpv_grid *g, const lpv_gv_point *gv, float *t);

/* One propagation step, flux-limited (docs/propagation.md): in -> out (out is
 * overwritten). t NULL means no occlusion. */
void lpv_oracle_propagate_step(const lpv_grid *g, const lpv_cell *in, const float *t, lpv_cell *out);

/* The whole propagation: acc = injected + sum over iterations of each step's
 * output; occlusion (t non-NULL) is skipped on the first step. Allocates its
 * own ping-pong buffers. Returns 0, or -1 on allocation failure. */
int lpv_oracle_propagate(const lpv_grid *g, const lpv_cell *injected, const float *t, int iterations,
                         lpv_cell *acc);

/* The same with a transport (LPV_TRANSPORT_PAPER or LPV_TRANSPORT_CENTRAL,
 * lpv_shared.h; docs/propagation.md section 4b). The functions above use the
 * paper's. */
void lpv_oracle_propagate_step_with(const lpv_grid *g, const lpv_cell *in, const float *t, int transport,
                                    lpv_cell *out);
int lpv_oracle_propagate_with(const lpv_grid *g, const lpv_cell *injected, const float *t, int iterations,
                              int transport, lpv_cell *acc);

/* The whole propagation's loop with any step (the oracle's, or a trial
 * transport's in bench/lpv_plane_reach.c): step(g, in, t or NULL, ctx, out)
 * overwrites out; acc, occlusion and the return as lpv_oracle_propagate. */
typedef void (*lpv_oracle_step_fn)(const lpv_grid *g, const lpv_cell *in, const float *t, void *ctx, lpv_cell *out);
int lpv_oracle_propagate_steps(const lpv_grid *g, const lpv_cell *injected, const float *t, int iterations,
                               lpv_oracle_step_fn step, void *ctx, lpv_cell *acc);

/* Normal bins (docs/propagation.md section 6b). The bin of a unit normal: its
 * dominant axis and sign in the direction order +x -x +y -y +z -z (ties go to
 * the lower axis). */
int lpv_oracle_normal_bin(const float n[3]);
/* As lpv_oracle_inject_vpls, into the volume of each VPL's normal bin:
 * cells holds LPV_NORMAL_BINS grids, bin b at b * cell count. */
size_t lpv_oracle_inject_vpls_binned(const lpv_grid *g, const lpv_vpl *vpls, size_t n, lpv_cell *cells);
/* Irradiance from LPV_NORMAL_BINS accumulated grids (bin b at b * cell count):
 * per bin, the intensity reconstructed on the bin's half-space and
 * integrated against the surface's cosine (lpv_oracle_bin_weights), summed,
 * / cell_size^2, clamped at 0 per channel. Same point offset and
 * interpolation as lpv_oracle_irradiance. */
void lpv_oracle_irradiance_binned(const lpv_grid *g, const lpv_cell *acc, const float p[3], const float n[3],
                                  float rgb[3]);
/* The weights W of bin b for a surface with unit normal n: E_b = dot(c, W). */
void lpv_oracle_bin_weights(int b, const float n[3], float w[4]);

/* Irradiance (W/m^2, rgb) at p for a surface with normal n (normalised here;
 * a degenerate n or NaN p gives 0): max(0, dot(c(q), lobe(-n)) / cell_size^2)
 * with q = p + 0.5 * cell_size * n (half a cell in front of the surface) and c
 * trilinearly interpolated between cell centres, clamped at the grid's edge. */
void lpv_oracle_irradiance(const lpv_grid *g, const lpv_cell *acc, const float p[3], const float n[3], float rgb[3]);

/* Total flux (W) of a grid per channel: sum of c0 * sqrt(4 pi). */
void lpv_oracle_total_flux(const lpv_grid *g, const lpv_cell *cells, double flux[3]);

#endif /* LPV_ORACLE_H */
