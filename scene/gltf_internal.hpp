/*
 * gltf_internal.hpp - what the files of the glTF adapter share (C++ only,
 * inside the scene library; the C API is gltf_load.h).
 *
 * One load runs through them in this order:
 *   gltf_load.cpp       the entry points, the tinygltf call, the hand-over
 *   gltf_files.cpp      the main file and every external URI (paths checked)
 *   gltf_container.cpp  size, format and the .glb container, before tinygltf
 *   gltf_schema.cpp     the JSON's syntax, depth and types, before tinygltf
 *   gltf_images.cpp     image size caps and decoding, tinygltf's callback
 *   gltf_build.cpp      the Builder: the node forest walked into draws
 *   gltf_animation.cpp  animations sampled at a time into node overrides
 *   gltf_transform.cpp  node transforms and the caller's node overrides
 *   gltf_accessor.cpp   buffer views and accessors, every range checked
 *   gltf_mesh.cpp       primitives into world-space triangles (morphed, skinned)
 *   gltf_material.cpp   materials and their textures
 *   gltf_lights_cameras.cpp  KHR_lights_punctual and cameras
 *   gltf_medium.cpp     lpvd_medium from the raw JSON
 *   gltf_messages.cpp   message formatting, failures and warnings
 * beside the helpers with their own headers (gltf_compressed.hpp,
 * gltf_features.hpp).
 *
 * Errors travel as a Failure exception inside the adapter and leave it in
 * gltf_load.cpp as "<path or label>: <problem>" and -1; nothing is thrown
 * into C.
 */
#ifndef LPV_GLTF_INTERNAL_HPP
#define LPV_GLTF_INTERNAL_HPP

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <tiny_gltf.h>

extern "C" {
#include "scene.h"
}
#include "gltf_load.h"

namespace lpv_gltf {

/* ---- limits ---------------------------------------------------------------- */
constexpr uint64_t kMaxTriangles = uint64_t(1) << 24;     /* 16M triangles */
constexpr uint64_t kMaxVertices = 3 * kMaxTriangles;      /* flat normals un-share */
constexpr uint64_t kMaxAccessorCount = 3 * kMaxTriangles; /* elements of one accessor */
constexpr int kMaxTextureSize = 16384;                    /* texels per side */
constexpr uint64_t kMaxTotalTexels = uint64_t(1) << 29;   /* 2 GiB of RGBA8 */
constexpr uint64_t kMaxFileBytes = uint64_t(1) << 30;     /* main file and each external file */
constexpr uint64_t kMaxSceneBytes = uint64_t(1) << 34;    /* RAM of one load (lpv_gltf_limits.max_bytes) */
constexpr int kMaxJsonDepth = 256;
constexpr int kMaxNodeDepth = 64;
constexpr size_t kMaxWarnings = LPV_GLTF_WARNINGS_MAX;

/* ---- messages (gltf_messages.cpp) ------------------------------------------ */
struct Failure {
    std::string msg;
    int code = LPV_GLTF_DEFECT; /* or the LPV_GLTF_OVER_* of the limit that refused the file */
};

std::string strf(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* Throws Failure with the formatted message. */
[[noreturn]] void fail(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* tinygltf's multi-line messages as one line. */
std::string one_line(const std::string &s);
/* A name taken from the file (an extension, attribute or type name) for a
 * message: shown only when it is an identifier (letters, digits, '_', at most
 * 64), else described, so that no message echoes arbitrary file contents. */
std::string show(const std::string &s);
/* An external URI as the file gives it, shortened and kept printable: the
 * one string from the file that messages quote (it names the file at fault). */
std::string show_uri(const std::string &s);

/* ---- load context, shared with tinygltf's callbacks ------------------------- */
struct Ctx {
    std::string label;
    bool allow_external = false; /* false for memory loads without a base folder */
    bool user_paths = false;     /* the invoking user's own files (lpv_gltf_load_file_user): URIs may be
                                    absolute or leave the folder, as any program the user runs reads them */
    int dir_fd = -1;             /* the scene's folder: external URIs open beneath it (open_beneath.h) */
    std::string refusal;         /* first security refusal: always fatal */
    std::string missing;         /* first external file that could not be read */
    std::string image_error;     /* fatal image problem (undecodable, bad range) */
    const tinygltf::Model *model = nullptr;
    /* Budgets (lpv_gltf_limits, 0 fields replaced by the caps above) and what
     * the file needs of them so far; once over one, nothing more is read or
     * decoded but the sizes from the headers are still summed for the message. */
    int max_side = kMaxTextureSize;
    uint64_t max_texels = kMaxTotalTexels;
    uint64_t max_bytes = kMaxSceneBytes;
    uint64_t texels = 0; /* decoded texels of every image, from their headers */
    uint64_t bytes = 0;  /* the file, external files and RGBA8 texels */
    int over = 0;        /* the first LPV_GLTF_OVER_* hit, 0 none */
    std::string over_what; /* for OVER_TEXTURE: "image 3 is 16384x16384 texels" */
    bool over_budget() const { return over != 0; }
    std::vector<std::string> warnings; /* each line once */
    size_t warnings_dropped = 0;       /* past kMaxWarnings */
    const lpv_gltf_node_override *overrides = nullptr; /* lpv_gltf_load_memory_ex */
    size_t override_count = 0;
    const lpv_gltf_animation_time *animation = nullptr; /* lpv_gltf_load_file_animated: the pose to sample */
    lpv_gltf_animation_list *animation_list = nullptr;   /* lpv_gltf_animations: list them, build nothing */
    std::vector<int> played;                             /* the animations applied (for the warnings) */
    lpv_gltf_warnings *sink = nullptr; /* NULL: warnings go to stderr */

    void warn(const std::string &w); /* gltf_messages.cpp */
};

/* ---- files (gltf_files.cpp) ------------------------------------------------- */
/* Routes every file access of tinygltf through checks that keep it inside
 * ctx's folder (or refuse it for memory loads without one). */
void set_fs_callbacks(tinygltf::TinyGLTF &loader, Ctx *ctx);
/* The folder tinygltf is told external URIs lie in: a tag, never a real path,
 * so that none of its messages can name one (the files open beneath dir_fd). */
extern const char *const kBaseTag;
/* Counts n more bytes of RAM against the budget; false once over it. */
bool take_bytes(Ctx &ctx, uint64_t n);
/* The main file's bytes into *data; "" or the problem (for "<path>: ..."). */
std::string read_main_file(const char *path, std::vector<unsigned char> *data);

/* ---- container and images (gltf_container.cpp, gltf_images.cpp) ------------- */
/* Checks size, format (glb magic or JSON) and the .glb container; returns
 * whether it is a .glb, and where its JSON lies. */
bool check_container(const unsigned char *data, size_t size, size_t *json_off, size_t *json_len);
/* One SAX pass over the JSON (no DOM) before tinygltf sees it
 * (gltf_schema.cpp): refuses invalid syntax, nesting deeper than
 * kMaxJsonDepth (tinygltf's recursive extras/extensions parser never sees a
 * hostile depth), and fields lpvd reads whose JSON type is wrong for the
 * glTF 2.0 schema, naming the JSON path; a name that is not a string is a
 * warning. */
void check_schema_types(const char *json, size_t len, Ctx &ctx);
/* Compressed files as tinygltf 2.7 accepts them (gltf_compressed.hpp,
 * tinygltf_compat_json): when the file needs it, *rewritten gets the file with
 * its JSON rewritten (a .glb's BIN chunk kept) and true is returned. */
bool tinygltf_compat_file(const unsigned char *data, size_t size, bool is_glb, size_t json_off, size_t json_len,
                          std::vector<unsigned char> *rewritten);
/* tinygltf's image callback (user data: the Ctx): sizes from the headers,
 * counted against the budgets; the bytes are kept encoded (component 0). */
bool image_loader(tinygltf::Image *image, const int image_idx, std::string *err, std::string *warn, int req_width,
                  int req_height, const unsigned char *bytes, int size, void *user);
/* Decodes every image image_loader kept to RGBA8; an undecodable one fails. */
void decode_images(tinygltf::Model &model);
/* tinygltf's messages as one line, without the names it quotes from the file. */
std::string tinygltf_text(const std::string &s);

/* ---- transforms (gltf_transform.cpp; column-major, like glTF) --------------- */
struct Mat4 {
    double m[16];
};
Mat4 identity();
Mat4 mul(const Mat4 &a, const Mat4 &b);
void xform_point(const Mat4 &a, const double p[3], double out[3]);
void xform_dir(const Mat4 &a, const double v[3], double out[3]);
double det3(const Mat4 &a);
/* The normal matrix: the inverse-transpose of the upper 3x3, up to a positive
 * scale. Row-major 3x3. */
void normal_matrix(const Mat4 &a, double n[9]);
bool normalize3(double v[3]);
bool finite_all(const std::vector<double> &v);
/* Node `index`'s local transform (matrix or TRS), every number checked. */
Mat4 node_local(const tinygltf::Node &n, int index);
/* The caller's node overrides (lpv_gltf_load_memory_ex) applied to model. */
void apply_node_overrides(tinygltf::Model &model, const lpv_gltf_node_override *o, size_t count);

/* ---- the medium (gltf_medium.cpp) ------------------------------------------- */
/* The medium of the scene that is loaded (scenes[scene].extras.lpvd_medium),
 * else of the document (extras.lpvd_medium). json is the file's JSON text. */
void read_medium(const char *json, size_t len, const tinygltf::Model &model, Ctx &ctx, lpv_medium &m,
                 std::vector<float> &values);

/* A name from the file into a fixed-size scene name (gltf_messages.cpp). */
void copy_name(char *dst, const std::string &src, const std::string &fallback);

/* How a mesh instance is deformed (glTF 2.0 "Skins", "Morph targets"): its
 * morph weights (the node's, else the mesh's; missing ones 0) and, for a
 * skinned node, each joint's skinning matrix world(joint) x its inverse bind
 * matrix (a primitive with joints then ignores the node's own transform). */
struct Deform {
    std::vector<double> weights;
    std::vector<Mat4> joints; /* empty: not skinned */
};

/* ---- the builder: tinygltf's model into the scene's arrays ------------------- */
class Builder {
  public:
    Builder(const tinygltf::Model &model, Ctx &ctx) : m_(model), ctx_(ctx) {}

    void build(); /* gltf_build.cpp */

    /* gltf_animation.cpp: the node overrides that pose the model at `at`
     * and the morph weights its "weights" channels give nodes (every channel
     * the chosen animations play checked first; the indices of those
     * animations go to ctx.played), and the file's animations, each checked
     * the same way. */
    std::vector<lpv_gltf_node_override> sample_animations(const lpv_gltf_animation_time &at,
                                                          std::vector<std::pair<int, std::vector<double>>> &weights);
    void list_animations(lpv_gltf_animation_list &out);

    std::vector<lpv_vertex> vertices;
    std::vector<uint32_t> indices;
    std::vector<lpv_draw> draws;
    std::vector<uint32_t> wire_indices; /* points and lines (lpv_scene.wire_draws) */
    std::vector<lpv_draw> wire_draws;
    std::vector<lpv_material> materials;
    std::vector<lpv_light> lights;
    std::vector<lpv_camera> cameras;
    /* Owned RGBA8 pixels (malloc) until handed to the scene. */
    std::vector<lpv_texture> textures;

    ~Builder();
    Builder(const Builder &) = delete;
    Builder &operator=(const Builder &) = delete;

  private:
    const tinygltf::Model &m_;
    Ctx &ctx_;
    int default_material_ = -1;
    std::map<std::pair<int, int>, int> image_texture_; /* (glTF image, linear) -> index in textures (-1: unusable) */
    std::vector<unsigned char> visited_;
    std::vector<Mat4> node_world_; /* every node's world transform (joints may lie outside the scene's tree) */
    std::map<int, std::vector<unsigned char>> meshopt_; /* bufferView -> its EXT_meshopt_compression data */
    std::vector<unsigned char> material_uv1_;            /* material index -> some texture reads TEXCOORD_1 */

    /* A validated byte range of a buffer view. */
    struct View {
        const unsigned char *data;
        size_t length;
        size_t stride;
    };
    /* gltf_accessor.cpp */
    View view(int bv_index, const char *what, int owner);
    template <class T> void read_accessor(int index, int want_ncomp, const char *what, std::vector<T> &out);
    void read_indices(int index, std::vector<uint32_t> &out);
    void check_buffer_views();
    /* gltf_animation.cpp: one animation's channels and samplers, read and
     * checked (defined there). */
    struct Animation;
    void read_animation(size_t index, Animation &out);
    void read_animation_parts(size_t index, Animation &out);
    /* gltf_build.cpp */
    void check_node_graph();
    void visit(int node, const Mat4 &parent, int depth);
    void compute_node_worlds();
    Deform deform_of(int node);
    void add_mesh(int mesh, const Mat4 &world, const Deform &d);
    /* gltf_material.cpp */
    void convert_materials();
    int texture_for(int material_index, const char *what, int index, bool linear);
    void texture_uv(int material_index, const char *what, int tex_coord, const tinygltf::ExtensionMap &ext,
                    lpv_uv_transform *out);
    int default_material();
    /* gltf_mesh.cpp */
    void add_primitive(const tinygltf::Primitive &p, int mesh, int prim, const Mat4 &world, const Deform &d);
    /* gltf_lights_cameras.cpp */
    void add_light(int node, int light, const Mat4 &world);
    void add_camera(int node, int camera, const Mat4 &world);
};

} // namespace lpv_gltf

#endif
