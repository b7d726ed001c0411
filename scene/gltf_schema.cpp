/*
 * gltf_schema.cpp - the JSON types of the glTF 2.0 fields lpvd reads,
 * checked before tinygltf sees the file (gltf_internal.hpp).
 *
 * tinygltf skips a field whose JSON type is wrong and goes on with its
 * default: a mesh whose "primitives" is an object instead of an array loads
 * with no triangles, a material whose pbrMetallicRoughness is an array loses
 * its base colour texture, a texture index of -1 drops the texture, and
 * nothing says so (assimp's glTF2/wrongTypes files). The glTF 2.0 schema
 * says what each field is; a file that breaks it is refused here, naming the
 * field by its JSON path ("meshes[0].primitives") and both types. Names are
 * the exception: a name that is not a string changes nothing lpvd computes,
 * so it is a warning. Fields outside the table (extras, unknown extensions)
 * are free-form and not looked at.
 *
 * One SAX pass (nlohmann-json, no DOM), the path matched against a tree built
 * once from the table: constant work per JSON value. The same pass refuses
 * invalid syntax and a nesting deeper than kMaxJsonDepth, so that
 * tinygltf's recursive extras/extensions parser never sees a hostile depth.
 */
#include "gltf_internal.hpp"

#include <cmath>
#include <map>
#include <memory>

#include <nlohmann/json.hpp>

namespace lpv_gltf {

namespace {

enum Type { kObject, kArray, kIndex, kNumber, kString, kBool, kName };

struct Rule {
    const char *path; /* '/'-separated; '*' any array element or any key */
    Type type;
};

/* textureInfo and its KHR_texture_transform, under each texture slot */
#define TEXINFO(p)                                                                                                 \
    {p, kObject}, {p "/index", kIndex}, {p "/texCoord", kIndex}, {p "/extensions", kObject},                       \
        {p "/extensions/KHR_texture_transform", kObject},                                                          \
        {p "/extensions/KHR_texture_transform/offset", kArray},                                                    \
        {p "/extensions/KHR_texture_transform/offset/*", kNumber},                                                 \
        {p "/extensions/KHR_texture_transform/scale", kArray},                                                     \
        {p "/extensions/KHR_texture_transform/scale/*", kNumber},                                                  \
        {p "/extensions/KHR_texture_transform/rotation", kNumber},                                                 \
        {p "/extensions/KHR_texture_transform/texCoord", kIndex}

/* a top-level array of objects with a name */
#define TOP(p) {p, kArray}, {p "/*", kObject}, {p "/*/name", kName}

const Rule kRules[] = {
    {"", kObject},
    {"scene", kIndex},
    {"extensionsUsed", kArray},
    {"extensionsUsed/*", kString},
    {"extensionsRequired", kArray},
    {"extensionsRequired/*", kString},
    {"asset", kObject},
    {"asset/version", kString},
    {"extensions", kObject},
    {"extensions/KHR_lights_punctual", kObject},
    TOP("extensions/KHR_lights_punctual/lights"),
    {"extensions/KHR_lights_punctual/lights/*/type", kString},
    {"extensions/KHR_lights_punctual/lights/*/color", kArray},
    {"extensions/KHR_lights_punctual/lights/*/color/*", kNumber},
    {"extensions/KHR_lights_punctual/lights/*/intensity", kNumber},
    {"extensions/KHR_lights_punctual/lights/*/range", kNumber},
    {"extensions/KHR_lights_punctual/lights/*/spot", kObject},
    {"extensions/KHR_lights_punctual/lights/*/spot/innerConeAngle", kNumber},
    {"extensions/KHR_lights_punctual/lights/*/spot/outerConeAngle", kNumber},

    TOP("scenes"),
    {"scenes/*/nodes", kArray},
    {"scenes/*/nodes/*", kIndex},

    TOP("nodes"),
    {"nodes/*/children", kArray},
    {"nodes/*/children/*", kIndex},
    {"nodes/*/mesh", kIndex},
    {"nodes/*/camera", kIndex},
    {"nodes/*/skin", kIndex},
    {"nodes/*/matrix", kArray},
    {"nodes/*/matrix/*", kNumber},
    {"nodes/*/translation", kArray},
    {"nodes/*/translation/*", kNumber},
    {"nodes/*/rotation", kArray},
    {"nodes/*/rotation/*", kNumber},
    {"nodes/*/scale", kArray},
    {"nodes/*/scale/*", kNumber},
    {"nodes/*/weights", kArray},
    {"nodes/*/weights/*", kNumber},
    {"nodes/*/extensions", kObject},
    {"nodes/*/extensions/KHR_lights_punctual", kObject},
    {"nodes/*/extensions/KHR_lights_punctual/light", kIndex},

    TOP("meshes"),
    {"meshes/*/primitives", kArray},
    {"meshes/*/primitives/*", kObject},
    {"meshes/*/primitives/*/attributes", kObject},
    {"meshes/*/primitives/*/attributes/*", kIndex},
    {"meshes/*/primitives/*/indices", kIndex},
    {"meshes/*/primitives/*/material", kIndex},
    {"meshes/*/primitives/*/mode", kIndex},
    {"meshes/*/primitives/*/targets", kArray},
    {"meshes/*/primitives/*/targets/*", kObject},
    {"meshes/*/primitives/*/targets/*/*", kIndex},
    {"meshes/*/weights", kArray},
    {"meshes/*/weights/*", kNumber},

    TOP("accessors"),
    {"accessors/*/bufferView", kIndex},
    {"accessors/*/byteOffset", kIndex},
    {"accessors/*/componentType", kIndex},
    {"accessors/*/normalized", kBool},
    {"accessors/*/count", kIndex},
    {"accessors/*/type", kString},
    {"accessors/*/min", kArray},
    {"accessors/*/min/*", kNumber},
    {"accessors/*/max", kArray},
    {"accessors/*/max/*", kNumber},
    {"accessors/*/sparse", kObject},
    {"accessors/*/sparse/count", kIndex},
    {"accessors/*/sparse/indices", kObject},
    {"accessors/*/sparse/indices/bufferView", kIndex},
    {"accessors/*/sparse/indices/byteOffset", kIndex},
    {"accessors/*/sparse/indices/componentType", kIndex},
    {"accessors/*/sparse/values", kObject},
    {"accessors/*/sparse/values/bufferView", kIndex},
    {"accessors/*/sparse/values/byteOffset", kIndex},

    TOP("bufferViews"),
    {"bufferViews/*/buffer", kIndex},
    {"bufferViews/*/byteOffset", kIndex},
    {"bufferViews/*/byteLength", kIndex},
    {"bufferViews/*/byteStride", kIndex},
    {"bufferViews/*/target", kIndex},

    TOP("buffers"),
    {"buffers/*/uri", kString},
    {"buffers/*/byteLength", kIndex},

    TOP("images"),
    {"images/*/uri", kString},
    {"images/*/mimeType", kString},
    {"images/*/bufferView", kIndex},

    TOP("textures"),
    {"textures/*/sampler", kIndex},
    {"textures/*/source", kIndex},

    TOP("samplers"),
    {"samplers/*/magFilter", kIndex},
    {"samplers/*/minFilter", kIndex},
    {"samplers/*/wrapS", kIndex},
    {"samplers/*/wrapT", kIndex},

    TOP("materials"),
    {"materials/*/pbrMetallicRoughness", kObject},
    {"materials/*/pbrMetallicRoughness/baseColorFactor", kArray},
    {"materials/*/pbrMetallicRoughness/baseColorFactor/*", kNumber},
    {"materials/*/pbrMetallicRoughness/metallicFactor", kNumber},
    {"materials/*/pbrMetallicRoughness/roughnessFactor", kNumber},
    TEXINFO("materials/*/pbrMetallicRoughness/baseColorTexture"),
    TEXINFO("materials/*/pbrMetallicRoughness/metallicRoughnessTexture"),
    TEXINFO("materials/*/normalTexture"),
    {"materials/*/normalTexture/scale", kNumber},
    TEXINFO("materials/*/occlusionTexture"),
    {"materials/*/occlusionTexture/strength", kNumber},
    TEXINFO("materials/*/emissiveTexture"),
    {"materials/*/emissiveFactor", kArray},
    {"materials/*/emissiveFactor/*", kNumber},
    {"materials/*/alphaMode", kString},
    {"materials/*/alphaCutoff", kNumber},
    {"materials/*/doubleSided", kBool},
    {"materials/*/extensions", kObject},
    {"materials/*/extensions/KHR_materials_emissive_strength", kObject},
    {"materials/*/extensions/KHR_materials_emissive_strength/emissiveStrength", kNumber},
    {"materials/*/extensions/KHR_materials_unlit", kObject},

    TOP("cameras"),
    {"cameras/*/type", kString},
    {"cameras/*/perspective", kObject},
    {"cameras/*/perspective/yfov", kNumber},
    {"cameras/*/perspective/aspectRatio", kNumber},
    {"cameras/*/perspective/znear", kNumber},
    {"cameras/*/perspective/zfar", kNumber},
    {"cameras/*/orthographic", kObject},
    {"cameras/*/orthographic/xmag", kNumber},
    {"cameras/*/orthographic/ymag", kNumber},
    {"cameras/*/orthographic/znear", kNumber},
    {"cameras/*/orthographic/zfar", kNumber},

    TOP("skins"),
    {"skins/*/inverseBindMatrices", kIndex},
    {"skins/*/skeleton", kIndex},
    {"skins/*/joints", kArray},
    {"skins/*/joints/*", kIndex},

    TOP("animations"),
    {"animations/*/channels", kArray},
    {"animations/*/channels/*", kObject},
    {"animations/*/channels/*/sampler", kIndex},
    {"animations/*/channels/*/target", kObject},
    {"animations/*/channels/*/target/node", kIndex},
    {"animations/*/channels/*/target/path", kString},
    {"animations/*/samplers", kArray},
    {"animations/*/samplers/*", kObject},
    {"animations/*/samplers/*/input", kIndex},
    {"animations/*/samplers/*/output", kIndex},
    {"animations/*/samplers/*/interpolation", kString},
};

#undef TEXINFO
#undef TOP

struct Node {
    bool has_type = false;
    Type type = kObject;
    std::map<std::string, std::unique_ptr<Node>> keys;
    std::unique_ptr<Node> any; /* '*' */
};

const Node &schema()
{
    static const Node *root = [] {
        Node *r = new Node;
        for (const Rule &rule : kRules) {
            Node *n = r;
            std::string p = rule.path;
            size_t at = 0;
            while (!p.empty() && at <= p.size()) {
                size_t slash = p.find('/', at);
                std::string tok = p.substr(at, slash == std::string::npos ? std::string::npos : slash - at);
                std::unique_ptr<Node> &next = tok == "*" ? n->any : n->keys[tok];
                if (!next)
                    next.reset(new Node);
                n = next.get();
                if (slash == std::string::npos)
                    break;
                at = slash + 1;
            }
            n->has_type = true;
            n->type = rule.type;
        }
        return r;
    }();
    return *root;
}

const char *expected(Type t)
{
    switch (t) {
    case kObject: return "an object";
    case kArray: return "an array";
    case kIndex: return "an index (an integer >= 0)";
    case kNumber: return "a number";
    case kString:
    case kName: return "a string";
    case kBool: return "true or false";
    }
    return "?";
}

struct Frame {
    const Node *node; /* nullptr: not in the table, nothing below is checked */
    bool array;
    size_t index;     /* the next element's (arrays) */
    std::string key;  /* the last key read (objects) */
};

struct SchemaScan : nlohmann::json_sax<nlohmann::json> {
    Ctx &ctx;
    std::vector<Frame> stack;
    bool too_deep = false;
    std::string error; /* the parser's, without the file's bytes */
    explicit SchemaScan(Ctx &c) : ctx(c) {}

    /* The path of the value being read, as JSON paths are written:
     * meshes[0].primitives */
    std::string path() const
    {
        std::string s;
        for (const Frame &f : stack) {
            if (f.array)
                s += strf("[%zu]", f.index);
            else {
                if (!s.empty())
                    s += '.';
                /* the table's keys and the attribute names as they are; any
                 * other key from the file described, not quoted (show) */
                const std::string shown = show(f.key);
                s += shown.size() == f.key.size() + 2 && shown[0] == '"' ? f.key : shown;
            }
        }
        return s.empty() ? "the file's top level" : s;
    }

    /* The table's node for the value now read (nullptr: unchecked). */
    const Node *here() const
    {
        if (stack.empty())
            return &schema();
        const Frame &f = stack.back();
        if (!f.node)
            return nullptr;
        if (!f.array) {
            auto it = f.node->keys.find(f.key);
            if (it != f.node->keys.end())
                return it->second.get();
        }
        return f.node->any.get();
    }

    /* A value of JSON type `found` at table node n, fits: whether that is
     * the node's type; a mismatch refuses the file, or warns for a name. */
    void check(const Node *n, const char *found, bool fits)
    {
        if (!n || !n->has_type || fits)
            return;
        if (n->type == kName) {
            ctx.warn(strf("%s: expected a string, found %s (glTF 2.0 schema); the name is ignored", path().c_str(),
                          found));
            return;
        }
        fail("%s: expected %s, found %s (glTF 2.0 schema)", path().c_str(), expected(n->type), found);
    }

    /* After a value: the next array element. */
    void next()
    {
        if (!stack.empty() && stack.back().array)
            ++stack.back().index;
    }

    bool scalar(const char *found, bool is_number, bool is_index, bool is_string, bool is_bool)
    {
        const Node *n = here();
        if (n && n->has_type) {
            bool fits = false;
            switch (n->type) {
            case kIndex: fits = is_index; break;
            case kNumber: fits = is_number; break;
            case kString:
            case kName: fits = is_string; break;
            case kBool: fits = is_bool; break;
            default: fits = false;
            }
            check(n, found, fits);
        }
        next();
        return true;
    }

    bool null() override { return scalar("null", false, false, false, false); }
    bool boolean(bool) override { return scalar("a boolean", false, false, false, true); }
    bool number_integer(number_integer_t v) override
    {
        /* nlohmann reads every integer >= 0 as unsigned: this one is negative */
        return scalar(v < 0 ? "a negative integer" : "an integer", true, v >= 0, false, false);
    }
    bool number_unsigned(number_unsigned_t) override { return scalar("an integer", true, true, false, false); }
    bool number_float(number_float_t v, const string_t &) override
    {
        /* 2.0 for an index: JSON Schema would count it an integer, but
         * tinygltf skips the field (a POSITION of 0.0 loads no vertices) */
        const bool integral = std::isfinite(v) && std::floor(v) == v;
        return scalar(integral ? "a number with a decimal point or exponent" : "a fractional number", true, false,
                      false, false);
    }
    bool string(string_t &) override { return scalar("a string", false, false, true, false); }
    bool binary(binary_t &) override { return scalar("binary data", false, false, false, false); }

    bool open(bool array)
    {
        if (stack.size() >= size_t(kMaxJsonDepth)) {
            too_deep = true;
            return false;
        }
        const Node *n = here();
        if (n && n->has_type && n->type != (array ? kArray : kObject))
            check(n, array ? "an array" : "an object", false);
        /* a container where a scalar or the other container belongs: nothing
         * below it is looked at (a name's object was only warned about) */
        const bool fits = n && (!n->has_type || n->type == (array ? kArray : kObject));
        stack.push_back(Frame{fits ? n : nullptr, array, 0, std::string()});
        return true;
    }
    bool close()
    {
        stack.pop_back();
        next();
        return true;
    }
    bool start_object(std::size_t) override { return open(false); }
    bool start_array(std::size_t) override { return open(true); }
    bool end_object() override { return close(); }
    bool end_array() override { return close(); }
    bool key(string_t &k) override
    {
        stack.back().key = k;
        return true;
    }
    bool parse_error(std::size_t, const std::string &, const nlohmann::detail::exception &ex) override
    {
        /* nlohmann's message ends with "; last read: '<the file's bytes>'...":
         * cut there, so that no message quotes the file */
        error = ex.what();
        size_t cut = error.find("; last read:");
        if (cut != std::string::npos)
            error.resize(cut);
        return false;
    }
};

} // namespace

void check_schema_types(const char *json, size_t len, Ctx &ctx)
{
    SchemaScan scan(ctx);
    const bool ok = nlohmann::json::sax_parse(json, json + len, &scan);
    if (scan.too_deep)
        fail("JSON nested deeper than %d levels (refused)", kMaxJsonDepth);
    if (!ok)
        fail("invalid JSON: %s", scan.error.empty() ? "parse error" : scan.error.c_str());
}

} // namespace lpv_gltf
