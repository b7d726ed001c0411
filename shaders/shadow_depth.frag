// shadow_depth.frag - shadow maps store depth (pass_shadow.c).
// Alpha-masked texels are cut away as in rsm.frag and gbuffer.frag: a
// cut-out casts no shadow where it has no surface. BLEND surfaces are drawn
// apart, into the face's transmission map: each texel lets 1 - alpha of the
// light through (the map multiplies them) and keeps the nearest one's depth
// (the map keeps the greatest reversed depth), LPV_TEX_SHADOW_TRANSMIT.
in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv;
in vec2 v_uv1;
in vec4 v_tangent;
in vec4 v_color;

layout(location = 0) out vec4 o_transmit; // the transmission map's (BLEND draws); no target in the depth pass

void main()
{
    if (LPV_MATERIAL_PLAIN == 0 && u_alpha_blend != 0) {
        float a = clamp(material_albedo(v_uv, v_uv1, v_color).a, 0.0, 1.0);
        o_transmit = vec4(vec3(1.0 - a), gl_FragCoord.z);
        return;
    }
    if (LPV_MATERIAL_PLAIN == 0 && u_alpha_cutoff > 0.0 && material_albedo(v_uv, v_uv1, v_color).a < u_alpha_cutoff)
        discard;
    o_transmit = vec4(1.0);
}
