// probes_update.comp - the probes' rays (one invocation each) for a batch of
// probes: traced through the scene's BVH (probes_trace.glsl), and what each
// hit sends back toward the probe: its emission where the frame does not
// light with the emitters itself, plus its albedo / pi times the irradiance
// on it: direct from the lights (a shadow ray each to the punctual lights
// and to one area light sample drawn per ray, weighted by their count) and
// indirect from the probes of the pass before (probes_lookup.glsl: every
// pass adds a bounce). A ray that meets the back of a one-sided triangle
// sends nothing and reports its distance negative (the blend counts them).
// The rays' directions are the batch's table (the CPU turns the spherical
// Fibonacci set by the tick's rotation, probes_math.c). The CPU oracle of
// the rays and statistics is probes_update.c.
layout(local_size_x = LPV_PROBES_WG) in;

layout(std430, binding = LPV_SSBO_PROBES_RAY_OUT) writeonly buffer ProbesRayOut { vec4 ray_out[]; };
layout(std430, binding = LPV_SSBO_PROBES_MATERIALS) readonly buffer ProbesMaterials { vec4 probes_materials[]; };
layout(std430, binding = LPV_SSBO_PROBES_RAY_DIRS) readonly buffer ProbesRayDirs { vec4 probes_ray_dirs[]; };

uniform uint u_rays;          // per probe
uniform uint u_tick;          // draws the area light sample
uniform float u_max_distance; // m: a ray stops here and counts as a miss
uniform float u_eps;          // m: shadow rays start this far off the surface
uniform float u_emission;     // 1: a hit's emission counts (area lights off), 0: the frame lights with it
uniform float u_feedback;     // 1: the probes' light of the pass before lights the hits
uniform vec3 u_sky;           // W/(m^2 sr) of a ray that hits nothing

uint probes_hash(uint x)
{
    x = (x ^ 61u) ^ (x >> 16);
    x *= 9u;
    x ^= x >> 4;
    x *= 0x27d4eb2du;
    x ^= x >> 15;
    return x;
}

bool probes_visible(vec3 p, vec3 n, vec3 to_light, float dist)
{
    return !probes_any_hit(p + n * u_eps, to_light, dist - 2.0 * u_eps);
}

// Direct irradiance (W/m^2) on a surface at p facing n.
vec3 probes_direct(vec3 p, vec3 n, uint ray)
{
    vec3 e = vec3(0.0);
    int punctual = int(L.counts.z), all = int(L.counts.x);
    for (int l = 0; l <= punctual; ++l) {
        int at = l;
        float weight = 1.0;
        if (l == punctual) { // one area light sample, drawn per ray, for all of them
            int samples = all - punctual;
            if (samples <= 0)
                break;
            at = punctual + int(probes_hash(ray * 0x9e3779b9u ^ probes_hash(u_tick)) % uint(samples));
            weight = float(samples);
        }
        LpvLightGpu li = L.lights[at];
        vec3 e_cos, to_light;
        if (!light_arrives(li, p, n, e_cos, to_light))
            continue;
        float dist = int(li.position_type.w) == LPV_LIGHT_TYPE_DIRECTIONAL ? u_max_distance
                                                                          : length(li.position_type.xyz - p);
        if (probes_visible(p, n, to_light, dist))
            e += weight * e_cos;
    }
    return e;
}

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_batch * u_rays)
        return;
    uint probe = probes_batch_probe(i / u_rays), r = i % u_rays;
    int k = int(probe) / grid_cells(), cell = int(probe) % grid_cells();
    ivec3 dims = grid_dims();
    ivec3 c = ivec3(cell % dims.x, (cell / dims.x) % dims.y, cell / (dims.x * dims.y));
    vec3 o = probes_position(k, c);
    vec3 d = probes_ray_dirs[r].xyz;
    float t;
    uint tri;
    if (!probes_closest_hit(o, d, u_max_distance, t, tri)) {
        ray_out[i] = vec4(u_sky, u_max_distance);
        return;
    }
    vec3 v0 = probes_verts[3u * tri].xyz, v1 = probes_verts[3u * tri + 1u].xyz, v2 = probes_verts[3u * tri + 2u].xyz;
    vec3 ng = cross(v1 - v0, v2 - v0);
    float len = length(ng);
    ng = len > 0.0 ? ng / len : -d;
    bool back = dot(ng, d) > 0.0;
    vec4 albedo = probes_materials[2u * tri], emission = probes_materials[2u * tri + 1u];
    if (back && albedo.w == 0.0) {
        ray_out[i] = vec4(0.0, 0.0, 0.0, -t);
        return;
    }
    vec3 n = back ? -ng : ng;
    vec3 hp = o + t * d;
    vec3 e = probes_direct(hp, n, i);
    if (u_feedback > 0.0)
        e += lpv_irradiance(hp, n);
    ray_out[i] = vec4(u_emission * emission.rgb + albedo.rgb * (1.0 / LPV_PI) * e, t);
}
