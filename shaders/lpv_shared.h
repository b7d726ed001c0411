/*
 * lpv_shared.h - the one header of constants and memory layouts shared by the
 * C code (core/, gpu/) and every GLSL shader (gpu/shader.c pastes it after the
 * #version line and a "#define LPV_GLSL 1").
 *
 * Keep to the subset both languages accept: #define with float literals that
 * carry an 'f' suffix, and structs whose members are vec4 (a 16-byte aligned
 * float[4] in C through cglm, a vec4 in GLSL std430/std140). Everything here is
 * a fact the two sides must agree on; change it in one place only.
 *
 * Units (see docs/units.md): positions in metres, flux in W, intensity in W/sr,
 * irradiance in W/m^2, radiance in W/(m^2 sr).
 */
#ifndef LPV_SHARED_H
#define LPV_SHARED_H

#ifndef LPV_GLSL
#include <cglm/types.h>
/* A struct type used as a member: GLSL names it bare, C with "struct". */
#define LPV_STRUCT(name) struct name
#else
#define LPV_STRUCT(name) name
#endif

/* ---- Spherical harmonics: 2 bands, 4 coefficients per colour channel ------
 * Coefficient order in a vec4: (Y00, Y1-1, Y10, Y11) = (1, y, z, x) shape.
 * The basis is the real SH *without* the Condon-Shortley phase:
 *   Y00 = C0, Y1-1 = C1*y, Y10 = C1*z, Y11 = C1*x.
 * Used identically in C and GLSL, so the sign choice cannot drift. */
#define LPV_SH_C0 0.28209479177387814f /* 1 / (2 sqrt(pi)) */
#define LPV_SH_C1 0.48860251190291992f /* sqrt(3 / (4 pi)) */

/* SH projection of the clamped cosine max(0, <n, w>) around a unit n:
 * (LOBE0, LOBE1*n.y, LOBE1*n.z, LOBE1*n.x); it integrates to pi over the sphere. */
#define LPV_SH_LOBE0 0.88622692545275801f /* sqrt(pi) / 2 */
#define LPV_SH_LOBE1 1.02332670794648849f /* sqrt(pi / 3) */

#define LPV_PI 3.14159265358979324f

/* ---- Propagation (cascaded-LPV paper section 3.3, see docs/propagation.md) ---
 * Source cell at the origin, destination at +d, cell size 1. The shared face
 * subtends 2 pi / 3 sr; rays through it leave the destination through its far
 * face and its four side faces.
 *   far face:  4 asin(1/10)                = 0.4006696846 sr
 *   side face: (2 pi / 3 - far) / 4         = 0.4234313544 sr
 * (lpv-notes.md prints 0.4234413544 for the side face; that value breaks the
 * 30 faces' partition of the sphere by 4e-5 sr per step. tests/test_sh.c
 * integrates both faces numerically.) */
#define LPV_FACE_SOLID_ANGLE_FAR  0.40066968464623920f
#define LPV_FACE_SOLID_ANGLE_SIDE 0.42343135443673900f

/* One propagation step from a source cell with coefficients c (one channel) to
 * its neighbour along axis k with sign s is the sparse 4x4 matrix
 *   out0 = A c0 + s B ck,   outk = s E c0 + F ck,   outj = G cj (j != k)
 * obtained by summing, over the five faces f of the destination,
 *   (solid_angle_f / pi) * lobe(n_f) * Y(w_f)^T
 * with w_f the direction from the source centre to the centre of face f.
 * A is exactly 1/6: the six neighbours share the source's total flux.
 * techniques/lpv/tests/test_propagation.c rebuilds the matrices from the face table. */
#define LPV_PROP_A 0.16666666666666666f
#define LPV_PROP_B 0.26402916857008096f
#define LPV_PROP_E 0.03681679577750147f
#define LPV_PROP_F 0.06376856085851985f
#define LPV_PROP_G 0.06027651555929470f

/* The "central" transport (a measured departure from the paper, setting
 * transport = central; docs/propagation.md section 4b): each face's flux is
 * re-emitted as a cosine lobe along the face's central direction w_f instead
 * of its normal n_f, i.e. M_d = sum_f (solid_angle_f / pi) lobe(w_f) Y(w_f)^T.
 * Row 0 (A, B), and so every face flux and the flux limiter, is the same as
 * the paper's; only the band-1 rows keep more of the light's direction:
 *   E = L1 C0 (far + 8 side / sqrt5) / pi,  F = L1 C1 (far + 16 side / 5) / pi,
 *   G = L1 C1 (2 side / 5) / pi. */
#define LPV_PROP_CENTRAL_E 0.17601944571338730f
#define LPV_PROP_CENTRAL_F 0.27942037883837060f
#define LPV_PROP_CENTRAL_G 0.02695647724748134f

/* Transports (LpvGridParams.info.w). */
#define LPV_TRANSPORT_PAPER 0
#define LPV_TRANSPORT_CENTRAL 1

/* Normal bins (setting normal_bins; docs/propagation.md section 6b): with
 * bins on, every cascade holds LPV_NORMAL_BINS volumes, one per dominant axis
 * of the emitting surface's normal (+x -x +y -y +z -z, the direction order).
 * Light from a surface facing e_b travels into the half-space <w, e_b> > 0;
 * the lookup reconstructs each bin's intensity on that half-space, so a
 * surface never reads back light emitted by surfaces that face its own way. */
#define LPV_NORMAL_BINS 6

/* Fuzzy occlusion (docs/propagation.md section 3): the L1 projection of the
 * clamped cosine lobe evaluates to 0.75 at its peak (L0 C0 + L1 C1), so the
 * blocking potential of a surface that covers a face is divided by it: a face
 * fully covered by a surface facing the light blocks all of it, not 75 %. */
#define LPV_GV_PEAK 0.75f

/* Cascades (cascaded-LPV paper section 4, docs/cascades.md). */
#define LPV_MAX_CASCADES 4

/* ---- Memory layouts (std430 SSBOs) -----------------------------------------
 * A light propagation volume is an array of LpvCell, x fastest:
 * index = x + dims.x * (y + dims.y * z). Each vec4 holds the 4 SH coefficients
 * of one colour channel of radiant intensity (W/sr). */
struct LpvCell {
    vec4 r;
    vec4 g;
    vec4 b;
};

/* A virtual point light: a small diffuse reflector or emitter whose radiant
 * intensity is I(w) = (flux / pi) max(0, <n, w>), so that its integral is flux. */
struct LpvVpl {
    vec4 position; /* xyz world position (m); w = 1 for a valid VPL, 0 = skip */
    vec4 normal;   /* xyz unit normal; w = size of the object it lies on (m), 0 = unknown */
    vec4 flux;     /* rgb flux (W); a unused */
};

/* A surfel for the geometry volume: an oriented patch that blocks light and,
 * with bounces on, reflects what it blocks. */
struct LpvSurfel {
    vec4 position; /* xyz world position (m); w = area (m^2), 0 = skip */
    vec4 normal;   /* xyz unit normal; w = size of the object it lies on (m), 0 = unknown */
    vec4 albedo;   /* rgb diffuse albedo; a unused */
};

/* Placement of the cascades, as a uniform block (std140). Every cascade has
 * the same dims; the buffers hold them one after another, cascade 0 (the
 * finest) first. A cascade's origin is stored in units of its own cells, so
 * the cell of a point is floor(p / cell - origin): for snapped cascades the
 * origin is an integer and moving a cascade by whole cells shifts every
 * injected point by exactly that many cells. */
struct LpvGridParams {
    vec4 dims;                             /* xyz cells per axis (integers as float); w = cells per cascade */
    vec4 info;                             /* x cascade count; y 1 = fade small objects out of coarse cascades;
                                              z volumes per cascade (1, or LPV_NORMAL_BINS); w transport */
    vec4 cascade[LPV_MAX_CASCADES];        /* xyz lower corner in cells of this cascade; w cell size (m) */
    vec4 mode;                             /* x 1 = far field (hand-off): cascade k + 1 carries on the light
                                              cascade k propagated, lookups sum the cascades holding a point;
                                              yzw unused */
};

/* Six propagation directions, in this order everywhere (C and GLSL):
 * +x, -x, +y, -y, +z, -z. Per-cell transmittances are stored the same way. */
#define LPV_DIR_COUNT 6

/* A point of the geometry volume's total (docs/propagation.md section 2),
 * the max-merge of every buffer's GV. The merge is per travel direction, not
 * per SH vector: one SH vector holds a single lobe's worth of direction, so
 * keeping one buffer's would drop the other side of a wall that another
 * buffer saw from behind. blocking[d / 4][d % 4] is, for light travelling
 * along direction d, the largest blocking potential B(-d) (towards where the
 * light comes from, in units of cell^2) any buffer holds here; 0 where none
 * blocks. The GV's array is per cascade, x fastest, as the cells'. */
struct LpvGvPoint {
    vec4 blocking[2]; /* travel +x -x +y -y, then +z -z; [1].zw unused (0) */
    vec4 albedo;      /* rgb the mean albedo of the buffer with the largest DC term here (the one that
                         saw the most surface), for bounces; w that DC term, 0 = no surface */
};

/* ---- Lights and their shadow-map faces (uniform block, std140) ------------
 * Every light renders a reflective shadow map (RSM) into one or more layers
 * of 2D array textures: 1 for directional and spot lights, 6 (cube faces)
 * for point lights and for spots wider than LPV_SPOT_MAX_SINGLE_FACE.
 * Area light samples (emissive surfaces, docs/area-lights.md) come after the
 * punctual lights: 5 faces each (the front and the four sides of a cube
 * around the emitter's normal; the back face would see no emission), each a
 * square tile of a layer (gpu/light_faces.c says how big). */
#define LPV_MAX_LIGHTS 16      /* punctual lights */
#define LPV_MAX_AREA_LIGHTS 64 /* area light samples */
#define LPV_AREA_FACES 5
#define LPV_MAX_FACES (48 + LPV_AREA_FACES * LPV_MAX_AREA_LIGHTS)
#define LPV_SPOT_MAX_SINGLE_FACE 1.3962634f /* 80 deg half angle */

#define LPV_LIGHT_TYPE_DIRECTIONAL 0
#define LPV_LIGHT_TYPE_POINT 1
#define LPV_LIGHT_TYPE_SPOT 2
#define LPV_LIGHT_TYPE_AREA 3 /* a sample of an emitter: I(w) = I max(0, <n, w>) */

struct LpvLightGpu {
    vec4 position_type;   /* xyz world position (m); w = LPV_LIGHT_TYPE_* */
    vec4 direction_range; /* xyz unit travel direction (area: the emitter's normal); w = range (m), 0 = unlimited */
    vec4 intensity;       /* rgb: W/sr (point, spot; area: along the normal) or W/m^2 (directional);
                             a: area only, A/pi (m^2) for the samples' A m^2 of emitter: the
                             falloff is 1/(d^2 + A/pi), a disc of area A's on its axis */
    vec4 cone_faces;      /* x cos(inner), y cos(outer), z first face, w face count */
};

struct LpvFaceGpu {
    mat4 view_proj;       /* world -> clip of this RSM / shadow-map face */
    vec4 info;            /* x light index; y 1 perspective, 0 orthographic;
                             z texel footprint: m^2 (ortho) or tan(fov/2) (persp);
                             w this face's side in texels */
    vec4 axis;            /* xyz unit view axis of the face; w 1 = its surfels stay out of the
                             geometry volume (another face already sees those surfaces) */
    vec4 tile;            /* where the face lies in the RSM textures: xy lower-left corner (uv),
                             z side (uv, 1 = the whole layer), w layer */
};

struct LpvLightBlock {
    vec4 counts;          /* x lights (punctual first, then area samples), y faces, z punctual lights,
                             w directional lights (the first of the punctual ones) */
    LPV_STRUCT(LpvLightGpu) lights[LPV_MAX_LIGHTS + LPV_MAX_AREA_LIGHTS];
    LPV_STRUCT(LpvFaceGpu) faces[LPV_MAX_FACES];
};

/* ---- Shadow maps for direct light (uniform block, std140; docs/shadows.md) --
 * Depth-only maps at shadow_size texels per side, separate from the RSMs:
 * a spot light (half angle <= LPV_SHADOW_SPOT_MAX_SINGLE_FACE) has one
 * perspective face, a point light (and a wider spot) six cube faces, a
 * directional light LPV_SHADOW_CASCADES orthographic cascades fitted to the
 * camera's view. A single face of half angle a spreads its texels over
 * 2 tan(a) per metre of depth, a cube face over 2: past 45 degrees the cube's
 * texels are the smaller ones.
 * An area light sample has five faces (the RSM's: front and four sides
 * around the emitter's normal), each a square tile of a layer after the
 * punctual lights' layers, the RSM's tile rule at shadow_size
 * (gpu/light_faces.c): four faces to a layer. */
#define LPV_SHADOW_CASCADES 4
#define LPV_SHADOW_SPOT_MAX_SINGLE_FACE 0.78539816f /* 45 deg half angle */
#define LPV_MAX_SHADOW_FACES (6 * LPV_MAX_LIGHTS + LPV_AREA_FACES * LPV_MAX_AREA_LIGHTS)
/* PCF: (2 R + 1)^2 hardware-compare bilinear taps one texel apart, so the
 * filter reaches R + 1 texels from the lookup and a shadow edge ramps over
 * 2 R + 1 texels. */
#define LPV_SHADOW_PCF_RADIUS 1
/* Texels kept free at each face's border so the kernel and the normal offset
 * stay inside the face that is chosen (cube faces are widened by as much). */
#define LPV_SHADOW_BORDER_TEXELS 4.0f
/* Receiver bias, in texels of the shadow map at the receiver (footprint T):
 *   normal offset  LPV_SHADOW_NORMAL_OFFSET * T * sin(theta) along the normal,
 *   depth bias     (LPV_SHADOW_DEPTH_BIAS + LPV_SHADOW_SLOPE_BIAS *
 *                   min(tan(theta), LPV_SHADOW_MAX_SLOPE)) * T towards the light,
 * theta the angle between the normal and the light. The normal offset lifts
 * the receiver off its plane by exactly what the plane rises across the
 * kernel's reach (R + 1 texels); the depth bias is the margin. */
#define LPV_SHADOW_NORMAL_OFFSET 2.0f
#define LPV_SHADOW_DEPTH_BIAS 0.5f
#define LPV_SHADOW_SLOPE_BIAS 0.5f
#define LPV_SHADOW_MAX_SLOPE 8.0f

struct LpvShadowFaceGpu {
    mat4 view_proj;       /* world -> clip of this shadow-map face */
    vec4 info;            /* x texel footprint: m (ortho) or m per m of depth along
                             axis (persp); y 1 perspective, 0 orthographic;
                             z light index; w cascade index (directional) */
    vec4 axis;            /* xyz unit view axis; w unused */
    vec4 tile;            /* where the face lies in the maps: xy lower-left corner (uv of the layer),
                             z side (uv, 1 = the whole layer), w layer */
};

struct LpvShadowBlock {
    vec4 counts;          /* x faces, y shadow_size (texels), z 1 / shadow_size, w layers */
    vec4 options;         /* x 1 = the transmission maps (LPV_TEX_SHADOW_TRANSMIT) hold BLEND surfaces */
    vec4 lights[LPV_MAX_LIGHTS + LPV_MAX_AREA_LIGHTS]; /* per light (as LpvLightBlock's): x first face,
                                                          y face count, z 1 = cascades, 2 = area sample */
    LPV_STRUCT(LpvShadowFaceGpu) faces[LPV_MAX_SHADOW_FACES];
};

/* The camera, as a uniform block (std140). */
struct LpvViewBlock {
    mat4 view_proj;       /* world -> clip */
    vec4 eye;             /* xyz world position; w 1 perspective, 0 orthographic */
    vec4 forward;         /* xyz unit view direction; w tan(yfov/2) or ymag (ortho) */
    vec4 viewport;        /* x width, y height (pixels); z aspect; w 1 = the ambient occlusion term */
    vec4 shading;         /* x indirect gain; y include direct (0/1); z include indirect (0/1);
                             w include emission (0/1) */
};

/* ---- Imperfect volumes (techniques/iv/gpu/, docs/imperfect-volumes.md) ---------------
 * The volume is a grid of cubic voxels over the scene (the LpvGridParams UBO
 * with one cascade). Every SH here is 2-band RGB in LpvCell layout and, as
 * the LPV's, a function of the direction light TRAVELS: a voxel's outgoing
 * radiance, and the radiance arriving at a voxel centre (so the lookup's
 * irradiance is the same lobe(-n) product as the LPV's, without its /cell^2).
 * Units: radiance W/(m^2 sr), irradiance W/m^2. */

/* A point of the cloud (techniques/iv/core/iv_points.c): Turk's uniform points, N per
 * triangle; the GPU lights it every tick. */
struct IvPoint {
    vec4 position; /* xyz world (m); w 1 = a point, 0 = skip */
    vec4 normal;   /* xyz unit interpolated normal of the triangle's front; w the area it stands for (m^2:
                      its piece's over the piece's points; 0 = not known, LPV_IV_COVER) */
    vec4 albedo;   /* rgb diffuse albedo (the material's base colour); a unused */
    vec4 emission; /* rgb emitted radiance W/(m^2 sr) (0 where area lights carry the emitters); a unused */
};

/* One voxel's share of one block of the camera's pixels (iv_reproject.comp):
 * the sums iv_points.comp stores for the cloud's points, over the block's
 * pixels in that voxel; iv_splat.vert blends it into the atlas. */
struct IvSplat {
    vec4 r;     /* SH of B / pi over each pixel's hemisphere, summed (r, g, b) */
    vec4 g;
    vec4 b;
    vec4 n;     /* xyz the pixels' unit normals summed; w the pixel count */
    vec4 a;     /* rgb the albedos summed; w 0 (a pixel stands for no area, LPV_IV_COVER) */
    vec4 f;     /* xyz the folded normals summed (LPV_IV_FOLD); w 0 */
    vec4 hi;    /* xyz the greatest place in the voxel (0..1) */
    vec4 lo;    /* xyz 1 - the least */
    vec4 texel; /* xy the voxel's atlas texel; w 1 = a used slot, 0 = none */
};

/* A voxel after creation: the mean of the points it received. */
struct IvVoxel {
    vec4 r;        /* SH of the surfaces' outgoing radiance, W/(m^2 sr): the mean over the  */
    vec4 g;        /*   points of B / pi over the hemisphere of the point's normal (B = its  */
    vec4 b;        /*   radiosity, W/m^2), LPV_IV_HEMI0 / LPV_IV_HEMI1 below                 */
    vec4 normal;   /* xyz the mean of the points' unit normals (not unit); w points, 0 = empty */
    vec4 albedo;   /* rgb the points' mean albedo (the bounces' reflectance); a the cloud's area in the
                      voxel over a voxel face's (LPV_IV_COVER; 0: not known) */
    vec4 fold;     /* xyz the mean of the points' folded normals (LPV_IV_FOLD); w as albedo.a, each
                      point's area signed by its fold (+1: n is its folded normal, -1: -n is) */
    vec4 extent;   /* xyz the points' extent along x, y, z in voxels (their range, widened by
                      (N + 1) / (N - 1) for N points, at most 1; 0 for one point); w unused */
    vec4 slab;     /* the points' extent across their surface (LPV_IV_SLAB): x the axis (0, 1, 2; -1:
                      none, a block), y, z their least and greatest coordinate on it (voxels from the
                      voxel's lower corner); w unused */
};

/* LPV_IV_FOLD: a point's normal n folded to s n, s the sign of its largest
 * component (ties: x before y before z). The two faces of a wall, n and -n,
 * add up to one axis there where their plain mean cancels: a wall thinner
 * than a voxel puts both faces in it, and the voxel shows each side at its
 * own radiance along that axis (iv_emit.comp, lpv_iv_emit). */
#define LPV_IV_ONE_SIDED 0.5f /* the mean normal is the axis when |m| >= this x |folded mean| */
#define LPV_IV_SIDE_MIN 0.05f /* the least share of a voxel's points a side is divided by */
/* LPV_IV_COVER: how much of a two-sided voxel's face each side shows. The
 * SH is the mean over the points, so a side with share c of them shows c of
 * its radiance; a wall's two faces each cover the whole voxel face and
 * should show all of theirs. Point counts are no measure of that: the
 * camera's pixels land on the seen face only (a seen wall's voxel at
 * 0.7-0.9 of its points) and 4 points a piece split a wall unevenly
 * between its faces, so a room of 10 cm box walls got 0.91 of the same
 * room of single quads at one bounce, 0.95 with the camera's pixels left
 * out (box-walls, thin-walls; 2026-11-28). Where a voxel's points all lie
 * along one axis (|folded mean| >= LPV_IV_FLAT) and the cloud says how much
 * area they stand for, each side shows the part of the voxel face it covers:
 * its area over the face's (every voxel face at least once: a wall is 1),
 * at most the points' extent across the axis (a stack of slats that cover
 * a quarter of the face shows a quarter, however many there are), never
 * less than its share c nor more than all. Both are estimates from a few
 * random points (a wall's voxel gets its area within about a third and
 * its extent within a fifth), and taking the smaller of 1 and a noisy
 * estimate loses light on average, so a side counts as covering the face
 * once its area reaches LPV_IV_COVER_AREA of it and its extent
 * LPV_IV_COVER_ACROSS of it (a room of 2 cm double-faced walls then gets
 * 1.000 of the single-quad room's light at one bounce; 0.927 with both 1).
 * Elsewhere (corners, curved pieces, hand-made points without area) the
 * count rule stays: t = 1 - |m| / |f| of the way from c to all. */
#define LPV_IV_FLAT 0.9f
#define LPV_IV_COVER_AREA 0.5f
#define LPV_IV_COVER_ACROSS 0.6f
/* LPV_IV_SLAB: a voxel whose points' folded normals agree on a lattice
 * axis (that component of their mean at least LPV_IV_FLAT: a wall, a floor,
 * both faces of a thin wall) and that lie within LPV_IV_SLAB_MAX voxels of
 * each other along it holds a slab across it, from their least to their
 * greatest coordinate on it (IvVoxel.slab). A corner's normals disagree,
 * and a sliver of another surface in the voxel (a wall's foot in a floor's
 * voxel) widens the extent past the limit (it is the points' own min and
 * max): neither has a slab. The surface gather (LPV_IV_SURFACE_GATHER)
 * starts on it, and every ray of a radiance gather (LPV_IV_SLAB_MARCH)
 * passes every occupied voxel whose slab it runs clear of (widened by
 * LPV_IV_SLAB_PAD voxels each way).
 *
 * LPV_IV_SLAB_MARCH: a whole voxel stops a ray a voxel short of a floor it
 * looks at from a low angle (the voxel's top face, not the floor in it), so
 * light arriving at grazing angles was read nearer than it is: in a tunnel
 * 4 voxels across, the floor under a lamp 0.2 m below the ceiling 1.5x its
 * one-bounce light and the floor 10 m on 0.6x. The ambient occlusion's
 * march keeps whole voxels (paper 3.5).
 * LPV_IV_CORNER_READ: passing slabs lets rays reach the voxels where two
 * surfaces meet, which the voxels in front had hidden; such a voxel has no
 * slab and shows its points' mean as two hemispheres along one axis (a
 * wall's lit face behind its dark back and the floor's hidden ends): 0.69
 * of the radiance every face of a glowing tunnel has. A ray that comes
 * straight from a surface it passed, through the face across axis a,
 * reads instead the mean of the voxel's face neighbours that hold a slab
 * across a: the wall that continues into the corner. */
#define LPV_IV_SLAB_MAX 0.5f
#define LPV_IV_SLAB_PAD 0.02f

/* The SH of a hemisphere of unit radiance around n, divided by pi:
 * (HEMI0, HEMI1 n.y, HEMI1 n.z, HEMI1 n.x), so radiosity B x this is the SH
 * of a Lambertian surface's outgoing radiance B / pi. HEMI0 = 2 C0, HEMI1 = C1. */
#define LPV_IV_HEMI0 0.56418958354775628f
#define LPV_IV_HEMI1 0.48860251190291992f

/* The march (paper section 3.3): rays start sqrt(3)/2 voxels from the voxel
 * centre (the voxel's bounding sphere) and step one voxel. */
#define LPV_IV_START 0.86602540378443865f
/* LPV_IV_AXIS_L0: the 2-band irradiance R0 + R1.n (R0 the L0 term, R1 the
 * dipole) flattens the cosine: it gives 3/4 of a source straight along n and
 * 1/4 of one at grazing, and weighs the light from behind a surface by
 * 1/4 - |cos|/2. With the path tracer's own radiance in box-walls' room
 * (a lamp under the ceiling, 2026-11-28) that made the floor 0.82-0.88 of
 * its 1-bounce irradiance and the ceiling 1.08-1.12, and a sunlit floor
 * seen from above with little else in view (the courtyard) read its own
 * light from behind as none or less (black patches on the ground). The
 * dipole already gives E(a) - E(-a) exactly for any axis a (both are the
 * rays' first moment), so an empty voxel that gathers on a surface
 * (LPV_IV_SURFACE_GATHER: over a floor, beside a wall) sets R0 = (E(a) + E(-a)) / 2 from the rays'
 * exact cosine sums along the axis a from that surface to it (its
 * normal): the volume is then exact for the surface beside it and
 * keeps the linear fit around that R0 for other normals. Other voxels keep
 * the projection's R0 (along an edge's diagonal the exact sums weigh the
 * corner voxels most, which show 0.85 of a uniform radiance there: the
 * furnace's edge voxels got 0.95 of it). */
/* LPV_IV_SURFACE_GATHER: an empty voxel with one occupied face neighbour
 * (a floor's voxel under it) gathers on that surface, not at its own centre
 * up to a voxel and a half away from it: irradiance changes with the height
 * above a floor (box-walls: +9 % at half a voxel, +23 % at one and a half
 * with the path tracer), and the lookups it serves are on the surface. Its
 * rays start on the slab's face towards the voxel (LPV_IV_SLAB); those into
 * the surface see the surface voxel's own light, the others go on through
 * it and through every occupied voxel whose slab they run clear of. Without a slab on that axis (a corner, a tilted piece), the voxel's
 * centre as before. */
/* LPV_IV_FILTER: each voxel marches its own rays (lpv_iv_ray's
 * stratification per voxel), so a flat wall's voxels carry independent noise that the lookup
 * shows as blotches a voxel wide (the panel room at 128 rays; smooth at 512).
 * After the last bounce (and the tail) a surface voxel (LPV_IV_SURFACE_GATHER
 * with a slab) takes the binomial 3 x 3 mean [1 2 1] x [1 2 1] / 16 of the
 * surface voxels around it in its plane: those beside the same surface axis
 * and side, whose slab faces lie within LPV_IV_FILTER_PLANE voxels of its
 * own; the weights are renormalised over those. A voxel touching two
 * surfaces (an edge, a corner) is none, so the mean never reaches round a
 * corner or through a wall; every other voxel keeps its gather. The noise
 * falls to 0.375 of its deviation (2.7 x fewer blotches for the cost of one
 * pass over the volume, where rays cost linearly). */
#define LPV_IV_FILTER_PLANE 0.5f
/* Where a sample lands in the LPV (docs/propagation.md §2): a VPL in the cell
 * holding its position moved LPV_VPL_SHIFT_CELLS cells along its normal, a
 * surfel on the geometry-volume point nearest its position moved
 * LPV_TIE_CELLS cells along its normal. The half cell keeps a surface's light
 * in the cell in front of it (paper, section 5); LPV_TIE_CELLS settles the
 * surfaces that lie exactly where rounding would split them (the default
 * grid pads the scene's bounds by half a cell, so its walls sit on cell
 * centres: their VPLs on cell faces, their surfels halfway between two GV
 * points) on the side in front of the surface, on every GPU and in the CPU
 * oracle alike, not by the last bit of a division (an H100 and llvmpipe put
 * the Cornell box's back-wall VPLs in different cells without it). Both are
 * linear in the normal, so a down-sampled group (mean normal, centroid) lands
 * where its members do. */
#define LPV_TIE_CELLS 0.00390625f
#define LPV_VPL_SHIFT_CELLS (0.5f + LPV_TIE_CELLS)

#define LPV_IV_WG 64 /* one-dimensional workgroups of the IV's compute passes */
/* Reprojection takes at most about this many of the G-buffer's pixels, a
 * regular subset (every k-th pixel in x and y): a voxel seen by the camera
 * still gets many, and a 512x512 view costs a quarter (paper 3.2: "the
 * number of the visible points ... is considerably larger than the number of
 * the visible voxels"). */
#define LPV_IV_REPROJECT_POINTS 65536
/* iv_reproject.comp sums the sampled pixels of each block of this many x
 * this many per voxel, so the splat (iv_splat.vert) blends a point per voxel
 * a block touches instead of one per pixel: llvmpipe blends a draw into a
 * small atlas on one thread, and lit pixels in a compute pass use them all. */
#define LPV_IV_REPROJECT_BLOCK 8
/* A point belongs to the voxel holding it moved this many voxels against its
 * normal, so a surface that lies exactly on a voxel face (a wall on a room's
 * bounds, a box on the lattice) goes wholly to the voxel behind it instead
 * of splitting between two by rounding; splatting and the lookup's own
 * voxel agree on it. */
#define LPV_IV_BEHIND 0.001f
/* The reconstruction's weight of a voxel that holds a surface, relative to an
 * empty one (iv_volume.glsl, iv_blend; docs/imperfect-volumes.md). */
#define LPV_IV_HELD_WEIGHT 0.015625f
/* Luminance weights (Rec. 709, summing to 1) of the lookup's rule for a
 * reconstructed irradiance with a channel below 0 (iv_lookup.glsl,
 * iv_physical; techniques/iv/core/oracle_iv_reconstruct.c). */
#define LPV_IV_LUMA_R 0.2126f
#define LPV_IV_LUMA_G 0.7152f
#define LPV_IV_LUMA_B 0.0722f
/* The bounces after the gathered ones as a series (iv_tail.comp,
 * techniques/iv/core/oracle_iv.c lpv_iv_add_tail): the per-bounce ratio is at most this
 * (the share two bounces keep at most its square, a factor q / (1 - q) of
 * 4.3 on the last two bounces); the totals S_k sit in slots 1..K of a float
 * buffer, the per-bounce ratios used in LPV_IV_TAIL_RATIO_SLOT, three
 * floats (r, g, b) a slot. */
#define LPV_IV_TAIL_MAX_RATIO 0.9f
#define LPV_IV_TAIL_SLOTS 16
#define LPV_IV_TAIL_RATIO_SLOT 15
#define LPV_IV_TAIL_WG 256

/* Random numbers both sides draw identically: a 32-bit integer hash (Chris
 * Wellons' lowbias32) and a uniform float in [0, 1) from its top 24 bits. */
#ifdef LPV_GLSL
#define LPV_U32 uint
#define LPV_INLINE
#define LPV_FLOOR floor
#define LPV_SQRT sqrt
#define LPV_COS cos
#define LPV_SIN sin
#else
#include <math.h>
#include <stdint.h>
#define LPV_U32 uint32_t
#define LPV_INLINE static inline
#define LPV_FLOOR floorf
#define LPV_SQRT sqrtf
#define LPV_COS cosf
#define LPV_SIN sinf
#endif

#ifdef LPV_GLSL
#define LPV_OUT_VEC3(name) out vec3 name
#define LPV_VEC3_SET(v, x, y, z) v = vec3(x, y, z)
#else
#define LPV_OUT_VEC3(name) float name[3]
#define LPV_VEC3_SET(v, x, y, z) ((v)[0] = (x), (v)[1] = (y), (v)[2] = (z))
#endif

LPV_INLINE LPV_U32 lpv_hash_u32(LPV_U32 x)
{
    x ^= x >> 16u;
    x *= 0x7feb352du;
    x ^= x >> 15u;
    x *= 0x846ca68bu;
    x ^= x >> 16u;
    return x;
}

LPV_INLINE float lpv_hash_unit(LPV_U32 x) { return (x >> 8u) * (1.0f / 16777216.0f); }

/* Alpha as coverage (docs/scenes.md, "Alpha"): whether a surface of alpha
 * `alpha` is there for a draw u in [0, 1). MASK (cutoff > 0): where alpha >=
 * cutoff. BLEND (blend != 0): where alpha > u, so over uniform draws it
 * covers the fraction alpha and lets 1 - alpha of the light through, as
 * glTF defines alpha (the fraction of the pixel the surface covers).
 * Otherwise (OPAQUE) always. The one rule of the shaders (material.glsl),
 * the CPU's surface samples (core/material_sample.h) and the reference's
 * rays; each draws u its own way (an ordered dither per texel, a hash per
 * voxel, a hash per ray). NaN alpha: nothing there. */
LPV_INLINE int lpv_alpha_covers(float alpha, float cutoff, int blend, float u)
{
    if (blend != 0)
        return alpha > u ? 1 : 0;
    if (cutoff > 0.0f)
        return alpha >= cutoff ? 1 : 0;
    return 1;
}

/* The draw u of texel (x, y) of a rasterised view for lpv_alpha_covers: an
 * 8 x 8 ordered (Bayer) dither, (rank + 0.5) / 64. Every aligned 2^k block
 * holds evenly spread ranks, so a shadow map's filter (4 x 4 texels at
 * LPV_SHADOW_PCF_RADIUS 1) and an RSM's VPLs see a BLEND surface cover
 * alpha of its texels to 1/32, the same texels every tick (no flicker). */
LPV_INLINE float lpv_dither8(LPV_U32 x, LPV_U32 y)
{
    LPV_U32 xy = (x ^ y) & 7u, yy = y & 7u, rank = 0u;
    for (LPV_U32 i = 0u; i < 3u; ++i)
        rank = (rank << 2u) | (((xy >> i) & 1u) << 1u) | ((yy >> i) & 1u);
    return (rank + 0.5f) / 64.0f;
}

/* Ray j of `rays` from voxel `voxel` under `seed` (paper section 3.3's
 * stratified directions): rays equal-area bands in z, one jittered ray per
 * band, azimuths on the golden-ratio sequence rotated per voxel. Writes the
 * unit direction to d[0..2]. */
LPV_INLINE void lpv_iv_ray(LPV_U32 seed, LPV_U32 voxel, LPV_U32 j, LPV_U32 rays, LPV_OUT_VEC3(d))
{
    LPV_U32 h = lpv_hash_u32(seed ^ lpv_hash_u32(voxel + 0x9e3779b9u));
    float u = (j + lpv_hash_unit(lpv_hash_u32(h + 2u * j))) / rays;
    float a = j * 0.61803398874989485f + lpv_hash_unit(h);
    float phi = 6.28318530717958648f * (a - LPV_FLOOR(a));
    float z = 1.0f - 2.0f * u;
    float r = LPV_SQRT(z * -z + 1.0f > 0.0f ? z * -z + 1.0f : 0.0f);
    LPV_VEC3_SET(d, r * LPV_COS(phi), r * LPV_SIN(phi), z);
}

/* ---- Binding points -------------------------------------------------------- */
#define LPV_UBO_GRID      0
#define LPV_UBO_VIEW      1
#define LPV_UBO_LIGHT     2
#define LPV_UBO_SHADOW    3

#define LPV_SSBO_LPV_OUT  1
#define LPV_SSBO_LPV_ACC  2
#define LPV_SSBO_TRANSMIT 3
#define LPV_SSBO_VPLS     5
#define LPV_SSBO_SURFELS  6
#define LPV_SSBO_GV_TOTAL 7
#define LPV_SSBO_SENT_OUT 8 /* LpvCell per cell: what it sends, its coefficients times its flux limits */
#define LPV_SSBO_REFLECT  9
#define LPV_SSBO_IV_POINTS 10   /* IvPoint */
#define LPV_SSBO_IV_VOXELS 11   /* IvVoxel per voxel */
#define LPV_SSBO_IV_OCCUPANCY 12 /* one bit per voxel, 32 to a uint, voxel index order */
#define LPV_SSBO_IV_EMIT 13     /* LpvCell per voxel: what each occupied voxel sends out this bounce */
#define LPV_SSBO_IV_AO 14       /* vec4 per voxel: the SH of the visible directions (travel convention) */
#define LPV_SSBO_IV_SPLATS 17      /* IvSplat, LPV_IV_REPROJECT_BLOCK^2 per block (iv_reproject.comp; shares 17
                                      with LPV_SSBO_PROBES_SH: one technique runs) */
#define LPV_SSBO_IV_POINT_STARTS 16 /* uint per voxel + 1: where its points begin in the sorted cloud (iv_points.comp) */
#define LPV_SSBO_IV_TAIL 3       /* float[3 x LPV_IV_TAIL_SLOTS]: iv_tail.comp's totals and ratio (shares 3 with
                                    LPV_SSBO_TRANSMIT, which no iv pass binds) */
#define LPV_SSBO_SHADE_REST 15  /* the frame's pixels left for shade_rest.comp (shading.glsl, LPV_LOOKUP_SPLIT) */
#define LPV_SSBO_COMPACT_HEAD 0 /* compact.comp: the draw command, then a count per chunk */
#define LPV_SSBO_COMPACT_DST 4  /* compact.comp: the live samples, in order */
#define LPV_SSBO_AREA_REST 0    /* the frame's pixels left for area_shadow_rest.comp (shading.glsl,
                                   LPV_AREA_SHADOW_BLOCKS); no frame program binds 0 otherwise */

/* Texture units of the propagation's inputs (RGBA32F buffer textures). */
#define LPV_TEX_LPV_IN    0
#define LPV_TEX_SENT_IN   1
#define LPV_TEX_ACC_IN    2
#define LPV_TEX_TRANSMIT  3
#define LPV_TEX_REFLECT   4
#define LPV_TEX_DENSITY   7 /* the medium's 3D density (units 0..6 are the shading's) */
/* The accumulated LPV as 3D textures for the lookup (lookup.glsl, techniques/lpv/gpu/lpv_lookup_volume.c). */
#define LPV_TEX_LOOKUP_R  8
#define LPV_TEX_LOOKUP_G  9
#define LPV_TEX_LOOKUP_B  10
/* The same volume's irradiance on the six axis-aligned normals (+x -x +y -y
 * +z -z), summed over the normal bins, per cascade (lpv_normals_pack.comp): a
 * surface whose normal is exactly an axis reads it with one fetch per
 * cascade instead of three per volume (lookup.glsl, cascade_irradiance_at). */
#define LPV_TEX_LOOKUP_NORMALS 13
#define LPV_LOOKUP_AXES 6
/* After the axes, the same for up to LPV_MAX_LOOKUP_PLANES normals of the
 * scene's largest flat surfaces (core/scene_planes.c): a pixel whose normal
 * is within LPV_LOOKUP_PLANE_TOLERANCE of one per component reads that
 * normal's irradiance (the G-buffer normalises the same vertex normal, so
 * it differs by rounding only). Only with normal bins (without, the full
 * lookup is three fetches per cascade) and in LPV_LOOKUP_NORMAL_TEXELS
 * texels in all: the six axes and as many planes as fit, or none when the
 * axes do not (filling them costs more than it saves at large grids). */
#define LPV_MAX_LOOKUP_PLANES 24
/* Where volume v of a lookup texture begins, in cells along y and z:
 * `slabs` volumes along z, then the next y-slab (lpv_lookup_volume.c sizes
 * the textures so; lookup.glsl and the packs address them so). GLSL takes
 * the slab's index in float arithmetic, exact for these small non-negative
 * values: llvmpipe has no vector integer division and divides lane by lane
 * (the frame's lookup calls it per pixel; 3 ms of a 512^2 frame). */
#ifdef LPV_GLSL
int lpv_slab_index(int v, int slabs) { return int((float(v) + 0.5) / float(slabs)); }
#else
LPV_INLINE int lpv_slab_index(int v, int slabs) { return v / slabs; }
#endif
LPV_INLINE int lpv_slab_y0(int v, int slabs, int dim_y) { return lpv_slab_index(v, slabs) * dim_y; }
LPV_INLINE int lpv_slab_z0(int v, int slabs, int dim_z) { return (v - lpv_slab_index(v, slabs) * slabs) * dim_z; }
/* The G-buffer's albedo is the base colour (glossy.frag's F0 needs it) and
 * its normal's w 1 + metallic where covered: the diffuse albedo, which lights
 * the frame and carries the bounces (iv's reprojected points, the camera's
 * surfels), is base x (1 - metallic), as glTF's metallic-roughness model has
 * it on a diffuse transport (core/material_sample.h for the CPU's side). */
/* Photometric -> radiometric (docs/units.md): the loaders' lm/W, and an
 * unlit material's base colour as luminance (nits) in the G-buffer. */
#define LPV_LUMENS_PER_WATT 683.0f

/* An unlit material's pixel (KHR_materials_unlit) has normal w
 * LPV_GBUF_UNLIT_W: covered, no diffuse albedo (lpv_gbuffer_kd 0), and the
 * emission target holds what the camera sees of it (its base colour as
 * luminance, core/material_sample.h), which lights nothing. */
#define LPV_GBUF_UNLIT_W 3.0
/* A point's or line's pixel (glTF's points and lines, lpv_scene.wire_draws)
 * has normal w LPV_GBUF_WIRE_W: shown as an unlit pixel is (lpv_gbuffer_unlit
 * holds), but no surface: no surfel (its area is 0), no point of the
 * imperfect volume's reprojection, no plane of the frame's blocks. */
#define LPV_GBUF_WIRE_W 4.0
#ifdef LPV_GLSL
float lpv_gbuffer_kd(float normal_w) { return 1.0 - clamp(normal_w - 1.0, 0.0, 1.0); }
bool lpv_gbuffer_unlit(float normal_w) { return normal_w > LPV_GBUF_UNLIT_W - 0.5; }
bool lpv_gbuffer_wire(float normal_w) { return normal_w > LPV_GBUF_WIRE_W - 0.5; }
#endif
#define LPV_LOOKUP_NORMAL_TEXELS 131072
#define LPV_LOOKUP_PLANE_TOLERANCE 1e-6

/* The frame's irradiance looked up once per lookup_step^2 block
 * (lookup_blocks.comp, shading.glsl's blocks_upsampled): per block the
 * irradiance (rgb, a 1 = the block saw a surface) and the plane it was
 * looked up on (xyz unit normal, w its distance along it from the origin). */
#define LPV_TEX_BLOCK_IRRADIANCE 11
#define LPV_TEX_BLOCK_PLANE      12
/* The area light samples' visibility once per area_shadow_step^2 block
 * (area_shadow_blocks.comp, shading.glsl's area_visibility): per block the
 * shadowed over the unshadowed irradiance of the samples (rgb, a 1 = the
 * block saw a surface) and its plane, as for the lookup step. */
#define LPV_TEX_AREA_SHADOW       14
#define LPV_TEX_AREA_SHADOW_PLANE 15
/* Where light can reach (core/reach.h, reach.glsl): an R8UI 3D texture of
 * the scene's voxels, each LPV_REACH_SOLID, _DARK (air no light reaches) or
 * _LIT; every pass that reads the technique's volume multiplies by it. */
#define LPV_TEX_REACH 16
/* The G-buffer's occlusion target (gbuffer.frag o_occlusion) in the frame. */
#define LPV_TEX_GBUF_OCCLUSION 17
/* The shadow maps' transmission (shadow_maps.c, shadow.glsl): per texel of
 * a face, rgb the share of light the BLEND surfaces in front of its opaque
 * depth let through (the product of 1 - alpha), a the reversed depth of the
 * nearest of them. */
#define LPV_TEX_SHADOW_TRANSMIT 18
#define LPV_REACH_SOLID 0
#define LPV_REACH_DARK 1
#define LPV_REACH_LIT 2

/* Image units of the frame that shade.comp writes (frame.c), of the
 * blocks' irradiance and planes that lookup_blocks.comp writes and of the
 * blocks' area light visibility that area_shadow_blocks.comp writes. */
#define LPV_IMG_FRAME 0
#define LPV_IMG_BLOCK_IRRADIANCE 1
#define LPV_IMG_BLOCK_PLANE 2
#define LPV_IMG_AREA_SHADOW 3
#define LPV_IMG_AREA_SHADOW_PLANE 4
/* Two points lie on one plane for the lookup step when their normals are
 * within LPV_BLOCK_NORMAL_COS and the plane of one passes within
 * LPV_BLOCK_PLANE_PIXELS block widths (at the point's depth) of the other. */
#define LPV_BLOCK_NORMAL_COS 0.999
#define LPV_BLOCK_PLANE_PIXELS 4.0

/* ---- Compute workgroup sizes (the C side dispatches with the same numbers) - */
#define LPV_SHADE_REST_WG 64
/* shade_rest.comp's workgroups at most (GL guarantees 65535 per dimension);
 * past that many pixels each invocation takes several */
#define LPV_SHADE_REST_MAX_GROUPS 65535
#define LPV_PROP_WG_X 32
#define LPV_PROP_WG_Y 2
#define LPV_WG_2D 8
/* compact.comp: samples per chunk (one invocation each; the bits of a uint,
 * compact.glsl), chunk invocations per workgroup, and the scan's single
 * workgroup. */
#define LPV_COMPACT_CHUNK 32
#define LPV_COMPACT_WG 64
#define LPV_COMPACT_SCAN_WG 1024
/* Samples per block of a down-sampled buffer at most (block_groups.glsl:
 * camera surfels, RSM VPLs and surfels): one per cell or geometry-volume
 * point the block's samples reach. */
#define LPV_BLOCK_SLOTS 8

/* ---- Limits ---------------------------------------------------------------- */
#define LPV_MAX_GRID_DIM     256  /* cells per axis */
#define LPV_MAX_ITERATIONS   4096
#define LPV_MAX_RSM_SIZE     2048
#define LPV_MAX_SHADOW_SIZE  8192 /* texels per side of a shadow map */
#define LPV_FP16_MAX         65504.0f

/* ---- Probes (techniques/probes, issue 34): the scene's BVH as the shaders
 * read it (techniques/probes/core/probes_bvh.h builds it; probes_trace.glsl
 * traverses it). A node is two vec4: lo.xyz and hi.xyz its box, the w's
 * uints (floatBitsToUint in GLSL; probes_bvh.h's lpv_probes_bvh_node names
 * them a and b). Inner node: b == 0, left child the next node, right child
 * node a. Leaf: b has LPV_PROBES_BVH_LEAF set, its triangles are
 * leaf_tris[a .. a + (b & LPV_PROBES_BVH_COUNT_MASK)). */
struct LpvBvhNode {
    vec4 lo;
    vec4 hi;
};
#define LPV_PROBES_BVH_LEAF 0x80000000u
#define LPV_PROBES_BVH_COUNT_MASK 0x7fffffffu
#define LPV_PROBES_BVH_STACK 64 /* the traversal's stack: the tree is at most LPV_PROBES_BVH_MAX_DEPTH deep */
#define LPV_PROBES_WG 64        /* one-dimensional workgroups of the probes' compute passes */
/* Its buffers (the probes' passes share 10..14 with iv's, which none of
 * theirs binds). */
#define LPV_SSBO_PROBES_NODES 10     /* LpvBvhNode, node 0 the root */
#define LPV_SSBO_PROBES_LEAF_TRIS 11 /* uint: triangle ids, each leaf's run */
#define LPV_SSBO_PROBES_VERTS 12     /* vec4: triangle t's corners at 3t, 3t + 1, 3t + 2 */
#define LPV_SSBO_PROBES_RAYS 13      /* probes_rays.comp: vec4 origin (w: tmax), vec4 direction per ray */
#define LPV_SSBO_PROBES_HITS 14      /* probes_rays.comp: uvec4 per ray: t (bits), triangle id, hit, 0 */
/* The technique's own (techniques/probes/gpu): the update's per-ray results
 * (vec4: radiance rgb, w the hit distance, negative for a back face) share
 * 13 with the test's rays; the lookup reads the last three, which no pass
 * of the frame or the queries binds otherwise. */
#define LPV_SSBO_PROBES_RAY_OUT 13
#define LPV_SSBO_PROBES_MATERIALS 16 /* vec4 albedo (w: double-sided), vec4 emission per triangle */
#define LPV_SSBO_PROBES_SH 17        /* LpvCell per probe: cell^2 x the L1 SH of the radiance by travel direction */
#define LPV_SSBO_PROBES_MOMENTS 18   /* vec2 per texel of each probe's distance map: mean, mean square (m, m^2) */
#define LPV_SSBO_PROBES_STATE 19     /* 2 vec4 per probe: (back-face share of its last rays, 1 = active,
                                        1 = moved by the last relocation, 0), (offset from its cell's centre
                                        xyz (m), 0) */
/* A batch's ray table (the same for every probe of the batch; the CPU makes
 * it with probes_math.h's functions): each ray's direction, then for the
 * distance moments each texel's (first, count) of taps and the taps (ray,
 * weight bits), the weights max(0, cos)^sharpness normalised per texel. */
#define LPV_SSBO_PROBES_RAY_DIRS 20  /* vec4 per ray: xyz its unit direction */
#define LPV_SSBO_PROBES_TAPS 21      /* uvec2: the distance map's oct^2 texel ranges, the irradiance map's
                                        LPV_PROBES_IRR_OCT^2, then the taps */
/* Each probe's irradiance map (Majercik et al. 2019: irradiance per
 * direction, not L1 SH, is what the server's lookup reads: L1 loses a
 * quarter of a small bright source's light and lights surfaces that face
 * darkness). The volume on the wire keeps the SH. */
#define LPV_SSBO_PROBES_IRRADIANCE 22 /* float: rgb (W/m^2) per texel of each probe's irradiance map */
#define LPV_PROBES_IRR_OCT 6          /* its texels per side (the paper's) */
/* A camera-following cascade that moved by whole cells keeps the probes
 * whose cells it still holds: probes_scroll.comp copies each of the four
 * buffers above into the new layout (it runs alone, so the rays' 13 and 14
 * are free), and only the probes it brought in warm up, a listed batch
 * (probes_batch.glsl). */
#define LPV_SSBO_PROBES_SCROLL_SRC 13
#define LPV_SSBO_PROBES_SCROLL_DST 14
#define LPV_SSBO_PROBES_LIST 23 /* uint: a listed batch's probe ids */
/* The lookup's weights (probes_lookup.glsl and its CPU oracle,
 * techniques/probes/core/probes_lookup.c; SPEC R5.15 states them): a
 * probe's weight is (facing^2 + LPV_PROBES_FACING_FLOOR) x the Chebyshev
 * bound (variance at least LPV_PROBES_MIN_VAR cells^2), crushed to
 * w^3 / LPV_PROBES_CRUSH^2 below LPV_PROBES_CRUSH; a level whose probes
 * see less than LPV_PROBES_UNSEEN of the point hands it to the next. */
#define LPV_PROBES_FACING_FLOOR 0.2f
#define LPV_PROBES_CRUSH 0.2f
#define LPV_PROBES_MIN_VAR 1e-4f
#define LPV_PROBES_UNSEEN 1e-3f
/* The blend's hysteresis drops to none as a probe's band 0 changes by
 * LPV_PROBES_CHANGE_Z0 .. Z1 standard errors of the batch's own estimate
 * (probes_blend.comp): a change its rays' noise does not explain. */
#define LPV_PROBES_CHANGE_Z0 3.0f
#define LPV_PROBES_CHANGE_Z1 6.0f

#endif /* LPV_SHARED_H */
