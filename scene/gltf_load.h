/*
 * gltf_load.h - glTF 2.0 (.gltf and .glb) into an lpv_scene, through tinygltf.
 *
 * Supported: triangle meshes (indexed or not, every accessor component type
 * the spec allows, normalized integers, sparse accessors), the node
 * hierarchy's transforms (matrix or TRS), base colour factor and texture,
 * emissive factor with KHR_materials_emissive_strength, metallic/roughness,
 * KHR_lights_punctual (directional, point, spot with cone angles and range),
 * cameras, and lpvd's participating medium from the loaded scene's extras
 * (scenes[scene].extras.lpvd_medium, else the document's extras.lpvd_medium;
 * docs/scenes.md, "Media"), every field checked and named when refused. Photometric values are converted to radiometric ones with
 * LPV_LUMENS_PER_WATT (docs/units.md).
 *
 * Refused with a message naming the file and the problem, never a crash:
 * truncated or mis-sized .glb, wrong magic, invalid JSON, accessors or
 * buffer views out of range, indices past the vertex count, NaN or infinite
 * positions, missing buffers, and external URIs that leave the scene's folder
 * (refused before anything is read).
 */
#ifndef LPV_GLTF_LOAD_H
#define LPV_GLTF_LOAD_H

#include <stddef.h>
#include "scene.h"

#ifdef __cplusplus
extern "C" {
#endif

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

#ifdef __cplusplus
}
#endif

#endif /* LPV_GLTF_LOAD_H */
