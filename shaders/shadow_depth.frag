// shadow_depth.frag - shadow maps store depth only (pass_shadow.c).
in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv;

void main()
{
}
