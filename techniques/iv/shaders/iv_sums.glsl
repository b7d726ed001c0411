// iv_sums.glsl - one lit surface point's share of its voxel's atlas sums,
// for the cloud's points (iv_points.comp) and the camera's pixels
// (iv_reproject.comp) alike; iv_resolve.comp turns the sums into means.
// n unit, radiosity B = albedo x E_direct + pi x emission (W/m^2), area the
// point stands for (m^2; 0 for a pixel, LPV_IV_COVER), local its place in
// the voxel (0..1 per axis).
void iv_sum_point(inout IvSplat s, vec3 n, vec3 albedo, vec3 radiosity, float area, vec3 local)
{
    // the SH of B / pi over the normal's hemisphere
    vec4 h = vec4(LPV_IV_HEMI0, LPV_IV_HEMI1 * n.y, LPV_IV_HEMI1 * n.z, LPV_IV_HEMI1 * n.x);
    s.r += h * radiosity.r;
    s.g += h * radiosity.g;
    s.b += h * radiosity.b;
    s.n += vec4(n, 1.0); // and the count
    s.a += vec4(albedo, area);
    vec3 an = abs(n); // LPV_IV_FOLD
    float fs = (an.x >= an.y && an.x >= an.z ? n.x : an.y >= an.z ? n.y : n.z) >= 0.0 ? 1.0 : -1.0;
    s.f += vec4(fs * n, fs * area);
    s.hi = max(s.hi, vec4(local, 0.0)); // the greatest place
    s.lo = max(s.lo, vec4(1.0 - local, 0.0)); // 1 - the least
}
