// propagate.comp - one propagation step, gathered per destination cell
// (docs/propagation.md). Light from the neighbour at cell - dir, travelling
// along dir, is the sparse matrix of lpv_shared.h applied to the neighbour's
// coefficients, scaled by the neighbour's flux limit sigma (computed when the
// neighbour was written: by lpv_pack.comp or the previous step) and by the face's
// transmittance. The step's output is also added to the accumulated volume.
layout(local_size_x = LPV_PROP_WG_X, local_size_y = LPV_PROP_WG_Y, local_size_z = 1) in;

layout(binding = LPV_TEX_LPV_IN) uniform samplerBuffer u_in;       // LpvCell as 3 texels
layout(std430, binding = LPV_SSBO_LPV_OUT) writeonly buffer Out { LpvCell cout[]; };
layout(std430, binding = LPV_SSBO_LPV_ACC) writeonly buffer Acc { LpvCell acc[]; };
layout(binding = LPV_TEX_ACC_IN) uniform samplerBuffer u_acc;           // LpvCell as 3 texels
layout(binding = LPV_TEX_TRANSMIT) uniform samplerBuffer u_transmit;    // 6 per cell
layout(binding = LPV_TEX_SIGMA_IN) uniform samplerBuffer u_sigma_in; // rgb flux limits
layout(std430, binding = LPV_SSBO_SIGMA_OUT) writeonly buffer SigmaOut { vec4 sigma_out[]; };

uniform int u_occlusion; // 0 on the first step and when occlusion is off

// The term one source channel c, with flux limit sigma (flux_limit.glsl),
// sends along +-axis (slot 1 = y, 2 = z, 3 = x).
vec4 transfer(vec4 c, float sigma, int slot, float s)
{
    float f = LPV_PROP_A * c.x + s * LPV_PROP_B * c[slot];
    if (!(f > 0.0) || !(sigma > 0.0))
        return vec4(0.0);
    vec4 o = LPV_PROP_G * c;
    o.x = f;
    o[slot] = s * LPV_PROP_E * c.x + LPV_PROP_F * c[slot];
    return o * sigma;
}

void main()
{
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (!cell_inside(c))
        return;
    int i = cell_index(c);
    LpvCell sum;
    sum.r = sum.g = sum.b = vec4(0.0);
    for (int dir = 0; dir < LPV_DIR_COUNT; ++dir) {
        int axis = dir / 2;
        float s = (dir & 1) == 0 ? 1.0 : -1.0;
        ivec3 src = c;
        src[axis] -= int(s);
        if (!cell_inside(src))
            continue;
        int slot = axis == 0 ? 3 : axis; // x lives in slot 3, y in 1, z in 2
        float t = u_occlusion != 0 ? texelFetch(u_transmit, i * LPV_DIR_COUNT + dir).x : 1.0;
        int j = cell_index(src);
        LpvCell n;
        n.r = texelFetch(u_in, 3 * j);
        n.g = texelFetch(u_in, 3 * j + 1);
        n.b = texelFetch(u_in, 3 * j + 2);
        vec4 sigma = texelFetch(u_sigma_in, j);
        sum.r += t * transfer(n.r, sigma.r, slot, s);
        sum.g += t * transfer(n.g, sigma.g, slot, s);
        sum.b += t * transfer(n.b, sigma.b, slot, s);
    }
    cout[i] = sum;
    // The next step needs each source's flux limit; computing it here, once
    // per cell, saves recomputing it for each of the six destinations.
    sigma_out[i] = vec4(flux_limit(sum.r), flux_limit(sum.g), flux_limit(sum.b), 0.0);
    LpvCell a;
    a.r = texelFetch(u_acc, 3 * i) + sum.r;
    a.g = texelFetch(u_acc, 3 * i + 1) + sum.g;
    a.b = texelFetch(u_acc, 3 * i + 2) + sum.b;
    acc[i] = a;
}
