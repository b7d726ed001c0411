// reach.glsl - where light can reach (core/reach.h; lpv_reach_at is the same
// rule on the CPU): 0 where the air in front of a surface is a space no
// light reaches (a room behind a closed wall, the outside of a closed lamp
// box), else 1. The engine pastes it after the technique's lookup into every
// pass that reads the volume and multiplies the technique's irradiance by it:
// the techniques' cells are wider than walls are thick and carry light
// through them (docs/propagation.md, "Enclosed lights").
layout(binding = LPV_TEX_REACH) uniform usampler3D u_reach;
uniform vec4 u_reach_grid; // xyz the voxels' lower corner (m), w the voxel side (m); w 0 = everywhere lit

// The first non-solid voxel at 0.75, 1.5, 2.5 and 3.5 voxels along n
// decides. When all four are solid (a surface in the corner of two others,
// whose voxels the steps run along), the 27 voxels around 2 voxels along n:
// any lit one gives 1, else any dark one 0. A point outside the voxels, or
// no air around, gives 1.
float lpv_reach(vec3 p, vec3 n)
{
    if (u_reach_grid.w <= 0.0)
        return 1.0;
    ivec3 dims = textureSize(u_reach, 0);
    vec3 q = (p - u_reach_grid.xyz) / u_reach_grid.w;
    const float steps[4] = float[4](0.75, 1.5, 2.5, 3.5);
    for (int i = 0; i < 4; ++i) {
        ivec3 c = ivec3(floor(q + n * steps[i]));
        if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, dims)))
            return 1.0;
        uint m = texelFetch(u_reach, c, 0).r;
        if (m != uint(LPV_REACH_SOLID))
            return m == uint(LPV_REACH_LIT) ? 1.0 : 0.0;
    }
    ivec3 c = ivec3(floor(q + 2.0 * n));
    bool dark = false;
    for (int k = 0; k < 27; ++k) {
        ivec3 x = c + ivec3(k % 3, (k / 3) % 3, k / 9) - 1;
        if (any(lessThan(x, ivec3(0))) || any(greaterThanEqual(x, dims)))
            continue;
        uint m = texelFetch(u_reach, x, 0).r;
        if (m == uint(LPV_REACH_LIT))
            return 1.0;
        dark = dark || m == uint(LPV_REACH_DARK);
    }
    return dark ? 0.0 : 1.0;
}

// A point in the air (glossy and media marches): 0 in a space no light
// reaches; 1 in solid voxels or outside.
float lpv_reach_point(vec3 x)
{
    if (u_reach_grid.w <= 0.0)
        return 1.0;
    ivec3 c = ivec3(floor((x - u_reach_grid.xyz) / u_reach_grid.w));
    if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, textureSize(u_reach, 0))))
        return 1.0;
    return texelFetch(u_reach, c, 0).r == uint(LPV_REACH_DARK) ? 0.0 : 1.0;
}
