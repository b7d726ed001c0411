// lpv_normals_pack.comp - the irradiance of each cascade on the lookup's normals
// (lookup.glsl's u_lpv_normals: the six axes, then the scene's plane normals):
// per cell and normal a, the sum over the cascade's volumes of
// dot(c, volume_irradiance_weights(bins, bin, lookup_normal(a))) per
// channel, before the 1 / cell^2 and the clamp at 0, which the lookup
// applies after its trilinear filter as on the full sum. Volume
// v = k * u_lpv_lookup_normals + a sits at z-slab v % u_slabs_z and y-slab
// v / u_slabs_z (techniques/lpv/gpu/lpv_lookup_volume.c).
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(std430, binding = LPV_SSBO_LPV_ACC) readonly buffer Src { LpvCell src[]; };
layout(binding = 0, rgba32f) writeonly uniform image3D u_normals;

uniform ivec4 u_dims; // one volume's cells x, y, z; the cascade count
uniform int u_bins;   // LPV volumes per cascade
uniform int u_slabs_z;

void main()
{
    ivec3 id = ivec3(gl_GlobalInvocationID);
    int v = id.z / u_dims.z, z = id.z % u_dims.z;
    int k = v / u_lpv_lookup_normals, a = v % u_lpv_lookup_normals;
    if (id.x >= u_dims.x || id.y >= u_dims.y || k >= u_dims.w || a >= LPV_LOOKUP_AXES + u_lpv_plane_count)
        return;
    vec3 n = lookup_normal(a);
    int cells = u_dims.x * u_dims.y * u_dims.z;
    int cell = id.x + u_dims.x * (id.y + u_dims.y * z);
    vec3 e = vec3(0.0);
    for (int bin = 0; bin < u_bins; ++bin) {
        LpvCell c = src[cell + cells * (k * u_bins + bin)];
        vec4 w = volume_irradiance_weights(u_bins, bin, n);
        e += vec3(dot(c.r, w), dot(c.g, w), dot(c.b, w));
    }
    ivec3 t = ivec3(id.x, id.y + lpv_slab_y0(v, u_slabs_z, u_dims.y), z + lpv_slab_z0(v, u_slabs_z, u_dims.z));
    imageStore(u_normals, t, vec4(e, 0.0));
}
