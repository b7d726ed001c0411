// The cascaded LPV's side of the technique seam (gpu/technique.h): with
// grid.glsl it is the "lpv" technique's lookup_includes, and defines what the
// engine's shade/glossy/media/query shaders call: lpv_irradiance,
// lpv_irradiance_listed, lpv_project, lpv_cell_at and the u_damping uniform.
// lookup.glsl - irradiance from the accumulated LPV cascades (techniques/lpv/core/oracle_lookup.c
// is the single-grid reference). In one cascade: trilinear interpolation
// between cell centres, clamped at the grid's edge, at half a cell in front
// of the surface, then E = max(0, c . lobe(-n) / cell^2) per channel: the
// stored intensity per cell cross-section read as radiance, integrated
// against the cosine over the hemisphere the surface faces.
// Across cascades (docs/cascades.md): the finest cascade containing the point
// is used, blended into the next coarser one over the last cells before its
// border, w = clamp((d - 1) / 2, 0, 1) with d the distance to the border in
// its cells, so the irradiance is continuous across every border.
// Damping (paper section 3.4, docs/effects.md): where the incoming light
// grows toward the surface (its directional derivative along n is negative,
// i.e. it arrives from behind a thin wall), the lookup is damped by
// 1 - strength * (1 - E(1.5 cells out) / E(0.5 cells out)); strength 0 = off.
// The accumulated volume as three RGBA32F 3D textures (r, g, b; linear
// filtering), volume v at z-slab v % u_lpv_slabs_z and y-slab
// v / u_lpv_slabs_z (techniques/lpv/gpu/lpv_lookup_volume.c fills them from the LPV
// buffer after each tick): one filtered fetch per channel is the trilinear
// interpolation between the 8 cell centres around q.
layout(binding = LPV_TEX_LOOKUP_R) uniform sampler3D u_lpv_r;
layout(binding = LPV_TEX_LOOKUP_G) uniform sampler3D u_lpv_g;
layout(binding = LPV_TEX_LOOKUP_B) uniform sampler3D u_lpv_b;
uniform int u_lpv_slabs_z;
// Each cascade's irradiance (before the 1 / cell^2 and the clamp at 0) on
// the six axis normals and then the scene's plane normals (u_lpv_planes,
// u_lpv_plane_count of them in use): normal a of cascade k as volume
// k * u_lpv_lookup_normals + a in the same slab layout (lpv_normals_pack.comp
// fills it from the LPV buffer).
layout(binding = LPV_TEX_LOOKUP_NORMALS) uniform sampler3D u_lpv_normals;
uniform int u_lpv_normals_slabs_z;
uniform int u_lpv_lookup_normals; // LPV_LOOKUP_AXES + the planes' room, or 0: none
uniform int u_lpv_plane_count;
uniform vec3 u_lpv_planes[LPV_MAX_LOOKUP_PLANES];

uniform float u_damping;
// 0 compiles the damping out (the engine's frame without damping): llvmpipe
// runs code inside an if under lane masks even when no lane takes it, and
// the damping's second lookup cost the undamped frame a fifth of its lookup.
#ifndef LPV_LOOKUP_DAMPING
#define LPV_LOOKUP_DAMPING 1
#endif

// Volume v's texture coordinates at continuous cell coordinates q in a
// texture of `size` texels with `slabs` volumes along z per y-slab, clamped
// half a cell inside v so that neighbouring volumes never mix.
vec3 volume_texcoord(int v, vec3 q, int slabs, vec3 size)
{
    ivec3 dims = grid_dims();
    slabs = max(slabs, 1);
    q = clamp(q, vec3(0.5), vec3(dims) - 0.5) +
        vec3(0.0, float(lpv_slab_y0(v, slabs, dims.y)), float(lpv_slab_z0(v, slabs, dims.z)));
    return q / size;
}

// Axis normal a: +x -x +y -y +z -z.
vec3 lookup_axis(int a)
{
    vec3 n = vec3(0.0);
    n[a >> 1] = (a & 1) == 0 ? 1.0 : -1.0;
    return n;
}

// The lookup's normal a: an axis, then the planes.
vec3 lookup_normal(int a)
{
    return a < LPV_LOOKUP_AXES ? lookup_axis(a) : u_lpv_planes[a - LPV_LOOKUP_AXES];
}

// Which of the lookup's normals unit n is: the axis it is exactly (two
// components zero), or a plane's normal it is within the tolerance of (the
// last one listed, should two be: core/scene_planes.c lists none within the
// tolerance of an axis or of each other); -1 if none. The planes are a loop
// each lane leaves at its match, and llvmpipe leaves a loop when no lane is
// left: a SIMD group of pixels facing axes or one plane stops there instead
// of comparing all the planes (3 ms of a 512^2 frame at the balanced preset).
int lookup_normal_of(vec3 n)
{
    if (u_lpv_lookup_normals == 0)
        return -1;
    if (n.y == 0.0 && n.z == 0.0)
        return n.x > 0.0 ? 0 : 1;
    if (n.x == 0.0 && n.z == 0.0)
        return n.y > 0.0 ? 2 : 3;
    if (n.x == 0.0 && n.y == 0.0)
        return n.z > 0.0 ? 4 : 5;
    for (int j = u_lpv_plane_count - 1; j >= 0; --j)
        if (all(lessThanEqual(abs(n - u_lpv_planes[j]), vec3(LPV_LOOKUP_PLANE_TOLERANCE))))
            return LPV_LOOKUP_AXES + j;
    return -1;
}

// The trilinearly interpolated SH (r, g, b) at continuous cell coordinates q
// (cell centres at +0.5) of volume v, clamped at the grid's edge: the clamp
// keeps the filter inside v's cells, so neighbouring volumes never mix.
void volume_sh_at(int v, vec3 q, out vec4 r, out vec4 g, out vec4 b)
{
    vec3 t = volume_texcoord(v, q, u_lpv_slabs_z, vec3(textureSize(u_lpv_r, 0)));
    r = textureLod(u_lpv_r, t, 0.0);
    g = textureLod(u_lpv_g, t, 0.0);
    b = textureLod(u_lpv_b, t, 0.0);
}

// The SH of cascade k at q summed over its volumes (the physical field).
void cascade_sh_at(int k, vec3 q, out vec4 r, out vec4 g, out vec4 b)
{
    volume_sh_at(k * bin_count(), q, r, g, b);
    for (int bin = 1; bin < bin_count(); ++bin) {
        vec4 r1, g1, b1;
        volume_sh_at(k * bin_count() + bin, q, r1, g1, b1);
        r += r1;
        g += g1;
        b += b1;
    }
}

// (r, g, b) . v / cell^2 at q in cascade k, clamped at 0: with v = lobe(-n)
// the irradiance of a surface facing n (without normal bins), with
// v = basis(w) the radiance travelling along w, with v = (sqrt(4 pi), 0, 0, 0)
// the fluence.
vec3 cascade_project_at(int k, vec3 q, vec4 v)
{
    vec4 r, g, b;
    cascade_sh_at(k, q, r, g, b);
    float cell = cascade_cell(k);
    return max(vec3(dot(r, v), dot(g, v), dot(b, v)) / (cell * cell), 0.0);
}

// The irradiance weights of a normal bin (docs/propagation.md section 6b).
// Light of bin b travels into the half-space H = {w : <w, e> > 0}, e the
// bin's axis. Its intensity is reconstructed on H as I(w) = a + <bv, w> with
// the same band-0/1 moments as the stored SH c (a cosine lobe and a uniform
// hemisphere are both reproduced exactly), and integrated against the
// surface's cosine max(0, <m, w>), m = -n, over H:
//   int_H max(0, <m,w>) dw   = pi (1 + cos t) / 2
//   int_H max(0, <m,w>) w dw = 2/3 ((pi - t) m + sin t e),   cos t = <m, e>
// Both are linear in c, so E = dot(c, W) with W returned here (per channel
// the same). A surface facing e (m = -e) gets W = 0: it never reads light
// emitted by surfaces that face its own way.
vec4 bin_irradiance_weights(int b, vec3 n)
{
    vec3 e = bin_axis(b);
    vec3 m = -n;
    float ct = clamp(dot(m, e), -1.0, 1.0);
    float t = acos(ct);
    float k0 = LPV_PI * (1.0 + ct) * 0.5;
    vec3 k1 = (2.0 / 3.0) * ((LPV_PI - t) * m + sin(t) * e);
    // a  = (2/pi) (c0 / C0 - 1.5 <cv, e> / C1)
    // bv = 3 / (2 pi) (cv / C1 - pi a e)
    // E  = a k0 + <bv, k1>
    //    = a (k0 - 1.5 <e, k1>) + 3 / (2 pi C1) <cv, k1>
    float ek1 = dot(e, k1);
    float wa = k0 - 1.5 * ek1;
    vec3 wv = (-(2.0 / LPV_PI) * 1.5 / LPV_SH_C1 * wa) * e + (1.5 / (LPV_PI * LPV_SH_C1)) * k1;
    float w0 = (2.0 / LPV_PI) / LPV_SH_C0 * wa;
    return vec4(w0, wv.y, wv.z, wv.x); // slot order (1, y, z, x)
}

// The weights of volume `bin` of a cascade with `bins` volumes for a surface
// facing unit n: E = sum over the volumes of dot(c, weights) / cell^2.
vec4 volume_irradiance_weights(int bins, int bin, vec3 n)
{
    return bins == 1 ? sh_lobe(-n) : bin_irradiance_weights(bin, n);
}

// One loop over the volumes, bins or not, and (lpv_irradiance) over the
// cascades in use, not LPV_MAX_CASCADES: on llvmpipe a return in the middle
// and a constant-bound loop both cost code that does not apply (the lookup
// took 92 ms of a 512^2 frame at the balanced preset, then 55).
// Surfaces facing an axis or one of the scene's plane normals read the sum
// over the volumes made once per cell for that normal (u_lpv_normals): one
// fetch instead of three per volume. Trilinear filtering and the sum are
// both linear, so the two ways give the same E up to rounding (and, for a
// plane, the normal's rounding); the full sum's fetches run only where some
// pixel of a SIMD group has another normal (llvmpipe fetches nothing for a
// group whose lanes are all masked off).
// a: lookup_normal_of(n), found once per pixel (the search is arithmetic
// that every lane runs). listed_only (a constant): leave the full sum out of
// the program (the caller looks up only listed normals; llvmpipe runs an
// if's arithmetic even where no lane takes it).
vec3 cascade_irradiance_at(int k, vec3 q, vec3 n, int a, const bool listed_only)
{
    const int bins = bin_count();
    vec3 e = vec3(0.0);
    if (a >= 0) {
        vec3 t = volume_texcoord(k * u_lpv_lookup_normals + a, q, u_lpv_normals_slabs_z, vec3(textureSize(u_lpv_normals, 0)));
        e = textureLod(u_lpv_normals, t, 0.0).rgb;
    } else if (!listed_only) {
        for (int bin = 0; bin < bins; ++bin) {
            vec4 w = volume_irradiance_weights(bins, bin, n);
            vec4 r, g, b;
            volume_sh_at(k * bins + bin, q, r, g, b);
            e += vec3(dot(r, w), dot(g, w), dot(b, w));
        }
    }
    float cell = cascade_cell(k);
    return max(e / (cell * cell), 0.0);
}

vec3 cascade_irradiance(int k, vec3 p, vec3 n, int a, const bool listed_only)
{
    // half a cell in front of the surface, mirroring the injection offset
    vec3 q = cascade_coords(k, p + 0.5 * cascade_cell(k) * n);
    vec3 e = cascade_irradiance_at(k, q, n, a, listed_only);
    if (LPV_LOOKUP_DAMPING != 0 && u_damping > 0.0) {
        vec3 far = cascade_irradiance_at(k, q + n, n, a, listed_only);
        float near_l = dot(e, vec3(0.2126, 0.7152, 0.0722));
        float far_l = dot(far, vec3(0.2126, 0.7152, 0.0722));
        float ratio = near_l > 0.0 ? clamp(far_l / near_l, 0.0, 1.0) : 1.0;
        e *= 1.0 - u_damping * (1.0 - ratio);
    }
    return e;
}

// Weight of cascade k at p: 1 deep inside, 0 within a cell of its border.
float cascade_weight(int k, vec3 p)
{
    vec3 q = cascade_coords(k, p);
    vec3 d3 = min(q, vec3(grid_dims()) - q);
    float d = min(d3.x, min(d3.y, d3.z));
    return clamp((d - 1.0) * 0.5, 0.0, 1.0);
}

// Each cascade's share of the blend at p (see the top of this file): the
// finest cascade holding p takes w, the rest goes to the next coarser one.
void cascade_blend(vec3 p, out float share[LPV_MAX_CASCADES])
{
    int count = cascade_count();
    float remaining = 1.0;
    for (int k = 0; k < LPV_MAX_CASCADES; ++k) {
        float w = k >= count ? 0.0 : (k == count - 1 ? 1.0 : cascade_weight(k, p));
        share[k] = remaining * w;
        remaining *= 1.0 - w;
    }
}

// 1 when p lies inside cascade k's cells, else 0 (the far field's sum).
float cascade_holds(int k, vec3 p)
{
    vec3 q = cascade_coords(k, p);
    return all(greaterThanEqual(q, vec3(0.0))) && all(lessThan(q, vec3(grid_dims()))) ? 1.0 : 0.0;
}

// Each cascade's share at p: the blend across borders, or with the far field
// 1 for every cascade holding p (they hold light of different ages).
void cascade_shares(vec3 p, out float share[LPV_MAX_CASCADES])
{
    if (!far_field()) {
        cascade_blend(p, share);
        return;
    }
    for (int k = 0; k < LPV_MAX_CASCADES; ++k)
        share[k] = k < cascade_count() ? cascade_holds(k, p) : 0.0;
}

// The irradiance at p facing n_in; with listed_only (a constant) only where
// n_in is one of the lookup's normals (done true; elsewhere 0 and done
// false, for lpv_irradiance in a second pass).
vec3 irradiance_of(vec3 p, vec3 n_in, const bool listed_only, out bool done)
{
    done = true;
    float len = length(n_in);
    if (!(len > 1e-8) || isinf(len) || !finite3(p))
        return vec3(0.0);
    vec3 n = n_in / len;
    int a = lookup_normal_of(n);
    done = !listed_only || a >= 0;
    float share[LPV_MAX_CASCADES];
    cascade_shares(p, share);
    vec3 e = vec3(0.0);
    for (int k = 0; k < cascade_count(); ++k) // not LPV_MAX_CASCADES: see cascade_irradiance_at
        if (share[k] > 0.0)
            e += share[k] * cascade_irradiance(k, p, n, a, listed_only);
    return e;
}

vec3 lpv_irradiance(vec3 p, vec3 n_in)
{
    bool done;
    return irradiance_of(p, n_in, false, done);
}

vec3 lpv_irradiance_listed(vec3 p, vec3 n_in, out bool done)
{
    return irradiance_of(p, n_in, true, done);
}

// (r, g, b) . v / cell^2 at world point x, blended across cascades like
// lpv_irradiance (for the glossy march and the media's in-scattering).
vec3 lpv_project(vec3 x, vec4 v)
{
    float share[LPV_MAX_CASCADES];
    cascade_shares(x, share);
    vec3 e = vec3(0.0);
    for (int k = 0; k < cascade_count(); ++k)
        if (share[k] > 0.0)
            e += share[k] * cascade_project_at(k, cascade_coords(k, x), v);
    return e;
}

// Cell size of the finest cascade holding x well inside (the march's scale).
float lpv_cell_at(vec3 x)
{
    int count = cascade_count();
    for (int k = 0; k < count - 1; ++k)
        if (cascade_weight(k, x) >= 1.0)
            return cascade_cell(k);
    return cascade_cell(count - 1);
}
