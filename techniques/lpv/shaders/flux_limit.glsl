// flux_limit.glsl - the flux limiter of docs/propagation.md (core's oracle:
// lpv_oracle_propagate_step). sigma = c0 / sum of the six positive directional
// fluxes F_d = A c0 +- B c_axis; exactly 1 when no F_d is negative (the linear
// scheme), 0 for a cell without positive or with non-finite flux, so a step
// never sends out more flux than the cell holds.
float flux_limit(vec4 c)
{
    if (any(isnan(c)) || any(isinf(c)))
        return 0.0;
    vec3 bc = LPV_PROP_B * c.yzw;
    float a = LPV_PROP_A * c.x;
    vec3 plus = max(vec3(a) + bc, 0.0);
    vec3 minus = max(vec3(a) - bc, 0.0);
    float p = plus.x + plus.y + plus.z + minus.x + minus.y + minus.z;
    return (c.x > 0.0 && p > 0.0 && !isinf(p)) ? c.x / p : 0.0;
}

// What a cell sends: its coefficients times its flux limits, per channel
// (0 for a channel whose limit is 0, non-finite coefficients included). A
// step's transfer is linear in them, so the neighbours read these and no
// separate limits: 12 values per neighbour instead of 16.
LpvCell limited(LpvCell c)
{
    float sr = flux_limit(c.r), sg = flux_limit(c.g), sb = flux_limit(c.b);
    LpvCell o;
    o.r = sr > 0.0 ? c.r * sr : vec4(0.0);
    o.g = sg > 0.0 ? c.g * sg : vec4(0.0);
    o.b = sb > 0.0 ? c.b * sb : vec4(0.0);
    return o;
}
