// transmit.comp - per cell and direction (+x -x +y -y +z -z, the direction
// light travels), the fraction of light from the neighbour at cell - dir that
// passes the face between them: 1 - clamp(B(-dir)), B the GV averaged over the
// face's four corners. Computed once per tick; propagation only multiplies.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(std430, binding = LPV_SSBO_GV_TOTAL) readonly buffer GvTotal { vec4 gv_total[]; };
layout(std430, binding = LPV_SSBO_TRANSMIT) writeonly buffer Transmit { float transmit[]; };

vec4 gv_at(ivec3 p)
{
    ivec3 d = grid_dims() + 1;
    return gv_total[p.x + d.x * (p.y + d.y * p.z)];
}

void main()
{
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (!cell_inside(c))
        return;
    int i = cell_index(c);
    for (int dir = 0; dir < LPV_DIR_COUNT; ++dir) {
        int axis = dir / 2;
        bool positive = (dir & 1) == 0;
        ivec3 e1 = ivec3(axis == 1 || axis == 2 ? 1 : 0, axis == 0 ? 1 : 0, 0);
        ivec3 e2 = ivec3(0, axis == 2 ? 1 : 0, axis == 2 ? 0 : 1);
        ivec3 base = c;
        if (!positive)
            base[axis] += 1;
        vec4 avg = 0.25 * (gv_at(base) + gv_at(base + e1) + gv_at(base + e2) + gv_at(base + e1 + e2));
        vec3 travel = vec3(0.0);
        travel[axis] = positive ? 1.0 : -1.0;
        float b = dot(avg, sh_basis(-travel));
        float t = 1.0 - clamp(b, 0.0, 1.0);
        transmit[i * LPV_DIR_COUNT + dir] = (isnan(b) || isinf(b)) ? 0.0 : t;
    }
}
