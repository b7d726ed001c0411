/*
 * lpv_lookup_volume.c - see lpv_lookup_volume.h.
 */
#include "lpv_lookup_volume.h"

#include "error.h"
#include "gl_util.h"
#include "lpv_shared.h"

#include <string.h>

void lpv_lookup_volume_free(lpv_lookup_volume *l)
{
    for (int i = 0; i < 3; ++i)
        lpv_gl_delete_texture(&l->tex[i]);
    lpv_gl_delete_texture(&l->normals_tex);
    *l = (lpv_lookup_volume){0};
}

/* An RGBA32F 3D texture for `volumes` volumes of dims cells, stacked along z
 * and then y (*slabs_z along z); 0 when GL's side limit does not allow it. */
static GLuint volume_texture(const int dims[3], int volumes, int *slabs_z)
{
    GLint max3d = 0;
    glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max3d);
    int sz = dims[2] > 0 ? max3d / dims[2] : 0;
    if (sz > volumes)
        sz = volumes;
    const int sy = sz > 0 ? (volumes + sz - 1) / sz : 0;
    if (sz < 1 || dims[0] > max3d || (long long)sy * dims[1] > max3d)
        return 0;
    GLuint tex = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_3D, tex);
    glTexStorage3D(GL_TEXTURE_3D, 1, GL_RGBA32F, dims[0], dims[1] * sy, dims[2] * sz);
    /* the lookup's trilinear interpolation between cell centres; it clamps
     * its coordinates half a cell inside each volume itself */
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_3D, 0);
    *slabs_z = sz;
    return tex;
}

int lpv_lookup_volume_alloc(lpv_lookup_volume *l, const int dims[3], int cascades, int bins, char *err,
                            size_t err_size)
{
    if (l->tex[0] && l->dims[0] == dims[0] && l->dims[1] == dims[1] && l->dims[2] == dims[2] &&
        l->cascades == cascades && l->bins == bins)
        return 0;
    lpv_lookup_volume_free(l);
    /* the lookup's own normals only with normal bins (without, the full
     * lookup is three fetches per cascade) and within
     * LPV_LOOKUP_NORMAL_TEXELS: the axes and as many planes as fit, in
     * pairs (n, -n), or none */
    const long long cells = (long long)dims[0] * dims[1] * dims[2] * cascades;
    long long fit = bins > 1 && cells > 0 ? LPV_LOOKUP_NORMAL_TEXELS / cells : 0;
    fit = fit > LPV_LOOKUP_AXES + LPV_MAX_LOOKUP_PLANES ? LPV_LOOKUP_AXES + LPV_MAX_LOOKUP_PLANES : fit;
    l->normals = fit >= LPV_LOOKUP_AXES ? LPV_LOOKUP_AXES + (((int)fit - LPV_LOOKUP_AXES) & ~1) : 0;
    const int volumes = cascades * bins, normal_volumes = cascades * l->normals;
    for (int i = 0; i < 3; ++i)
        l->tex[i] = volume_texture(dims, volumes, &l->slabs_z);
    if (normal_volumes > 0)
        l->normals_tex = volume_texture(dims, normal_volumes, &l->normals_slabs_z);
    if (!l->tex[0] || (normal_volumes > 0 && !l->normals_tex)) {
        GLint max3d = 0;
        glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max3d);
        lpv_lookup_volume_free(l);
        return lpv_error(err, err_size, "%d volumes of %dx%dx%d cells do not fit the lookup's 3D textures (GL allows %d "
                         "texels a side)", normal_volumes > volumes ? normal_volumes : volumes, dims[0], dims[1], dims[2], max3d);
    }
    for (int i = 0; i < 3; ++i)
        l->dims[i] = dims[i];
    l->cascades = cascades;
    l->bins = bins;
    if (glGetError() != GL_NO_ERROR) {
        lpv_lookup_volume_free(l);
        return lpv_error(err, err_size, "could not allocate the lookup's 3D textures for %d volumes of %dx%dx%d cells",
                         volumes, dims[0], dims[1], dims[2]);
    }
    return 0;
}

/* The lookup normals' uniforms of prog (in use). */
static void set_normals(const lpv_lookup_volume *l, GLuint prog)
{
    glUniform1i(glGetUniformLocation(prog, "u_lpv_lookup_normals"), l->normals);
    glUniform1i(glGetUniformLocation(prog, "u_lpv_plane_count"), l->plane_count);
    if (l->plane_count > 0)
        glUniform3fv(glGetUniformLocation(prog, "u_lpv_planes"), l->plane_count, &l->planes[0][0]);
}

void lpv_lookup_volume_fill(lpv_lookup_volume *l, lpv_lookup_programs progs, GLuint src, const float (*planes)[3],
                            int plane_count, lpv_timer *timer)
{
    if (!l->tex[0])
        return;
    const int room = l->normals > 0 ? l->normals - LPV_LOOKUP_AXES : 0;
    l->plane_count = plane_count < room ? plane_count : room;
    if (l->plane_count > 0)
        memcpy(l->planes, planes, (size_t)l->plane_count * sizeof l->planes[0]);
    lpv_timer_begin(timer, "lookup_pack");
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_ACC, src);
    glUseProgram(progs.pack);
    glUniform4i(glGetUniformLocation(progs.pack, "u_dims"), l->dims[0], l->dims[1], l->dims[2],
                l->cascades * l->bins);
    glUniform1i(glGetUniformLocation(progs.pack, "u_slabs_z"), l->slabs_z);
    for (int i = 0; i < 3; ++i)
        glBindImageTexture((GLuint)i, l->tex[i], 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glDispatchCompute(lpv_div_up((size_t)l->dims[0], LPV_WG_2D), lpv_div_up((size_t)l->dims[1], LPV_WG_2D),
                      (GLuint)(l->dims[2] * l->cascades * l->bins));
    lpv_timer_count(timer, 1);
    if (l->normals > 0) {
        glUseProgram(progs.normals);
        glUniform4i(glGetUniformLocation(progs.normals, "u_dims"), l->dims[0], l->dims[1], l->dims[2], l->cascades);
        glUniform1i(glGetUniformLocation(progs.normals, "u_bins"), l->bins);
        glUniform1i(glGetUniformLocation(progs.normals, "u_slabs_z"), l->normals_slabs_z);
        set_normals(l, progs.normals);
        glBindImageTexture(0, l->normals_tex, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        glDispatchCompute(lpv_div_up((size_t)l->dims[0], LPV_WG_2D), lpv_div_up((size_t)l->dims[1], LPV_WG_2D),
                          (GLuint)(l->dims[2] * l->cascades * l->normals));
        lpv_timer_count(timer, 1);
    }
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    lpv_timer_end(timer);
}

void lpv_lookup_volume_bind(const lpv_lookup_volume *l, GLuint prog)
{
    static const GLenum units[3] = {LPV_TEX_LOOKUP_R, LPV_TEX_LOOKUP_G, LPV_TEX_LOOKUP_B};
    for (int i = 0; i < 3; ++i) {
        glActiveTexture(GL_TEXTURE0 + units[i]);
        glBindTexture(GL_TEXTURE_3D, l->tex[i]);
    }
    glActiveTexture(GL_TEXTURE0 + LPV_TEX_LOOKUP_NORMALS);
    glBindTexture(GL_TEXTURE_3D, l->normals_tex);
    glActiveTexture(GL_TEXTURE0);
    glUniform1i(glGetUniformLocation(prog, "u_lpv_slabs_z"), l->slabs_z > 0 ? l->slabs_z : 1);
    glUniform1i(glGetUniformLocation(prog, "u_lpv_normals_slabs_z"), l->normals_slabs_z > 0 ? l->normals_slabs_z : 1);
    set_normals(l, prog);
}
