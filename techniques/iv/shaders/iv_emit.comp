// iv_emit.comp - what every occupied voxel sends out in bounce u_bounce:
// its direct light, plus from the second bounce on its albedo times the
// irradiance the previous gather reconstructs at its centre over the
// hemisphere it arrives on, for each side of its axis in proportion to the
// points facing that way (a thin wall's voxel holds both sides;
// techniques/iv/core/oracle_iv.h, lpv_iv_emit). Then each side is shown at its own
// radiance as far as it covers the voxel (iv_sides, iv_cover). The two volumes alternate (paper 3.3). Empty voxels
// send nothing.
layout(local_size_x = LPV_IV_WG) in;

layout(std430, binding = LPV_SSBO_IV_VOXELS) readonly buffer Voxels { IvVoxel voxels[]; };
layout(std430, binding = LPV_SSBO_IV_EMIT) writeonly buffer Emit { LpvCell emit[]; };
uniform int u_bounce; // 1: direct light only

// The voxel's SH e is the mean over its points of B / pi over each point's
// hemisphere, so a wall whose two faces share the voxel showed each face at
// half its radiance (the other half of the points face away): the lit side
// of every thin wall, in a room of box walls, at half its light, which
// darkened every bounce (two-rooms: -0.28 of the 1-bounce reference's
// light). Read along the axis a as two hemispheres B_f (its share of the
// points cf) and B_b (cb), each side is shown at the part kf, kb of its
// mean radiance B / c that iv_cover gives (kf = cf: as the plain mean).
vec4 iv_sides(vec4 e, vec3 a, float cf, float cb, float kf, float kb)
{
    float sum = e.x / LPV_IV_HEMI0;
    if (!(sum > 0.0))
        return e;
    float diff = clamp(dot(vec3(e.w, e.y, e.z) / LPV_IV_HEMI1, a), -sum, sum);
    float bf = 0.5 * (sum + diff), bb = 0.5 * (sum - diff);
    float xf = kf / max(cf, LPV_IV_SIDE_MIN) - 1.0, xb = kb / max(cb, LPV_IV_SIDE_MIN) - 1.0;
    vec4 hf = vec4(LPV_IV_HEMI0, LPV_IV_HEMI1 * a.y, LPV_IV_HEMI1 * a.z, LPV_IV_HEMI1 * a.x);
    vec4 hb = vec4(LPV_IV_HEMI0, -hf.yzw);
    return e + bf * max(xf, 0.0) * hf + bb * max(xb, 0.0) * hb;
}

// How much of its mean radiance each side of the voxel shows (LPV_IV_COVER):
// where its points all lie along one axis and the cloud gave their area, the
// part of the voxel face that side covers (its area over
// LPV_IV_COVER_AREA of the face's, at most the points' extent across the
// axis over LPV_IV_COVER_ACROSS), at least its share c, at most 1;
// elsewhere c + t (1 - c), t = 1 - |m| / |f| (1 for a wall's two faces, 0
// for one surface or a corner, whose points agree: |m| = |f|; 2 min(cf, cb)
// in between, which keeps every factor at most 2: a few points a curved
// surface has facing backwards are not spread over the voxel's face).
void iv_cover(IvVoxel v, vec3 a, float cf, out float kf, out float kb)
{
    float cb = 1.0 - cf;
    vec3 m = v.normal.xyz, f = v.fold.xyz;
    float lm = length(m), lf = length(f);
    if (lf >= LPV_IV_FLAT && v.albedo.w > 0.0) {
        float plus = 0.5 * (v.albedo.w + v.fold.w), minus = 0.5 * (v.albedo.w - v.fold.w);
        bool front_plus = dot(a, f) >= 0.0;
        vec3 aa = abs(a);
        vec3 e = v.extent.xyz;
        float across = aa.x >= aa.y && aa.x >= aa.z ? e.y * e.z : aa.y >= aa.z ? e.x * e.z : e.x * e.y;
        kf = clamp(min((front_plus ? plus : minus) / LPV_IV_COVER_AREA, across / LPV_IV_COVER_ACROSS), cf, 1.0);
        kb = clamp(min((front_plus ? minus : plus) / LPV_IV_COVER_AREA, across / LPV_IV_COVER_ACROSS), cb, 1.0);
        return;
    }
    float t = lf > 1e-3 ? clamp(1.0 - lm / lf, 0.0, 1.0) : 0.0;
    kf = cf + t * (1.0 - cf);
    kb = cb + t * (1.0 - cb);
}

// The voxel's axis a and the share cf of its points facing it (the rest
// face -a, if every normal is +-a): the mean normal m where the points
// mostly agree (one surface, a corner), else the folded mean f (LPV_IV_FOLD:
// a wall's two faces); cf = (1 + m.a) / 2. False where neither gives an axis.
bool iv_axis(vec3 m, vec3 f, out vec3 a, out float cf)
{
    float lm = length(m), lf = length(f);
    a = vec3(0.0);
    cf = 1.0;
    if (lm >= LPV_IV_ONE_SIDED * lf && lm > 1e-3)
        a = m / lm;
    else if (lf > 1e-3)
        a = f / lf;
    else
        return false;
    cf = clamp(0.5 * (1.0 + dot(m, a)), 0.0, 1.0);
    return true;
}

void main()
{
    int i = int(gl_GlobalInvocationID.x);
    if (i >= grid_cells())
        return;
    IvVoxel v = voxels[i];
    LpvCell o;
    o.r = o.g = o.b = vec4(0.0);
    if (v.normal.w > 0.0) {
        o.r = v.r;
        o.g = v.g;
        o.b = v.b;
        vec3 a;
        float cf;
        if (iv_axis(v.normal.xyz, v.fold.xyz, a, cf)) {
            float cb = 1.0 - cf;
            if (u_bounce > 1) {
                ivec3 d = grid_dims();
                ivec3 c = ivec3(i % d.x, (i / d.x) % d.y, i / (d.x * d.y));
                vec3 ef = lpv_irradiance(iv_centre(c), a) * v.albedo.rgb * cf;
                vec3 eb = cb > 0.0 ? lpv_irradiance(iv_centre(c), -a) * v.albedo.rgb * cb : vec3(0.0);
                vec4 hf = vec4(LPV_IV_HEMI0, LPV_IV_HEMI1 * a.y, LPV_IV_HEMI1 * a.z, LPV_IV_HEMI1 * a.x);
                vec4 hb = vec4(LPV_IV_HEMI0, -hf.yzw);
                o.r += ef.r * hf + eb.r * hb;
                o.g += ef.g * hf + eb.g * hb;
                o.b += ef.b * hf + eb.b * hb;
            }
            float kf, kb;
            iv_cover(v, a, cf, kf, kb);
            o.r = iv_sides(o.r, a, cf, cb, kf, kb);
            o.g = iv_sides(o.g, a, cf, cb, kf, kb);
            o.b = iv_sides(o.b, a, cf, cb, kf, kb);
        }
    }
    emit[i] = o;
}
