// fuzz_image.cpp - libFuzzer target for the image path of a scene load: the
// input is image 0 of a one-triangle .glb (in its BIN chunk, used as the base
// colour texture), loaded through lpv_gltf_load_at as the daemon does, so the
// header reading, the budgets, stb's decoder and the texture hand-over all
// see it. Budgets keep one input under 16 Mi texels.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

extern "C" {
#include "gltf_load.h"
}

namespace {

void put32(std::vector<uint8_t> &v, uint32_t x)
{
    for (int i = 0; i < 4; i++)
        v.push_back(uint8_t(x >> (8 * i)));
}

std::vector<uint8_t> glb_with_image(const uint8_t *img, size_t n)
{
    static const float tri[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1}; /* 3 positions, 3 uvs */
    std::vector<uint8_t> bin(reinterpret_cast<const uint8_t *>(tri), reinterpret_cast<const uint8_t *>(tri) + 60);
    bin.insert(bin.end(), img, img + n);
    while (bin.size() % 4)
        bin.push_back(0);
    char js[1024];
    snprintf(js, sizeof js,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24},"
             "{\"buffer\":0,\"byteOffset\":60,\"byteLength\":%zu}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
             "\"min\":[0,0,0],\"max\":[1,1,0]},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"}],"
             "\"images\":[{\"bufferView\":2,\"mimeType\":\"image/png\"}],\"textures\":[{\"source\":0}],"
             "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":0}]}],"
             "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],\"scene\":0}",
             bin.size(), n);
    std::string j(js);
    while (j.size() % 4)
        j += ' ';
    std::vector<uint8_t> out;
    out.insert(out.end(), {'g', 'l', 'T', 'F'});
    put32(out, 2);
    put32(out, uint32_t(12 + 8 + j.size() + 8 + bin.size()));
    put32(out, uint32_t(j.size()));
    put32(out, 0x4E4F534Au);
    out.insert(out.end(), j.begin(), j.end());
    put32(out, uint32_t(bin.size()));
    put32(out, 0x004E4942u);
    out.insert(out.end(), bin.begin(), bin.end());
    return out;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size == 0 || size > (size_t(1) << 24))
        return 0;
    std::vector<uint8_t> glb = glb_with_image(data, size);
    lpv_gltf_limits limits = {4096, uint64_t(16) << 20, uint64_t(256) << 20};
    lpv_gltf_warnings warnings;
    lpv_scene scene;
    char err[1024];
    if (lpv_gltf_load_at(glb.data(), glb.size(), -1, "fuzz", nullptr, 0, &limits, &scene, &warnings, err,
                         sizeof err) == LPV_GLTF_OK)
        lpv_scene_free(&scene);
    return 0;
}
