/*
 * gltf_compressed.hpp - compressed glTF geometry for the glTF adapter (C++ only,
 * inside the scene library): KHR_draco_mesh_compression through Google's
 * Draco library and EXT_meshopt_compression through meshoptimizer, both the
 * Debian packages (docs/scenes.md, "Compressed meshes"). Every problem comes
 * back as a message naming the extension; the caller refuses the file.
 */
#ifndef LPV_GLTF_COMPRESSED_HPP
#define LPV_GLTF_COMPRESSED_HPP

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <tiny_gltf.h>

namespace lpv_gltf {

/* A decoded Draco primitive: points, triangle indices into them, and the
 * glTF attributes asked for, as floats (components per point as asked). */
struct DracoMesh {
    size_t points = 0;
    std::vector<uint32_t> indices;
    std::map<std::string, std::vector<float>> attributes;
};

/* Decodes the Draco bitstream data[0 .. len) into out. ids maps each glTF
 * attribute name to its Draco unique id (the extension's "attributes"),
 * components the number of floats wanted per point for each. Returns "" or
 * the problem ("KHR_draco_mesh_compression: ..."). */
std::string draco_decode(const unsigned char *data, size_t len, const std::map<std::string, int> &ids,
                         const std::map<std::string, int> &components, size_t max_points, DracoMesh *out);

/* What tinygltf 2.7 (built without Draco) refuses in compressed files:
 * EXT_meshopt_compression's "fallback" buffers without data, and the
 * KHR_draco_mesh_compression primitives' "indices" accessors without a
 * bufferView. When the JSON text has either, *out gets the text with each
 * fallback buffer given a 4-byte placeholder (a data: URI, never read: the
 * compressed views are decoded instead) and the Draco primitives' "indices"
 * dropped (the bitstream holds them), and true is returned; false leaves *out
 * untouched. A JSON problem returns false (the caller's parse reports it). */
bool tinygltf_compat_json(const char *json, size_t len, std::string *out);

/* Decodes bufferView bv's EXT_meshopt_compression (ATTRIBUTES, TRIANGLES or
 * INDICES, with the NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL filter) into
 * *out: count x byteStride bytes, byteStride in *stride. Returns "" or the
 * problem. max_bytes bounds the decoded size. */
std::string meshopt_decode(const tinygltf::Model &m, int bv, size_t max_bytes, std::vector<unsigned char> *out,
                           size_t *stride);

} // namespace lpv_gltf

#endif
