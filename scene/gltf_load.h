/*
 * gltf_load.h - glTF 2.0 (.gltf and .glb) into an lpv_scene, through tinygltf.
 *
 * Supported: triangle meshes (indexed or not, every accessor component type
 * the spec allows, normalized integers, sparse accessors), the node
 * hierarchy's transforms (matrix or TRS), base colour factor and texture,
 * emissive factor with KHR_materials_emissive_strength, metallic/roughness,
 * KHR_lights_punctual (directional, point, spot with cone angles and range)
 * and cameras. Photometric values are converted to radiometric ones with
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

#ifdef __cplusplus
}
#endif

#endif /* LPV_GLTF_LOAD_H */
