// query.comp - irradiance (W/m^2) from the accumulated LPV at caller-given
// points and normals, with the same lookup as shading (lookup.glsl).
layout(local_size_x = 64, local_size_y = 1, local_size_z = 1) in;

layout(std430, binding = LPV_SSBO_VPLS) readonly buffer Queries { vec4 queries[]; }; // (p, 0), (n, 0) pairs
layout(std430, binding = LPV_SSBO_SURFELS) writeonly buffer Results { vec4 results[]; };

uniform int u_count;

void main()
{
    int i = int(gl_GlobalInvocationID.x);
    if (i >= u_count)
        return;
    results[i] = vec4(lpv_irradiance(queries[2 * i].xyz, queries[2 * i + 1].xyz), 0.0);
}
