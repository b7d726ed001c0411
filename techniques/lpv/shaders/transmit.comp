// transmit.comp - per cascade, cell and direction (+x -x +y -y +z -z, the
// direction light travels), the fraction of light from the neighbour at
// cell - dir that passes the face between them: 1 - clamp(B(-dir) / peak), B
// the total's blocking for dir (gv_merge.comp) averaged over the face's four
// corners. With bounces, also the face's reflectance: the blocked fraction
// times the corners' albedo weighted by what each blocks of dir, times the
// bounce intensity. Computed once per tick; propagation only multiplies.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(std430, binding = LPV_SSBO_GV_TOTAL) readonly buffer GvTotal { LpvGvPoint gv_total[]; };
layout(std430, binding = LPV_SSBO_TRANSMIT) writeonly buffer Transmit { float transmit[]; };
layout(std430, binding = LPV_SSBO_REFLECT) writeonly buffer Reflect { vec4 reflectance[]; };

uniform int u_bounce;
uniform float u_bounce_intensity;

int gv_index(int k, ivec3 p)
{
    ivec3 d = grid_dims() + 1;
    return k * d.x * d.y * d.z + p.x + d.x * (p.y + d.y * p.z);
}

void main()
{
    ivec3 c;
    int k = cascade_of_invocation(ivec3(gl_GlobalInvocationID), c);
    if (!cell_inside(c) || k >= cascade_count())
        return;
    int i = k * grid_cells() + cell_index(c);
    for (int dir = 0; dir < LPV_DIR_COUNT; ++dir) {
        int axis = dir / 2;
        bool positive = (dir & 1) == 0;
        ivec3 e1 = ivec3(axis == 1 || axis == 2 ? 1 : 0, axis == 0 ? 1 : 0, 0);
        ivec3 e2 = ivec3(0, axis == 2 ? 1 : 0, axis == 2 ? 0 : 1);
        ivec3 base = c;
        if (!positive)
            base[axis] += 1;
        ivec3 corner[4] = ivec3[4](base, base + e1, base + e2, base + e1 + e2);
        float b = 0.0;
        vec3 albedo = vec3(0.0);
        float weight = 0.0;
        for (int q = 0; q < 4; ++q) {
            int g = gv_index(k, corner[q]);
            float v = gv_total[g].blocking[dir / 4][dir % 4];
            b += 0.25 * v;
            if (u_bounce != 0 && v > 0.0) {
                albedo += v * gv_total[g].albedo.rgb;
                weight += v;
            }
        }
        bool bad = isnan(b) || isinf(b);
        float blocked = bad ? 1.0 : clamp(b / LPV_GV_PEAK, 0.0, 1.0);
        transmit[i * LPV_DIR_COUNT + dir] = 1.0 - blocked;
        if (u_bounce != 0) {
            vec3 a = weight > 0.0 ? clamp(albedo / weight, 0.0, 1.0) : vec3(0.0);
            reflectance[i * LPV_DIR_COUNT + dir] = vec4(bad ? vec3(0.0) : a * blocked * u_bounce_intensity, 0.0);
        }
    }
}
