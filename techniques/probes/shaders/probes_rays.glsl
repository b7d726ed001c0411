// probes_rays.glsl - a probe's ray set in a tick (probes_math.c's
// lpv_probes_ray): direction i of n of the spherical Fibonacci set, turned
// by the tick's rotation. probes_update.comp traces them and
// probes_blend.comp weighs what came back by the same directions.
uniform mat3 u_rotation; // lpv_probes_rotation's, uploaded transposed (GLSL is column-major)

vec3 probes_ray_dir(uint i, uint n)
{
    float z = 1.0 - (2.0 * float(i) + 1.0) / float(n);
    float r = sqrt(max(0.0, 1.0 - z * z));
    float phi = 6.28318530717958648 * fract(0.3819660112501051 * float(i));
    return u_rotation * vec3(r * cos(phi), r * sin(phi), z);
}
