// propagate.comp - one propagation step in every cascade, gathered per
// destination cell (docs/propagation.md). Light from the neighbour at
// cell - dir, travelling along dir, is the sparse matrix of lpv_shared.h
// applied to the neighbour's coefficients times its flux limit sigma (what
// it sends, flux_limit.glsl limited(): written with the neighbour by
// lpv_pack.comp, the hand-off or the previous step), scaled by the face's
// transmittance. Cascades never exchange
// light: each is its own volume. The step's output is also added to the
// accumulated volume.
//
// Bounces (paper section 7, docs/effects.md): the part of what this cell
// sends along dir that the blocker on the face ahead stops (1 - transmittance)
// is reflected back into this cell with the blocker's albedo times the bounce
// intensity, as a diffuse lobe facing -dir. Transmitted plus reflected never
// exceeds what was sent, so the energy stays bounded for albedo <= 1.
layout(local_size_x = LPV_PROP_WG_X, local_size_y = LPV_PROP_WG_Y, local_size_z = 1) in;

layout(binding = LPV_TEX_SENT_IN) uniform samplerBuffer u_sent;    // LpvCell as 3 texels: coefficients x sigma
layout(std430, binding = LPV_SSBO_LPV_OUT) writeonly buffer Out { LpvCell cout[]; };
layout(std430, binding = LPV_SSBO_LPV_ACC) writeonly buffer Acc { LpvCell acc[]; };
layout(binding = LPV_TEX_ACC_IN) uniform samplerBuffer u_acc;           // LpvCell as 3 texels
layout(binding = LPV_TEX_TRANSMIT) uniform samplerBuffer u_transmit;    // 6 per cell, as 3 RG texels (+-x, +-y, +-z)
layout(binding = LPV_TEX_REFLECT) uniform samplerBuffer u_reflect;   // rgb reflectance, 6 per cell
layout(std430, binding = LPV_SSBO_SENT_OUT) writeonly buffer SentOut { LpvCell sent_out[]; };

uniform int u_occlusion; // 0 on the first step and when occlusion is off
uniform int u_bounce;    // 1: reflect blocked light (only with u_occlusion)
uniform int u_write_coeffs; // 1: also write the coefficients (cout): the last step and before a hand-off

// The term one source channel c (already times its flux limit) sends along
// +-axis (slot 1 = y, 2 = z, 3 = x).
// The band-1 rows of the transfer (E, F, G of lpv_shared.h) depend on the
// transport; row 0 (A, B) does not.
vec3 prop_efg;

vec4 transfer(vec4 c, int slot, float s)
{
    float f = LPV_PROP_A * c.x + s * LPV_PROP_B * c[slot];
    if (!(f > 0.0))
        return vec4(0.0);
    vec4 o = prop_efg.z * c;
    o.x = f;
    o[slot] = s * prop_efg.x * c.x + prop_efg.y * c[slot];
    return o;
}

// DC of what channel c (times its flux limit) sends along +-axis: the flux
// it sends / sqrt(4 pi).
float sent_dc(vec4 c, int slot, float s)
{
    float f = LPV_PROP_A * c.x + s * LPV_PROP_B * c[slot];
    return f > 0.0 ? f : 0.0;
}

LpvCell fetch_cell(samplerBuffer b, int j)
{
    LpvCell n;
    n.r = texelFetch(b, 3 * j);
    n.g = texelFetch(b, 3 * j + 1);
    n.b = texelFetch(b, 3 * j + 2);
    return n;
}

void main()
{
    ivec3 c;
    int v = volume_of_invocation(ivec3(gl_GlobalInvocationID), c);
    if (!cell_inside(c) || v >= volume_count())
        return;
    prop_efg = transport() == LPV_TRANSPORT_CENTRAL
                ? vec3(LPV_PROP_CENTRAL_E, LPV_PROP_CENTRAL_F, LPV_PROP_CENTRAL_G)
                : vec3(LPV_PROP_E, LPV_PROP_F, LPV_PROP_G);
    int k = volume_cascade(v);     // the cascade: cell size, transmittances
    int base = v * grid_cells();   // this volume's cells
    int i = base + cell_index(c);
    int ti = k * grid_cells() + cell_index(c); // this cell in the per-cascade buffers
    LpvCell sum;
    sum.r = sum.g = sum.b = vec4(0.0);
    // the transmittances of the six faces, a pair (+axis, -axis) per fetch
    vec2 trans[3] = vec2[3](vec2(1.0), vec2(1.0), vec2(1.0));
    if (u_occlusion != 0)
        for (int axis = 0; axis < 3; ++axis)
            trans[axis] = texelFetch(u_transmit, ti * 3 + axis).xy;
    // the six directions written out (GATHER), so that the axis, the sign
    // and the SH slot are constants: llvmpipe would otherwise index vectors
    // and branch per lane. A neighbour outside the grid is read clamped
    // (the cell itself) and weighted 0, without a branch: llvmpipe runs
    // a branch that differs between lanes under masks, which costs more than
    // the fetch it would save at the border.
#define GATHER(dir, axis, s, slot)                                                               \
    {                                                                                            \
        ivec3 src = c;                                                                           \
        src[axis] -= int(s);                                                                     \
        bool inside = src[axis] >= 0 && src[axis] < grid_dims()[axis];                          \
        float t = inside ? trans[axis][dir & 1] : 0.0;                                           \
        src[axis] = clamp(src[axis], 0, grid_dims()[axis] - 1);                                  \
        int j = base + cell_index(src);                                                          \
        LpvCell n = fetch_cell(u_sent, j);                                                       \
        sum.r += t * transfer(n.r, slot, s);                                                     \
        sum.g += t * transfer(n.g, slot, s);                                                     \
        sum.b += t * transfer(n.b, slot, s);                                                     \
    }
    // direction order +x -x +y -y +z -z; x lives in SH slot 3, y in 1, z in 2
    GATHER(0, 0, 1.0, 3)
    GATHER(1, 0, -1.0, 3)
    GATHER(2, 1, 1.0, 1)
    GATHER(3, 1, -1.0, 1)
    GATHER(4, 2, 1.0, 2)
    GATHER(5, 2, -1.0, 2)
#undef GATHER
#if LPV_PROPAGATE_EFFECTS
    // Compiled only into the variant the engine uses when a bounce or a
    // medium is on (techniques/lpv/gpu/lpv_propagate.c): llvmpipe runs a branch's code
    // under lane masks even when no lane takes it, and these two blocks cost
    // the plain step 15 %.
    if (u_bounce != 0 && u_occlusion != 0) {
        LpvCell self = fetch_cell(u_sent, i);
        for (int dir = 0; dir < LPV_DIR_COUNT; ++dir) {
            int axis = dir / 2;
            float s = (dir & 1) == 0 ? 1.0 : -1.0;
            ivec3 ahead = c;
            ahead[axis] += int(s);
            if (!cell_inside(ahead))
                continue;
            int slot = axis == 0 ? 3 : axis;
            vec3 refl = texelFetch(u_reflect, (k * grid_cells() + cell_index(ahead)) * LPV_DIR_COUNT + dir).rgb;
            if (!any(greaterThan(refl, vec3(0.0))))
                continue;
            vec3 back = vec3(0.0);
            back[axis] = -s;
            vec4 lobe = sh_lobe(back) / LPV_SH_LOBE0; // DC 1: the reflected DC is refl x sent DC
            sum.r += lobe * (refl.r * sent_dc(self.r, slot, s));
            sum.g += lobe * (refl.g * sent_dc(self.g, slot, s));
            sum.b += lobe * (refl.b * sent_dc(self.b, slot, s));
        }
    }
    if ((u_medium & 1) != 0) {
        // light crossing this cell loses what the medium scatters or absorbs
        // on the way: the media pass scatters it toward the eye instead
        float cell = cascade_cell(k);
        vec3 att = exp(-medium_sigma_t((vec3(c) + 0.5 + cascade_origin_cells(k)) * cell) * cell);
        sum.r *= att.r;
        sum.g *= att.g;
        sum.b *= att.b;
    }
#endif
    // Only the hand-off and the read-back of the last step read the
    // coefficients themselves (the next step gathers what is sent): other
    // steps skip the store, a third of what a cell-step writes.
    if (u_write_coeffs != 0)
        cout[i] = sum;
    // The next step gathers what each source sends; computing it here, once
    // per cell, saves recomputing the flux limit for each of the six
    // destinations, and the neighbours read 12 values instead of 16.
    sent_out[i] = limited(sum);
    LpvCell a = fetch_cell(u_acc, i);
    a.r += sum.r;
    a.g += sum.g;
    a.b += sum.b;
    acc[i] = a;
}
