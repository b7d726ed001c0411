// iv_filter.comp - LPV_IV_FILTER (lpv_shared.h): after the last bounce, a
// surface voxel's gather becomes the binomial 3 x 3 mean of the surface
// voxels around it on the same plane; every other voxel is copied.
// techniques/iv/core/oracle_iv_filter.c is its oracle.
layout(local_size_x = LPV_IV_WG) in;

layout(std430, binding = LPV_SSBO_LPV_ACC) readonly buffer Raw { LpvCell raw[]; };
layout(std430, binding = LPV_SSBO_LPV_OUT) writeonly buffer Filtered { LpvCell filtered[]; };

void main()
{
    int i = int(gl_GlobalInvocationID.x);
    if (i >= grid_cells())
        return;
    ivec3 d = grid_dims();
    ivec3 c = ivec3(i % d.x, (i / d.x) % d.y, i / (d.x * d.y));
    ivec3 own;
    vec3 side;
    int k;
    float plane;
    if (!surface_plane(c, own, side, k, plane)) {
        filtered[i] = raw[i];
        return;
    }
    const int u = (k + 1) % 3, v = (k + 2) % 3;
    vec4 r = vec4(0.0), g = vec4(0.0), b = vec4(0.0);
    float sum = 0.0;
    for (int dv = -1; dv <= 1; ++dv)
        for (int du = -1; du <= 1; ++du) {
            ivec3 n = c;
            n[u] += du;
            n[v] += dv;
            if (n != c) {
                ivec3 own_n;
                vec3 side_n;
                int k_n;
                float plane_n;
                if (!cell_inside(n) || !surface_plane(n, own_n, side_n, k_n, plane_n) || side_n != side ||
                    abs(plane_n - plane) > LPV_IV_FILTER_PLANE)
                    continue;
            }
            float w = float((2 - abs(du)) * (2 - abs(dv)));
            LpvCell x = raw[cell_index(n)];
            r += w * x.r;
            g += w * x.g;
            b += w * x.b;
            sum += w;
        }
    filtered[i] = LpvCell(r / sum, g / sum, b / sum);
}
