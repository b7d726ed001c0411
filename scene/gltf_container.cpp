/*
 * gltf_container.cpp - the file's outer layers, checked before tinygltf sees
 * them (gltf_internal.hpp): size and format, the whole .glb container
 * (tinygltf 2.7's own chunk checks are off by the 8-byte chunk header), and a
 * SAX pre-scan of the JSON for syntax and nesting depth (no DOM), so that
 * tinygltf's recursive extras/extensions parser never sees a hostile depth.
 * Also the one rewrite of the JSON that compressed files need for tinygltf.
 */
#include "gltf_internal.hpp"
#include "gltf_compressed.hpp"

#include <cstring>

namespace lpv_gltf {

namespace {

/* ---- GLB container ------------------------------------------------------ */
uint32_t le32(const unsigned char *p)
{
    return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

constexpr uint32_t kGlbMagic = 0x46546C67u; /* "glTF" */
constexpr uint32_t kChunkJson = 0x4E4F534Au;
constexpr uint32_t kChunkBin = 0x004E4942u;

/* Validates the whole container; returns the JSON chunk's place. */
void check_glb(const unsigned char *d, size_t size, size_t *json_off, size_t *json_len)
{
    if (size < 12)
        fail("truncated .glb: %zu bytes, shorter than the 12-byte header", size);
    uint32_t version = le32(d + 4), length = le32(d + 8);
    if (version != 2)
        fail("unsupported .glb container version %u (expected 2)", version);
    if (length > size)
        fail("truncated .glb: the header says %u bytes but there are only %zu (header length larger than the file)",
             length, size);
    if (length < size)
        fail("the .glb header length %u is smaller than the file (%zu bytes): length mismatch", length, size);
    if (size < 20)
        fail("truncated .glb: no room for the JSON chunk header (%zu bytes)", size);
    uint32_t len0 = le32(d + 12), type0 = le32(d + 16);
    if (type0 != kChunkJson)
        fail("the first .glb chunk is not JSON (type 0x%08x)", type0);
    if (uint64_t(len0) > uint64_t(length) - 20)
        fail("the JSON chunk length %u runs past the end of the .glb (%u bytes): out of range (truncated?)", len0,
             length);
    if (len0 == 0)
        fail("empty JSON chunk in the .glb");
    uint64_t off = 20 + uint64_t(len0);
    if (off < length) {
        if (off + 8 > length)
            fail("truncated .glb: incomplete BIN chunk header at byte %llu", (unsigned long long)off);
        uint32_t len1 = le32(d + off), type1 = le32(d + off + 4);
        if (type1 != kChunkBin)
            fail("the second .glb chunk is not BIN (type 0x%08x)", type1);
        if (uint64_t(len1) > uint64_t(length) - off - 8)
            fail("the BIN chunk length %u runs past the end of the .glb: out of range (truncated?)", len1);
        if (len1 < 4 || len1 % 4 != 0)
            fail("the BIN chunk length %u is not a positive multiple of 4", len1);
    }
    *json_off = 20;
    *json_len = len0;
}

} // namespace

bool check_container(const unsigned char *data, size_t size, size_t *json_off, size_t *json_len)
{
    if (size == 0)
        fail("the file is empty (0 bytes; truncated?)");
    if (uint64_t(size) > kMaxFileBytes)
        fail("%zu bytes is over the %llu-byte limit (absurd size)", size, (unsigned long long)kMaxFileBytes);

    /* glb by its magic, JSON by its first character, anything else refused. */
    size_t skip = 0;
    if (size >= 3 && data[0] == 0xEF && data[1] == 0xBB && data[2] == 0xBF)
        skip = 3; /* UTF-8 byte order mark */
    while (skip < size && (data[skip] == ' ' || data[skip] == '\t' || data[skip] == '\n' || data[skip] == '\r'))
        skip++;
    bool is_glb = size >= 4 && le32(data) == kGlbMagic;
    bool is_json = !is_glb && skip < size && data[skip] == '{';
    if (!is_glb && !is_json) {
        if (size < 4 && memcmp(data, "glTF", size) == 0)
            fail("truncated .glb: %zu bytes, shorter than the 12-byte header", size);
        fail("wrong magic: neither a .glb (a 'glTF' header) nor a JSON .gltf (a '{' first)");
    }

    *json_off = 0;
    *json_len = size;
    if (is_glb)
        check_glb(data, size, json_off, json_len);
    return is_glb;
}

bool tinygltf_compat_file(const unsigned char *data, size_t size, bool is_glb, size_t json_off, size_t json_len,
                          std::vector<unsigned char> *rewritten)
{
    const char *const json_text = reinterpret_cast<const char *>(data) + json_off; /* the file's own JSON */
    static const char meshopt_key[] = "EXT_meshopt_compression", draco_key[] = "KHR_draco_mesh_compression";
    std::string json2;
    if (!((memmem(json_text, json_len, meshopt_key, sizeof meshopt_key - 1) ||
           memmem(json_text, json_len, draco_key, sizeof draco_key - 1)) &&
          tinygltf_compat_json(json_text, json_len, &json2)))
        return false;
    if (is_glb) {
        size_t jpad = (json2.size() + 3) & ~size_t(3);
        size_t rest = size - (json_off + json_len); /* the BIN chunk, if any */
        rewritten->assign(20 + jpad + rest, ' ');
        memcpy(rewritten->data(), data, 12);
        auto put32 = [&](size_t at, uint32_t v) {
            for (int k = 0; k < 4; k++)
                (*rewritten)[at + size_t(k)] = (unsigned char)(v >> (8 * k));
        };
        put32(8, uint32_t(rewritten->size()));
        put32(12, uint32_t(jpad));
        memcpy(rewritten->data() + 16, data + 16, 4);
        memcpy(rewritten->data() + 20, json2.data(), json2.size());
        if (rest)
            memcpy(rewritten->data() + 20 + jpad, data + json_off + json_len, rest);
    } else {
        rewritten->assign(json2.begin(), json2.end());
    }
    return true;
}

} // namespace lpv_gltf
