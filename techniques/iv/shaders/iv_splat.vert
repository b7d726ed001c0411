// iv_splat.vert - one slot of iv_reproject.comp (the camera's pixels of one
// block in one voxel) into the atlas: the point lands on the voxel's texel,
// where iv_points.comp has written the cloud's sums before this draw blends
// on top (iv_splat.frag: added, the place's two attachments kept greatest).
// An unused slot is dropped outside the clip volume.
layout(std430, binding = LPV_SSBO_IV_SPLATS) readonly buffer Splats { IvSplat splats[]; };

uniform vec2 u_atlas_size;

flat out vec4 v_r;
flat out vec4 v_g;
flat out vec4 v_b;
flat out vec4 v_n;
flat out vec4 v_a;
flat out vec4 v_f;
flat out vec4 v_hi;
flat out vec4 v_lo;

void main()
{
    gl_PointSize = 1.0;
    vec4 texel = splats[gl_VertexID].texel;
    if (texel.w == 0.0) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0); // outside the clip volume: dropped
        v_r = v_g = v_b = v_n = v_a = v_f = v_hi = v_lo = vec4(0.0);
        return;
    }
    IvSplat s = splats[gl_VertexID];
    v_r = s.r;
    v_g = s.g;
    v_b = s.b;
    v_n = s.n;
    v_a = s.a;
    v_f = s.f;
    v_hi = s.hi;
    v_lo = s.lo;
    gl_Position = vec4((texel.xy + 0.5) / u_atlas_size * 2.0 - 1.0, 0.0, 1.0);
}
