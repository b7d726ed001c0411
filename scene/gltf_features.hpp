/*
 * gltf_features.hpp - what of a glTF file lpvd uses and what it does not, for
 * gltf_build.cpp (C++ only, inside the scene library; docs/scenes.md,
 * "Supported and warned").
 */
#ifndef LPV_GLTF_FEATURES_HPP
#define LPV_GLTF_FEATURES_HPP

#include <string>
#include <vector>

#include <tiny_gltf.h>

namespace lpv_gltf {

/* Whether lpvd implements the extension (so a file may require it). */
bool extension_supported(const std::string &name);

/* One line per feature of the file that lpvd does not use (an extension it
 * does not implement, occlusion/emissive/metallic-roughness textures, vertex
 * colours and other attributes, skins, morph targets, animations not played
 * and the channels of played ones that animate morph-target weights, points
 * and lines, texture wrap modes, uv sets past TEXCOORD_1, scenes other than
 * the loaded one), each naming the feature, where it is used and what lpvd
 * does instead. scene is the scene that is loaded (-1: none); played the
 * animations whose pose was applied (gltf_animation.cpp). */
std::vector<std::string> unused_features(const tinygltf::Model &m, int scene, const std::vector<int> &played);

} // namespace lpv_gltf

#endif
