// inject_vpl.frag - writes a VPL's SH coefficients; the atlas blends additively.
flat in vec4 v_r;
flat in vec4 v_g;
flat in vec4 v_b;

layout(location = 0) out vec4 o_r;
layout(location = 1) out vec4 o_g;
layout(location = 2) out vec4 o_b;

void main()
{
    o_r = v_r;
    o_g = v_g;
    o_b = v_b;
}
