// probes_lookup.glsl - the probes' side of the technique seam
// (gpu/technique.h): with grid.glsl it is the "probes" technique's
// lookup_includes, and defines lpv_irradiance, lpv_irradiance_listed,
// lpv_project, lpv_cell_at and u_damping. probes_update.comp includes it too:
// a ray's hit reads the probes' light of the pass before (more bounces).
//
// A probe sits at the centre of every cell of every cascade (grid.glsl's
// placement). It keeps its irradiance per texel of an octahedral map
// (LPV_PROBES_IRR_OCT a side), which this lookup reads, and cell^2 x the L1
// SH of the radiance it saw, by travel direction: an LpvCell in the
// cascaded LPV's convention, the volume on the wire, whose lookup by the
// clients is the LPV's, and lpv_project's here. A surface at p
// facing n blends the 8 probes around p + bias n (Majercik et al. 2019,
// section 4): trilinear weights, times a smooth back-face term (a probe
// behind the surface counts less), times the Chebyshev bound from the
// probe's distance moments in the direction of the point (a probe that
// sees a wall nearer than the point counts almost nothing), normalised.
// Probes that see mostly back faces (inside geometry) are off.
// Across cascades: the finest whose probes surround p, blended into the
// next coarser over two cells before its last probes, like lookup.glsl.
layout(std430, binding = LPV_SSBO_PROBES_SH) readonly buffer ProbesSH { LpvCell probes_sh[]; };
layout(std430, binding = LPV_SSBO_PROBES_MOMENTS) readonly buffer ProbesMoments { vec2 probes_moments[]; };
layout(std430, binding = LPV_SSBO_PROBES_STATE) readonly buffer ProbesState { vec4 probes_state[]; };
layout(std430, binding = LPV_SSBO_PROBES_IRRADIANCE) readonly buffer ProbesIrradiance { float probes_irradiance[]; };
uniform int u_probes_oct;       // texels per side of a probe's distance map
uniform float u_probes_bias;    // cells: how far along n the surface's point moves before it looks up
uniform float u_damping;        // the seam's; the probes' visibility takes its place (unused)

// The octahedral map (probes_math.c's lpv_probes_oct_encode): unit d to [-1, 1]^2.
vec2 probes_oct_encode(vec3 d)
{
    float l1 = abs(d.x) + abs(d.y) + abs(d.z);
    vec2 uv = l1 > 0.0 ? d.xy / l1 : vec2(0.0);
    if (d.z < 0.0)
        uv = (1.0 - abs(uv.yx)) * vec2(uv.x >= 0.0 ? 1.0 : -1.0, uv.y >= 0.0 ? 1.0 : -1.0);
    return uv;
}

vec3 probes_oct_decode(vec2 uv)
{
    vec3 d = vec3(uv, 1.0 - abs(uv.x) - abs(uv.y));
    if (d.z < 0.0)
        d.xy = (1.0 - abs(d.yx)) * vec2(d.x >= 0.0 ? 1.0 : -1.0, d.y >= 0.0 ? 1.0 : -1.0);
    return normalize(d);
}

// Bilinear weights over the four texel centres around unit d's place on
// a side x side octahedral map, clamped at its edge: texel indices in i.
vec4 probes_oct_bilinear(int side, vec3 d, out ivec4 i)
{
    vec2 st = clamp((probes_oct_encode(d) * 0.5 + 0.5) * float(side) - 0.5, vec2(0.0), vec2(float(side - 1)));
    ivec2 b = min(ivec2(floor(st)), ivec2(max(side - 2, 0)));
    vec2 f = st - vec2(b);
    ivec2 b1 = min(b + 1, ivec2(side - 1));
    i = ivec4(b.y * side + b.x, b.y * side + b1.x, b1.y * side + b.x, b1.y * side + b1.x);
    return vec4((1.0 - f.x) * (1.0 - f.y), f.x * (1.0 - f.y), (1.0 - f.x) * f.y, f.x * f.y);
}

// Probe `probe`'s distance moments toward unit d.
vec2 probes_moments_toward(int probe, vec3 d)
{
    ivec4 i;
    vec4 w = probes_oct_bilinear(u_probes_oct, d, i);
    int base = probe * u_probes_oct * u_probes_oct;
    return w.x * probes_moments[base + i.x] + w.y * probes_moments[base + i.y] + w.z * probes_moments[base + i.z] +
           w.w * probes_moments[base + i.w];
}

// Probe `probe`'s irradiance (W/m^2) on a surface facing unit n.
vec3 probes_irradiance_toward(int probe, vec3 n)
{
    ivec4 i;
    vec4 w = probes_oct_bilinear(LPV_PROBES_IRR_OCT, n, i);
    int base = probe * LPV_PROBES_IRR_OCT * LPV_PROBES_IRR_OCT;
    vec3 e = vec3(0.0);
    for (int k = 0; k < 4; ++k) {
        int at = 3 * (base + i[k]);
        e += w[k] * vec3(probes_irradiance[at], probes_irradiance[at + 1], probes_irradiance[at + 2]);
    }
    return e;
}

// probes_math.c's lpv_probes_chebyshev: 1 when the point is no farther than
// the mean hit, else the one-sided bound, cubed.
float probes_chebyshev(vec2 m, float d, float min_var)
{
    if (d <= m.x)
        return 1.0;
    float var = max(m.y - m.x * m.x, min_var), dd = d - m.x;
    float w = var / (var + dd * dd);
    return w * w * w;
}

// The probe of cascade k at cell c: its index and world position (m): the
// cell's centre and the offset relocation gave it.
int probes_index(int k, ivec3 c) { return k * grid_cells() + cell_index(c); }
vec3 probes_position(int k, ivec3 c)
{
    return (vec3(c) + 0.5 + cascade_origin_cells(k)) * cascade_cell(k) + probes_state[2 * probes_index(k, c) + 1].xyz;
}

// The irradiance (W/m^2) of a surface at p facing unit n from cascade k's
// probes (rgb), and how much of them sees it (a: the trilinear, back-face
// and visibility weights' sum before the floor that keeps the division
// defined; 0 when every probe around p is off or hidden from it).
vec4 probes_irradiance_in(int k, vec3 p, vec3 n)
{
    float cell = cascade_cell(k);
    ivec3 dims = grid_dims();
    vec3 ps = p + n * (u_probes_bias * cell);
    vec3 q = clamp(cascade_coords(k, ps) - 0.5, vec3(0.0), vec3(dims - 1));
    ivec3 b = min(ivec3(floor(q)), max(dims - 2, ivec3(0)));
    vec3 f = q - vec3(b);
    vec3 sum = vec3(0.0);
    float wsum = 0.0, seen = 0.0, min_var = LPV_PROBES_MIN_VAR * cell * cell;
    for (int i = 0; i < 8; ++i) {
        ivec3 o = ivec3(i & 1, (i >> 1) & 1, i >> 2);
        ivec3 c = min(b + o, dims - 1);
        int probe = probes_index(k, c);
        if (probes_state[2 * probe].y == 0.0)
            continue; // off: inside geometry
        vec3 pp = probes_position(k, c);
        vec3 tri = mix(1.0 - f, f, vec3(o));
        vec3 to_probe = pp - p;
        float dl = length(to_probe);
        float facing = dl > 0.0 ? (dot(to_probe / dl, n) + 1.0) * 0.5 : 1.0;
        float w = facing * facing + LPV_PROBES_FACING_FLOOR;
        vec3 v = ps - pp;
        float d = length(v);
        w *= probes_chebyshev(probes_moments_toward(probe, d > 0.0 ? v / d : n), d, min_var);
        if (w < LPV_PROBES_CRUSH) // the paper's crush of small weights: less light through walls
            w *= w * w / (LPV_PROBES_CRUSH * LPV_PROBES_CRUSH);
        float t = tri.x * tri.y * tri.z;
        seen += w * t;
        w = max(w, 1e-6) * t;
        sum += w * probes_irradiance_toward(probe, n);
        wsum += w;
    }
    return vec4(wsum > 0.0 ? sum / wsum : vec3(0.0), seen);
}

// How far p lies inside cascade k's probes, in its cells (< 0.5: outside
// the last probes).
float probes_inside(int k, vec3 p)
{
    vec3 q = cascade_coords(k, p);
    vec3 e = min(q, vec3(grid_dims()) - q);
    return min(e.x, min(e.y, e.z));
}

int probes_cascade_at(vec3 p)
{
    int last = cascade_count() - 1;
    for (int k = 0; k < last; ++k)
        if (probes_inside(k, p) >= 0.5)
            return k;
    return last;
}

vec3 lpv_irradiance(vec3 p, vec3 n)
{
    float ln = length(n); // SPEC R5.15: a unit normal, no light without one (or one a float cannot normalise)
    if (!(ln > 1e-8 && ln < 1e18))
        return vec3(0.0);
    n /= ln;
    int k = probes_cascade_at(p);
    vec4 e = probes_irradiance_in(k, p, n);
    // a fine cascade's probes may all sit in the geometry around p (a
    // camera-following cascade in terrain): a coarser one's may not
    while (e.a < LPV_PROBES_UNSEEN && k + 1 < cascade_count())
        e = probes_irradiance_in(++k, p, n);
    float w = clamp((probes_inside(k, p) - 0.5) * 0.5, 0.0, 1.0);
    if (w < 1.0 && k + 1 < cascade_count()) {
        vec4 c = probes_irradiance_in(k + 1, p, n);
        if (c.a >= LPV_PROBES_UNSEEN)
            e.rgb = mix(c.rgb, e.rgb, w);
    }
    return e.rgb;
}

vec3 lpv_irradiance_listed(vec3 p, vec3 n, out bool done)
{
    done = true;
    return lpv_irradiance(p, n);
}

// The SH at x (trilinear between the probes, no visibility: x has no
// surface) dotted with v per channel, / cell^2, clamped at 0.
vec3 lpv_project(vec3 x, vec4 v)
{
    int k = probes_cascade_at(x);
    ivec3 dims = grid_dims();
    vec3 q = clamp(cascade_coords(k, x) - 0.5, vec3(0.0), vec3(dims - 1));
    ivec3 b = min(ivec3(floor(q)), max(dims - 2, ivec3(0)));
    vec3 f = q - vec3(b);
    vec3 sum = vec3(0.0);
    for (int i = 0; i < 8; ++i) {
        ivec3 o = ivec3(i & 1, (i >> 1) & 1, i >> 2);
        vec3 tri = mix(1.0 - f, f, vec3(o));
        LpvCell s = probes_sh[probes_index(k, min(b + o, dims - 1))];
        sum += tri.x * tri.y * tri.z * vec3(dot(s.r, v), dot(s.g, v), dot(s.b, v));
    }
    float cell = cascade_cell(k);
    return max(sum / (cell * cell), 0.0);
}

float lpv_cell_at(vec3 x) { return cascade_cell(probes_cascade_at(x)); }
