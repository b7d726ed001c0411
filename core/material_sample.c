/* material_sample.c - see material_sample.h. */
#include "material_sample.h"

#include <math.h>
#include <pthread.h>

#include "lpv_shared.h" /* lpv_alpha_covers */
#include "tonemap.h"    /* lpv_srgb_decode */

static float srgb_lut[256];
static pthread_once_t srgb_once = PTHREAD_ONCE_INIT;

static void srgb_lut_fill(void)
{
    for (int i = 0; i < 256; ++i)
        srgb_lut[i] = lpv_srgb_decode((float)i / 255.0f);
}

int lpv_material_texture(const lpv_scene *s, int index, int linear)
{
    if (index < 0 || (uint32_t)index >= s->texture_count)
        return -1;
    const lpv_texture *t = &s->textures[index];
    if (!t->rgba8 || t->width < 1 || t->height < 1 || (t->linear != 0) != (linear != 0))
        return -1;
    return index;
}

static float texel(const lpv_texture *t, int x, int y, int c, const float *lut)
{
    const uint8_t b = t->rgba8[4 * ((size_t)y * (size_t)t->width + (size_t)x) + (size_t)c];
    return c < 3 && !t->linear ? lut[b] : (float)b / 255.0f;
}

void lpv_texture_sample(const lpv_texture *t, float u, float v, float out[4])
{
    pthread_once(&srgb_once, srgb_lut_fill);
    const float *lut = srgb_lut;
    if (!isfinite(u) || !isfinite(v))
        u = v = 0.0f;
    /* texel centres at (i + 0.5) / w; REPEAT wraps both neighbours */
    const double x = (double)u * t->width - 0.5, y = (double)v * t->height - 0.5;
    const double fx = floor(x), fy = floor(y);
    const float ax = (float)(x - fx), ay = (float)(y - fy);
    const int x0 = (int)(fmod(fmod(fx, t->width) + t->width, t->width));
    const int y0 = (int)(fmod(fmod(fy, t->height) + t->height, t->height));
    const int x1 = (x0 + 1) % t->width, y1 = (y0 + 1) % t->height;
    for (int c = 0; c < 4; ++c) {
        const float a = texel(t, x0, y0, c, lut) * (1.0f - ax) + texel(t, x1, y0, c, lut) * ax;
        const float b = texel(t, x0, y1, c, lut) * (1.0f - ax) + texel(t, x1, y1, c, lut) * ax;
        out[c] = a * (1.0f - ay) + b * ay;
    }
}

void lpv_material_uv(const lpv_uv_transform *t, const float uv0[2], const float uv1[2], float out[2])
{
    const float *uv = t->texcoord == 1 ? uv1 : uv0;
    float m[6];
    lpv_uv_transform_matrix(t, m);
    out[0] = m[0] * uv[0] + m[1] * uv[1] + m[2];
    out[1] = m[3] * uv[0] + m[4] * uv[1] + m[5];
}

static int sample(const lpv_scene *s, int index, int linear, const lpv_uv_transform *t, const float uv0[2],
                  const float uv1[2], float out[4])
{
    const int k = lpv_material_texture(s, index, linear);
    if (k < 0)
        return 0;
    float uv[2];
    lpv_material_uv(t, uv0, uv1, uv);
    lpv_texture_sample(&s->textures[k], uv[0], uv[1], out);
    return 1;
}

static float unit(float x) { return x > 0.0f ? (x < 1.0f ? x : 1.0f) : 0.0f; /* NaN: 0 */ }

float lpv_material_alpha_at(const lpv_scene *s, const lpv_material *m, const float uv0[2], const float uv1[2],
                            float color_alpha)
{
    float t[4] = {1.0f, 1.0f, 1.0f, 1.0f};
    sample(s, m->base_color_texture, 0, &m->base_color_uv, uv0, uv1, t);
    return m->base_color[3] * t[3] * color_alpha;
}

int lpv_material_covers_at(const lpv_scene *s, const lpv_material *m, const float uv0[2], const float uv1[2],
                           float color_alpha, float u)
{
    const int blend = m->alpha_mode == LPV_ALPHA_BLEND;
    const float cutoff = lpv_material_alpha_cutoff(m);
    if (!blend && !(cutoff > 0.0f))
        return 1; /* no texture read for an opaque surface */
    return lpv_alpha_covers(lpv_material_alpha_at(s, m, uv0, uv1, color_alpha), cutoff, blend, u);
}

float lpv_material_metallic_at(const lpv_scene *s, const lpv_material *m, const float uv0[2], const float uv1[2])
{
    float t[4];
    float metallic = m->metallic;
    if (sample(s, m->metallic_roughness_texture, 1, &m->metallic_roughness_uv, uv0, uv1, t))
        metallic *= t[2];
    return unit(metallic);
}

void lpv_material_albedo_at(const lpv_scene *s, const lpv_material *m, const float uv0[2], const float uv1[2],
                            const float *color, float out[3])
{
    float t[4] = {1.0f, 1.0f, 1.0f, 1.0f};
    sample(s, m->base_color_texture, 0, &m->base_color_uv, uv0, uv1, t);
    const float kd = m->unlit ? 0.0f : 1.0f - lpv_material_metallic_at(s, m, uv0, uv1);
    for (int c = 0; c < 3; ++c)
        out[c] = unit(m->base_color[c] * t[c] * (color ? color[c] : 1.0f)) * kd;
}

void lpv_material_unlit_radiance_at(const lpv_scene *s, const lpv_material *m, const float uv0[2],
                                    const float uv1[2], const float *color, float out[3])
{
    float t[4] = {1.0f, 1.0f, 1.0f, 1.0f};
    if (m->unlit)
        sample(s, m->base_color_texture, 0, &m->base_color_uv, uv0, uv1, t);
    for (int c = 0; c < 3; ++c)
        out[c] = m->unlit ? unit(m->base_color[c] * t[c] * (color ? color[c] : 1.0f)) / LPV_LUMENS_PER_WATT : 0.0f;
}

float lpv_material_occlusion_at(const lpv_scene *s, const lpv_material *m, const float uv0[2], const float uv1[2])
{
    float t[4];
    if (!sample(s, m->occlusion_texture, 1, &m->occlusion_uv, uv0, uv1, t))
        return 1.0f;
    return unit(1.0f + m->occlusion_strength * (t[0] - 1.0f));
}

void lpv_material_emission_at(const lpv_scene *s, const lpv_material *m, const float uv0[2], const float uv1[2],
                              float out[3])
{
    float t[4] = {1.0f, 1.0f, 1.0f, 1.0f};
    sample(s, m->emissive_texture, 0, &m->emissive_uv, uv0, uv1, t);
    for (int c = 0; c < 3; ++c)
        out[c] = m->emission[c] * t[c];
}

void lpv_triangle_emission(const lpv_scene *s, const lpv_material *m, const lpv_vertex *const v[3], float out[3])
{
    const int k = lpv_material_texture(s, m->emissive_texture, 0);
    if (k < 0) {
        for (int c = 0; c < 3; ++c)
            out[c] = m->emission[c];
        return;
    }
    /* as many points as the triangle covers texels, four each, within the
     * bounds; on the R2 low-discrepancy sequence warped uniformly onto the
     * triangle (as core/emissive.c places its VPLs), which does not line up
     * with the texels' edges as a grid would */
    float uv[3][2];
    for (int j = 0; j < 3; ++j)
        lpv_material_uv(&m->emissive_uv, v[j]->uv, v[j]->uv1, uv[j]);
    const double uv_area = 0.5 * fabs((double)(uv[1][0] - uv[0][0]) * (uv[2][1] - uv[0][1]) -
                                      (double)(uv[2][0] - uv[0][0]) * (uv[1][1] - uv[0][1]));
    const double texels = uv_area * s->textures[k].width * s->textures[k].height;
    const double want = isfinite(texels) ? 4.0 * texels : 0.0;
    const int n = want < LPV_TRIANGLE_EMISSION_SAMPLES ? LPV_TRIANGLE_EMISSION_SAMPLES
                  : want > LPV_TRIANGLE_EMISSION_SAMPLES_MAX ? LPV_TRIANGLE_EMISSION_SAMPLES_MAX
                                                              : (int)want;
    const double a1 = 0.7548776662466927, a2 = 0.5698402909980532;
    double sum[3] = {0.0, 0.0, 0.0};
    for (int i = 0; i < n; ++i) {
        const double u = fmod(0.5 + a1 * (i + 1), 1.0), w = fmod(0.5 + a2 * (i + 1), 1.0), r = sqrt(u);
        const double b[3] = {1.0 - r, r * (1.0 - w), r * w};
        float uv0[2] = {0, 0}, uv1[2] = {0, 0}, e[3];
        for (int j = 0; j < 3; ++j)
            for (int c = 0; c < 2; ++c) {
                uv0[c] += (float)b[j] * v[j]->uv[c];
                uv1[c] += (float)b[j] * v[j]->uv1[c];
            }
        lpv_material_emission_at(s, m, uv0, uv1, e);
        for (int c = 0; c < 3; ++c)
            sum[c] += e[c];
    }
    for (int c = 0; c < 3; ++c)
        out[c] = (float)(sum[c] / n);
}
