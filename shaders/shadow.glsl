// shadow.glsl - visibility of the lights through their shadow maps
// (pass_shadow.c, docs/shadows.md), shared by the shading and the media's
// in-scattering. Needs lights.glsl.
layout(binding = 4) uniform sampler2DArrayShadow u_shadow;
layout(std140, binding = LPV_UBO_SHADOW) uniform ShadowUBO { LpvShadowBlock S; };
layout(binding = LPV_TEX_SHADOW_TRANSMIT) uniform sampler2DArray u_shadow_transmit;

// Percentage-closer filtering: (2R + 1)^2 hardware-compare bilinear taps one
// texel apart (a separable tent of 2R + 2 texels; R = 0: one bilinear
// compare), 1 = lit. uv is the face's own (0..1); every tap is kept half a
// texel inside the face's tile (area light faces share a layer), so the
// filter never reads a neighbouring face.
//
// The same filter in (R + 1)^2 taps instead of (2R + 1)^2: along an axis the
// 2R + 1 taps weigh the 2R + 2 texels under them (1 - f, 1, ..., 1, f), f the
// sample's fraction between texel centres. Each pair of neighbouring texels
// is one bilinear compare placed so that its lerp gives the pair's ratio, with
// the pair's total as its weight: (1 - f, 1) at 1 / (2 - f) into the pair,
// weight 2 - f; (1, 1) at 1/2, weight 2; (1, f) at f / (1 + f), weight 1 + f.
float shadow_pcf(int face, vec2 uv, float depth, int R)
{
    float texel = S.counts.z;
    vec4 tile = S.faces[face].tile;
    vec2 at = tile.xy + uv * tile.z, lo = tile.xy + 0.5 * texel, hi = tile.xy + tile.z - 0.5 * texel;
    if (R == 0)
        return texture(u_shadow, vec4(clamp(at, lo, hi), tile.w, depth));
    vec2 u = at / texel - 0.5; // texel-centre coordinates
    vec2 i = floor(u), f = u - i;
    float sum = 0.0;
    for (int y = 0; y <= R; ++y) {
        // pair y along t covers texels i.y - R + 2y and the one after it
        float wy = y == 0 ? 2.0 - f.y : (y == R ? 1.0 + f.y : 2.0);
        float oy = y == 0 ? 1.0 / (2.0 - f.y) : (y == R ? f.y / (1.0 + f.y) : 0.5);
        float ty = i.y - float(R) + 2.0 * float(y) + oy;
        for (int x = 0; x <= R; ++x) {
            float wx = x == 0 ? 2.0 - f.x : (x == R ? 1.0 + f.x : 2.0);
            float ox = x == 0 ? 1.0 / (2.0 - f.x) : (x == R ? f.x / (1.0 + f.x) : 0.5);
            float tx = i.x - float(R) + 2.0 * float(x) + ox;
            vec2 c = (vec2(tx, ty) + 0.5) * texel;
            sum += wx * wy * texture(u_shadow, vec4(clamp(c, lo, hi), tile.w, depth));
        }
    }
    return sum / float((2 * R + 1) * (2 * R + 1));
}

// The share of the light that the BLEND surfaces of face `face` let through
// to a receiver at reversed depth `depth` at the face's uv (1 where none lies
// in front of it): bilinear over the four texels around uv, each passing its
// product of 1 - alpha where the receiver lies behind its nearest BLEND
// surface (a smaller reversed depth). A receiver between two of them takes
// both (docs/scenes.md, "Alpha").
float shadow_transmit(int face, vec2 uv, float depth)
{
    float texel = S.counts.z;
    vec4 tile = S.faces[face].tile;
    vec2 u = (tile.xy + uv * tile.z) / texel - 0.5; // texel-centre coordinates
    vec2 i = floor(u), f = u - i;
    ivec2 lo = ivec2(round(tile.xy / texel)), hi = ivec2(round((tile.xy + tile.z) / texel)) - 1;
    float sum = 0.0;
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        vec4 t = texelFetch(u_shadow_transmit, ivec3(clamp(ivec2(i) + o, lo, hi), int(tile.w)), 0);
        float w = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
        sum += w * (depth < t.a ? t.r : 1.0);
    }
    return sum;
}

// Which lights a caller passes (a constant, so that after inlining the
// compiler drops the code of the other kinds): llvmpipe runs both sides of
// every branch under lane masks, so a loop over all lights pays for every
// kind's face selection with each light (a spot paid 4 ms of a 512^2 frame
// for the directional lights' cascade search); the shading loops over each
// kind apart (shading.glsl; gpu/light_faces.c orders the lights so).
const int SHADOW_ANY_LIGHT = 0;
const int SHADOW_DIRECTIONAL = 1; // lights [0, L.counts.w): cascades
const int SHADOW_PERSPECTIVE = 2; // lights [L.counts.w, L.counts.z): points and spots, one face or a cube
const int SHADOW_AREA_SAMPLE = 3; // lights [L.counts.z, L.counts.x)

// The shadow-map face of light l that holds x: the cube face of the major
// axis of x - light, the area light face whose axis is nearest x - light, the
// single face of a spot, or the finest cascade whose
// square holds x with LPV_SHADOW_BORDER_TEXELS to spare; -1 if none does.
// depth: x's depth along that face's axis (m) for a perspective face (every
// light but a directional one), 0 for a cascade.
// kind: which lights l can be (SHADOW_ANY_LIGHT when unknown).
int shadow_face_at(int l, vec3 x, const int kind, out float depth)
{
    vec4 info = S.lights[l];
    int first = int(info.x), count = int(info.y);
    vec3 d = x - L.lights[l].position_type.xyz;
    depth = 0.0;
    if (kind == SHADOW_AREA_SAMPLE || (kind == SHADOW_ANY_LIGHT && info.z == 2.0)) {
        // area light sample: the face whose axis is nearest x's direction
        int best = first;
        float best_dot = dot(d, S.faces[first].axis.xyz);
        // every sample has LPV_AREA_FACES faces (gpu/light_faces.c): a
        // constant bound that the compiler unrolls (llvmpipe runs a loop
        // with a mask and an any-lane test per trip)
        for (int k = 1; k < LPV_AREA_FACES; ++k) {
            float dk = dot(d, S.faces[first + k].axis.xyz);
            if (dk > best_dot) {
                best = first + k;
                best_dot = dk;
            }
        }
        depth = best_dot;
        return best;
    }
    if (kind != SHADOW_DIRECTIONAL && count == 6) {
        vec3 a = abs(d);
        depth = max(a.x, max(a.y, a.z));
        if (a.x >= a.y && a.x >= a.z)
            return first + (d.x >= 0.0 ? 0 : 1);
        if (a.y >= a.z)
            return first + (d.y >= 0.0 ? 2 : 3);
        return first + (d.z >= 0.0 ? 4 : 5);
    }
    if (kind == SHADOW_PERSPECTIVE || (kind == SHADOW_ANY_LIGHT && info.z == 0.0)) {
        depth = dot(d, S.faces[first].axis.xyz);
        return first;
    }
    float inner = 1.0 - 2.0 * LPV_SHADOW_BORDER_TEXELS * S.counts.z;
    for (int k = 0; k < count; ++k) {
        vec4 c = S.faces[first + k].view_proj * vec4(x, 1.0); // orthographic: w = 1
        if (all(lessThanEqual(abs(c.xy), vec2(inner))))
            return first + k;
    }
    return -1;
}

int shadow_face_of(int l, vec3 x, const int kind)
{
    float depth;
    return shadow_face_at(l, x, kind, depth);
}

// Size (m) of one texel of face f at x.
float shadow_texel(int f, vec3 x, vec3 light_pos)
{
    LpvShadowFaceGpu F = S.faces[f];
    if (F.info.y == 0.0)
        return F.info.x;
    return F.info.x * max(dot(x - light_pos, F.axis.xyz), 0.0);
}

// Visibility (0..1) of light l from a receiver at p with unit normal n,
// a light of the given kind (SHADOW_ANY_LIGHT when unknown),
// filtered over the kernel (taps = 1: one bilinear compare, for callers that
// average many lookups themselves, such as the media's ray march). The
// receiver bias is in texels of the map at p (texel size T), so it does not
// grow with the scene: p moves LPV_SHADOW_NORMAL_OFFSET * T * sin(theta)
// along n, which lifts it off its own plane by what that plane rises across
// the kernel, then (LPV_SHADOW_DEPTH_BIAS + LPV_SHADOW_SLOPE_BIAS * tan(theta))
// * T towards the light (the slope-scaled depth bias; moving along the ray to
// the light keeps the texel the same).
float shadow_visibility_of(int l, vec3 p, vec3 n, int taps, const int kind)
{
    LpvLightGpu li = L.lights[l];
    if (int(S.lights[l].y) == 0)
        return 1.0;
    vec3 lp = li.position_type.xyz;
    vec3 to_light = int(li.position_type.w) == LPV_LIGHT_TYPE_DIRECTIONAL ? -li.direction_range.xyz
                                                                          : normalize(lp - p);
    float c = clamp(dot(n, to_light), 0.0, 1.0);
    float s = sqrt(max(1.0 - c * c, 0.0));
    float tan_t = min(s / max(c, 1e-4), LPV_SHADOW_MAX_SLOPE);
    // the offset may cross into a neighbouring face or cascade: the face is
    // the offset point's
    int f;
    vec3 q = p;
    if (kind == SHADOW_AREA_SAMPLE || kind == SHADOW_PERSPECTIVE || (kind == SHADOW_ANY_LIGHT && S.lights[l].z != 1.0)) {
        // perspective faces: all of a light's faces have the same texel per
        // metre of depth (info.x), so T needs only p's depth along the axis of
        // the face holding p; the face that is read is the offset point's
        float depth;
        shadow_face_at(l, p, kind, depth);
        float T = S.faces[int(S.lights[l].x)].info.x * max(depth, 0.0);
        q = p + n * (LPV_SHADOW_NORMAL_OFFSET * T * s) +
            to_light * ((LPV_SHADOW_DEPTH_BIAS + LPV_SHADOW_SLOPE_BIAS * tan_t) * T);
        f = shadow_face_of(l, q, kind);
    } else {
        // a directional light's cascades: each has its own texel, so a
        // crossing is offset again by the next cascade's
        f = shadow_face_of(l, p, kind);
        for (int pass = 0; pass < 2 && f >= 0; ++pass) {
            float T = shadow_texel(f, p, lp);
            q = p + n * (LPV_SHADOW_NORMAL_OFFSET * T * s) +
                to_light * ((LPV_SHADOW_DEPTH_BIAS + LPV_SHADOW_SLOPE_BIAS * tan_t) * T);
            int g = shadow_face_of(l, q, kind);
            if (g == f)
                break;
            f = g;
        }
    }
    if (f < 0)
        return 1.0; // outside every cascade: no shadow information
    vec4 clip = S.faces[f].view_proj * vec4(q, 1.0);
    if (!(clip.w > 0.0))
        return 0.0;
    vec3 ndc = clip.xyz / clip.w;
    if (any(greaterThan(abs(ndc.xy), vec2(1.0))))
        return S.faces[f].info.y == 0.0 ? 1.0 : 0.0; // outside a spot's face is outside its cone
    // the maps hold reversed depth in [0, 1] as it is (pass_shadow.c)
    float v = shadow_pcf(f, ndc.xy * 0.5 + 0.5, ndc.z, taps == 1 ? 0 : LPV_SHADOW_PCF_RADIUS);
    if (S.options.x != 0.0 && v > 0.0)
        v *= shadow_transmit(f, ndc.xy * 0.5 + 0.5, ndc.z);
    return v;
}

float shadow_visibility_taps(int l, vec3 p, vec3 n, int taps)
{
    return shadow_visibility_of(l, p, n, taps, SHADOW_ANY_LIGHT);
}

// The filtered visibility for surfaces (shading.glsl), of a light of the
// given kind.
float shadow_visibility(int l, vec3 p, vec3 n, const int kind)
{
    return shadow_visibility_of(l, p, n, 0, kind);
}
