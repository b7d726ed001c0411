/*
 * gltf_material.cpp - the Builder's materials (gltf_internal.hpp; docs/scenes.md,
 * "Materials"): base colour, emission (with KHR_materials_emissive_strength,
 * nits to radiance), metallic/roughness, alpha mode and cutoff, double-sided,
 * normal maps, each texture reference's uv set and KHR_texture_transform, and
 * the textures' decoded pixels (sRGB colour or linear data). Problems refuse
 * the file with a message naming the material and the field.
 */
#include "gltf_internal.hpp"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>

namespace lpv_gltf {

namespace {

/* alphaMode ("OPAQUE", "MASK", "BLEND") and alphaCutoff (finite, >= 0) into
 * mat. Returns "" or the problem ("alphaMode \"X\" is not ..."). */
std::string read_alpha(const tinygltf::Material &gm, lpv_material *mat)
{
    if (gm.alphaMode == "OPAQUE")
        mat->alpha_mode = LPV_ALPHA_OPAQUE;
    else if (gm.alphaMode == "MASK")
        mat->alpha_mode = LPV_ALPHA_MASK;
    else if (gm.alphaMode == "BLEND")
        mat->alpha_mode = LPV_ALPHA_BLEND;
    else {
        std::string shown = gm.alphaMode.substr(0, 40);
        for (char &c : shown)
            if (static_cast<unsigned char>(c) < 0x20)
                c = '?';
        return "alphaMode \"" + shown + "\" is not OPAQUE, MASK or BLEND";
    }
    if (!std::isfinite(gm.alphaCutoff) || gm.alphaCutoff < 0.0)
        return "alphaCutoff must be a finite number >= 0";
    mat->alpha_cutoff = float(gm.alphaCutoff);
    return "";
}

bool numbers(const tinygltf::Value &v, size_t n, double *out)
{
    if (!v.IsArray() || v.ArrayLen() != n)
        return false;
    for (size_t i = 0; i < n; i++) {
        const tinygltf::Value &e = v.Get(int(i));
        if (!e.IsNumber() || !std::isfinite(e.GetNumberAsDouble()))
            return false;
        out[i] = e.GetNumberAsDouble();
    }
    return true;
}

/* A texture reference's uv set and transform: texCoord, then
 * KHR_texture_transform's offset, rotation, scale and texCoord override.
 * Returns "" or the problem, naming the field (e.g. "KHR_texture_transform.scale
 * must hold 2 finite numbers"). */
std::string read_uv_transform(int tex_coord, const tinygltf::ExtensionMap &ext, lpv_uv_transform *out)
{
    *out = lpv_uv_transform{};
    out->texcoord = tex_coord;
    out->scale[0] = out->scale[1] = 1.0f;
    auto it = ext.find("KHR_texture_transform");
    if (it == ext.end())
        return "";
    const tinygltf::Value &t = it->second;
    if (!t.IsObject())
        return "KHR_texture_transform must be an object";
    double v[2];
    if (t.Has("offset")) {
        if (!numbers(t.Get("offset"), 2, v))
            return "KHR_texture_transform.offset must hold 2 finite numbers";
        out->offset[0] = float(v[0]);
        out->offset[1] = float(v[1]);
    }
    if (t.Has("rotation")) {
        const tinygltf::Value &r = t.Get("rotation");
        if (!r.IsNumber() || !std::isfinite(r.GetNumberAsDouble()))
            return "KHR_texture_transform.rotation must be a finite number (rad)";
        out->rotation = float(r.GetNumberAsDouble());
    }
    if (t.Has("scale")) {
        if (!numbers(t.Get("scale"), 2, v))
            return "KHR_texture_transform.scale must hold 2 finite numbers";
        out->scale[0] = float(v[0]);
        out->scale[1] = float(v[1]);
    }
    if (t.Has("texCoord")) {
        const tinygltf::Value &c = t.Get("texCoord");
        double d = c.IsNumber() ? c.GetNumberAsDouble() : -1.0;
        if (!(d >= 0.0 && d <= 65535.0) || d != std::floor(d))
            return "KHR_texture_transform.texCoord must be an integer >= 0";
        out->texcoord = int(d);
    }
    out->has_transform = 1;
    return "";
}

} // namespace

int Builder::default_material()
{
    if (default_material_ < 0) {
        lpv_material mat;
        lpv_material_init(&mat);
        copy_name(mat.name, "default", "default");
        materials.push_back(mat);
        default_material_ = int(materials.size() - 1);
    }
    return default_material_;
}

/* The scene texture of glTF texture `index` for a material's `what` (a
 * message's words): decoded pixels, sRGB colour or linear data (normal maps);
 * -1 when the texture has no usable image (a warning). */
int Builder::texture_for(int material_index, const char *what, int index, bool linear)
{
    if (index < 0)
        return -1;
    if (size_t(index) >= m_.textures.size())
        fail("material %d: %s %d does not exist (out of range)", material_index, what, index);
    int src = m_.textures[size_t(index)].source;
    if (src < 0) {
        ctx_.warn(strf("texture %d has no source image (extension-only?); ignored", index));
        return -1;
    }
    if (size_t(src) >= m_.images.size())
        fail("texture %d: source image %d does not exist (out of range)", index, src);
    auto it = image_texture_.find({src, linear ? 1 : 0});
    if (it != image_texture_.end())
        return it->second;
    const tinygltf::Image &img = m_.images[size_t(src)];
    int result = -1;
    if (!img.image.empty() && img.component == 4 && img.bits == 8 && img.width > 0 && img.height > 0 &&
        img.width <= kMaxTextureSize && img.height <= kMaxTextureSize &&
        img.image.size() == size_t(img.width) * size_t(img.height) * 4) {
        lpv_texture t;
        memset(&t, 0, sizeof t);
        t.width = img.width;
        t.height = img.height;
        t.linear = linear ? 1 : 0;
        t.rgba8 = static_cast<uint8_t *>(malloc(img.image.size()));
        if (!t.rgba8)
            throw std::bad_alloc();
        memcpy(t.rgba8, img.image.data(), img.image.size());
        try {
            textures.push_back(t);
        } catch (...) {
            free(t.rgba8);
            throw;
        }
        result = int(textures.size() - 1);
    } else {
        ctx_.warn(strf("image %d has no decoded RGBA8 pixels; texture ignored", src));
    }
    image_texture_[{src, linear ? 1 : 0}] = result;
    return result;
}

/* A texture reference's uv set and KHR_texture_transform into out. */
void Builder::texture_uv(int material_index, const char *what, int tex_coord, const tinygltf::ExtensionMap &ext,
                         lpv_uv_transform *out)
{
    std::string e = read_uv_transform(tex_coord, ext, out);
    if (!e.empty())
        fail("material %d: %s: %s", material_index, what, e.c_str());
    if (out->texcoord > 1)
        out->texcoord = 0; /* reported once among the unused features */
    if (out->texcoord == 1) {
        material_uv1_.resize(m_.materials.size(), 0);
        material_uv1_[size_t(material_index)] = 1;
    }
}

void Builder::convert_materials()
{
    for (size_t i = 0; i < m_.materials.size(); i++) {
        const tinygltf::Material &gm = m_.materials[i];
        const int mi = int(i);
        lpv_material mat;
        lpv_material_init(&mat);
        copy_name(mat.name, gm.name, strf("material%d", mi));
        const auto &pbr = gm.pbrMetallicRoughness;
        if (pbr.baseColorFactor.size() != 4 || !finite_all(pbr.baseColorFactor))
            fail("material %d: baseColorFactor must hold 4 finite numbers", mi);
        for (int k = 0; k < 4; k++)
            mat.base_color[k] = float(pbr.baseColorFactor[size_t(k)]);
        mat.base_color_texture = texture_for(mi, "baseColorTexture", pbr.baseColorTexture.index, false);
        texture_uv(mi, "baseColorTexture", pbr.baseColorTexture.texCoord, pbr.baseColorTexture.extensions,
                   &mat.base_color_uv);
        mat.metallic_roughness_texture =
            texture_for(mi, "metallicRoughnessTexture", pbr.metallicRoughnessTexture.index, true);
        texture_uv(mi, "metallicRoughnessTexture", pbr.metallicRoughnessTexture.texCoord,
                   pbr.metallicRoughnessTexture.extensions, &mat.metallic_roughness_uv);
        mat.emissive_texture = texture_for(mi, "emissiveTexture", gm.emissiveTexture.index, false);
        texture_uv(mi, "emissiveTexture", gm.emissiveTexture.texCoord, gm.emissiveTexture.extensions,
                   &mat.emissive_uv);
        const tinygltf::OcclusionTextureInfo &ot = gm.occlusionTexture;
        mat.occlusion_texture = texture_for(mi, "occlusionTexture", ot.index, true);
        texture_uv(mi, "occlusionTexture", ot.texCoord, ot.extensions, &mat.occlusion_uv);
        if (!std::isfinite(ot.strength) || ot.strength < 0.0 || ot.strength > 1.0)
            fail("material %d: occlusionTexture.strength must be a number in [0, 1]", mi);
        mat.occlusion_strength = float(ot.strength);
        const tinygltf::NormalTextureInfo &nt = gm.normalTexture;
        mat.normal_texture = texture_for(mi, "normalTexture", nt.index, true);
        texture_uv(mi, "normalTexture", nt.texCoord, nt.extensions, &mat.normal_uv);
        if (!std::isfinite(nt.scale))
            fail("material %d: normalTexture.scale must be a finite number", mi);
        mat.normal_scale = float(nt.scale);
        std::string alpha = read_alpha(gm, &mat);
        if (!alpha.empty())
            fail("material %d: %s", mi, alpha.c_str());
        if (gm.emissiveFactor.size() != 3 || !finite_all(gm.emissiveFactor))
            fail("material %d: emissiveFactor must hold 3 finite numbers", mi);
        double strength = 1.0;
        auto ext = gm.extensions.find("KHR_materials_emissive_strength");
        if (ext != gm.extensions.end() && ext->second.IsObject() && ext->second.Has("emissiveStrength")) {
            const tinygltf::Value &v = ext->second.Get("emissiveStrength");
            if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()) || v.GetNumberAsDouble() < 0.0)
                fail("material %d: emissiveStrength must be a finite number >= 0", mi);
            strength = v.GetNumberAsDouble();
        }
        for (int k = 0; k < 3; k++) {
            /* nits (cd/m^2) -> W/(m^2 sr): a unit conversion, docs/units.md */
            mat.emission[k] = float(gm.emissiveFactor[size_t(k)] * strength / double(LPV_LUMENS_PER_WATT));
        }
        if (!std::isfinite(pbr.metallicFactor) || !std::isfinite(pbr.roughnessFactor))
            fail("material %d: metallicFactor and roughnessFactor must be finite", mi);
        mat.metallic = float(pbr.metallicFactor);
        mat.roughness = float(pbr.roughnessFactor);
        mat.double_sided = gm.doubleSided ? 1 : 0;
        if (gm.extensions.count("KHR_materials_unlit")) {
            /* shown as its base colour, lit by nothing and lighting nothing:
             * an emissive factor has no meaning on it (the extension) */
            mat.unlit = 1;
            mat.emission[0] = mat.emission[1] = mat.emission[2] = 0.0f;
        }
        materials.push_back(mat);
    }
}

} // namespace lpv_gltf
