// media.frag - single scattering in a participating medium (cascaded-LPV
// paper section 7, docs/effects.md). Each pixel's view ray is marched from
// the eye to the surface (or out of the medium) in steps of media_step x the
// cell of the finest cascade there. At each step the medium scatters, with an
// isotropic phase function 1 / (4 pi), the LPV's fluence (its DC term:
// integral of I / cell^2 over the sphere) and the lights' direct irradiance
// through their shadow maps; the result is attenuated by the transmittance
// back to the eye. Composited with dual-source blending:
// frame = in-scattered + transmittance x frame (per channel). The LPV itself
// is attenuated during propagation, so the light scattered here is light the
// volume lost: in-scattering creates no energy.
in vec2 v_uv;

layout(binding = 0) uniform sampler2D u_gbuf_position;
layout(binding = 1) uniform sampler2D u_gbuf_normal;

layout(std140, binding = LPV_UBO_VIEW) uniform ViewUBO { LpvViewBlock V; };

uniform float u_media_step;   // fraction of a cell
uniform vec3 u_march_min;     // m: the region the march may cover (scene or medium box)
uniform vec3 u_march_max;

layout(location = 0, index = 0) out vec4 o_scattered;
layout(location = 0, index = 1) out vec4 o_transmittance;

const int MAX_STEPS = 512;

// Entry and exit distances of the ray o + t d through the box, or (1, 0).
vec2 ray_box(vec3 o, vec3 d, vec3 lo, vec3 hi)
{
    vec3 inv = 1.0 / d;
    vec3 t0 = (lo - o) * inv, t1 = (hi - o) * inv;
    vec3 tmin = min(t0, t1), tmax = max(t0, t1);
    float a = max(max(tmin.x, tmin.y), max(tmin.z, 0.0));
    float b = min(min(tmax.x, tmax.y), tmax.z);
    return b > a ? vec2(a, b) : vec2(1.0, 0.0);
}

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    o_scattered = vec4(0.0);
    o_transmittance = vec4(1.0);
    // the pixel's ray: through the G-buffer's point, or unprojected
    vec2 ndc = (vec2(px) + 0.5) / V.viewport.xy * 2.0 - 1.0;
    mat4 inv = inverse(V.view_proj);
    vec4 a = inv * vec4(ndc, -1.0, 1.0), b = inv * vec4(ndc, 1.0, 1.0);
    vec3 o = a.xyz / a.w;
    vec3 d = normalize(b.xyz / b.w - o);
    float t_end = 1e30;
    if (texelFetch(u_gbuf_normal, px, 0).w >= 0.5) {
        vec3 p = texelFetch(u_gbuf_position, px, 0).xyz;
        t_end = dot(p - o, d);
    }
    vec2 span = ray_box(o, d, u_march_min, u_march_max);
    span.y = min(span.y, t_end);
    if (!(span.y > span.x) || !finite3(o) || !finite3(d))
        return;

    vec3 T = vec3(1.0), scattered = vec3(0.0);
    float t = span.x;
    int lights = int(L.counts.x);
    const vec4 fluence = vec4(2.0 * sqrt(LPV_PI), 0.0, 0.0, 0.0); // sqrt(4 pi): DC -> integral over the sphere
    for (int i = 0; i < MAX_STEPS && t < span.y; ++i) {
        vec3 x0 = o + t * d;
        float dt = max(u_media_step * lpv_cell_at(x0), (span.y - span.x) / float(MAX_STEPS));
        dt = min(dt, span.y - t);
        vec3 x = x0 + 0.5 * dt * d;
        float rho = medium_density(x);
        if (rho > 0.0) {
            vec3 sigma_s = u_medium_sigma_s * rho, sigma_t = (u_medium_sigma_s + u_medium_sigma_a) * rho;
            vec3 source = lpv_reach_point(x) * lpv_project(x, fluence);
            for (int l = 0; l < lights; ++l) {
                vec3 to_light;
                vec3 e = light_irradiance_normal(L.lights[l], x, to_light);
                if (any(greaterThan(e, vec3(0.0))))
                    source += e * shadow_visibility_taps(l, x, to_light, 1); // the march averages
            }
            // integral over the step of T(t) sigma_s source / (4 pi), exactly for constant coefficients
            vec3 step_t = exp(-sigma_t * dt);
            vec3 frac = mix(vec3(dt), (1.0 - step_t) / max(sigma_t, vec3(1e-30)), greaterThan(sigma_t, vec3(1e-6)));
            scattered += T * sigma_s * source / (4.0 * LPV_PI) * frac;
            T *= step_t;
        }
        t += dt;
    }
    o_scattered = vec4(scattered, 0.0);
    o_transmittance = vec4(T, 1.0);
}
