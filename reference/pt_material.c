/*
 * pt_material.c - the surface at a hit: its diffuse albedo, unlit colour,
 * occlusion and emission, by core/material_sample.h's rules (the ones
 * lpvd's shaders follow), so the estimators ask a hit what it is in one
 * place.
 */
#include "pt_internal.h"

#include "material_sample.h"

/* ---- materials ----------------------------------------------------------- */

/* The diffuse albedo at a hit (core/material_sample.h: base colour x
 * texture x (1 - metallic)); 0 without a material. */
void lpv_pt_hit_albedo(const lpv_ref *r, const hit *h, float out[3])
{
    const ref_tri *tr = &r->tris[h->tri];
    if (tr->material < 0) {
        out[0] = out[1] = out[2] = 0.0f;
        return;
    }
    float uv0[2], uv1[2], color[4];
    tri_uv(tr, h->u, h->v, uv0, uv1, color);
    lpv_material_albedo_at(&r->look, &r->look.materials[tr->material], uv0, uv1, color, out);
}

/* What the camera sees of an unlit material at a primary hit (its base
 * colour as luminance, core/material_sample.h); 0 where lit. Never at a
 * path's later hits: an unlit surface lights nothing. */
int lpv_pt_hit_unlit(const lpv_ref *r, const hit *h, float out[3])
{
    const ref_tri *tr = &r->tris[h->tri];
    if (tr->material < 0 || !r->look.materials[tr->material].unlit)
        return 0;
    float uv0[2], uv1[2], color[4];
    tri_uv(tr, h->u, h->v, uv0, uv1, color);
    lpv_material_unlit_radiance_at(&r->look, &r->look.materials[tr->material], uv0, uv1, color, out);
    return 1;
}

/* The factor a hit's indirect light takes in the image: its material's
 * occlusionTexture (core/material_sample.h), 1 without one: lpvd applies it
 * to the frame's indirect term, so the reference's image does the same. */
float lpv_pt_hit_occlusion(const lpv_ref *r, const hit *h)
{
    const ref_tri *tr = &r->tris[h->tri];
    if (tr->material < 0)
        return 1.0f;
    float uv0[2], uv1[2];
    tri_uv(tr, h->u, h->v, uv0, uv1, NULL);
    return lpv_material_occlusion_at(&r->look, &r->look.materials[tr->material], uv0, uv1);
}

/* The radiance a hit's side emits (W/(m^2 sr), x its emissiveTexture): 0
 * and no write where it emits none. */
int lpv_pt_hit_emission(const lpv_ref *r, const hit *h, float out[3])
{
    const ref_tri *tr = &r->tris[h->tri];
    if (tr->material < 0 || !r->materials[tr->material].emits || (!h->front && r->materials[tr->material].sides < 2))
        return 0;
    float uv0[2], uv1[2];
    tri_uv(tr, h->u, h->v, uv0, uv1, NULL);
    lpv_material_emission_at(&r->look, &r->look.materials[tr->material], uv0, uv1, out);
    for (int i = 0; i < 3; ++i)
        out[i] = isfinite(out[i]) && out[i] > 0.0f ? out[i] : 0.0f;
    return 1;
}

