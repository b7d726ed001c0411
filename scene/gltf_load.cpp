/*
 * gltf_load.cpp - glTF 2.0 into an lpv_scene through tinygltf (gltf_load.h):
 * the C entry points and the one load they share.
 *
 * tinygltf parses the JSON and fetches buffers and images; everything it does
 * not check is checked by the adapter before it is used (gltf_internal.hpp
 * lists its files):
 *   - the .glb container is validated completely and the JSON pre-scanned for
 *     syntax and depth before tinygltf sees them (gltf_container.cpp);
 *   - every file access goes through our FsCallbacks, which open it beneath
 *     the scene's folder descriptor (gltf_files.cpp);
 *   - images are decoded by our own loader callback after the size cap and
 *     the bufferView range are checked (gltf_images.cpp);
 *   - accessors, buffer views, sparse data, indices, node graphs and limits
 *     are checked by the Builder, never trusted (gltf_build.cpp and the files
 *     it names).
 * Errors travel as a C++ exception (Failure) inside the adapter and leave it
 * here as "<path or label>: <problem>" and -1 (or the LPV_GLTF_OVER_* of the
 * budget that refused it); nothing is thrown into C.
 * Units: glTF's photometric values are divided by LPV_LUMENS_PER_WATT
 * (docs/units.md).
 */
#include "gltf_internal.hpp"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <new>
#include <unistd.h>

using namespace lpv_gltf;

namespace {

template <class T> T *c_array(const std::vector<T> &v)
{
    if (v.empty())
        return nullptr;
    T *p = static_cast<T *>(malloc(v.size() * sizeof(T)));
    if (!p)
        throw std::bad_alloc();
    memcpy(p, v.data(), v.size() * sizeof(T));
    return p;
}

void set_error(char *err, size_t err_size, const std::string &label, const std::string &msg)
{
    if (err && err_size > 0)
        snprintf(err, err_size, "%s: %s", label.c_str(), msg.c_str());
}

/* The message of a load refused by a budget (ctx.over), with what the file
 * needs of it: the texels of all images (summed from their headers) or the
 * bytes counted until the load stopped. */
[[noreturn]] void fail_budget(const Ctx &ctx)
{
    Failure f;
    f.code = ctx.over;
    if (ctx.over == LPV_GLTF_OVER_TEXTURE)
        f.msg = strf("%s, over the texture limit of %d texels per side", ctx.over_what.c_str(), ctx.max_side);
    else if (ctx.over == LPV_GLTF_OVER_TEXELS)
        f.msg = strf("the images need %llu decoded texels, over the budget of %llu texels per scene",
                     (unsigned long long)ctx.texels, (unsigned long long)ctx.max_texels);
    else
        f.msg = strf("the scene needs at least %llu bytes of memory (file, buffers, RGBA8 texels, model), over "
                     "the budget of %llu bytes per scene",
                     (unsigned long long)ctx.bytes, (unsigned long long)ctx.max_bytes);
    throw f;
}

/* The scene model's arrays, counted against the RAM budget before they are copied out. */
uint64_t model_bytes(const Builder &b, size_t density_count)
{
    return uint64_t(b.vertices.size()) * sizeof(lpv_vertex) + uint64_t(b.indices.size()) * sizeof(uint32_t) +
           uint64_t(b.draws.size()) * sizeof(lpv_draw) + uint64_t(b.materials.size()) * sizeof(lpv_material) +
           uint64_t(b.wire_indices.size()) * sizeof(uint32_t) + uint64_t(b.wire_draws.size()) * sizeof(lpv_draw) +
           uint64_t(b.lights.size()) * sizeof(lpv_light) + uint64_t(b.cameras.size()) * sizeof(lpv_camera) +
           uint64_t(b.textures.size()) * sizeof(lpv_texture) + uint64_t(density_count) * sizeof(float);
}

void load(const unsigned char *data, size_t size, Ctx &ctx, lpv_scene *out)
{
    if (!take_bytes(ctx, size))
        fail_budget(ctx);
    size_t json_off = 0, json_len = size;
    const bool is_glb = check_container(data, size, &json_off, &json_len);
    check_schema_types(reinterpret_cast<const char *>(data) + json_off, json_len, ctx);

    tinygltf::TinyGLTF loader;
    set_fs_callbacks(loader, &ctx);
    loader.SetImageLoader(image_loader, &ctx);

    const char *const json_text = reinterpret_cast<const char *>(data) + json_off; /* the file's own JSON */
    std::vector<unsigned char> rewritten; /* compressed files as tinygltf 2.7 accepts them */
    if (tinygltf_compat_file(data, size, is_glb, json_off, json_len, &rewritten)) {
        data = rewritten.data();
        size = rewritten.size();
    }

    tinygltf::Model model;
    ctx.model = &model;
    std::string terr, twarn;
    const std::string base = ctx.allow_external ? std::string(kBaseTag) : std::string();
    bool ok;
    if (is_glb)
        ok = loader.LoadBinaryFromMemory(&model, &terr, &twarn, data, unsigned(size), base);
    else
        ok = loader.LoadASCIIFromString(&model, &terr, &twarn, reinterpret_cast<const char *>(data), unsigned(size),
                                        base);
    ctx.model = nullptr;
    if (!ctx.refusal.empty())
        fail("%s", ctx.refusal.c_str());
    if (ctx.over_budget())
        fail_budget(ctx);
    if (!ctx.image_error.empty())
        fail("%s", ctx.image_error.c_str());
    if (!ok) {
        std::string t = tinygltf_text(terr);
        if (!ctx.missing.empty())
            fail("%s (missing buffer or image; tinygltf: %s)", ctx.missing.c_str(), t.c_str());
        fail("glTF rejected by tinygltf: %s", t.empty() ? "unknown error" : t.c_str());
    }
    if (!ctx.missing.empty())
        ctx.warn(ctx.missing + "; that image is ignored");
    if (!terr.empty())
        ctx.warn("tinygltf: " + tinygltf_text(terr));
    if (!twarn.empty())
        ctx.warn("tinygltf: " + tinygltf_text(twarn));
    Builder b(model, ctx);
    if (ctx.animation_list) { /* lpv_gltf_animations: no images, no scene */
        b.list_animations(*ctx.animation_list);
        return;
    }
    decode_images(model); /* every image counted and within the budgets: now decoded */

    /* The animation's pose first, then the caller's overrides (which win). */
    if (ctx.animation) {
        std::vector<std::pair<int, std::vector<double>>> weights;
        std::vector<lpv_gltf_node_override> pose = b.sample_animations(*ctx.animation, weights);
        apply_node_overrides(model, pose.data(), pose.size());
        for (const auto &w : weights) /* the node's weights win over its mesh's (glTF) */
            model.nodes[size_t(w.first)].weights = w.second;
    }
    apply_node_overrides(model, ctx.overrides, ctx.override_count);

    b.build();
    lpv_medium medium;
    std::vector<float> density;
    read_medium(json_text, json_len, model, ctx, medium, density);

    if (b.vertices.size() > UINT32_MAX || b.indices.size() > UINT32_MAX || b.wire_indices.size() > UINT32_MAX)
        fail("scene too large (absurd size)");
    if (!take_bytes(ctx, model_bytes(b, density.size())))
        fail_budget(ctx);
    /* Hand everything over as malloc'd C arrays; lpv_scene_free releases it. */
    out->vertices = c_array(b.vertices);
    out->vertex_count = uint32_t(b.vertices.size());
    out->indices = c_array(b.indices);
    out->index_count = uint32_t(b.indices.size());
    out->draws = c_array(b.draws);
    out->draw_count = uint32_t(b.draws.size());
    out->wire_indices = c_array(b.wire_indices);
    out->wire_index_count = uint32_t(b.wire_indices.size());
    out->wire_draws = c_array(b.wire_draws);
    out->wire_draw_count = uint32_t(b.wire_draws.size());
    out->materials = c_array(b.materials);
    out->material_count = uint32_t(b.materials.size());
    out->lights = c_array(b.lights);
    out->light_count = uint32_t(b.lights.size());
    out->cameras = c_array(b.cameras);
    out->camera_count = uint32_t(b.cameras.size());
    out->textures = c_array(b.textures);
    if (out->textures) {
        out->texture_count = uint32_t(b.textures.size());
        b.textures.clear(); /* the pixels now belong to the scene */
    }
    medium.density = nullptr;
    out->medium = medium;
    out->medium.density = c_array(density); /* NULL without a density texture */
    snprintf(out->source, sizeof out->source, "%s", ctx.label.c_str());
    out->default_light_added = 0;
    lpv_scene_compute_bounds(out);
}

int run_load(const unsigned char *data, size_t size, Ctx &ctx, lpv_scene *out, char *err, size_t err_size)
{
    try {
        load(data, size, ctx, out);
        if (ctx.animation_list) {
            /* a list, not a load: its warnings are the load's to give */
        } else if (ctx.sink) {
            for (const std::string &w : ctx.warnings)
                snprintf(ctx.sink->line[ctx.sink->count++], LPV_GLTF_WARNING_LEN, "%s", w.c_str());
            ctx.sink->dropped = int(ctx.warnings_dropped);
        } else {
            for (const std::string &w : ctx.warnings)
                fprintf(stderr, "lpvd: %s: warning: %s\n", ctx.label.c_str(), w.c_str());
            if (ctx.warnings_dropped)
                fprintf(stderr, "lpvd: %s: warning: %zu more warnings not shown\n", ctx.label.c_str(),
                        ctx.warnings_dropped);
        }
        return 0;
    } catch (const Failure &f) {
        set_error(err, err_size, ctx.label, f.msg);
        lpv_scene_free(out);
        return f.code;
    } catch (const std::bad_alloc &) {
        set_error(err, err_size, ctx.label, "out of memory");
    } catch (const std::exception &e) {
        set_error(err, err_size, ctx.label, std::string("unexpected error: ") + e.what());
    } catch (...) {
        set_error(err, err_size, ctx.label, "unexpected error");
    }
    lpv_scene_free(out);
    return -1;
}

/* What every entry point does first: clear the caller's warnings and error
 * and zero the scene; false, with "<name>: no scene to load into", without one. */
bool begin_load(const char *name, lpv_scene *out, lpv_gltf_warnings *warnings, char *err, size_t err_size)
{
    if (warnings)
        memset(warnings, 0, sizeof *warnings);
    if (err && err_size)
        err[0] = '\0';
    if (!out) {
        if (err && err_size)
            snprintf(err, err_size, "%s: no scene to load into", name);
        return false;
    }
    memset(out, 0, sizeof *out);
    return true;
}

/* body() with whatever escapes it turned into "<name>: out of memory" or
 * "<name>: unexpected error" and -1, the scene freed: nothing is thrown into C. */
template <class F> int guarded(const char *name, lpv_scene *out, char *err, size_t err_size, F body)
{
    try {
        return body();
    } catch (const std::bad_alloc &) {
        if (err && err_size)
            snprintf(err, err_size, "%s: out of memory", name);
    } catch (...) {
        if (err && err_size)
            snprintf(err, err_size, "%s: unexpected error", name);
    }
    lpv_scene_free(out);
    return -1;
}

/* A file's load: the scene (posed by animation when it is given), or with
 * list the file's animations only (out then stays zeroed). */
int load_file(const char *path, const lpv_gltf_animation_time *animation, lpv_gltf_animation_list *list,
              lpv_scene *out, lpv_gltf_warnings *warnings, char *err, size_t err_size, bool user_paths = false)
{
    if (!begin_load(path ? path : "(null)", out, warnings, err, err_size))
        return -1;
    if (!path || !path[0]) {
        if (err && err_size)
            snprintf(err, err_size, "(null): no path given");
        return -1;
    }
    return guarded(path, out, err, err_size, [&]() {
        Ctx ctx;
        ctx.label = path;
        ctx.sink = warnings;
        ctx.animation = animation;
        ctx.animation_list = list;
        ctx.user_paths = user_paths;
        std::string p(path);
        size_t slash = p.find_last_of('/');
        std::string dir = slash == std::string::npos ? std::string(".")
                                                     : (slash == 0 ? std::string("/") : p.substr(0, slash));

        std::vector<unsigned char> data;
        std::string problem = read_main_file(path, &data);
        if (!problem.empty()) {
            set_error(err, err_size, ctx.label, problem);
            return -1;
        }
        /* the folder the user named (links and all); URIs open beneath it */
        ctx.dir_fd = open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
        ctx.allow_external = ctx.dir_fd >= 0;
        int rc = run_load(data.data(), data.size(), ctx, out, err, err_size);
        if (ctx.dir_fd >= 0)
            close(ctx.dir_fd);
        return rc < 0 ? -1 : rc;
    });
}

} // namespace

extern "C" int lpv_gltf_load_file(const char *path, lpv_scene *out, char *err, size_t err_size)
{
    return load_file(path, nullptr, nullptr, out, nullptr, err, err_size);
}

extern "C" int lpv_gltf_load_file_w(const char *path, lpv_scene *out, lpv_gltf_warnings *warnings, char *err,
                                    size_t err_size)
{
    return load_file(path, nullptr, nullptr, out, warnings, err, err_size);
}

extern "C" int lpv_gltf_load_file_animated(const char *path, const lpv_gltf_animation_time *at, lpv_scene *out,
                                           char *err, size_t err_size)
{
    return load_file(path, at, nullptr, out, nullptr, err, err_size);
}

extern "C" int lpv_gltf_load_file_animated_w(const char *path, const lpv_gltf_animation_time *at, lpv_scene *out,
                                             lpv_gltf_warnings *warnings, char *err, size_t err_size)
{
    return load_file(path, at, nullptr, out, warnings, err, err_size);
}

extern "C" int lpv_gltf_load_file_user(const char *path, const lpv_gltf_animation_time *at, lpv_scene *out,
                                       lpv_gltf_warnings *warnings, char *err, size_t err_size)
{
    return load_file(path, at, nullptr, out, warnings, err, err_size, true);
}

extern "C" int lpv_gltf_animations(const char *path, lpv_gltf_animation_list *out, char *err, size_t err_size)
{
    if (!out) {
        if (err && err_size)
            snprintf(err, err_size, "%s: no animation list to fill", path ? path : "(null)");
        return -1;
    }
    memset(out, 0, sizeof *out);
    lpv_scene unused; /* zeroed by begin_load, never filled */
    int rc = load_file(path, nullptr, out, &unused, nullptr, err, err_size);
    if (rc != 0)
        memset(out, 0, sizeof *out);
    return rc;
}

extern "C" int lpv_gltf_load_memory(const void *data, size_t size, const char *base_dir, const char *label,
                                    lpv_scene *out, char *err, size_t err_size)
{
    return lpv_gltf_load_memory_ex(data, size, base_dir, label, nullptr, 0, out, err, err_size);
}

extern "C" int lpv_gltf_load_memory_ex(const void *data, size_t size, const char *base_dir, const char *label,
                                       const lpv_gltf_node_override *nodes, size_t node_count, lpv_scene *out,
                                       char *err, size_t err_size)
{
    return lpv_gltf_load_memory_w(data, size, base_dir, label, nodes, node_count, out, nullptr, err, err_size);
}

extern "C" int lpv_gltf_load_memory_w(const void *data, size_t size, const char *base_dir, const char *label,
                                      const lpv_gltf_node_override *nodes, size_t node_count, lpv_scene *out,
                                      lpv_gltf_warnings *warnings, char *err, size_t err_size)
{
    const char *name = label && label[0] ? label : "<memory>";
    int fd = -1;
    if (base_dir) {
        fd = open(base_dir[0] ? base_dir : ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
        if (fd < 0) {
            int e = errno;
            if (!begin_load(name, out, warnings, err, err_size))
                return -1;
            if (err && err_size)
                snprintf(err, err_size, "%s: base folder: %s", name, strerror(e));
            return -1;
        }
    }
    int rc = lpv_gltf_load_at(data, size, fd, label, nodes, node_count, nullptr, out, warnings, err, err_size);
    if (fd >= 0)
        close(fd);
    return rc < 0 ? -1 : rc;
}

extern "C" int lpv_gltf_load_at(const void *data, size_t size, int base_fd, const char *label,
                                const lpv_gltf_node_override *nodes, size_t node_count, const lpv_gltf_limits *limits,
                                lpv_scene *out, lpv_gltf_warnings *warnings, char *err, size_t err_size)
{
    return lpv_gltf_load_at_posed(data, size, base_fd, label, nullptr, nodes, node_count, limits, out, warnings, err,
                                  err_size);
}

extern "C" int lpv_gltf_load_at_posed(const void *data, size_t size, int base_fd, const char *label,
                                      const lpv_gltf_animation_time *at, const lpv_gltf_node_override *nodes,
                                      size_t node_count, const lpv_gltf_limits *limits, lpv_scene *out,
                                      lpv_gltf_warnings *warnings, char *err, size_t err_size)
{
    const char *name = label && label[0] ? label : "<memory>";
    if (!begin_load(name, out, warnings, err, err_size))
        return LPV_GLTF_DEFECT;
    if (!data && size > 0) {
        if (err && err_size)
            snprintf(err, err_size, "%s: no data", name);
        return LPV_GLTF_DEFECT;
    }
    return guarded(name, out, err, err_size, [&]() {
        Ctx ctx;
        ctx.label = name;
        ctx.sink = warnings;
        ctx.overrides = nodes;
        ctx.override_count = nodes ? node_count : 0;
        ctx.animation = at;
        ctx.dir_fd = base_fd;
        ctx.allow_external = base_fd >= 0;
        if (limits) {
            if (limits->max_texture > 0 && limits->max_texture < ctx.max_side)
                ctx.max_side = limits->max_texture;
            if (limits->max_texels > 0 && limits->max_texels < ctx.max_texels)
                ctx.max_texels = limits->max_texels;
            if (limits->max_bytes > 0 && limits->max_bytes < ctx.max_bytes)
                ctx.max_bytes = limits->max_bytes;
        }
        static const unsigned char empty = 0;
        return run_load(size ? static_cast<const unsigned char *>(data) : &empty, size, ctx, out, err, err_size);
    });
}
