// lpv_lookup_pack.comp - copies an LPV buffer (LpvCell per cell, x fastest,
// volumes one after another) into the three RGBA32F 3D textures the lookup
// filters (lookup.glsl): one per colour channel, volume v's cells at z-slab
// v % u_slabs_z and y-slab v / u_slabs_z. One trilinear texture read then
// replaces the lookup's 8 x 3 buffer loads per volume (techniques/lpv/gpu/lpv_lookup_volume.c).
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(std430, binding = LPV_SSBO_LPV_ACC) readonly buffer Src { LpvCell src[]; };
layout(binding = 0, rgba32f) writeonly uniform image3D u_r;
layout(binding = 1, rgba32f) writeonly uniform image3D u_g;
layout(binding = 2, rgba32f) writeonly uniform image3D u_b;

uniform ivec4 u_dims; // one volume's cells x, y, z; the volume count
uniform int u_slabs_z;

void main()
{
    ivec3 id = ivec3(gl_GlobalInvocationID);
    int v = id.z / u_dims.z, z = id.z % u_dims.z;
    if (id.x >= u_dims.x || id.y >= u_dims.y || v >= u_dims.w)
        return;
    int i = id.x + u_dims.x * (id.y + u_dims.y * id.z); // volumes follow each other in z
    ivec3 t = ivec3(id.x, id.y + lpv_slab_y0(v, u_slabs_z, u_dims.y), z + lpv_slab_z0(v, u_slabs_z, u_dims.z));
    LpvCell c = src[i];
    imageStore(u_r, t, c.r);
    imageStore(u_g, t, c.g);
    imageStore(u_b, t, c.b);
}
