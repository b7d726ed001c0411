// iv_splat.vert - one visible pixel of the camera's G-buffer into the voxel
// that holds it (paper 3.2; the point cloud's voxels gather theirs in
// iv_points.comp, which has written every voxel's texel before this draw
// blends on top). Each is lit here (iv_direct.glsl) and carries its
// outgoing radiance B / pi over its normal's hemisphere as SH (B = albedo x
// E_direct + pi x emission), its normal, its albedo, a count of 1 and its
// folded normal (LPV_IV_FOLD); the atlas sums them and iv_resolve.comp
// divides by the count. A pixel carries no area (LPV_IV_COVER: only the
// cloud's points stand for one), and its place in the voxel goes to the two
// attachments that keep the greatest.
layout(binding = 0) uniform sampler2D u_gbuf_position;
layout(binding = 1) uniform sampler2D u_gbuf_normal;
layout(binding = 2) uniform sampler2D u_gbuf_albedo;
layout(binding = 3) uniform sampler2D u_gbuf_emission;

uniform ivec2 u_gbuf_size;
uniform int u_stride;      // every u_stride-th pixel in x and y
uniform vec2 u_atlas_size;
uniform float u_emission;  // 1: emission counts (area lights off); 0: the area lights carry the emitters

flat out vec4 v_r;
flat out vec4 v_g;
flat out vec4 v_b;
flat out vec4 v_n;
flat out vec4 v_a;
flat out vec4 v_f;
flat out vec4 v_hi;
flat out vec4 v_lo;

void main()
{
    gl_PointSize = 1.0;
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0); // outside the clip volume: dropped
    v_r = v_g = v_b = v_n = v_a = v_f = v_hi = v_lo = vec4(0.0);
    int cols = (u_gbuf_size.x + u_stride - 1) / u_stride;
    ivec2 t = ivec2(gl_VertexID % cols, gl_VertexID / cols) * u_stride;
    vec4 gn = texelFetch(u_gbuf_normal, t, 0);
    if (gn.w < 0.5 || lpv_gbuffer_wire(gn.w))
        return; // background, or a point's or line's pixel (no surface)
    vec3 p = texelFetch(u_gbuf_position, t, 0).xyz, n = gn.xyz;
    vec3 albedo = texelFetch(u_gbuf_albedo, t, 0).rgb * lpv_gbuffer_kd(gn.w); // diffuse
    // an unlit pixel's emission target is what the camera sees, not light
    vec3 emission = lpv_gbuffer_unlit(gn.w) ? vec3(0.0) : texelFetch(u_gbuf_emission, t, 0).rgb;
    float len = length(n);
    if (!finite3(p) || !(len > 1e-8) || isinf(len) || !finite3(albedo) || !finite3(emission))
        return;
    n /= len;
    vec3 u = iv_coords_of(p, n);
    ivec3 c = ivec3(floor(u));
    if (!cell_inside(c))
        return;
    vec3 radiosity = albedo * iv_direct_irradiance(p, n) + LPV_PI * u_emission * emission;
    if (!finite3(radiosity))
        return;
    vec4 h = vec4(LPV_IV_HEMI0, LPV_IV_HEMI1 * n.y, LPV_IV_HEMI1 * n.z, LPV_IV_HEMI1 * n.x);
    v_r = h * radiosity.r;
    v_g = h * radiosity.g;
    v_b = h * radiosity.b;
    v_n = vec4(n, 1.0);
    v_a = vec4(albedo, 0.0);
    vec3 an = abs(n); // LPV_IV_FOLD
    float fs = (an.x >= an.y && an.x >= an.z ? n.x : an.y >= an.z ? n.y : n.z) >= 0.0 ? 1.0 : -1.0;
    v_f = vec4(fs * n, 0.0);
    vec3 local = clamp(u - vec3(c), 0.0, 1.0);
    v_hi = vec4(local, 0.0);
    v_lo = vec4(1.0 - local, 0.0);
    vec2 texel = vec2(atlas_texel(c, grid_dims().xy)) + 0.5;
    gl_Position = vec4(texel / u_atlas_size * 2.0 - 1.0, 0.0, 1.0);
}
