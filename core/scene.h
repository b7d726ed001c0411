/*
 * scene.h - the scene model every part of lpvd works on.
 *
 * A scene is flattened at load time: every mesh primitive instanced by a node
 * becomes a draw over world-space vertices, so the GPU passes and the C oracle
 * never walk a hierarchy. Units: metres; light intensities are radiometric
 * (W/sr for point and spot lights, W/m^2 for directional lights) and emission
 * is radiance in W/(m^2 sr). Loaders convert from glTF's photometric units
 * (candela, lux, nits) with 683 lm/W; see docs/units.md.
 */
#ifndef LPV_SCENE_H
#define LPV_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "lpv_shared.h" /* LPV_LUMENS_PER_WATT */

#define LPV_NAME_MAX 64

/* The largest |coordinate| (m) lpvd computes with: scene vertices after node
 * transforms, lights' positions and ranges, the camera's eye and target,
 * CONFIG bounds. Positions are 32-bit floats: at 1e9 m one ulp is 64 m, and
 * squared distances (at most ~1.2e19) stay far below FLT_MAX, where 2e19 m
 * between eye and target overflowed. 1e9 m is 2.6 times the distance to the
 * Moon. Larger values are refused, naming the field (SPEC R4.15). */
#define LPV_MAX_COORD 1e9
/* The largest intensity x colour of a light: W/sr (point, spot) or W/m^2
 * (directional). The GPU hard cases tick at 1e30 (tests/test_gpu_stability.c);
 * intensity 1e30 with colour 1e30 overflowed float and lit nothing. */
#define LPV_MAX_LIGHT_INTENSITY 1e30

typedef enum lpv_light_type {
    LPV_LIGHT_DIRECTIONAL = 0,
    LPV_LIGHT_POINT = 1,
    LPV_LIGHT_SPOT = 2,
} lpv_light_type;

typedef struct lpv_light {
    lpv_light_type type;
    char name[LPV_NAME_MAX];
    float color[3];     /* linear RGB factor, multiplies intensity */
    float intensity;    /* W/sr (point, spot) or W/m^2 (directional) */
    float range;        /* m; 0 = unlimited (glTF's smooth window when > 0) */
    float inner_cone;   /* rad, spot only */
    float outer_cone;   /* rad, spot only */
    float position[3];  /* world, m (unused for directional) */
    float direction[3]; /* world, unit: the direction the light travels */
} lpv_light;

typedef struct lpv_camera {
    char name[LPV_NAME_MAX];
    int orthographic;   /* 0 perspective, 1 orthographic */
    float yfov;         /* rad, perspective */
    float aspect;       /* 0 = use the image's aspect */
    float znear, zfar;  /* m; zfar 0 = infinite */
    float xmag, ymag;   /* orthographic half extents, m */
    float eye[3];       /* world position */
    float forward[3];   /* unit view direction (glTF camera -Z) */
    float up[3];        /* unit up (glTF camera +Y) */
} lpv_camera;

typedef struct lpv_texture {
    int width, height;
    uint8_t *rgba8; /* width*height*4 bytes: sRGB-encoded colour, or linear data when `linear` */
    int linear;     /* 0: sRGB colour (base colour); 1: linear data (normal map) */
} lpv_texture;

/* Alpha modes of glTF materials (docs/scenes.md, "Alpha"). */
typedef enum lpv_alpha_mode {
    LPV_ALPHA_OPAQUE = 0, /* alpha ignored */
    LPV_ALPHA_MASK = 1,   /* cut away where alpha < alpha_cutoff */
    LPV_ALPHA_BLEND = 2,  /* alpha is coverage: the surface covers alpha, 1 - alpha of the light passes */
} lpv_alpha_mode;

/* Which uv set a texture reads and its KHR_texture_transform:
 * uv' = T(offset) R(rotation) S(scale) uv, with R(a) = [cos a, sin a; -sin a, cos a]
 * as the extension defines it. All zero = TEXCOORD_0 untransformed. */
typedef struct lpv_uv_transform {
    int texcoord;      /* 0 = TEXCOORD_0, 1 = TEXCOORD_1 */
    int has_transform; /* 0: offset, rotation and scale are ignored (identity) */
    float offset[2];
    float rotation; /* rad */
    float scale[2];
} lpv_uv_transform;

typedef struct lpv_material {
    char name[LPV_NAME_MAX];
    float base_color[4];    /* linear RGBA factor */
    int base_color_texture; /* index into textures, -1 = none */
    float emission[3];      /* radiance, W/(m^2 sr) (factor x strength / 683) */
    float metallic;
    float roughness;
    int double_sided;       /* 0: the camera culls back faces (light views never do; docs/scenes.md) */
    int alpha_mode;         /* lpv_alpha_mode */
    float alpha_cutoff;     /* MASK only: alpha below it is cut away (glTF default 0.5) */
    lpv_uv_transform base_color_uv;
    int normal_texture;     /* index into textures, -1 = none; must be a linear texture to be used */
    float normal_scale;     /* glTF normalTexture.scale: tangent-space x, y multiplied by it */
    lpv_uv_transform normal_uv;
    int metallic_roughness_texture; /* index into textures, -1 = none; linear: G x roughness, B x metallic */
    lpv_uv_transform metallic_roughness_uv;
    int emissive_texture;   /* index into textures, -1 = none; sRGB colour x emission */
    lpv_uv_transform emissive_uv;
    int unlit;              /* KHR_materials_unlit: the frame shows the base colour as it is (1 = 1 nit); it
                               neither reflects nor emits light (core/material_sample.h) */
    int occlusion_texture;  /* index into textures, -1 = none; linear: R darkens the frame's indirect light */
    float occlusion_strength; /* glTF occlusionTexture.strength: 1 + strength x (R - 1) */
    lpv_uv_transform occlusion_uv;
} lpv_material;

/* A material at glTF's defaults: white, opaque, metallic 0, roughness 1,
 * single-sided, no emission, no texture (-1) and identity uv transforms.
 * Every builder starts from it, so that a field added here has its default
 * in one place. */
void lpv_material_init(lpv_material *m);

typedef struct lpv_vertex {
    float position[3]; /* world, m */
    float normal[3];   /* world, unit (zero if the file had a degenerate one) */
    float uv[2];       /* TEXCOORD_0 */
    float uv1[2];      /* TEXCOORD_1 (zero when absent) */
    float tangent[4];  /* world xyz unit and handedness w = +-1 (the file's TANGENT); all zero = none */
    float color[4];    /* COLOR_0, linear RGBA (alpha 1 for a VEC3); read only where the draw's vertex_color is 1 */
} lpv_vertex;

/* What a draw's indices are: triangles (3 each: every draw of
 * lpv_scene.draws), or a wire draw's points (1 each) or line segments (2
 * each, glTF's strips and loops unrolled): lpv_scene.wire_draws. */
typedef enum lpv_draw_mode { LPV_DRAW_TRIANGLES = 0, LPV_DRAW_POINTS, LPV_DRAW_LINES } lpv_draw_mode;

/* A run of primitives sharing one material. */
typedef struct lpv_draw {
    uint32_t first_index;
    uint32_t index_count;
    int material; /* index into materials */
    int vertex_color; /* 1: the vertices' color (COLOR_0) multiplies the base colour and its alpha (glTF) */
    int mode;         /* lpv_draw_mode */
} lpv_draw;

/* A participating medium (docs/scenes.md, "Media"): single scattering with an
 * isotropic phase function. The coefficients hold at density 1; the density is
 * 1 everywhere (homogeneous fog) unless a box is given: then it is the density
 * texture inside the box (1 when density is NULL) and 0 outside. */
/* Limits a medium must respect (loader and scene_build refuse anything else). */
#define LPV_MEDIUM_SIGMA_MAX 1000.0f  /* sigma_s, sigma_a: finite, 0 .. this, 1/m */
#define LPV_MEDIUM_DIMS_MAX 256       /* density texture cells per axis: 1 .. this */
#define LPV_MEDIUM_DENSITY_MAX 1.0e6f /* density values: finite, 0 .. this */

typedef struct lpv_medium {
    int present;          /* 0: no medium */
    float sigma_s[3];     /* scattering coefficient, 1/m, rgb */
    float sigma_a[3];     /* absorption coefficient, 1/m, rgb */
    int has_box;          /* 0: unbounded */
    float box_min[3], box_max[3];
    int dims[3];          /* density texture cells per axis; 0 = none */
    float *density;       /* dims product values >= 0, x fastest; owned by the scene */
} lpv_medium;

typedef struct lpv_scene {
    lpv_vertex *vertices;
    uint32_t vertex_count;
    uint32_t *indices;
    uint32_t index_count;
    lpv_draw *draws;
    uint32_t draw_count;
    /* glTF's points and lines (docs/scenes.md, "Points and lines"): their
     * vertices are in `vertices`, their indices apart; they have no area, so
     * only the camera's frame draws them (one pixel wide, in their colour),
     * and nothing that carries light (the triangles' draws) sees them */
    uint32_t *wire_indices;
    uint32_t wire_index_count;
    lpv_draw *wire_draws;
    uint32_t wire_draw_count;
    lpv_material *materials;
    uint32_t material_count;
    lpv_texture *textures;
    uint32_t texture_count;
    lpv_light *lights;
    uint32_t light_count;
    lpv_camera *cameras;
    uint32_t camera_count;
    float bounds_min[3], bounds_max[3]; /* of all vertices */
    lpv_medium medium;                  /* participating medium, if any */
    int default_light_added;            /* 1 when lpv_scene_add_defaults added a light (scene/scene_defaults.h) */
    int default_camera_added;           /* 1 when lpv_scene_add_defaults added a camera */
    char source[256];                   /* file path, or "built-in:cornell-box" */
} lpv_scene;

/* Frees everything the scene owns and zeroes it. Safe on a zeroed scene. */
void lpv_scene_free(lpv_scene *scene);

/* A deep copy of the scene's geometry: vertices, indices, draws, wire
 * draws and materials, the bounds and the source; no textures, lights,
 * cameras or medium. What the engine keeps to
 * re-sample the scene when a knob changes without the scene being sent again.
 * Returns 0, or -1 out of memory (dst then zeroed; free it with
 * lpv_scene_free either way). */
int lpv_scene_copy_geometry(lpv_scene *dst, const lpv_scene *src);

/* Recomputes bounds_min/max from the vertices. */
void lpv_scene_compute_bounds(lpv_scene *scene);

/* Bytes the scene's arrays take in memory: vertices, indices, draws,
 * materials, texture texels, lights, cameras and the medium's density. */
uint64_t lpv_scene_bytes(const lpv_scene *scene);

/* 0 when every vertex position is finite and within +-LPV_MAX_COORD and every
 * light's position, range and intensity x colour are within the limits
 * above; else -1 with a message naming the first value out of range (a
 * vertex or light by index, never data of the file beyond the number). */
int lpv_scene_check_ranges(const lpv_scene *scene, char *err, size_t err_size);

/* 0 when intensity x the largest colour channel is finite and at most
 * LPV_MAX_LIGHT_INTENSITY; else -1 with a message ("... = %g W/sr ..."). */
int lpv_light_check_intensity(const lpv_light *light, char *err, size_t err_size);

/* The alpha below which a MASK material's surface is cut away (its cutoff);
 * 0 (nothing cut at a threshold) for OPAQUE and BLEND, whose alpha is
 * coverage (lpv_alpha_covers in shaders/lpv_shared.h). */
float lpv_material_alpha_cutoff(const lpv_material *m);

/* The sides an emissive material emits from: 2 when double-sided (glTF's
 * doubleSided, as Blender, three.js and the Khronos viewer light it: the
 * back emits the same radiance), else 1 (the front). The emitters' samples
 * and VPLs and the reference count sides by it. */
int lpv_material_emitting_sides(const lpv_material *m);

/* A texture's uv transform as the 2x3 matrix (rows) applied to (u, v, 1):
 * u' = m[0] u + m[1] v + m[2], v' = m[3] u + m[4] v + m[5]. */
void lpv_uv_transform_matrix(const lpv_uv_transform *t, float m[6]);

/* Number of materials with non-zero emission that some draw uses. */
uint32_t lpv_scene_emissive_draw_count(const lpv_scene *scene);

/* Triangle at indices[first .. first+2]: its corners (v), area (m^2) and the
 * unit normal of its front side: the winding's normal, flipped to agree with
 * the file's (finite) vertex normals. Emission leaves through the front, for
 * the emissive VPLs and the reference alike. Returns 0 for an index out of
 * range, a non-finite corner or a degenerate triangle. */
int lpv_scene_triangle(const lpv_scene *scene, uint32_t first, const lpv_vertex *v[3], float front[3], double *area);


/* The built-in scene: the Cornell box (McGuire & Cardenas 2011 data, public
 * domain) with its emissive ceiling quad, a spot light under the ceiling and a
 * camera, in the same units as ../shared/scenes/cornell-box.glb after loading.
 * Returns 0, or -1 on allocation failure. */
int lpv_scene_builtin_cornell(lpv_scene *scene);

#endif /* LPV_SCENE_H */
