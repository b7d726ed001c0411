// gbuffer.frag - the camera's view of the scene: position, normal facing the
// camera, albedo and emission per pixel (also the camera's surfels for the
// geometry volume). Alpha-masked texels are cut away (no pixel, no surfel);
// the shading normal follows the normal map (docs/scenes.md, "Materials").
// BLEND draws are drawn apart, into the translucent layer's G-buffer
// (pass_camera.c), which also keeps their alpha as coverage.
in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv;
in vec2 v_uv1;
in vec4 v_tangent;
in vec4 v_color;

uniform vec3 u_eye;
uniform float u_pixel_solid_angle; // sr per pixel at the image centre (perspective), 0 = orthographic
uniform float u_pixel_area;        // m^2 per pixel (orthographic)
uniform vec3 u_forward;
uniform int u_wire; // 1: a point or line (lpv_engine_draw_wires): shown unlit, no surface (LPV_GBUF_WIRE_W)

layout(location = 0) out vec4 o_position; // xyz world; w surfel area (m^2), > 0 = covered
layout(location = 1) out vec4 o_normal;   // xyz unit shading normal, on the camera's side; w 1 + metallic where covered
layout(location = 2) out vec4 o_albedo;   // rgb linear base colour (diffuse: x lpv_gbuffer_kd); a roughness
layout(location = 3) out vec4 o_emission; // rgb W/(m^2 sr); a object size (m)
layout(location = 4) out float o_occlusion; // the frame's indirect light x this (occlusionTexture; 1 = open)
layout(location = 5) out float o_coverage;  // the translucent layer's: alpha (BLEND), 1 otherwise; the G-buffer has no such target

void main()
{
    vec3 p = v_position;
    vec3 to_eye = normalize(u_eye - p);
    float side;
    vec3 n = surface_normal(v_normal, p, to_eye, side);
    // the surfel's area from the geometric facing (before the normal map)
    float cos_s = max(abs(dot(n, to_eye)), 0.05);
    if (LPV_MATERIAL_PLAIN == 0 && u_has_normal_texture != 0) {
        vec2 uvn = texture_uv(u_normal_uv_set, u_normal_uv_row0, u_normal_uv_row1, v_uv, v_uv1);
        // mapped on the front side, then turned with the side seen (glTF)
        n = side * normal_mapped(side * n, p, v_tangent, uvn);
    }
    vec4 base = material_albedo(v_uv, v_uv1, v_color);
    float area;
    if (u_pixel_solid_angle > 0.0) {
        vec3 d = p - u_eye;
        float dist2 = dot(d, d);
        float cos_t = max(dot(normalize(d), u_forward), 1e-3);
        // a pixel's solid angle falls as cos^3 away from the image centre
        area = u_pixel_solid_angle * cos_t * cos_t * cos_t * dist2 / cos_s;
    } else {
        area = u_pixel_area / cos_s;
    }
    // after every derivative: cut-away texels leave no pixel (and no depth),
    // nor do a translucent layer's texels of alpha 0
    if (LPV_MATERIAL_PLAIN == 0 && (u_alpha_blend != 0 ? !(base.a > 0.0) : base.a < u_alpha_cutoff))
        discard;
    if (u_wire != 0) {
        // its colour as the camera sees it, lit by nothing (three.js's line
        // and point materials; docs/scenes.md "Points and lines"); no area
        o_position = vec4(p, 0.0);
        o_normal = vec4(to_eye, LPV_GBUF_WIRE_W);
        o_albedo = vec4(base.rgb, 1.0);
        o_emission = vec4(clamp(base.rgb, 0.0, 1.0) / LPV_LUMENS_PER_WATT + material_emission(v_uv, v_uv1), 0.0);
        o_occlusion = 1.0;
        o_coverage = 1.0;
        return;
    }
    vec2 mr = material_metallic_roughness(v_uv, v_uv1);
    o_position = vec4(p, area);
    // w >= 1: covered; w - 1: metallic (lpv_gbuffer_kd); LPV_GBUF_UNLIT_W: unlit
    o_normal = vec4(n, u_unlit != 0 ? LPV_GBUF_UNLIT_W : 1.0 + mr.x);
    o_albedo = vec4(base.rgb, mr.y);
    // an unlit pixel's emission target: what the camera sees (nits / 683, material_sample.h)
    o_emission = vec4(u_unlit != 0 ? clamp(base.rgb, 0.0, 1.0) / LPV_LUMENS_PER_WATT : material_emission(v_uv, v_uv1),
                      u_object_size);
    o_occlusion = material_occlusion(v_uv, v_uv1);
    o_coverage = u_alpha_blend != 0 ? min(base.a, 1.0) : 1.0;
}
