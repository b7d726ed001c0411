/*
 * gltf_features.cpp - the file's features lpvd does not use, one line each
 * (gltf_features.hpp).
 */
#include "gltf_features.hpp"

#include <map>
#include <set>

namespace lpv_gltf {

namespace {

/* Implemented by lpvd (docs/scenes.md). */
const char *const kSupported[] = {
    "KHR_lights_punctual",        "KHR_materials_emissive_strength", "KHR_mesh_quantization",
    "KHR_texture_transform",      "KHR_draco_mesh_compression",      "EXT_meshopt_compression",
    "KHR_materials_unlit",
};

/* Places a feature is used: "materials 0, 2, 5 and 3 more". */
struct Uses {
    std::map<std::string, std::vector<int>> by_kind; /* "material" -> indices */
    size_t total = 0;

    void add(const char *kind, int index)
    {
        std::vector<int> &v = by_kind[kind];
        if (v.empty() || v.back() != index)
            v.push_back(index), total++;
    }

    std::string describe() const
    {
        std::string s;
        for (const auto &k : by_kind) {
            if (!s.empty())
                s += "; ";
            if (k.second.size() == 1 && k.second[0] < 0) {
                s += k.first;
                continue;
            }
            s += k.first + (k.second.size() > 1 ? (k.first.back() == 'h' ? "es " : "s ") : " ");
            for (size_t i = 0; i < k.second.size() && i < 4; i++)
                s += (i ? ", " : "") + std::to_string(k.second[i]);
            if (k.second.size() > 4)
                s += " and " + std::to_string(k.second.size() - 4) + " more";
        }
        return s;
    }
};

/* A name from the file, printable and at most 64 bytes, for a message. */
std::string clean(const std::string &name)
{
    std::string out;
    for (unsigned char c : name) {
        if (out.size() >= 64) {
            out += "...";
            break;
        }
        out += (c < 0x20 || c == 0x7f) ? '?' : char(c);
    }
    return out;
}

void note_extensions(std::map<std::string, Uses> &ext, const tinygltf::ExtensionMap &e, const char *kind, int index)
{
    for (const auto &kv : e)
        ext[kv.first].add(kind, index);
}

std::string what_instead(const std::string &name)
{
    if (name.compare(0, 14, "KHR_materials_") == 0 || name == "KHR_materials_pbrSpecularGlossiness")
        return "not supported; the material's base colour, metallic and roughness are used";
    if (name == "KHR_texture_basisu" || name == "EXT_texture_webp" || name == "EXT_texture_avif")
        return "not supported; textures that need it are ignored (their fallback image is used when there is one)";
    if (name == "EXT_mesh_gpu_instancing")
        return "not supported; each mesh is drawn once at its node, without the instances";
    if (name == "KHR_animation_pointer")
        return "not supported; its animation channels are ignored";
    return "not supported by lpvd; ignored";
}

} // namespace

bool extension_supported(const std::string &name)
{
    for (const char *s : kSupported)
        if (name == s)
            return true;
    return false;
}

std::vector<std::string> unused_features(const tinygltf::Model &m, int scene, const std::vector<int> &played)
{
    std::vector<std::string> out;

    /* Extensions: listed in extensionsUsed or found on an object. */
    std::map<std::string, Uses> ext;
    for (const std::string &e : m.extensionsUsed)
        (void)ext[e];
    note_extensions(ext, m.extensions, "the document", -1);
    for (size_t i = 0; i < m.materials.size(); i++) {
        const tinygltf::Material &g = m.materials[i];
        const int k = int(i);
        note_extensions(ext, g.extensions, "material", k);
        note_extensions(ext, g.normalTexture.extensions, "material", k);
        note_extensions(ext, g.occlusionTexture.extensions, "material", k);
        note_extensions(ext, g.emissiveTexture.extensions, "material", k);
        note_extensions(ext, g.pbrMetallicRoughness.baseColorTexture.extensions, "material", k);
        note_extensions(ext, g.pbrMetallicRoughness.metallicRoughnessTexture.extensions, "material", k);
    }
    for (size_t i = 0; i < m.textures.size(); i++)
        note_extensions(ext, m.textures[i].extensions, "texture", int(i));
    for (size_t i = 0; i < m.images.size(); i++)
        note_extensions(ext, m.images[i].extensions, "image", int(i));
    for (size_t i = 0; i < m.meshes.size(); i++) {
        note_extensions(ext, m.meshes[i].extensions, "mesh", int(i));
        for (const tinygltf::Primitive &p : m.meshes[i].primitives)
            note_extensions(ext, p.extensions, "mesh", int(i));
    }
    for (size_t i = 0; i < m.nodes.size(); i++)
        note_extensions(ext, m.nodes[i].extensions, "node", int(i));
    for (size_t i = 0; i < m.bufferViews.size(); i++)
        note_extensions(ext, m.bufferViews[i].extensions, "bufferView", int(i));
    for (size_t i = 0; i < m.buffers.size(); i++)
        note_extensions(ext, m.buffers[i].extensions, "buffer", int(i));
    for (size_t i = 0; i < m.scenes.size(); i++)
        note_extensions(ext, m.scenes[i].extensions, "scene", int(i));
    for (size_t i = 0; i < m.animations.size(); i++)
        for (const tinygltf::AnimationChannel &c : m.animations[i].channels) {
            note_extensions(ext, c.extensions, "animation", int(i));
            note_extensions(ext, c.target_extensions, "animation", int(i));
        }
    for (const auto &kv : ext) {
        if (extension_supported(kv.first))
            continue;
        std::string where = kv.second.total ? " (" + kv.second.describe() + ")" : " (listed in extensionsUsed)";
        out.push_back("extension " + clean(kv.first) + where + ": " + what_instead(kv.first));
    }

    /* Materials lpvd approximates or reads only in part. */
    Uses far_uv;
    std::set<int> far_sets;
    for (size_t i = 0; i < m.materials.size(); i++) {
        const tinygltf::Material &g = m.materials[i];
        const int k = int(i);
        for (const tinygltf::TextureInfo *t :
             {&g.pbrMetallicRoughness.baseColorTexture, &g.pbrMetallicRoughness.metallicRoughnessTexture,
              &g.emissiveTexture})
            if (t->index >= 0 && t->texCoord > 1)
                far_uv.add("material", k), far_sets.insert(t->texCoord);
        if (g.normalTexture.index >= 0 && g.normalTexture.texCoord > 1)
            far_uv.add("material", k), far_sets.insert(g.normalTexture.texCoord);
        if (g.occlusionTexture.index >= 0 && g.occlusionTexture.texCoord > 1)
            far_uv.add("material", k), far_sets.insert(g.occlusionTexture.texCoord);
    }
    if (far_uv.total) {
        std::string sets;
        for (int s : far_sets)
            sets += (sets.empty() ? "TEXCOORD_" : ", TEXCOORD_") + std::to_string(s);
        out.push_back("texture coordinates " + sets + " (" + far_uv.describe() +
                      "): not supported (lpvd reads TEXCOORD_0 and TEXCOORD_1); TEXCOORD_0 is used instead");
    }

    /* Samplers: lpvd repeats and filters every texture (trilinear). */
    Uses wrap;
    for (size_t i = 0; i < m.samplers.size(); i++)
        if (m.samplers[i].wrapS != TINYGLTF_TEXTURE_WRAP_REPEAT || m.samplers[i].wrapT != TINYGLTF_TEXTURE_WRAP_REPEAT)
            wrap.add("sampler", int(i));
    if (wrap.total)
        out.push_back("texture wrap modes CLAMP_TO_EDGE / MIRRORED_REPEAT (" + wrap.describe() +
                      "): not used; lpvd repeats every texture");

    /* Mesh data lpvd does not draw. */
    std::map<std::string, Uses> attrs;
    Uses points_lines;
    for (size_t i = 0; i < m.meshes.size(); i++) {
        for (const tinygltf::Primitive &p : m.meshes[i].primitives) {
            for (const auto &a : p.attributes) {
                const std::string &n = a.first;
                if (n == "POSITION" || n == "NORMAL" || n == "TANGENT" || n == "TEXCOORD_0" || n == "TEXCOORD_1" ||
                    n == "COLOR_0")
                    continue;
                if (n.compare(0, 9, "TEXCOORD_") == 0)
                    continue; /* reported with the textures that ask for them */
                if (n.compare(0, 7, "JOINTS_") == 0 || n.compare(0, 8, "WEIGHTS_") == 0)
                    continue; /* skinning: applied (gltf_mesh.cpp) */
                std::string key;
                if (n.compare(0, 6, "COLOR_") == 0)
                    key = "vertex colours (" + clean(n) + ")";
                else
                    key = "vertex attribute " + clean(n);
                attrs[key].add("mesh", int(i));
            }
            if (p.mode == TINYGLTF_MODE_POINTS || p.mode == TINYGLTF_MODE_LINE || p.mode == TINYGLTF_MODE_LINE_LOOP ||
                p.mode == TINYGLTF_MODE_LINE_STRIP)
                points_lines.add("mesh", int(i));
        }
    }
    for (const auto &kv : attrs)
        out.push_back(kv.first + " (" + kv.second.describe() + "): not used");
    if (points_lines.total)
        out.push_back("point and line primitives (" + points_lines.describe() +
                      "): drawn one pixel wide in their colour, unlit; they carry no surface, so they neither block "
                      "nor reflect light");
    if (played.empty() && !m.animations.empty())
        out.push_back(std::to_string(m.animations.size()) + (m.animations.size() == 1 ? " animation" : " animations") +
                      ": not played; the file's static pose is drawn");
    if (m.scenes.size() > 1)
        out.push_back("the file holds " + std::to_string(m.scenes.size()) + " scenes: only scene " +
                      std::to_string(scene < 0 ? 0 : scene) + " is loaded");
    return out;
}

} // namespace lpv_gltf
