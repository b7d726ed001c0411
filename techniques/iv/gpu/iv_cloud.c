/*
 * iv_cloud.c - the imperfect volume's point cloud of the scene
 * (techniques/iv/core/iv_points.h), sampled at the voxel size its settings
 * place over where light can go, and kept on the GPU for iv_points. The
 * engine calls these through the class (sample_scene, samples_stale) when
 * the scene, the technique or a knob that touches samples changes.
 */
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "iv_internal.h"

void lpv_iv_free_cloud(lpv_iv_gpu *v)
{
    lpv_gl_delete_buffer(&v->points);
    memset(&v->cloud, 0, sizeof v->cloud);
    memset(&v->cloud_grid, 0, sizeof v->cloud_grid);
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
    v->points = lpv_gl_new_ssbo(n * sizeof *pts);
    if (n)
        glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(n * sizeof *pts), pts);
    v->cloud.points = n;
    v->cloud_grid = g;
    free(pts);
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
