/*
 * gltf_material.cpp - alpha and texture transforms of glTF materials
 * (gltf_material.hpp; docs/scenes.md, "Materials").
 */
#include "gltf_material.hpp"

#include <cmath>

namespace lpv_gltf {

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

namespace {

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

} // namespace

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

} // namespace lpv_gltf
