// vpl_extract.comp - turns every RSM texel of every face into one VPL and one
// surfel (position.w = 0 / area 0 where the texel saw nothing): the
// extraction at rsm_vpl_step 1; vpl_blocks.comp down-samples.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform sampler2DArray u_rsm_position;
layout(binding = 1) uniform sampler2DArray u_rsm_normal;
layout(binding = 2) uniform sampler2DArray u_rsm_flux;
layout(binding = 3) uniform sampler2DArray u_rsm_albedo;

layout(std430, binding = LPV_SSBO_VPLS) writeonly buffer Vpls { LpvVpl vpls[]; };
layout(std430, binding = LPV_SSBO_SURFELS) writeonly buffer Surfels { LpvSurfel surfels[]; };

uniform int u_size;
uniform int u_layer0; // the first layer of this dispatch
uniform int u_base;   // its first element

void main()
{
    ivec3 t = ivec3(gl_GlobalInvocationID);
    if (t.x >= u_size || t.y >= u_size)
        return;
    uint i = uint(u_base + t.x + u_size * (t.y + u_size * t.z));
    t.z += u_layer0;
    vec4 p = texelFetch(u_rsm_position, t, 0);
    vec4 n = texelFetch(u_rsm_normal, t, 0);
    vec4 f = texelFetch(u_rsm_flux, t, 0);
    bool covered = n.w > 0.5;
    vpls[i].position = vec4(p.xyz, covered ? 1.0 : 0.0);
    if (covered)
        compact_mark_live(int(i));
    vpls[i].normal = vec4(n.xyz, f.a); // w: object size
    vpls[i].flux = vec4(f.rgb, 0.0);
    vec4 albedo = texelFetch(u_rsm_albedo, t, 0);
    bool occluder = albedo.a > 0.5; // emitters do not block (see rsm.frag)
    surfels[i].position = vec4(p.xyz, covered && occluder ? p.w : 0.0);
    surfels[i].normal = vec4(n.xyz, f.a);
    surfels[i].albedo = vec4(albedo.rgb, 0.0);
}
