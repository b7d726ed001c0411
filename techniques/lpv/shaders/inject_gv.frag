// inject_gv.frag - writes a surfel's blocking SH and its blocking-weighted
// albedo (for bounces); the atlas blends additively.
flat in vec4 v_gv;
flat in vec4 v_albedo;
layout(location = 0) out vec4 o_gv;
layout(location = 1) out vec4 o_albedo;

void main()
{
    o_gv = v_gv;
    o_albedo = v_albedo;
}
