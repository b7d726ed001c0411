// shadow_depth.frag - shadow maps store depth only (pass_shadow.c).
// Alpha-masked texels are cut away as in rsm.frag and gbuffer.frag: a
// cut-out casts no shadow where it has no surface.
in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv;
in vec2 v_uv1;
in vec4 v_tangent;
in vec4 v_color;

void main()
{
    if (LPV_MATERIAL_PLAIN == 0 && u_alpha_cutoff > 0.0 && material_albedo(v_uv, v_uv1, v_color).a < u_alpha_cutoff)
        discard;
}
