/*
 * gltf_load.h - glTF 2.0 (.gltf and .glb) into an lpv_scene, through tinygltf.
 *
 * Supported: triangle meshes (indexed or not, every accessor component type
 * the spec allows, normalized integers, sparse accessors), the node
 * hierarchy's transforms (matrix or TRS), base colour factor and texture,
 * emissive factor with KHR_materials_emissive_strength, metallic/roughness,
 * alphaMode and alphaCutoff, doubleSided, normal maps (with the file's
 * TANGENTs, else per-pixel frames), KHR_texture_transform and TEXCOORD_1,
 * KHR_draco_mesh_compression (libdraco) and EXT_meshopt_compression
 * (libmeshoptimizer) (docs/scenes.md, "Materials", "Compressed meshes"),
 * KHR_lights_punctual (directional, point, spot with cone angles and range),
 * cameras, node translation / rotation / scale animations sampled at a
 * given time (lpv_gltf_load_file_animated, below), and lpvd's participating
 * medium from the loaded scene's extras (scenes[scene].extras.lpvd_medium,
 * else the document's extras.lpvd_medium; docs/scenes.md, "Media"), every
 * field checked and named when refused. Photometric values are converted to
 * radiometric ones with LPV_LUMENS_PER_WATT (docs/units.md).
 *
 * Refused with a message naming the file and the problem, never a crash:
 * truncated or mis-sized .glb, wrong magic, invalid JSON, accessors or
 * buffer views out of range, indices past the vertex count, NaN or infinite
 * positions, missing buffers, images that cannot be decoded, external URIs
 * that leave the scene's folder (absolute, "..", or through any symbolic
 * link: refused by the same step that opens them, core/open_beneath.h), and
 * extensionsRequired that lpvd does not implement (named). Messages never
 * quote the file's bytes: only indices, sizes, URIs and identifier names.
 *
 * Everything else in the file that lpvd does not use (extensions it does not
 * implement, vertex colours beyond COLOR_0, animations unless played
 * (below), ...) is a
 * warning, one line per feature
 * (docs/scenes.md, "Supported and warned"): printed on stderr as
 * "lpvd: <file>: warning: <line>", or handed to the caller through the _w
 * functions below.
 */
#ifndef LPV_GLTF_LOAD_H
#define LPV_GLTF_LOAD_H

#include <stddef.h>
#include "scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The loader's warnings, for callers that report them themselves (the
 * daemon's SCENE_LOAD reply). Each line is one feature, at most once. */
#define LPV_GLTF_WARNINGS_MAX 32
#define LPV_GLTF_WARNING_LEN 320
typedef struct lpv_gltf_warnings {
    int count;   /* lines in line[] */
    int dropped; /* further warnings that did not fit */
    char line[LPV_GLTF_WARNINGS_MAX][LPV_GLTF_WARNING_LEN]; /* without the "<file>: warning: " prefix */
} lpv_gltf_warnings;

/* Loads a .gltf or .glb file (chosen by content: glb magic, else JSON).
 * External resources must lie inside the file's folder. Returns 0, or -1 with
 * "<path>: <problem>" in err; out is left zeroed on failure. */
int lpv_gltf_load_file(const char *path, lpv_scene *out, char *err, size_t err_size);

/* Loads glb bytes from memory. External URIs are refused unless base_dir is
 * given, and then must lie inside it. label names the data in messages. */
int lpv_gltf_load_memory(const void *data, size_t size, const char *base_dir, const char *label,
                         lpv_scene *out, char *err, size_t err_size);

/* A node transform that replaces the file's (for the daemon's SCENE_UPDATE):
 * either a column-major matrix, or any of translation / rotation (unit
 * quaternion x y z w) / scale replacing those of the node's TRS. */
typedef struct lpv_gltf_node_override {
    int node;
    int has_matrix, has_translation, has_rotation, has_scale;
    float matrix[16];
    float translation[3];
    float rotation[4];
    float scale[3];
} lpv_gltf_node_override;

/* lpv_gltf_load_memory with node transforms replaced before the scene is
 * flattened; applied in order (a later override of the same node wins for
 * the parts it gives). A node index out of range is refused like any other
 * defect. */
int lpv_gltf_load_memory_ex(const void *data, size_t size, const char *base_dir, const char *label,
                            const lpv_gltf_node_override *nodes, size_t node_count, lpv_scene *out, char *err,
                            size_t err_size);

/* ---- animations (docs/scenes.md, "Animations") -----------------------------
 * Node translation / rotation / scale / weights channels of the file's animations,
 * sampled at a time (LINEAR, with rotations slerped along the shortest path;
 * STEP; CUBICSPLINE), become node overrides (above) before the scene is
 * flattened, so meshes, cameras and lights below an animated node move with
 * it. Times before an animation's first keyframe take the first value, after
 * its last the last. Skins and morph targets deform the meshes at that pose
 * (docs/scenes.md, "Animations"); KHR_animation_pointer is not supported:
 * warned, ignored. Defects (an unknown animation, a
 * negative or non-finite time, sampler times not finite or not increasing,
 * an output count that does not fit the interpolation, a target node out of
 * range or given as a matrix, an accessor of the wrong type) refuse the
 * file with "<path>: animation 2 ("Walk"): <problem>". */

/* Which animation, and when. */
typedef struct lpv_gltf_animation_time {
    /* The animation's name, else its index as a decimal string (a name is
     * looked up first); NULL or "" plays every animation of the file at
     * once (a later animation wins where two animate the same property). */
    const char *animation;
    double time; /* seconds from the animation's start, finite, >= 0 */
} lpv_gltf_animation_time;

/* lpv_gltf_load_file with the nodes posed by *at; at NULL loads the file's
 * static pose exactly like lpv_gltf_load_file. A file without animations is
 * refused when at is given. */
int lpv_gltf_load_file_animated(const char *path, const lpv_gltf_animation_time *at, lpv_scene *out, char *err,
                                size_t err_size);
/* lpv_gltf_load_file_animated_w for the invoking user's own file (lpvd
 * render, lpvd-reference, the benchmarks): its external URIs may be absolute
 * paths or leave the file's folder (through ".." or a symbolic link), and
 * open as the user opens any file; a project's images in ../textures load.
 * The daemon (lpv_gltf_load_at) and batch jobs (lpv_gltf_load_file) keep
 * every URI beneath the scene's folder: their files come from others
 * (docs/scenes.md, "Where external files may lie"). at and warnings may be
 * NULL. */
int lpv_gltf_load_file_user(const char *path, const lpv_gltf_animation_time *at, lpv_scene *out,
                            lpv_gltf_warnings *warnings, char *err, size_t err_size);
/* The same with the warnings stored in *warnings, like lpv_gltf_load_file_w. */
int lpv_gltf_load_file_animated_w(const char *path, const lpv_gltf_animation_time *at, lpv_scene *out,
                                  lpv_gltf_warnings *warnings, char *err, size_t err_size);

#define LPV_GLTF_ANIMATIONS_MAX 64
#define LPV_GLTF_ANIMATION_NAME_LEN 64
typedef struct lpv_gltf_animation_info {
    char name[LPV_GLTF_ANIMATION_NAME_LEN]; /* the file's name, cut to fit (whole UTF-8 characters); "" if none */
    double duration;                        /* seconds: the largest input time of its samplers */
    int channels;                           /* node translation / rotation / scale channels it plays */
} lpv_gltf_animation_info;

typedef struct lpv_gltf_animation_list {
    int count; /* the file's animations, possibly more than LPV_GLTF_ANIMATIONS_MAX */
    lpv_gltf_animation_info animation[LPV_GLTF_ANIMATIONS_MAX]; /* the first min(count, MAX), by index */
} lpv_gltf_animation_list;

/* The animations of a .gltf or .glb file, each checked as if it were played
 * (a defect in any refuses the call like a load would). Images are not
 * decoded and no scene is built; no warnings are printed. Returns 0, or -1
 * with "<path>: <problem>" in err and *out zeroed. */
int lpv_gltf_animations(const char *path, lpv_gltf_animation_list *out, char *err, size_t err_size);

/* What one load may take (the daemon's per-scene budgets). A 0 field means
 * the loader's own absurd-size cap. Sizes come from the images' headers
 * before anything is decoded. */
typedef struct lpv_gltf_limits {
    int max_texture;     /* texels per image side */
    uint64_t max_texels; /* decoded texels of all images together */
    uint64_t max_bytes;  /* RAM: the file, its external files, RGBA8 texels and the scene model */
} lpv_gltf_limits;

/* lpv_gltf_load_at's results: a defect, or the limit that refused the file
 * (its message names the limit's value and what the file would need). */
enum {
    LPV_GLTF_OK = 0,
    LPV_GLTF_DEFECT = -1,
    LPV_GLTF_OVER_TEXTURE = -2, /* lpv_gltf_limits.max_texture */
    LPV_GLTF_OVER_TEXELS = -3,  /* max_texels */
    LPV_GLTF_OVER_BYTES = -4    /* max_bytes */
};

/* The daemon's entry: glb or glTF bytes whose external URIs open beneath the
 * folder descriptor base_fd (-1: external URIs refused; the descriptor is only
 * used during the call), within limits (NULL: the caps). Returns LPV_GLTF_OK
 * or one of the codes above with "<label>: <problem>" in err. */
int lpv_gltf_load_at(const void *data, size_t size, int base_fd, const char *label,
                     const lpv_gltf_node_override *nodes, size_t node_count, const lpv_gltf_limits *limits,
                     lpv_scene *out, lpv_gltf_warnings *warnings, char *err, size_t err_size);

/* lpv_gltf_load_at with the nodes posed by *at first (its animations at a
 * time, skins and morph targets with them; lpv_gltf_load_file_animated),
 * then the node overrides; at NULL is lpv_gltf_load_at. The daemon's
 * SCENE_UPDATE "animation" (SPEC R4.4c). */
int lpv_gltf_load_at_posed(const void *data, size_t size, int base_fd, const char *label,
                           const lpv_gltf_animation_time *at, const lpv_gltf_node_override *nodes, size_t node_count,
                           const lpv_gltf_limits *limits, lpv_scene *out, lpv_gltf_warnings *warnings, char *err,
                           size_t err_size);

/* The loaders above with the warnings stored in *warnings (zeroed first)
 * instead of printed on stderr; warnings NULL prints them as above. */
int lpv_gltf_load_file_w(const char *path, lpv_scene *out, lpv_gltf_warnings *warnings, char *err,
                         size_t err_size);
int lpv_gltf_load_memory_w(const void *data, size_t size, const char *base_dir, const char *label,
                           const lpv_gltf_node_override *nodes, size_t node_count, lpv_scene *out,
                           lpv_gltf_warnings *warnings, char *err, size_t err_size);

#ifdef __cplusplus
}
#endif

#endif /* LPV_GLTF_LOAD_H */
