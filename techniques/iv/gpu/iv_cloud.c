/*
 * iv_cloud.c - the imperfect volume's point cloud of the scene
 * (techniques/iv/core/iv_points.h), sampled at the voxel size its settings
 * place over where light can go, sorted by the voxel each point falls in and
 * kept on the GPU for iv_points (iv_points.comp: each voxel gathers its own
 * points). The engine calls these through the class (sample_scene,
 * samples_stale) when the scene, the technique or a knob that touches
 * samples changes.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "iv_internal.h"
#include "oracle_iv.h"

void lpv_iv_free_cloud(lpv_iv_gpu *v)
{
    lpv_gl_delete_buffer(&v->points);
    lpv_gl_delete_buffer(&v->point_starts);
    free(v->chunk_ends);
    v->chunk_ends = NULL;
    v->chunk_count = 0;
    memset(&v->cloud, 0, sizeof v->cloud);
    memset(&v->cloud_grid, 0, sizeof v->cloud_grid);
}

/* The voxel of g a point falls in (oracle_iv.h lpv_iv_surface_voxel_of,
 * the oracle's reading of iv_volume.glsl's iv_cell_of), as a voxel index;
 * -1 for a point the voxels would skip (no surface, not finite, no normal)
 * or one outside the grid. A point on a voxel face may round to the other
 * side on the GPU: it is counted here and clamped to this voxel's face
 * there. */
static long voxel_of(const lpv_grid *g, const struct IvPoint *q)
{
    const float *p = q->position, *n = q->normal;
    const float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    int c[3];
    if (p[3] == 0.0f || !(len > 1e-8f) || isinf(len) || !lpv_iv_surface_voxel_of(g, p, n, c))
        return -1;
    return (long)lpv_grid_index(g, c[0], c[1], c[2]);
}

/* Sorts the cloud by voxel in place (stable: a voxel sums its points in the
 * cloud's order, as the splat's blending did; the points no voxel takes go
 * last and are not stored), then stores the sorted points, each voxel's
 * start and the dispatch chunks. In place, so that sampling needs 4 bytes a
 * point beyond the cloud itself, not a second cloud. */
static int store_sorted(lpv_iv_gpu *v, const lpv_grid *g, struct IvPoint *pts, size_t n)
{
    const size_t cells = lpv_grid_cell_count(g);
    uint32_t *starts = calloc(cells + 1, sizeof *starts), *fill = malloc(cells * sizeof *fill);
    uint32_t *dest = malloc((n ? n : 1) * sizeof *dest); /* first each point's voxel, then its place */
    size_t *ends = malloc(cells * sizeof *ends);
    if (!starts || !fill || !dest || !ends || n > UINT32_MAX - 1) {
        free(starts);
        free(fill);
        free(dest);
        free(ends);
        return -1;
    }
    for (size_t i = 0; i < n; ++i) {
        const long c = voxel_of(g, &pts[i]);
        dest[i] = c >= 0 ? (uint32_t)c : UINT32_MAX;
        if (c >= 0)
            starts[c + 1]++;
    }
    for (size_t c = 0; c < cells; ++c)
        starts[c + 1] += starts[c];
    const size_t kept = starts[cells];
    memcpy(fill, starts, cells * sizeof *fill);
    uint32_t dropped = (uint32_t)kept;
    for (size_t i = 0; i < n; ++i)
        dest[i] = dest[i] == UINT32_MAX ? dropped++ : fill[dest[i]]++;
    /* each swap puts one point in its place: n swaps at most */
    for (size_t i = 0; i < n; ++i)
        while (dest[i] != i) {
            const uint32_t j = dest[i];
            const struct IvPoint t = pts[j];
            pts[j] = pts[i];
            pts[i] = t;
            dest[i] = dest[j];
            dest[j] = j;
        }
    free(dest);
    free(fill);
    /* dispatch chunks of whole voxels, about LPV_ATLAS_SPLAT_CHUNK points
     * each, with a yield point between them (timer.h), as the splat had */
    size_t chunks = 0, from = 0;
    for (size_t c = 0; c < cells; ++c)
        if (starts[c + 1] - starts[from] >= LPV_ATLAS_SPLAT_CHUNK || c + 1 == cells) {
            ends[chunks++] = c + 1;
            from = c + 1;
        }
    v->points = lpv_gl_new_ssbo((kept ? kept : 1) * sizeof *pts);
    if (kept)
        glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(kept * sizeof *pts), pts);
    v->point_starts = lpv_gl_new_ssbo((cells + 1) * sizeof *starts);
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)((cells + 1) * sizeof *starts), starts);
    v->chunk_ends = ends;
    v->chunk_count = chunks;
    free(starts);
    return 0;
}

int lpv_iv_sample_scene(lpv_technique *t, const lpv_technique_scene *sc, char *err, size_t err_size)
{
    lpv_iv_gpu *v = (lpv_iv_gpu *)t;
    const lpv_settings *s = sc->settings;
    lpv_iv_free_cloud(v);
    lpv_grid g;
    if (lpv_iv_place(s, sc->lit_min, sc->lit_max, sc->free_path, &g) != 0)
        return lpv_error(err, err_size, "%s: cannot place the imperfect volume over the scene's bounds",
                         sc->geometry->source);
    const lpv_iv_point_params p = lpv_iv_point_params_of(s, &g);
    struct IvPoint *pts = NULL;
    size_t n = 0;
    if (lpv_iv_points_make(sc->geometry, &p, &pts, &n, &v->cloud) != 0)
        return lpv_error(err, err_size, "out of memory for the imperfect volume's points (iv_max_points %d)",
                         s->iv.max_points);
    const int stored = store_sorted(v, &g, pts, n);
    free(pts);
    if (stored != 0)
        return lpv_error(err, err_size, "out of memory sorting the imperfect volume's %zu points", n);
    v->cloud.points = n;
    v->cloud_grid = g;
    if (glGetError() != GL_NO_ERROR)
        return lpv_error(err, err_size, "%s: GL error while storing %zu imperfect-volume points",
                         sc->geometry->source, n);
    return 0;
}

int lpv_iv_samples_stale(const lpv_technique *t, const lpv_technique_scene *sc)
{
    const lpv_iv_gpu *v = (const lpv_iv_gpu *)t;
    lpv_grid g;
    if (!v->points || lpv_iv_place(sc->settings, sc->lit_min, sc->lit_max, sc->free_path, &g) != 0)
        return 0;
    return memcmp(&g, &v->cloud_grid, sizeof g) != 0; /* its pieces were split by its voxel, kept in its box */
}
