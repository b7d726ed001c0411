/*
 * gltf_material.hpp - the parts of a glTF material lpvd reads beyond colour,
 * for gltf_load.cpp (C++ only, inside the scene library): alpha mode and
 * cutoff, and a texture reference's uv set and KHR_texture_transform
 * (docs/scenes.md, "Materials"). Problems come back as a message naming the
 * field; the caller refuses the file with it.
 */
#ifndef LPV_GLTF_MATERIAL_HPP
#define LPV_GLTF_MATERIAL_HPP

#include <string>

#include <tiny_gltf.h>

extern "C" {
#include "scene.h"
}

namespace lpv_gltf {

/* alphaMode ("OPAQUE", "MASK", "BLEND") and alphaCutoff (finite, >= 0) into
 * mat. Returns "" or the problem ("alphaMode \"X\" is not ..."). */
std::string read_alpha(const tinygltf::Material &gm, lpv_material *mat);

/* A texture reference's uv set and transform: texCoord, then
 * KHR_texture_transform's offset, rotation, scale and texCoord override.
 * Returns "" or the problem, naming the field (e.g. "KHR_texture_transform.scale
 * must hold 2 finite numbers"). */
std::string read_uv_transform(int tex_coord, const tinygltf::ExtensionMap &ext, lpv_uv_transform *out);

} // namespace lpv_gltf

#endif
