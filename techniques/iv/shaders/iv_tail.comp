// iv_tail.comp - the bounces after the K the volume gathers, as the
// series they tend to (iv_tail, docs/imperfect-volumes.md). Once the light's
// shape has settled every bounce brings about the same share of the one
// before (the dominant eigenvalue of the scene's transfer), but a room lit
// from above alternates first: the ceiling's light, then the floor's, with
// other albedos (the path tracer's panel room: 0.84 then 0.46 of the bounce
// before). So the series steps two bounces at a time: with I_k the radiance
// gathered after bounce k, S_k its total per channel (every voxel's DC
// term; per channel, since a red wall keeps red light longer) and
// D_k = S_k - S_{k-1},
//   q = D_K / D_{K-2}    (S_0 = 0; the share two bounces keep)
//   I = I_K + (I_K - I_{K-2}) q / (1 - q)
// the last two bounces' light times q + q^2 + ... . One q per channel for the
// whole volume: a voxel's own would be the noise of its rays. q is clamped
// to [0, LPV_IV_TAIL_MAX_RATIO^2]; with K < 3 there is none and no tail. A
// voxel's channel whose last two bounces brought it no light gets none.
// u_mode 0: one workgroup sums I_k (binding LPV_SSBO_LPV_OUT) into slot
// u_bounce (three floats a slot: r, g, b); u_mode 1: every voxel adds its
// tail (I_{K-2} at LPV_SSBO_LPV_ACC) and invocation 0 records sqrt(q), the
// per-bounce ratio, in LPV_IV_TAIL_RATIO_SLOT for the stats.
layout(local_size_x = LPV_IV_TAIL_WG) in;

layout(std430, binding = LPV_SSBO_LPV_OUT) buffer Last { LpvCell last[]; };
layout(std430, binding = LPV_SSBO_LPV_ACC) readonly buffer Before { LpvCell before[]; }; // I_{K-2}
layout(std430, binding = LPV_SSBO_IV_TAIL) buffer Sums { float sums[]; };

uniform int u_mode;
uniform int u_bounce; // mode 0: the bounce just gathered; mode 1: K

shared vec3 part[LPV_IV_TAIL_WG];

vec3 sum_at(int k) { return k <= 0 ? vec3(0.0) : vec3(sums[3 * k], sums[3 * k + 1], sums[3 * k + 2]); }

float share_of(float s3, float s2, float s1, float s0)
{
    float d0 = s2 - s3, d1 = s0 - s1;
    return d0 > 0.0 && d1 > 0.0 ? min(d1 / d0, LPV_IV_TAIL_MAX_RATIO * LPV_IV_TAIL_MAX_RATIO) : 0.0;
}

// q per channel after bounce k (0 before the third)
vec3 tail_share(int k)
{
    if (k < 3)
        return vec3(0.0);
    vec3 s3 = sum_at(k - 3), s2 = sum_at(k - 2), s1 = sum_at(k - 1), s0 = sum_at(k);
    return vec3(share_of(s3.x, s2.x, s1.x, s0.x), share_of(s3.y, s2.y, s1.y, s0.y), share_of(s3.z, s2.z, s1.z, s0.z));
}

void main()
{
    int n = grid_cells();
    if (u_mode == 0) {
        uint t = gl_LocalInvocationID.x;
        vec3 s = vec3(0.0);
        for (int i = int(t); i < n; i += LPV_IV_TAIL_WG)
            s += vec3(last[i].r.x, last[i].g.x, last[i].b.x);
        part[t] = s;
        barrier();
        for (uint w = uint(LPV_IV_TAIL_WG) / 2u; w > 0u; w /= 2u) {
            if (t < w)
                part[t] += part[t + w];
            barrier();
        }
        if (t == 0u) {
            sums[3 * u_bounce] = part[0].x;
            sums[3 * u_bounce + 1] = part[0].y;
            sums[3 * u_bounce + 2] = part[0].z;
        }
        return;
    }
    int i = int(gl_GlobalInvocationID.x);
    vec3 q = tail_share(u_bounce);
    if (i == 0) {
        sums[3 * LPV_IV_TAIL_RATIO_SLOT] = sqrt(q.x);
        sums[3 * LPV_IV_TAIL_RATIO_SLOT + 1] = sqrt(q.y);
        sums[3 * LPV_IV_TAIL_RATIO_SLOT + 2] = sqrt(q.z);
    }
    if (i >= n)
        return;
    vec3 f = q / (1.0 - q);
    LpvCell a = last[i], b = before[i];
    vec4 dr = a.r - b.r, dg = a.g - b.g, db = a.b - b.b;
    // a channel whose last two bounces took light away here (the lookup's
    // non-linear rule can) gets no tail: it would run below zero
    last[i] = LpvCell(dr.x > 0.0 && f.x > 0.0 ? a.r + dr * f.x : a.r, dg.x > 0.0 && f.y > 0.0 ? a.g + dg * f.y : a.g,
                      db.x > 0.0 && f.z > 0.0 ? a.b + db * f.z : a.b);
}
