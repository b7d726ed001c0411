// iv_splat.frag - writes a point's sums; the atlas blends additively, but
// for the last two attachments, which keep the greatest (LPV_IV_COVER).
flat in vec4 v_r;
flat in vec4 v_g;
flat in vec4 v_b;
flat in vec4 v_n;
flat in vec4 v_a;
flat in vec4 v_f;
flat in vec4 v_hi;
flat in vec4 v_lo;

layout(location = 0) out vec4 o_r;
layout(location = 1) out vec4 o_g;
layout(location = 2) out vec4 o_b;
layout(location = 3) out vec4 o_n;
layout(location = 4) out vec4 o_a;
layout(location = 5) out vec4 o_f;
layout(location = 6) out vec4 o_hi; // GL_MAX: the greatest place in the voxel
layout(location = 7) out vec4 o_lo; // GL_MAX: 1 - the least

void main()
{
    o_r = v_r;
    o_g = v_g;
    o_b = v_b;
    o_n = v_n;
    o_a = v_a;
    o_f = v_f;
    o_hi = v_hi;
    o_lo = v_lo;
}
