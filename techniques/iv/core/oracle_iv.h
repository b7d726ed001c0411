/*
 * oracle_iv.h - the plain-C reference of imperfect volumes (Mavridis &
 * Papaioannou, the third seed, sections 3.1 to 3.5). It plays for the GPU
 * technique in techniques/iv/gpu/ the role techniques/lpv/core/oracle.h plays for the cascaded LPV:
 * literal loops the shaders are checked against. No GL.
 *
 * Conventions (shaders/lpv_shared.h): the grid is an lpv_grid of cubic
 * voxels of side s, voxel (x, y, z) at lpv_grid_index (x fastest), centre
 * origin + (v + 0.5) s. SH are 2-band, (Y00, Y1-1, Y10, Y11), basis
 * Y(d) = (C0, C1 d.y, C1 d.z, C1 d.x), lobe(n) = (LOBE0, LOBE1 n.y, LOBE1 n.z,
 * LOBE1 n.x), hemi(n) = (LPV_IV_HEMI0, HEMI1 n.y, HEMI1 n.z, HEMI1 n.x), and
 * every SH is a function of the direction light TRAVELS. RGB SH are
 * lpv_cell (LpvCell: r, g, b, 4 coefficients each).
 *
 * The pipeline, in order:
 *   lpv_iv_create     points and their radiosity -> voxels (means per voxel)
 *   for k = 1..K:
 *     lpv_iv_emit     what each occupied voxel sends out at bounce k
 *     lpv_iv_gather   the march: the radiance arriving at every voxel, I_k
 *   lpv_iv_filter     the surface voxels' plane means (LPV_IV_FILTER)
 *   lpv_iv_irradiance at a surface point from I_K (the final lookup)
 * or lpv_iv_run for all of it; lpv_iv_gather_ao / lpv_iv_run_ao and
 * lpv_iv_ao for ambient occlusion.
 */
#ifndef LPV_ORACLE_IV_H
#define LPV_ORACLE_IV_H

#include <stddef.h>
#include <stdint.h>

#include "grid.h"
#include "lpv_shared.h"
#include "oracle.h"

typedef struct IvPoint lpv_iv_point;
typedef struct IvVoxel lpv_iv_voxel;

/* march results other than a voxel index */
#define LPV_IV_ESCAPED (-1L) /* the ray left the grid: no light (lpvd has no environment) */
#define LPV_IV_BEYOND (-2L)  /* AO only: the ray went past its reach (visible) */

/* The voxel of point p: floor((p - origin) / s) per axis, in float (not
 * grid.glsl's p / s - origin / s). Returns 1 and cell when it lies in the
 * grid, 0 otherwise (also for a non-finite p). Creation, the march and
 * techniques/iv/core/iv_voxelize.c all find voxels with it. */
int lpv_iv_voxel_of(const lpv_grid *g, const float p[3], int cell[3]);

/* The voxel of a surface point p facing n: floor((p - origin) / s -
 * LPV_IV_BEHIND n^), so a surface on a voxel face goes wholly to the voxel
 * behind it (lpv_shared.h). Creation files points with it. */
int lpv_iv_surface_voxel_of(const lpv_grid *g, const float p[3], const float n[3], int cell[3]);

/* A voxel is occupied when at least one point landed in it. */
static inline int lpv_iv_occupied(const lpv_iv_voxel *v) { return v->normal[3] > 0.0f; }

/* Volume creation (3.1). For every point (skipped: position.w == 0, a
 * non-finite position, normal, albedo or radiosity, or a voxel
 * floor((p - origin) / s), computed in float, outside the grid) the voxel
 * accumulates B * hemi(n) per channel (B = radiosity[i], W/m^2, rgb, as the
 * GPU lit it; radiosity NULL: B = 0; the point's emission field is not read:
 * fold it into B), its normal n as given (unit), its albedo and a count;
 * then everything is divided by the count. Sums run in double, each result
 * is rounded to float once. So a voxel holds: r, g, b the mean SH of its
 * surfaces' outgoing radiance (W/(m^2 sr)), normal.xyz the mean unit normal
 * (not renormalised), normal.w the count (0: empty, every field 0),
 * albedo.rgb the mean albedo (albedo.a 0). voxels has lpv_grid_cell_count
 * entries and is overwritten. Returns 0 (*taken, if not NULL, gets the
 * number of points used) or -1 out of memory (voxels all zero). */
int lpv_iv_create(const lpv_grid *g, const lpv_iv_point *points, const float (*radiosity)[3], size_t n,
                  lpv_iv_voxel *voxels, size_t *taken);

/* Reconstruction (3.4): the SH radiance L at surface point p with normal n
 * (normalised here) from vol (one per voxel, incoming radiance). Zero when n
 * is not unit-able (lpv_unit_direction) or p not finite. Otherwise, with
 * n^ = n / |n|: q = p + 0.5 s n^, u = (q - origin) / s - 0.5, base = floor(u), f = u - base; corner
 * c = base + (i, j, k), i, j, k in {0, 1}, has index i + 2j + 4k and
 * trilinear weight t_c = prod(bit ? f : 1 - f). The `neighbours` (1..8,
 * clamped) corners nearest to q are kept (distance to the corner's voxel
 * centre; computed as |f - (i, j, k)|^2 in float, which is that distance
 * / s, squared; ties go to the lower corner index); of those, corners
 * outside the grid are skipped (not replaced by a farther corner). The
 * voxel holding p (lpv_iv_surface_voxel_of) is not skipped: it holds p's
 * surface and weighs LPV_IV_HELD_WEIGHT like any such voxel; a cut there
 * was a step in L wherever p crossed a voxel face.
 * w_c = t_c * max(0, dot(n^, normalize(centre_c - p))), 0 when
 * centre_c == p, times LPV_IV_HELD_WEIGHT when voxels (may be NULL: no
 * such factor) says c holds a surface; L = sum w_c vol(c) / sum w_c, 0 when
 * the sum is 0. */
void lpv_iv_reconstruct(const lpv_grid *g, const lpv_iv_voxel *voxels, const lpv_cell *vol, const float p[3],
                        const float n[3], int neighbours, lpv_cell *out);

/* Irradiance (W/m^2, rgb) at p for normal n: e = dot(L, lobe(-n^)) per
 * channel, L = lpv_iv_reconstruct, made light as a whole colour: 0 where
 * its luminance y <= 0, else y kept and the chroma scaled by y / (y - 2 m)
 * where its most negative channel m < 0 (iv_lookup.glsl, iv_physical). 0
 * where the reconstruction gives 0. */
void lpv_iv_irradiance(const lpv_grid *g, const lpv_iv_voxel *voxels, const lpv_cell *vol, const float p[3],
                       const float n[3], int neighbours, float rgb[3]);

/* The same two with the surface-holding voxels given as one flag per voxel
 * (lpv_grid_index order; non-zero: holds a surface, as the index of an iv
 * volume on the wire, SPEC R5.14; NULL: none does) instead of the created
 * voxels: held[i] != 0 where those test lpv_iv_occupied, the rest is the
 * same code. For clients that have the volume and its flags, not the voxels
 * (protocol/volume_lookup.h). */
void lpv_iv_reconstruct_held(const lpv_grid *g, const uint32_t *held, const lpv_cell *vol, const float p[3],
                             const float n[3], int neighbours, lpv_cell *out);
void lpv_iv_irradiance_held(const lpv_grid *g, const uint32_t *held, const lpv_cell *vol, const float p[3],
                            const float n[3], int neighbours, float rgb[3]);

/* Emission at bounce k >= 1 from I_{k-1} (incoming; NULL or k == 1: none).
 * Empty voxels emit 0. An occupied voxel h emits its direct SH and, for
 * k > 1 when |m| > 1e-3 (m its mean normal, |m| in float), also both
 * sides' bounce light: with n^ = m / |m|, front = (1 + min(|m|, 1)) / 2 and
 * back = 1 - front (the shares of its points facing +-n^, if every normal
 * is one of the two), albedo_h * (front E(n^) hemi(n^) + back E(-n^)
 * hemi(-n^)) per channel, E(n) = lpv_iv_irradiance(I_{k-1}, centre of h,
 * n, neighbours): a thin wall's voxel re-emits each side's light on its
 * own side.
 * emit has lpv_grid_cell_count entries and is overwritten. */
void lpv_iv_emit(const lpv_grid *g, const lpv_iv_voxel *voxels, const lpv_cell *incoming, int bounce, int neighbours,
                 lpv_cell *emit);

/* One ray of the march (3.3) from voxel (x, y, z) along unit w, in voxel
 * units: it starts at the centre + start w (start = LPV_IV_START for an
 * occupied voxel, the paper's guard against its own surface; 0 for an empty
 * one, which has none) and visits every voxel the ray crosses (Amanatides &
 * Woo), t the distance where it enters each: t > reach: LPV_IV_BEYOND;
 * outside the grid: LPV_IV_ESCAPED; the ray's own voxel: on; occupied:
 * that voxel's index. reach is in m; INFINITY for the radiance march. */
long lpv_iv_march(const lpv_grid *g, const lpv_iv_voxel *voxels, int x, int y, int z, const float w[3], float reach);

/* The radiance (W/(m^2 sr)) one channel e of a voxel's emission sends along
 * unit t: the two Lambertian hemispheres e is the projection of, B_f / pi
 * along its dipole d and B_b / pi against it (B_f + B_b = e0 / HEMI0,
 * (B_f - B_b) d = e1 / HEMI1), as iv_gather.comp reads it. */
float lpv_iv_emitted(const float e[4], const float t[3]);

/* The radiance march, I_k from emit: a voxel with no occupied voxel in its
 * 3x3x3 neighbourhood (itself included) gets 0 (the lookup never reads it).
 * Every other voxel v marches `rays` rays w_j = lpv_iv_ray(seed, v's index,
 * j, rays); a ray that hits voxel h brings L_ch = the radiance emit_ch(h)
 * sends along -w read as the two Lambertian hemispheres it is the SH of
 * (B_f / pi on the side of its dipole d, B_b / pi on the other, with
 * B_f + B_b = e0 / LPV_IV_HEMI0 and (B_f - B_b) d = e1 / LPV_IV_HEMI1, as
 * iv_gather.comp's emitted), an escaped one 0; I(v)_ch = 4 pi / rays * sum_j L_ch Y(-w_j)
 * (summed in double, rounded once). incoming is overwritten. */
void lpv_iv_gather(const lpv_grid *g, const lpv_iv_voxel *voxels, const lpv_cell *emit, uint32_t seed, int rays,
                   lpv_cell *incoming);

/* The AO march (3.5) with reach (m): V_j = 1 when ray j escaped or went
 * past reach, 0 when it hit; ao(v) = 4 pi / rays * sum_j V_j Y(-w_j), one
 * SH per voxel. A voxel with no occupied voxel in its 3x3x3 neighbourhood
 * gets (4 pi C0, 0, 0, 0): everything visible. ao is overwritten. */
void lpv_iv_gather_ao(const lpv_grid *g, const lpv_iv_voxel *voxels, uint32_t seed, int rays, float reach, vec4 *ao);

/* AO at a surface point: clamp(dot(L, lobe(-n^)) / pi, 0, 1) with L the
 * reconstruction of the ao volume as lpv_iv_reconstruct does it (one
 * channel); 1 (open) where nothing can be blended (also a bad p or n). */
float lpv_iv_ao(const lpv_grid *g, const lpv_iv_voxel *voxels, const vec4 *ao, const float p[3], const float n[3],
                int neighbours);

/* The bounces after the K gathered ones as the series they set, two
 * bounces at a time (iv_tail.comp says why), per channel: lpv_iv_total is
 * S_k, every voxel's DC term of I_k summed in double (total[ch]);
 * lpv_iv_tail_share with totals[0] = S_0 = 0 .. totals[K] gives
 * q = D_K / D_{K-2} (D_k = S_k - S_{k-1}), clamped to
 * [0, LPV_IV_TAIL_MAX_RATIO^2], 0 when K < 3 or either difference is not
 * above 0; lpv_iv_add_tail makes last (I_K) into
 * I_K + (I_K - base) q / (1 - q), base = I_{K-2}, for each voxel's channel
 * whose DC term the last two bounces raised (the others keep I_K). */
void lpv_iv_total(size_t cells, const lpv_cell *incoming, double total[3]);
void lpv_iv_tail_share(const double (*totals)[3], int K, float q[3]);
void lpv_iv_add_tail(size_t cells, const lpv_cell *base, const float q[3], lpv_cell *last);

/* LPV_IV_FILTER on I_K (after the tail): a voxel that gathers on a surface
 * (empty, its one occupied face neighbour holding a slab across the axis k
 * between them) gets sum w I / sum w over the voxels of the 3 x 3 block
 * around it across k that do too, beside the same axis and side, with slab
 * faces within LPV_IV_FILTER_PLANE voxels of its own, w = (2 - |du|) (2 -
 * |dv|) (itself 4); every other voxel is copied. raw and out are different
 * arrays of lpv_grid_cell_count cells. */
void lpv_iv_filter(const lpv_grid *g, const lpv_iv_voxel *voxels, const lpv_cell *raw, lpv_cell *out);

/* The whole volume. */
typedef struct lpv_iv_desc {
    lpv_grid grid;                /* cubic voxels; finite origin, finite cell size > 0 */
    const lpv_iv_point *points;
    const float (*radiosity)[3];  /* per point, W/m^2 rgb */
    size_t point_count;
    uint32_t seed;                /* the rays' */
    int rays;                     /* per voxel, >= 1 */
    int bounces;                  /* K >= 1 */
    int neighbours;               /* 1..8 */
    int tail;                     /* 1: the bounces after K (>= 3) as a series (lpv_iv_add_tail) */
    int filter;                   /* 1: then the surface voxels' plane means (lpv_iv_filter) */
} lpv_iv_desc;

/* create, then for k = 1..K emit_k and gather_k: incoming gets I_K (which
 * already holds bounces 1..K), plus the tail with d->tail, filtered with
 * d->filter. voxels (may be NULL) gets the created
 * volume. Both have lpv_grid_cell_count entries. Returns 0, or -1 with a
 * message in err (bad grid or knobs, out of memory). */
int lpv_iv_run(const lpv_iv_desc *d, lpv_iv_voxel *voxels, lpv_cell *incoming, char *err, size_t err_size);

/* create and lpv_iv_gather_ao with reach (m; the caller resolves the
 * setting's 0 = auto, LPV_IV_AO_VOXELS voxels). bounces and the radiosity
 * are not used (radiosity may be NULL). Returns 0 or -1 as lpv_iv_run. */
int lpv_iv_run_ao(const lpv_iv_desc *d, float reach, lpv_iv_voxel *voxels, vec4 *ao, char *err, size_t err_size);

#endif /* LPV_ORACLE_IV_H */
