/*
 * medium.c - see medium.h.
 */
#include <string.h>

#include "error.h"
#include "lpv_shared.h"
#include "medium.h"

void lpv_medium_free(lpv_medium_gpu *g)
{
    if (g->density)
        glDeleteTextures(1, &g->density);
    memset(g, 0, sizeof *g);
}

int lpv_medium_upload(lpv_medium_gpu *g, const lpv_scene *scene, char *err, size_t err_size)
{
    lpv_medium_free(g);
    const lpv_medium *m = &scene->medium;
    if (!m->present)
        return 0;
    g->medium = *m;
    g->medium.density = NULL; /* the texture holds it */
    size_t n = (size_t)m->dims[0] * (size_t)m->dims[1] * (size_t)m->dims[2];
    if (!m->has_box || !m->density || n == 0)
        return 0;
    glGenTextures(1, &g->density);
    glBindTexture(GL_TEXTURE_3D, g->density);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexImage3D(GL_TEXTURE_3D, 0, GL_R32F, m->dims[0], m->dims[1], m->dims[2], 0, GL_RED, GL_FLOAT, m->density);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    GLenum wrap[] = {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R};
    for (int i = 0; i < 3; ++i)
        glTexParameteri(GL_TEXTURE_3D, wrap[i], GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_3D, 0);
    if (glGetError() != GL_NO_ERROR)
        return lpv_error(err, err_size, "could not upload a %dx%dx%d medium density texture", m->dims[0], m->dims[1],
                         m->dims[2]);
    return 0;
}

int lpv_medium_active(const lpv_medium_gpu *g, const lpv_settings *s, int on)
{
    return on && (s->fog_sigma_s > 0.0f || s->fog_sigma_a > 0.0f || g->medium.present);
}

void lpv_medium_bind(const lpv_medium_gpu *g, const lpv_settings *s, GLuint prog, int on)
{
    int flags = 0;
    float sigma_s[3] = {0, 0, 0}, sigma_a[3] = {0, 0, 0}, lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    if (!lpv_medium_active(g, s, on)) {
        /* no medium: flags 0 */
    } else if (s->fog_sigma_s > 0.0f || s->fog_sigma_a > 0.0f) { /* the fog settings win */
        flags = 1;
        for (int i = 0; i < 3; ++i) {
            sigma_s[i] = s->fog_sigma_s;
            sigma_a[i] = s->fog_sigma_a;
        }
    } else { /* the scene's medium */
        const lpv_medium *m = &g->medium;
        flags = 1 | (m->has_box ? 2 : 0) | (g->density ? 4 : 0);
        memcpy(sigma_s, m->sigma_s, sizeof sigma_s);
        memcpy(sigma_a, m->sigma_a, sizeof sigma_a);
        if (m->has_box) {
            memcpy(lo, m->box_min, sizeof lo);
            memcpy(hi, m->box_max, sizeof hi);
        }
    }
    glUniform1i(glGetUniformLocation(prog, "u_medium"), flags);
    glUniform3fv(glGetUniformLocation(prog, "u_medium_sigma_s"), 1, sigma_s);
    glUniform3fv(glGetUniformLocation(prog, "u_medium_sigma_a"), 1, sigma_a);
    glUniform3fv(glGetUniformLocation(prog, "u_medium_box_min"), 1, lo);
    glUniform3fv(glGetUniformLocation(prog, "u_medium_box_max"), 1, hi);
    glActiveTexture(GL_TEXTURE0 + LPV_TEX_DENSITY);
    glBindTexture(GL_TEXTURE_3D, (flags & 4) ? g->density : 0);
}
