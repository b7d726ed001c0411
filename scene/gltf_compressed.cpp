/*
 * gltf_compressed.cpp - KHR_draco_mesh_compression (libdraco) and
 * EXT_meshopt_compression (libmeshoptimizer) for the glTF loader
 * (gltf_compressed.hpp).
 */
#include "gltf_compressed.hpp"

#include <cmath>
#include <cstring>

#include <draco/compression/decode.h>
#include <draco/core/decoder_buffer.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

namespace lpv_gltf {

std::string draco_decode(const unsigned char *data, size_t len, const std::map<std::string, int> &ids,
                         const std::map<std::string, int> &components, size_t max_points, DracoMesh *out)
{
    const std::string ext = "KHR_draco_mesh_compression: ";
    *out = DracoMesh{};
    draco::DecoderBuffer buffer;
    buffer.Init(reinterpret_cast<const char *>(data), len);
    draco::Decoder decoder;
    auto type = draco::Decoder::GetEncodedGeometryType(&buffer);
    if (!type.ok())
        return ext + "not a Draco bitstream (" + type.status().error_msg_string() + ")";
    if (type.value() != draco::TRIANGULAR_MESH)
        return ext + "the bitstream holds a point cloud, not a triangle mesh";
    auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
    if (!decoded.ok())
        return ext + "decoding failed (" + decoded.status().error_msg_string() + ")";
    const draco::Mesh &mesh = *decoded.value();
    const size_t np = mesh.num_points();
    if (np > max_points)
        return ext + std::to_string(np) + " points, over the limit of " + std::to_string(max_points) +
               " (absurd size)";
    out->points = np;
    out->indices.reserve(size_t(mesh.num_faces()) * 3);
    for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f) {
        const draco::Mesh::Face &face = mesh.face(f);
        for (int k = 0; k < 3; k++) {
            uint32_t v = face[k].value();
            if (v >= np)
                return ext + "face " + std::to_string(f.value()) + " refers to point " + std::to_string(v) +
                       ", out of range (" + std::to_string(np) + " points)";
            out->indices.push_back(v);
        }
    }
    for (const auto &kv : ids) {
        auto c = components.find(kv.first);
        if (c == components.end())
            continue; /* an attribute lpvd does not read */
        const int n = c->second;
        if (kv.second < 0)
            return ext + "attribute " + kv.first + " has a negative Draco id";
        const draco::PointAttribute *a = mesh.GetAttributeByUniqueId(uint32_t(kv.second));
        if (!a)
            return ext + "attribute " + kv.first + ": Draco id " + std::to_string(kv.second) +
                   " is not in the bitstream";
        if (a->num_components() < 1 || a->num_components() > 4)
            return ext + "attribute " + kv.first + " has " + std::to_string(int(a->num_components())) +
                   " components";
        std::vector<float> &v = out->attributes[kv.first];
        v.assign(np * size_t(n), 0.0f);
        float tmp[4];
        for (draco::PointIndex p(0); p < np; ++p) {
            const draco::AttributeValueIndex ai = a->mapped_index(p);
            if (ai.value() >= a->size() || !a->ConvertValue<float>(ai, a->num_components(), tmp))
                return ext + "attribute " + kv.first + ": point " + std::to_string(p.value()) +
                       " has no value";
            for (int k = 0; k < n && k < a->num_components(); k++)
                v[size_t(p.value()) * size_t(n) + size_t(k)] = tmp[k];
            if (kv.first == "COLOR_0" && a->num_components() == 3 && n == 4)
                v[size_t(p.value()) * 4 + 3] = 1.0f; /* an RGB colour is opaque */
        }
    }
    return "";
}

bool tinygltf_compat_json(const char *json, size_t len, std::string *out)
{
    using Json = nlohmann::json;
    Json doc = Json::parse(json, json + len, nullptr, false);
    if (doc.is_discarded() || !doc.is_object())
        return false;
    bool changed = false;
    auto buffers = doc.find("buffers");
    if (buffers != doc.end() && buffers->is_array())
        for (Json &b : *buffers) {
            if (!b.is_object() || b.contains("uri"))
                continue;
            auto e = b.find("extensions");
            if (e == b.end() || !e->is_object())
                continue;
            auto mo = e->find("EXT_meshopt_compression");
            if (mo == e->end() || !mo->is_object())
                continue;
            auto fb = mo->find("fallback");
            if (fb == mo->end() || !fb->is_boolean() || !fb->get<bool>())
                continue;
            b["uri"] = "data:application/octet-stream;base64,AAAAAA==";
            b["byteLength"] = 4;
            changed = true;
        }
    auto meshes = doc.find("meshes");
    if (meshes != doc.end() && meshes->is_array())
        for (Json &m : *meshes) {
            auto prims = m.is_object() ? m.find("primitives") : m.end();
            if (!m.is_object() || prims == m.end() || !prims->is_array())
                continue;
            for (Json &p : *prims) {
                auto e = p.is_object() ? p.find("extensions") : p.end();
                if (!p.is_object() || e == p.end() || !e->is_object() || !e->contains("KHR_draco_mesh_compression") ||
                    !p.contains("indices"))
                    continue;
                p.erase("indices");
                changed = true;
            }
        }
    if (!changed)
        return false;
    *out = doc.dump();
    return true;
}

namespace {

bool get_size(const tinygltf::Value &o, const char *key, bool required, size_t *out)
{
    if (!o.Has(key))
        return !required;
    const tinygltf::Value &v = o.Get(key);
    if (!v.IsNumber())
        return false;
    double d = v.GetNumberAsDouble();
    if (!(d >= 0.0 && d <= 9007199254740992.0) || d != std::floor(d))
        return false;
    *out = size_t(d);
    return true;
}

std::string get_string(const tinygltf::Value &o, const char *key, const char *fallback)
{
    if (!o.Has(key))
        return fallback;
    const tinygltf::Value &v = o.Get(key);
    return v.IsString() ? v.Get<std::string>() : std::string();
}

} // namespace

std::string meshopt_decode(const tinygltf::Model &m, int bv, size_t max_bytes, std::vector<unsigned char> *out,
                           size_t *stride)
{
    const std::string ext = "bufferView " + std::to_string(bv) + ": EXT_meshopt_compression: ";
    const tinygltf::BufferView &view = m.bufferViews[size_t(bv)];
    auto it = view.extensions.find("EXT_meshopt_compression");
    if (it == view.extensions.end())
        return ext + "missing";
    const tinygltf::Value &e = it->second;
    if (!e.IsObject())
        return ext + "must be an object";
    size_t buffer = 0, offset = 0, length = 0, bstride = 0, count = 0;
    if (!get_size(e, "buffer", true, &buffer) || !get_size(e, "byteOffset", false, &offset) ||
        !get_size(e, "byteLength", true, &length) || !get_size(e, "byteStride", true, &bstride) ||
        !get_size(e, "count", true, &count))
        return ext + "buffer, byteLength, byteStride and count must be integers >= 0 (byteOffset too, if given)";
    const std::string mode = get_string(e, "mode", "");
    const std::string filter = get_string(e, "filter", "NONE");
    if (buffer >= m.buffers.size())
        return ext + "buffer " + std::to_string(buffer) + " does not exist (out of range)";
    const std::vector<unsigned char> &src = m.buffers[buffer].data;
    if (offset > src.size() || length > src.size() - offset)
        return ext + "the compressed range (offset " + std::to_string(offset) + ", length " +
               std::to_string(length) + ") is out of range of buffer " + std::to_string(buffer) + " (" +
               std::to_string(src.size()) + " bytes)";
    if (count == 0 || bstride == 0)
        return ext + "count and byteStride must be positive";
    if (count > max_bytes / bstride)
        return ext + "count x byteStride is over the limit of " + std::to_string(max_bytes) + " bytes (absurd size)";
    out->assign(count * bstride, 0);
    const unsigned char *p = src.data() + offset;
    int rc;
    if (mode == "ATTRIBUTES") {
        if (bstride % 4 != 0 || bstride > 256)
            return ext + "ATTRIBUTES need a byteStride that is a multiple of 4, at most 256";
        rc = meshopt_decodeVertexBuffer(out->data(), count, bstride, p, length);
    } else if (mode == "TRIANGLES") {
        if ((bstride != 2 && bstride != 4) || count % 3 != 0)
            return ext + "TRIANGLES need a byteStride of 2 or 4 and a count divisible by 3";
        rc = meshopt_decodeIndexBuffer(out->data(), count, bstride, p, length);
    } else if (mode == "INDICES") {
        if (bstride != 2 && bstride != 4)
            return ext + "INDICES need a byteStride of 2 or 4";
        rc = meshopt_decodeIndexSequence(out->data(), count, bstride, p, length);
    } else {
        return ext + "mode \"" + mode.substr(0, 20) + "\" is not ATTRIBUTES, TRIANGLES or INDICES";
    }
    if (rc != 0)
        return ext + mode + " data could not be decoded (meshoptimizer error " + std::to_string(rc) +
               "; corrupt or a newer encoding)";
    if (filter == "OCTAHEDRAL") {
        if (mode != "ATTRIBUTES" || (bstride != 4 && bstride != 8))
            return ext + "the OCTAHEDRAL filter needs ATTRIBUTES with a byteStride of 4 or 8";
        meshopt_decodeFilterOct(out->data(), count, bstride);
    } else if (filter == "QUATERNION") {
        if (mode != "ATTRIBUTES" || bstride != 8)
            return ext + "the QUATERNION filter needs ATTRIBUTES with a byteStride of 8";
        meshopt_decodeFilterQuat(out->data(), count, bstride);
    } else if (filter == "EXPONENTIAL") {
        if (mode != "ATTRIBUTES" || bstride % 4 != 0)
            return ext + "the EXPONENTIAL filter needs ATTRIBUTES with a byteStride that is a multiple of 4";
        meshopt_decodeFilterExp(out->data(), count, bstride);
    } else if (filter != "NONE") {
        return ext + "filter \"" + filter.substr(0, 20) + "\" is not NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL";
    }
    *stride = bstride;
    return "";
}

} // namespace lpv_gltf
