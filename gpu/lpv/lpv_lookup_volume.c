/*
 * lpv_lookup_volume.c - see lpv_lookup_volume.h.
 */
#include "lpv_lookup_volume.h"

#include "error.h"
#include "gl_util.h"
#include "lpv_shared.h"

void lpv_lookup_volume_free(lpv_lookup_volume *l)
{
    for (int i = 0; i < 3; ++i)
        lpv_gl_delete_texture(&l->tex[i]);
    *l = (lpv_lookup_volume){0};
}

int lpv_lookup_volume_alloc(lpv_lookup_volume *l, const int dims[3], int volumes, char *err, size_t err_size)
{
    if (l->tex[0] && l->dims[0] == dims[0] && l->dims[1] == dims[1] && l->dims[2] == dims[2] && l->volumes == volumes)
        return 0;
    lpv_lookup_volume_free(l);
    GLint max3d = 0;
    glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max3d);
    int slabs_z = dims[2] > 0 ? max3d / dims[2] : 0;
    if (slabs_z > volumes)
        slabs_z = volumes;
    int slabs_y = slabs_z > 0 ? (volumes + slabs_z - 1) / slabs_z : 0;
    if (slabs_z < 1 || dims[0] > max3d || (long long)slabs_y * dims[1] > max3d)
        return lpv_error(err, err_size, "%d volumes of %dx%dx%d cells do not fit the lookup's 3D textures (GL allows %d "
                         "texels a side)", volumes, dims[0], dims[1], dims[2], max3d);
    glGenTextures(3, l->tex);
    for (int i = 0; i < 3; ++i) {
        glBindTexture(GL_TEXTURE_3D, l->tex[i]);
        glTexStorage3D(GL_TEXTURE_3D, 1, GL_RGBA32F, dims[0], dims[1] * slabs_y, dims[2] * slabs_z);
        /* the lookup's trilinear interpolation between cell centres; it
         * clamps its coordinates half a cell inside each volume itself */
        glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    }
    glBindTexture(GL_TEXTURE_3D, 0);
    for (int i = 0; i < 3; ++i)
        l->dims[i] = dims[i];
    l->volumes = volumes;
    l->slabs_z = slabs_z;
    if (glGetError() != GL_NO_ERROR) {
        lpv_lookup_volume_free(l);
        return lpv_error(err, err_size, "could not allocate the lookup's 3D textures for %d volumes of %dx%dx%d cells",
                         volumes, dims[0], dims[1], dims[2]);
    }
    return 0;
}

void lpv_lookup_volume_fill(const lpv_lookup_volume *l, GLuint prog, GLuint src, lpv_timer *timer)
{
    if (!l->tex[0])
        return;
    lpv_timer_begin(timer, "lookup_pack");
    glUseProgram(prog);
    glUniform4i(glGetUniformLocation(prog, "u_dims"), l->dims[0], l->dims[1], l->dims[2], l->volumes);
    glUniform1i(glGetUniformLocation(prog, "u_slabs_z"), l->slabs_z);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_ACC, src);
    for (int i = 0; i < 3; ++i)
        glBindImageTexture((GLuint)i, l->tex[i], 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glDispatchCompute(lpv_div_up((size_t)l->dims[0], LPV_WG_2D), lpv_div_up((size_t)l->dims[1], LPV_WG_2D),
                      (GLuint)(l->dims[2] * l->volumes));
    lpv_timer_count(timer, 1);
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
    glActiveTexture(GL_TEXTURE0);
    glUniform1i(glGetUniformLocation(prog, "u_lpv_slabs_z"), l->slabs_z > 0 ? l->slabs_z : 1);
}
