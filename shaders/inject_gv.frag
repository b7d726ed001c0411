// inject_gv.frag - writes a surfel's blocking SH; the atlas blends additively.
flat in vec4 v_gv;
layout(location = 0) out vec4 o_gv;

void main()
{
    o_gv = v_gv;
}
