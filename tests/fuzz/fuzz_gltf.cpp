// fuzz_gltf.cpp - libFuzzer target for the glTF loader: bytes (a .glb or a
// JSON .gltf) into the scene model through the daemon's own entry,
// lpv_gltf_load_at, with external URIs refused (no folder) and budgets small
// enough that a fuzzer's input can never decode more than 64 MiB of texels.
// A file that loads is loaded again posed at a time its last byte picks
// (lpv_gltf_load_at_posed: animations, skins and morph weights sampled;
// SCENE_UPDATE "animation" takes that path). Any crash, leak, ASan or UBSan
// report is a finding; refusals are not.
#include <cstddef>
#include <cstdint>

extern "C" {
#include "gltf_load.h"
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    lpv_gltf_limits limits = {4096, uint64_t(16) << 20, uint64_t(256) << 20};
    lpv_gltf_warnings warnings;
    lpv_scene scene;
    char err[1024];
    if (lpv_gltf_load_at(data, size, -1, "fuzz", nullptr, 0, &limits, &scene, &warnings, err, sizeof err) !=
        LPV_GLTF_OK)
        return 0;
    lpv_scene_free(&scene);
    const lpv_gltf_animation_time at = {nullptr, size ? data[size - 1] / 16.0 : 0.0};
    if (lpv_gltf_load_at_posed(data, size, -1, "fuzz", &at, nullptr, 0, &limits, &scene, &warnings, err, sizeof err) ==
        LPV_GLTF_OK)
        lpv_scene_free(&scene);
    return 0;
}
