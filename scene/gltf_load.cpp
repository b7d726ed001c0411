/*
 * gltf_load.cpp - glTF 2.0 into an lpv_scene through tinygltf (gltf_load.h).
 *
 * tinygltf parses the JSON and fetches buffers and images; everything it does
 * not check is checked here before it is used:
 *   - the .glb container is validated completely before tinygltf sees it
 *     (tinygltf 2.7's own chunk checks are off by the 8-byte chunk header);
 *   - the JSON is pre-scanned (SAX, no DOM) for syntax and nesting depth, so
 *     tinygltf's recursive extras/extensions parser never sees a hostile depth;
 *   - every file access goes through our FsCallbacks, which refuse ".."
 *     components, absolute paths and anything whose realpath leaves the
 *     scene's folder before a single byte is read;
 *   - images are decoded by our own loader callback (stb, as tinygltf would)
 *     after the size cap and the bufferView range are checked;
 *   - accessors, buffer views, sparse data, indices, node graphs and limits
 *     are checked here, never trusted.
 * Errors travel as a C++ exception inside this file and leave it as
 * "<path or label>: <problem>" and -1; nothing is thrown into C.
 * Units: glTF's photometric values are divided by LPV_LUMENS_PER_WATT
 * (docs/units.md).
 */
#include <tiny_gltf.h>
#include <nlohmann/json.hpp>
#include <stb_image.h>

extern "C" {
#include "scene.h"
}
#include "gltf_load.h"
#include "gltf_compressed.hpp"
#include "gltf_features.hpp"
#include "gltf_material.hpp"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <initializer_list>
#include <limits>
#include <map>
#include <new>
#include <string>
#include <sys/stat.h>
#include <unistd.h>
#include <vector>

namespace {

/* ---- limits ---------------------------------------------------------------- */
constexpr uint64_t kMaxTriangles = uint64_t(1) << 24;         /* 16M triangles */
constexpr uint64_t kMaxVertices = 3 * kMaxTriangles;          /* flat normals un-share */
constexpr uint64_t kMaxAccessorCount = 3 * kMaxTriangles;     /* elements of one accessor */
constexpr int kMaxTextureSize = 16384;                        /* texels per side */
constexpr uint64_t kMaxTotalTexels = uint64_t(1) << 29;       /* 2 GiB of RGBA8 */
constexpr uint64_t kMaxFileBytes = uint64_t(1) << 30;         /* main file and each external file */
constexpr int kMaxJsonDepth = 256;
constexpr int kMaxNodeDepth = 64;
constexpr size_t kMaxWarnings = LPV_GLTF_WARNINGS_MAX;

/* ---- errors ---------------------------------------------------------------- */
struct Failure {
    std::string msg;
};

std::string vformat(const char *fmt, va_list ap)
{
    va_list ap2;
    va_copy(ap2, ap);
    int n = vsnprintf(nullptr, 0, fmt, ap2);
    va_end(ap2);
    if (n < 0)
        return std::string(fmt);
    std::string s(size_t(n) + 1, '\0');
    vsnprintf(&s[0], s.size(), fmt, ap);
    s.resize(size_t(n));
    return s;
}

std::string strf(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
std::string strf(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    std::string s = vformat(fmt, ap);
    va_end(ap);
    return s;
}

[[noreturn]] void fail(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
[[noreturn]] void fail(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    std::string s = vformat(fmt, ap);
    va_end(ap);
    throw Failure{s};
}

/* tinygltf's multi-line messages as one line. */
std::string one_line(const std::string &s)
{
    std::string out;
    bool sep = false;
    for (char c : s) {
        if (c == '\n' || c == '\r') {
            sep = !out.empty();
            continue;
        }
        if (sep) {
            out += "; ";
            sep = false;
        }
        out += c;
    }
    return out;
}

/* Shortens a value taken from the file for a message (and keeps it printable). */
std::string show(const std::string &s)
{
    std::string out = "\"";
    size_t n = 0;
    for (unsigned char c : s) {
        if (n++ >= 80) {
            out += "...";
            break;
        }
        if (c < 0x20 || c == 0x7f)
            out += strf("\\x%02x", c);
        else
            out += char(c);
    }
    out += "\"";
    return out;
}

/* ---- load context, shared with tinygltf's callbacks ------------------------- */
struct Ctx {
    std::string label;
    bool allow_external = false; /* false for memory loads without base_dir */
    std::string base_dir;        /* as handed to tinygltf */
    std::string root_real;       /* realpath(base_dir) */
    std::string refusal;         /* first security refusal: always fatal */
    std::string missing;         /* first external file that could not be read */
    std::string image_error;     /* fatal image problem (size cap, bad range) */
    const tinygltf::Model *model = nullptr;
    uint64_t texels = 0;
    std::vector<std::string> warnings; /* each line once */
    size_t warnings_dropped = 0;       /* past kMaxWarnings */
    const lpv_gltf_node_override *overrides = nullptr; /* lpv_gltf_load_memory_ex */
    size_t override_count = 0;
    lpv_gltf_warnings *sink = nullptr; /* NULL: warnings go to stderr */

    void warn(const std::string &w)
    {
        if (std::find(warnings.begin(), warnings.end(), w) != warnings.end())
            return;
        if (warnings.size() < kMaxWarnings)
            warnings.push_back(w);
        else
            warnings_dropped++;
    }
};

bool inside_root(const std::string &root, const std::string &p)
{
    if (root == "/")
        return p.size() > 1 && p[0] == '/';
    return p.size() > root.size() + 1 && p.compare(0, root.size(), root) == 0 && p[root.size()] == '/';
}

enum PathCheck { PATH_OK, PATH_REFUSED, PATH_MISSING };

/* Decides whether tinygltf may touch `candidate` (= base_dir joined with the
 * URI, already percent-decoded) and resolves it. Nothing is opened here. */
PathCheck check_external(Ctx *ctx, const std::string &candidate, std::string *resolved)
{
    if (!ctx->allow_external) {
        if (ctx->refusal.empty())
            ctx->refusal = "external URI " + show(candidate) +
                           " refused: data loaded from memory without a base folder may only use "
                           "data: URIs and the GLB BIN chunk (anything else would be outside)";
        return PATH_REFUSED;
    }
    std::string prefix = ctx->base_dir;
    if (prefix.empty() || prefix.back() != '/')
        prefix += '/';
    if (candidate.compare(0, prefix.size(), prefix) != 0) {
        /* tinygltf's second search path, the working directory: never used,
         * and not worth a message (the first path, the folder, has one). */
        return PATH_MISSING;
    }
    std::string rel = candidate.substr(prefix.size());
    if (rel.empty()) {
        if (ctx->missing.empty())
            ctx->missing = "a buffer or image has an empty URI (no data)";
        return PATH_MISSING;
    }
    if (rel.find('\0') != std::string::npos) {
        if (ctx->refusal.empty())
            ctx->refusal = "external URI " + show(rel) + " contains a NUL byte (refused)";
        return PATH_REFUSED;
    }
    if (rel[0] == '/') {
        if (ctx->refusal.empty())
            ctx->refusal = "external URI " + show(rel) +
                           " is an absolute path, outside the scene's folder (refused)";
        return PATH_REFUSED;
    }
    size_t start = 0;
    while (start <= rel.size()) {
        size_t end = rel.find('/', start);
        if (end == std::string::npos)
            end = rel.size();
        if (rel.compare(start, end - start, "..") == 0 && end - start == 2) {
            if (ctx->refusal.empty())
                ctx->refusal = "external URI " + show(rel) +
                               " leaves the scene's folder through \"..\" (outside; refused)";
            return PATH_REFUSED;
        }
        start = end + 1;
    }
    char *real = realpath(candidate.c_str(), nullptr);
    if (!real) {
        int e = errno;
        if (ctx->missing.empty())
            ctx->missing = "external file " + show(rel) +
                           (e == ENOENT ? std::string(" not found") : " cannot be resolved: " + std::string(strerror(e)));
        return PATH_MISSING;
    }
    std::string r(real);
    free(real);
    if (!inside_root(ctx->root_real, r)) {
        if (ctx->refusal.empty())
            ctx->refusal = "external URI " + show(rel) + " resolves to " + show(r) +
                           ", outside the scene's folder (symbolic link?; refused)";
        return PATH_REFUSED;
    }
    struct stat st;
    if (stat(r.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) {
        if (ctx->missing.empty())
            ctx->missing = "external file " + show(rel) + " is not a regular file";
        return PATH_MISSING;
    }
    *resolved = r;
    return PATH_OK;
}

std::string fs_expand(const std::string &path, void *)
{
    return path; /* no ~ or $VAR expansion (tinygltf's default runs wordexp) */
}

bool fs_exists(const std::string &path, void *user)
{
    std::string resolved;
    return check_external(static_cast<Ctx *>(user), path, &resolved) == PATH_OK;
}

bool fs_read(std::vector<unsigned char> *out, std::string *err, const std::string &path, void *user)
{
    Ctx *ctx = static_cast<Ctx *>(user);
    std::string resolved;
    if (check_external(ctx, path, &resolved) != PATH_OK) {
        if (err)
            *err += "refused or missing";
        return false;
    }
    int fd = open(resolved.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
    if (fd < 0) {
        if (ctx->missing.empty())
            ctx->missing = "external file " + show(path) + " cannot be opened: " + strerror(errno);
        return false;
    }
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || uint64_t(st.st_size) > kMaxFileBytes) {
        close(fd);
        if (ctx->missing.empty())
            ctx->missing = "external file " + show(path) + " is not a regular file or larger than " +
                           std::to_string(kMaxFileBytes) + " bytes";
        return false;
    }
    try {
        out->resize(size_t(st.st_size));
    } catch (...) {
        close(fd);
        throw;
    }
    size_t got = 0;
    while (got < out->size()) {
        ssize_t n = read(fd, out->data() + got, out->size() - got);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            break;
        got += size_t(n);
    }
    close(fd);
    if (got != out->size()) {
        if (ctx->missing.empty())
            ctx->missing = "external file " + show(path) + " could not be read completely";
        out->clear();
        return false;
    }
    return true;
}

bool fs_write(std::string *err, const std::string &, const std::vector<unsigned char> &, void *)
{
    if (err)
        *err += "lpvd never writes glTF files";
    return false;
}

uint32_t be32(const unsigned char *p)
{
    return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}

/* Width and height from a PNG's IHDR or a JPEG's SOF marker, without decoding.
 * Dimensions beyond INT_MAX come back as INT_MAX. */
bool image_header_size(const unsigned char *d, size_t n, int *w, int *h)
{
    auto clamp = [](uint32_t v) { return v > uint32_t(INT_MAX) ? INT_MAX : int(v); };
    static const unsigned char png_sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (n >= 24 && memcmp(d, png_sig, 8) == 0 && memcmp(d + 12, "IHDR", 4) == 0) {
        *w = clamp(be32(d + 16));
        *h = clamp(be32(d + 20));
        return true;
    }
    if (n >= 4 && d[0] == 0xFF && d[1] == 0xD8) {
        size_t i = 2;
        while (i + 4 <= n) {
            if (d[i] != 0xFF)
                return false;
            unsigned char m = d[i + 1];
            if (m == 0xFF) { /* fill byte */
                i++;
                continue;
            }
            if (m == 0x01 || (m >= 0xD0 && m <= 0xD8)) { /* no payload */
                i += 2;
                continue;
            }
            if (m == 0xD9 || m == 0xDA) /* end of image, start of scan */
                return false;
            size_t len = size_t(d[i + 2]) << 8 | d[i + 3];
            if (len < 2)
                return false;
            bool sof = m >= 0xC0 && m <= 0xCF && m != 0xC4 && m != 0xC8 && m != 0xCC;
            if (sof) {
                if (i + 9 > n || len < 7)
                    return false;
                *h = int(size_t(d[i + 5]) << 8 | d[i + 6]);
                *w = int(size_t(d[i + 7]) << 8 | d[i + 8]);
                return true;
            }
            i += 2 + len;
        }
    }
    return false;
}

/* Decodes an image to RGBA8 with stb after checking its size, and checks an
 * image's bufferView range, which tinygltf 2.7 does not. Undecodable images
 * are kept without pixels (a warning; the texture is then ignored). */
bool image_loader(tinygltf::Image *image, const int image_idx, std::string *err, std::string *,
                  int, int, const unsigned char *bytes, int size, void *user)
{
    Ctx *ctx = static_cast<Ctx *>(user);
    if (image->bufferView >= 0) {
        const tinygltf::Model *m = ctx->model;
        bool ok = m && size_t(image->bufferView) < m->bufferViews.size();
        if (ok) {
            const tinygltf::BufferView &bv = m->bufferViews[size_t(image->bufferView)];
            ok = bv.buffer >= 0 && size_t(bv.buffer) < m->buffers.size();
            if (ok) {
                size_t have = m->buffers[size_t(bv.buffer)].data.size();
                ok = bv.byteOffset <= have && bv.byteLength <= have - bv.byteOffset &&
                     bv.byteLength <= size_t(INT_MAX);
            }
        }
        if (!ok) {
            if (ctx->image_error.empty())
                ctx->image_error = strf("image %d: its bufferView %d is out of range of its buffer", image_idx,
                                          image->bufferView);
            if (err)
                *err += ctx->image_error;
            return false;
        }
    }
    if (!bytes || size <= 0) {
        ctx->warn(strf("image %d has no data; texture ignored", image_idx));
        return true;
    }
    int w = 0, h = 0, comp = 0;
    /* Our own reading of PNG and JPEG headers first: stb refuses some large
     * images itself and would make them look merely corrupt. */
    if (image_header_size(bytes, size_t(size), &w, &h) &&
        (w < 1 || h < 1 || w > kMaxTextureSize || h > kMaxTextureSize)) {
        if (ctx->image_error.empty())
            ctx->image_error = strf("image %d is %dx%d texels, over the %dx%d texture limit (absurd size)",
                                    image_idx, w, h, kMaxTextureSize, kMaxTextureSize);
        if (err)
            *err += ctx->image_error;
        return false;
    }
    if (!stbi_info_from_memory(bytes, size, &w, &h, &comp)) {
        ctx->warn(strf("image %d: unsupported or corrupt image data (%s); texture ignored", image_idx,
                         stbi_failure_reason() ? stbi_failure_reason() : "unknown"));
        return true;
    }
    if (w < 1 || h < 1 || w > kMaxTextureSize || h > kMaxTextureSize) {
        if (ctx->image_error.empty())
            ctx->image_error = strf("image %d is %dx%d texels, over the %dx%d texture limit (absurd size)",
                                      image_idx, w, h, kMaxTextureSize, kMaxTextureSize);
        if (err)
            *err += ctx->image_error;
        return false;
    }
    if (ctx->texels + uint64_t(w) * uint64_t(h) > kMaxTotalTexels) {
        if (ctx->image_error.empty())
            ctx->image_error = strf("image %d: the textures together exceed %llu texels (absurd size)", image_idx,
                                      (unsigned long long)kMaxTotalTexels);
        if (err)
            *err += ctx->image_error;
        return false;
    }
    int w2 = 0, h2 = 0, comp2 = 0;
    unsigned char *px = stbi_load_from_memory(bytes, size, &w2, &h2, &comp2, 4);
    if (!px || w2 != w || h2 != h) {
        if (px)
            stbi_image_free(px);
        ctx->warn(strf("image %d could not be decoded (%s); texture ignored", image_idx,
                         stbi_failure_reason() ? stbi_failure_reason() : "size changed"));
        return true;
    }
    try {
        image->image.assign(px, px + size_t(w) * size_t(h) * 4);
    } catch (...) {
        stbi_image_free(px);
        throw;
    }
    stbi_image_free(px);
    image->width = w;
    image->height = h;
    image->component = 4;
    image->bits = 8;
    image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    ctx->texels += uint64_t(w) * uint64_t(h);
    return true;
}

/* ---- JSON pre-scan: syntax and depth, without building anything ------------ */
struct JsonScan : nlohmann::json_sax<nlohmann::json> {
    int depth = 0;
    bool too_deep = false;
    std::string error;

    bool push()
    {
        if (++depth > kMaxJsonDepth) {
            too_deep = true;
            return false;
        }
        return true;
    }
    bool null() override { return true; }
    bool boolean(bool) override { return true; }
    bool number_integer(number_integer_t) override { return true; }
    bool number_unsigned(number_unsigned_t) override { return true; }
    bool number_float(number_float_t, const string_t &) override { return true; }
    bool string(string_t &) override { return true; }
    bool binary(binary_t &) override { return true; }
    bool start_object(std::size_t) override { return push(); }
    bool key(string_t &) override { return true; }
    bool end_object() override
    {
        --depth;
        return true;
    }
    bool start_array(std::size_t) override { return push(); }
    bool end_array() override
    {
        --depth;
        return true;
    }
    bool parse_error(std::size_t, const std::string &, const nlohmann::detail::exception &ex) override
    {
        error = ex.what();
        return false;
    }
};

void scan_json(const char *text, size_t len)
{
    JsonScan scan;
    bool ok = nlohmann::json::sax_parse(text, text + len, &scan);
    if (scan.too_deep)
        fail("JSON nested deeper than %d levels (refused)", kMaxJsonDepth);
    if (!ok)
        fail("invalid JSON: %s", scan.error.empty() ? "parse error" : scan.error.c_str());
}

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

/* ---- matrices (column-major, like glTF) ------------------------------------ */
struct Mat4 {
    double m[16];
};

Mat4 identity()
{
    Mat4 r{};
    r.m[0] = r.m[5] = r.m[10] = r.m[15] = 1.0;
    return r;
}

Mat4 mul(const Mat4 &a, const Mat4 &b)
{
    Mat4 r{};
    for (int c = 0; c < 4; c++)
        for (int row = 0; row < 4; row++) {
            double s = 0.0;
            for (int k = 0; k < 4; k++)
                s += a.m[k * 4 + row] * b.m[c * 4 + k];
            r.m[c * 4 + row] = s;
        }
    return r;
}

void xform_point(const Mat4 &a, const double p[3], double out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = a.m[r] * p[0] + a.m[4 + r] * p[1] + a.m[8 + r] * p[2] + a.m[12 + r];
}

void xform_dir(const Mat4 &a, const double v[3], double out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = a.m[r] * v[0] + a.m[4 + r] * v[1] + a.m[8 + r] * v[2];
}

double det3(const Mat4 &a)
{
    const double *m = a.m;
    return m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
           m[8] * (m[1] * m[6] - m[5] * m[2]);
}

/* The normal matrix: the inverse-transpose of the upper 3x3, up to a positive
 * scale (the cofactor matrix times the determinant's sign). Row-major 3x3. */
void normal_matrix(const Mat4 &a, double n[9])
{
    const double *m = a.m;
    /* A[r][c] = m[c*4+r]; cofactor C[r][c]. */
    auto A = [m](int r, int c) { return m[c * 4 + r]; };
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
            n[r * 3 + c] = A(r1, c1) * A(r2, c2) - A(r1, c2) * A(r2, c1);
        }
    double d = det3(a);
    if (d < 0.0)
        for (int i = 0; i < 9; i++)
            n[i] = -n[i];
}

bool normalize3(double v[3])
{
    double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(l > 0.0) || !std::isfinite(l))
        return false;
    v[0] /= l;
    v[1] /= l;
    v[2] /= l;
    return true;
}

bool finite_all(const std::vector<double> &v)
{
    for (double x : v)
        if (!std::isfinite(x))
            return false;
    return true;
}

Mat4 node_local(const tinygltf::Node &n, int index)
{
    if (!n.matrix.empty()) {
        if (n.matrix.size() != 16 || !finite_all(n.matrix))
            fail("node %d: \"matrix\" must hold 16 finite numbers", index);
        Mat4 r;
        for (int i = 0; i < 16; i++)
            r.m[i] = n.matrix[size_t(i)];
        return r;
    }
    double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
    if (!n.translation.empty()) {
        if (n.translation.size() != 3 || !finite_all(n.translation))
            fail("node %d: \"translation\" must hold 3 finite numbers", index);
        for (int i = 0; i < 3; i++)
            t[i] = n.translation[size_t(i)];
    }
    if (!n.rotation.empty()) {
        if (n.rotation.size() != 4 || !finite_all(n.rotation))
            fail("node %d: \"rotation\" must hold 4 finite numbers", index);
        double l = 0;
        for (int i = 0; i < 4; i++) {
            q[i] = n.rotation[size_t(i)];
            l += q[i] * q[i];
        }
        l = std::sqrt(l);
        if (l > 0 && std::isfinite(l))
            for (double &c : q)
                c /= l;
        else
            q[0] = q[1] = q[2] = 0, q[3] = 1;
    }
    if (!n.scale.empty()) {
        if (n.scale.size() != 3 || !finite_all(n.scale))
            fail("node %d: \"scale\" must hold 3 finite numbers", index);
        for (int i = 0; i < 3; i++)
            s[i] = n.scale[size_t(i)];
    }
    double x = q[0], y = q[1], z = q[2], w = q[3];
    double R[3][3] = {
        {1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
        {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
        {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)},
    };
    Mat4 r = identity();
    for (int c = 0; c < 3; c++)
        for (int row = 0; row < 3; row++)
            r.m[c * 4 + row] = R[row][c] * s[c];
    r.m[12] = t[0];
    r.m[13] = t[1];
    r.m[14] = t[2];
    return r;
}

/* ---- accessors ------------------------------------------------------------- */
size_t component_size(int ctype)
{
    switch (ctype) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
        return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
        return 4;
    default:
        return 0; /* INT and DOUBLE are not glTF 2.0 accessor types */
    }
}

int type_components(int type)
{
    switch (type) {
    case TINYGLTF_TYPE_SCALAR:
        return 1;
    case TINYGLTF_TYPE_VEC2:
        return 2;
    case TINYGLTF_TYPE_VEC3:
        return 3;
    case TINYGLTF_TYPE_VEC4:
        return 4;
    default:
        return 0;
    }
}

double read_component(const unsigned char *p, int ctype, bool normalized)
{
    switch (ctype) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
        int8_t v;
        memcpy(&v, p, 1);
        return normalized ? std::max(double(v) / 127.0, -1.0) : double(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
        uint8_t v;
        memcpy(&v, p, 1);
        return normalized ? double(v) / 255.0 : double(v);
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t v;
        memcpy(&v, p, 2);
        return normalized ? std::max(double(v) / 32767.0, -1.0) : double(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        memcpy(&v, p, 2);
        return normalized ? double(v) / 65535.0 : double(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v;
        memcpy(&v, p, 4);
        return normalized ? double(v) / 4294967295.0 : double(v);
    }
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float v;
        memcpy(&v, p, 4);
        return double(v);
    }
    default:
        return 0.0;
    }
}

const char *type_name(int ncomp)
{
    static const char *names[] = {"?", "SCALAR", "VEC2", "VEC3", "VEC4"};
    return ncomp >= 0 && ncomp <= 4 ? names[ncomp] : "?";
}

class Builder {
  public:
    Builder(const tinygltf::Model &model, Ctx &ctx) : m_(model), ctx_(ctx) {}

    void build();

    std::vector<lpv_vertex> vertices;
    std::vector<uint32_t> indices;
    std::vector<lpv_draw> draws;
    std::vector<lpv_material> materials;
    std::vector<lpv_light> lights;
    std::vector<lpv_camera> cameras;
    /* Owned RGBA8 pixels (malloc) until handed to the scene. */
    std::vector<lpv_texture> textures;

    ~Builder()
    {
        for (lpv_texture &t : textures)
            free(t.rgba8);
    }
    Builder(const Builder &) = delete;
    Builder &operator=(const Builder &) = delete;

  private:
    const tinygltf::Model &m_;
    Ctx &ctx_;
    int default_material_ = -1;
    std::map<std::pair<int, int>, int> image_texture_; /* (glTF image, linear) -> index in textures (-1: unusable) */
    std::vector<unsigned char> visited_;
    std::map<int, std::vector<unsigned char>> meshopt_; /* bufferView -> its EXT_meshopt_compression data */
    std::vector<unsigned char> material_uv1_;            /* material index -> some texture reads TEXCOORD_1 */

    /* A validated byte range of a buffer view. */
    struct View {
        const unsigned char *data;
        size_t length;
        size_t stride;
    };
    View view(int bv_index, const char *what, int owner);
    template <class T> void read_accessor(int index, int want_ncomp, const char *what, std::vector<T> &out);
    void read_indices(int index, std::vector<uint32_t> &out);

    void check_buffer_views();
    void check_node_graph();
    void convert_materials();
    int texture_for(int material_index, const char *what, int index, bool linear);
    void texture_uv(int material_index, const char *what, int tex_coord, const tinygltf::ExtensionMap &ext,
                    lpv_uv_transform *out);
    void visit(int node, const Mat4 &parent, int depth);
    void add_mesh(int mesh, const Mat4 &world);
    void add_primitive(const tinygltf::Primitive &p, int mesh, int prim, const Mat4 &world);
    void add_light(int node, int light, const Mat4 &world);
    void add_camera(int node, int camera, const Mat4 &world);
    int default_material();
};

void copy_name(char *dst, const std::string &src, const std::string &fallback)
{
    const std::string &s = src.empty() ? fallback : src;
    size_t n = std::min(s.size(), size_t(LPV_NAME_MAX - 1));
    /* Do not cut a UTF-8 sequence in half, and stop at an embedded NUL. */
    if (n < s.size())
        while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80)
            n--;
    size_t z = s.find('\0');
    if (z != std::string::npos && z < n)
        n = z;
    memcpy(dst, s.data(), n);
    dst[n] = '\0';
}

Builder::View Builder::view(int bv_index, const char *what, int owner)
{
    if (bv_index < 0 || size_t(bv_index) >= m_.bufferViews.size())
        fail("%s %d refers to bufferView %d, which does not exist (out of range)", what, owner, bv_index);
    const tinygltf::BufferView &bv = m_.bufferViews[size_t(bv_index)];
    if (bv.buffer < 0 || size_t(bv.buffer) >= m_.buffers.size())
        fail("bufferView %d refers to buffer %d, which does not exist (out of range)", bv_index, bv.buffer);
    if (bv.extensions.count("EXT_meshopt_compression")) {
        /* decoded once; the view's own range is the (maybe empty) fallback */
        auto it = meshopt_.find(bv_index);
        if (it == meshopt_.end()) {
            std::vector<unsigned char> data;
            size_t stride = 0;
            std::string e = lpv_gltf::meshopt_decode(m_, bv_index, size_t(kMaxFileBytes), &data, &stride);
            if (!e.empty())
                fail("%s", e.c_str());
            it = meshopt_.emplace(bv_index, std::move(data)).first;
        }
        return View{it->second.data(), it->second.size(), bv.byteStride};
    }
    const tinygltf::Buffer &b = m_.buffers[size_t(bv.buffer)];
    size_t have = b.data.size();
    if (bv.byteOffset > have || bv.byteLength > have - bv.byteOffset)
        fail("bufferView %d (offset %zu, length %zu) is out of range of buffer %d (%zu bytes)", bv_index,
             bv.byteOffset, bv.byteLength, bv.buffer, have);
    return View{b.data.data() + bv.byteOffset, bv.byteLength, bv.byteStride};
}

void Builder::check_buffer_views()
{
    for (size_t i = 0; i < m_.bufferViews.size(); i++)
        (void)view(int(i), "bufferView", int(i));
}

template <class T> void Builder::read_accessor(int index, int want_ncomp, const char *what, std::vector<T> &out)
{
    if (index < 0 || size_t(index) >= m_.accessors.size())
        fail("%s accessor %d does not exist (out of range)", what, index);
    const tinygltf::Accessor &a = m_.accessors[size_t(index)];
    int ncomp = type_components(a.type);
    if (ncomp != want_ncomp)
        fail("%s accessor %d must be %s", what, index, type_name(want_ncomp));
    size_t csize = component_size(a.componentType);
    if (csize == 0)
        fail("%s accessor %d has unsupported componentType %d", what, index, a.componentType);
    if (a.count > kMaxAccessorCount)
        fail("%s accessor %d: count %zu is over the limit of %llu elements (absurd size)", what, index, a.count,
             (unsigned long long)kMaxAccessorCount);
    const size_t elem = csize * size_t(ncomp);

    /* Every range is checked before anything is allocated or read. */
    View v = {nullptr, 0, 0};
    size_t stride = elem;
    if (a.bufferView >= 0) {
        v = view(a.bufferView, "accessor", index);
        stride = v.stride ? v.stride : elem;
        if (stride < elem)
            fail("accessor %d: byteStride %zu is smaller than its element (%zu bytes)", index, stride, elem);
        if (a.count > 0) {
            size_t span, end;
            if (__builtin_mul_overflow(a.count - 1, stride, &span) || __builtin_add_overflow(span, elem, &span) ||
                __builtin_add_overflow(span, a.byteOffset, &end))
                fail("accessor %d: count * stride overflows (out of range)", index);
            if (end > v.length)
                fail("accessor %d (offset %zu, count %zu, stride %zu) is out of range of bufferView %d (%zu bytes)",
                     index, a.byteOffset, a.count, stride, a.bufferView, v.length);
        }
    } else if (a.bufferView != -1) {
        fail("accessor %d refers to bufferView %d, which does not exist (out of range)", index, a.bufferView);
    }
    View iv = {nullptr, 0, 0}, vv = {nullptr, 0, 0};
    size_t ioff = 0, voff = 0, isize = 0;
    int ictype = 0;
    const int sc = a.sparse.isSparse ? a.sparse.count : 0;
    if (a.sparse.isSparse) {
        if (sc <= 0 || size_t(sc) > a.count)
            fail("accessor %d: sparse count %d is out of range (accessor count %zu)", index, sc, a.count);
        ictype = a.sparse.indices.componentType;
        isize = component_size(ictype);
        if (ictype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ictype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            ictype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            fail("accessor %d: sparse indices have unsupported componentType %d", index, ictype);
        iv = view(a.sparse.indices.bufferView, "sparse indices of accessor", index);
        vv = view(a.sparse.values.bufferView, "sparse values of accessor", index);
        if (a.sparse.indices.byteOffset < 0 || a.sparse.values.byteOffset < 0)
            fail("accessor %d: negative sparse byteOffset", index);
        ioff = size_t(a.sparse.indices.byteOffset);
        voff = size_t(a.sparse.values.byteOffset);
        if (ioff > iv.length || size_t(sc) * isize > iv.length - ioff)
            fail("accessor %d: sparse indices are out of range of bufferView %d", index, a.sparse.indices.bufferView);
        if (voff > vv.length || size_t(sc) * elem > vv.length - voff)
            fail("accessor %d: sparse values are out of range of bufferView %d", index, a.sparse.values.bufferView);
    }

    out.assign(a.count * size_t(ncomp), T(0));
    if (a.bufferView >= 0) {
        const unsigned char *base = v.data + a.byteOffset;
        for (size_t i = 0; i < a.count; i++)
            for (int c = 0; c < ncomp; c++)
                out[i * size_t(ncomp) + size_t(c)] =
                    T(read_component(base + i * stride + size_t(c) * csize, a.componentType, a.normalized));
    }

    if (a.sparse.isSparse) {
        for (size_t s = 0; s < size_t(sc); s++) {
            double di = read_component(iv.data + ioff + s * isize, ictype, false);
            if (!(di < double(a.count)))
                fail("accessor %d: sparse index %.0f is out of range (count %zu)", index, di, a.count);
            size_t target = size_t(di);
            for (int c = 0; c < ncomp; c++)
                out[target * size_t(ncomp) + size_t(c)] =
                    T(read_component(vv.data + voff + s * elem + size_t(c) * csize, a.componentType, a.normalized));
        }
    }
}

void Builder::read_indices(int index, std::vector<uint32_t> &out)
{
    if (index < 0 || size_t(index) >= m_.accessors.size())
        fail("indices accessor %d does not exist (out of range)", index);
    int ct = m_.accessors[size_t(index)].componentType;
    if (ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
        fail("indices accessor %d has componentType %d; indices must be UNSIGNED_BYTE, UNSIGNED_SHORT or "
             "UNSIGNED_INT",
             index, ct);
    /* Indices are never normalized; read_component only normalizes when asked. */
    std::vector<double> tmp;
    if (m_.accessors[size_t(index)].normalized)
        fail("indices accessor %d must not be normalized", index);
    read_accessor(index, 1, "indices", tmp);
    out.resize(tmp.size());
    for (size_t i = 0; i < tmp.size(); i++)
        out[i] = uint32_t(tmp[i]);
}

/* The hierarchy must be a forest: children in range, one parent at most, no
 * cycles, at most kMaxNodeDepth levels. tinygltf checks none of this. */
void Builder::check_node_graph()
{
    const size_t n = m_.nodes.size();
    std::vector<int> parent(n, -1);
    for (size_t i = 0; i < n; i++) {
        for (int c : m_.nodes[i].children) {
            if (c < 0 || size_t(c) >= n)
                fail("node %zu has child %d, which does not exist (out of range)", i, c);
            if (size_t(c) == i)
                fail("node %zu lists itself as its child (node cycle)", i);
            if (parent[size_t(c)] != -1)
                fail("node %d has more than one parent (nodes %d and %zu); the node graph must be a tree (cycle or "
                     "shared child)",
                     c, parent[size_t(c)], i);
            parent[size_t(c)] = int(i);
        }
    }
    /* Every node must lead up to a root within n steps; otherwise it hangs off
     * a cycle. Depth is checked while walking down from the roots. */
    std::vector<unsigned char> state(n, 0); /* 0 unknown, 1 reaches a root */
    std::vector<size_t> path;
    for (size_t i = 0; i < n; i++) {
        path.clear();
        size_t cur = i;
        while (state[cur] == 0 && parent[cur] != -1) {
            path.push_back(cur);
            if (path.size() > n)
                fail("node %zu is part of a node cycle", i);
            cur = size_t(parent[cur]);
        }
        state[cur] = 1;
        for (size_t p : path)
            state[p] = 1;
    }
    /* Depth from each root (iterative). */
    std::vector<std::pair<size_t, int>> stack;
    for (size_t i = 0; i < n; i++) {
        if (parent[i] != -1)
            continue;
        stack.push_back({i, 1});
        while (!stack.empty()) {
            auto [node, depth] = stack.back();
            stack.pop_back();
            if (depth > kMaxNodeDepth)
                fail("the node hierarchy under node %zu is deeper than %d levels", i, kMaxNodeDepth);
            for (int c : m_.nodes[node].children)
                stack.push_back({size_t(c), depth + 1});
        }
    }
}

int Builder::default_material()
{
    if (default_material_ < 0) {
        lpv_material mat;
        memset(&mat, 0, sizeof mat);
        copy_name(mat.name, "default", "default");
        mat.base_color[0] = mat.base_color[1] = mat.base_color[2] = mat.base_color[3] = 1.0f;
        mat.base_color_texture = -1;
        mat.normal_texture = -1;
        mat.metallic = 0.0f;
        mat.roughness = 1.0f;
        mat.double_sided = 0;
        mat.alpha_cutoff = 0.5f;
        mat.base_color_uv.scale[0] = mat.base_color_uv.scale[1] = 1.0f;
        mat.normal_uv.scale[0] = mat.normal_uv.scale[1] = 1.0f;
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
    std::string e = lpv_gltf::read_uv_transform(tex_coord, ext, out);
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
        memset(&mat, 0, sizeof mat);
        copy_name(mat.name, gm.name, strf("material%d", mi));
        const auto &pbr = gm.pbrMetallicRoughness;
        if (pbr.baseColorFactor.size() != 4 || !finite_all(pbr.baseColorFactor))
            fail("material %d: baseColorFactor must hold 4 finite numbers", mi);
        for (int k = 0; k < 4; k++)
            mat.base_color[k] = float(pbr.baseColorFactor[size_t(k)]);
        mat.base_color_texture = texture_for(mi, "baseColorTexture", pbr.baseColorTexture.index, false);
        texture_uv(mi, "baseColorTexture", pbr.baseColorTexture.texCoord, pbr.baseColorTexture.extensions,
                   &mat.base_color_uv);
        const tinygltf::NormalTextureInfo &nt = gm.normalTexture;
        mat.normal_texture = texture_for(mi, "normalTexture", nt.index, true);
        texture_uv(mi, "normalTexture", nt.texCoord, nt.extensions, &mat.normal_uv);
        if (!std::isfinite(nt.scale))
            fail("material %d: normalTexture.scale must be a finite number", mi);
        mat.normal_scale = float(nt.scale);
        std::string alpha = lpv_gltf::read_alpha(gm, &mat);
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
        materials.push_back(mat);
    }
}

void Builder::add_primitive(const tinygltf::Primitive &p, int mesh, int prim, const Mat4 &world)
{
    const int mode = p.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
        if (mode < TINYGLTF_MODE_POINTS || mode > TINYGLTF_MODE_TRIANGLE_FAN)
            ctx_.warn(strf("mesh %d primitive %d: unknown mode %d skipped", mesh, prim, mode));
        return; /* points and lines carry no surface */
    }
    auto pos_it = p.attributes.find("POSITION");
    if (pos_it == p.attributes.end()) {
        ctx_.warn(strf("mesh %d primitive %d has no POSITION; skipped", mesh, prim));
        return;
    }
    /* KHR_draco_mesh_compression: the attributes and indices come from the
     * Draco bitstream instead of the accessors (which hold no data). */
    lpv_gltf::DracoMesh draco;
    bool is_draco = false;
    auto dext = p.extensions.find("KHR_draco_mesh_compression");
    if (dext != p.extensions.end()) {
        const tinygltf::Value &d = dext->second;
        const tinygltf::Value none;
        const tinygltf::Value &bvv = d.IsObject() && d.Has("bufferView") ? d.Get("bufferView") : none;
        const tinygltf::Value &attrs = d.IsObject() && d.Has("attributes") ? d.Get("attributes") : none;
        if (!bvv.IsNumber() || !attrs.IsObject())
            fail("mesh %d primitive %d: KHR_draco_mesh_compression needs a bufferView and attributes", mesh, prim);
        std::map<std::string, int> ids, comps = {{"POSITION", 3}, {"NORMAL", 3}, {"TEXCOORD_0", 2},
                                                 {"TEXCOORD_1", 2}, {"TANGENT", 4}};
        for (const std::string &k : attrs.Keys()) {
            const tinygltf::Value &id = attrs.Get(k);
            double v = id.IsNumber() ? id.GetNumberAsDouble() : -1.0;
            if (!(v >= 0.0 && v <= double(INT_MAX)) || v != std::floor(v))
                fail("mesh %d primitive %d: KHR_draco_mesh_compression.attributes.%s must be an integer >= 0", mesh,
                     prim, show(k).c_str());
            ids[k] = int(v);
        }
        if (!ids.count("POSITION"))
            fail("mesh %d primitive %d: KHR_draco_mesh_compression has no POSITION attribute", mesh, prim);
        double bvd = bvv.GetNumberAsDouble();
        if (!(bvd >= 0.0 && bvd < double(m_.bufferViews.size())) || bvd != std::floor(bvd))
            fail("mesh %d primitive %d: KHR_draco_mesh_compression bufferView %g does not exist (out of range)", mesh,
                 prim, bvd);
        View dv = view(int(bvd), "KHR_draco_mesh_compression of mesh", mesh);
        std::string e = lpv_gltf::draco_decode(dv.data, dv.length, ids, comps, size_t(kMaxAccessorCount), &draco);
        if (!e.empty())
            fail("mesh %d primitive %d: %s", mesh, prim, e.c_str());
        is_draco = true;
    }
    /* One vertex attribute: from the Draco data, else its accessor. */
    char what[96];
    auto attribute = [&](const char *name, int ncomp, std::vector<float> &out) -> bool {
        auto it = p.attributes.find(name);
        if (is_draco) {
            auto d = draco.attributes.find(name);
            if (d != draco.attributes.end()) {
                out = d->second;
                return true;
            }
        }
        if (it == p.attributes.end())
            return false;
        snprintf(what, sizeof what, "mesh %d primitive %d %s", mesh, prim, name);
        if (is_draco && m_.accessors.size() > size_t(it->second) && m_.accessors[size_t(it->second)].bufferView < 0 &&
            !m_.accessors[size_t(it->second)].sparse.isSparse)
            return false; /* listed, but neither compressed nor stored: no data */
        read_accessor(it->second, ncomp, what, out);
        return true;
    };
    std::vector<float> pos;
    attribute("POSITION", 3, pos);
    const size_t nv = pos.size() / 3;
    for (size_t i = 0; i < pos.size(); i++)
        if (!std::isfinite(pos[i]))
            fail("mesh %d primitive %d: POSITION of vertex %zu is not finite (NaN or Inf)", mesh, prim, i / 3);

    std::vector<float> nrm, uv, uv1, tan;
    struct {
        const char *name;
        int ncomp;
        std::vector<float> *out;
    } extra[] = {{"NORMAL", 3, &nrm}, {"TEXCOORD_0", 2, &uv}, {"TEXCOORD_1", 2, &uv1}, {"TANGENT", 4, &tan}};
    for (const auto &a : extra)
        if (attribute(a.name, a.ncomp, *a.out) && a.out->size() / size_t(a.ncomp) != nv)
            fail("mesh %d primitive %d: %s has %zu elements but POSITION has %zu", mesh, prim, a.name,
                 a.out->size() / size_t(a.ncomp), nv);

    std::vector<uint32_t> idx;
    if (is_draco) {
        idx = draco.indices;
    } else if (p.indices >= 0) {
        read_indices(p.indices, idx);
    } else {
        idx.resize(nv);
        for (size_t i = 0; i < nv; i++)
            idx[i] = uint32_t(i);
    }
    for (size_t i = 0; i < idx.size(); i++)
        if (idx[i] >= nv)
            fail("mesh %d primitive %d: index %u at position %zu is out of range (vertex count %zu)", mesh, prim,
                 idx[i], i, nv);

    /* Triangle list in glTF's vertex order per mode. */
    std::vector<uint32_t> tri;
    const size_t ni = idx.size();
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        tri.assign(idx.begin(), idx.begin() + ptrdiff_t(ni - ni % 3));
    } else if (ni >= 3) {
        tri.reserve((ni - 2) * 3);
        for (size_t i = 0; i + 2 < ni; i++) {
            if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                size_t b = i + 1 + (i % 2), c = i + 2 - (i % 2);
                tri.insert(tri.end(), {idx[i], idx[b], idx[c]});
            } else {
                tri.insert(tri.end(), {idx[i + 1], idx[i + 2], idx[0]});
            }
        }
    }
    const size_t ntri = tri.size() / 3;
    if (ntri == 0)
        return;
    if (uint64_t(indices.size()) / 3 + ntri > kMaxTriangles)
        fail("more than %llu triangles (absurd size)", (unsigned long long)kMaxTriangles);

    int material;
    if (p.material >= 0) {
        if (size_t(p.material) >= m_.materials.size())
            fail("mesh %d primitive %d: material %d does not exist (out of range)", mesh, prim, p.material);
        material = p.material;
    } else {
        material = default_material();
    }

    if (uv1.empty() && size_t(material) < material_uv1_.size() && material_uv1_[size_t(material)])
        ctx_.warn(strf("material %d reads TEXCOORD_1, which mesh %d primitive %d lacks; (0, 0) is used there",
                       material, mesh, prim));

    const bool flip = det3(world) < 0.0;
    double nm[9];
    normal_matrix(world, nm);

    auto world_vertex = [&](size_t v, lpv_vertex &out) {
        double lp[3] = {pos[v * 3], pos[v * 3 + 1], pos[v * 3 + 2]}, wp[3];
        xform_point(world, lp, wp);
        for (int k = 0; k < 3; k++) {
            out.position[k] = float(wp[k]);
            if (!std::isfinite(out.position[k]))
                fail("mesh %d primitive %d: world position of vertex %zu is not finite (NaN or Inf)", mesh, prim, v);
        }
        out.uv[0] = uv.empty() ? 0.0f : uv[v * 2];
        out.uv[1] = uv.empty() ? 0.0f : uv[v * 2 + 1];
        if (!std::isfinite(out.uv[0]) || !std::isfinite(out.uv[1]))
            out.uv[0] = out.uv[1] = 0.0f;
        out.uv1[0] = uv1.empty() ? 0.0f : uv1[v * 2];
        out.uv1[1] = uv1.empty() ? 0.0f : uv1[v * 2 + 1];
        if (!std::isfinite(out.uv1[0]) || !std::isfinite(out.uv1[1]))
            out.uv1[0] = out.uv1[1] = 0.0f;
        /* TANGENT: xyz moves with the model matrix, w (handedness) flips with
         * a mirroring one; a degenerate or non-finite tangent is dropped (the
         * shader then builds its own frame) */
        out.tangent[0] = out.tangent[1] = out.tangent[2] = out.tangent[3] = 0.0f;
        if (!tan.empty()) {
            double lt[3] = {tan[v * 4], tan[v * 4 + 1], tan[v * 4 + 2]}, wt[3];
            xform_dir(world, lt, wt);
            const double w = tan[v * 4 + 3];
            if (normalize3(wt) && std::isfinite(w)) {
                for (int k = 0; k < 3; k++)
                    out.tangent[k] = float(wt[k]);
                out.tangent[3] = ((w < 0.0) != flip) ? -1.0f : 1.0f;
            }
        }
    };

    const uint64_t add_vertices = nrm.empty() ? uint64_t(ntri) * 3 : uint64_t(nv);
    if (uint64_t(vertices.size()) + add_vertices > kMaxVertices)
        fail("more than %llu vertices (absurd size)", (unsigned long long)kMaxVertices);

    lpv_draw draw;
    draw.first_index = uint32_t(indices.size());
    draw.index_count = uint32_t(ntri * 3);
    draw.material = material;

    if (!nrm.empty()) {
        const uint32_t base = uint32_t(vertices.size());
        vertices.resize(vertices.size() + nv);
        for (size_t v = 0; v < nv; v++) {
            lpv_vertex &out = vertices[base + v];
            world_vertex(v, out);
            double ln[3] = {nrm[v * 3], nrm[v * 3 + 1], nrm[v * 3 + 2]}, wn[3];
            for (int r = 0; r < 3; r++)
                wn[r] = nm[r * 3] * ln[0] + nm[r * 3 + 1] * ln[1] + nm[r * 3 + 2] * ln[2];
            if (!normalize3(wn))
                wn[0] = wn[1] = wn[2] = 0.0; /* degenerate normal: kept as zero */
            for (int k = 0; k < 3; k++)
                out.normal[k] = float(wn[k]);
        }
        indices.reserve(indices.size() + ntri * 3);
        for (size_t t = 0; t < ntri; t++) {
            uint32_t a = tri[t * 3], b = tri[t * 3 + 1], c = tri[t * 3 + 2];
            if (flip)
                std::swap(b, c);
            indices.insert(indices.end(), {base + a, base + b, base + c});
        }
    } else {
        /* No normals: flat per triangle from the (world) winding; vertices un-shared. */
        vertices.reserve(vertices.size() + ntri * 3);
        indices.reserve(indices.size() + ntri * 3);
        for (size_t t = 0; t < ntri; t++) {
            uint32_t corner[3] = {tri[t * 3], tri[t * 3 + 1], tri[t * 3 + 2]};
            if (flip)
                std::swap(corner[1], corner[2]);
            lpv_vertex vx[3];
            memset(vx, 0, sizeof vx);
            for (int k = 0; k < 3; k++)
                world_vertex(corner[k], vx[k]);
            double e1[3], e2[3], n[3];
            for (int k = 0; k < 3; k++) {
                e1[k] = double(vx[1].position[k]) - vx[0].position[k];
                e2[k] = double(vx[2].position[k]) - vx[0].position[k];
            }
            n[0] = e1[1] * e2[2] - e1[2] * e2[1];
            n[1] = e1[2] * e2[0] - e1[0] * e2[2];
            n[2] = e1[0] * e2[1] - e1[1] * e2[0];
            if (!normalize3(n))
                n[0] = n[1] = n[2] = 0.0;
            const uint32_t base = uint32_t(vertices.size());
            for (int k = 0; k < 3; k++) {
                for (int j = 0; j < 3; j++)
                    vx[k].normal[j] = float(n[j]);
                vertices.push_back(vx[k]);
            }
            indices.insert(indices.end(), {base, base + 1, base + 2});
        }
    }
    draws.push_back(draw);
}

void Builder::add_mesh(int mesh, const Mat4 &world)
{
    if (mesh < 0 || size_t(mesh) >= m_.meshes.size())
        fail("mesh %d does not exist (out of range)", mesh);
    const tinygltf::Mesh &gm = m_.meshes[size_t(mesh)];
    for (size_t i = 0; i < gm.primitives.size(); i++)
        add_primitive(gm.primitives[i], mesh, int(i), world);
}

void Builder::add_light(int node, int li, const Mat4 &world)
{
    if (li < 0 || size_t(li) >= m_.lights.size())
        fail("node %d: KHR_lights_punctual light %d does not exist (out of range)", node, li);
    const tinygltf::Light &gl = m_.lights[size_t(li)];
    lpv_light l;
    memset(&l, 0, sizeof l);
    if (gl.type == "directional")
        l.type = LPV_LIGHT_DIRECTIONAL;
    else if (gl.type == "point")
        l.type = LPV_LIGHT_POINT;
    else if (gl.type == "spot")
        l.type = LPV_LIGHT_SPOT;
    else {
        ctx_.warn(strf("light %d has unknown type %s; skipped", li, show(gl.type).c_str()));
        return;
    }
    copy_name(l.name, gl.name, strf("light%zu", lights.size()));
    l.color[0] = l.color[1] = l.color[2] = 1.0f;
    if (!gl.color.empty()) {
        if (gl.color.size() != 3 || !finite_all(gl.color))
            fail("light %d: color must hold 3 finite numbers", li);
        for (int k = 0; k < 3; k++)
            l.color[k] = float(gl.color[size_t(k)]);
    }
    if (!std::isfinite(gl.intensity) || gl.intensity < 0.0)
        fail("light %d: intensity must be a finite number >= 0", li);
    /* cd -> W/sr (point, spot) and lx -> W/m^2 (directional): docs/units.md */
    l.intensity = float(gl.intensity / double(LPV_LUMENS_PER_WATT));
    l.range = (std::isfinite(gl.range) && gl.range > 0.0) ? float(gl.range) : 0.0f;
    if (l.type == LPV_LIGHT_SPOT) {
        if (!std::isfinite(gl.spot.innerConeAngle) || !std::isfinite(gl.spot.outerConeAngle))
            fail("light %d: spot cone angles must be finite", li);
        l.inner_cone = float(gl.spot.innerConeAngle);
        l.outer_cone = float(gl.spot.outerConeAngle);
    }
    double origin[3] = {0, 0, 0}, pos[3], down[3] = {0, 0, -1}, dir[3];
    xform_point(world, origin, pos);
    xform_dir(world, down, dir);
    if (!normalize3(dir)) {
        dir[0] = 0;
        dir[1] = 0;
        dir[2] = -1;
    }
    for (int k = 0; k < 3; k++) {
        l.position[k] = float(pos[k]);
        l.direction[k] = float(dir[k]);
    }
    lights.push_back(l);
}

void Builder::add_camera(int node, int ci, const Mat4 &world)
{
    if (ci < 0 || size_t(ci) >= m_.cameras.size())
        fail("node %d: camera %d does not exist (out of range)", node, ci);
    const tinygltf::Camera &gc = m_.cameras[size_t(ci)];
    lpv_camera c;
    memset(&c, 0, sizeof c);
    if (gc.type == "perspective") {
        c.orthographic = 0;
        c.yfov = float(gc.perspective.yfov);
        c.aspect = float(gc.perspective.aspectRatio);
        c.znear = float(gc.perspective.znear);
        c.zfar = float(gc.perspective.zfar);
    } else if (gc.type == "orthographic") {
        c.orthographic = 1;
        c.xmag = float(gc.orthographic.xmag);
        c.ymag = float(gc.orthographic.ymag);
        c.znear = float(gc.orthographic.znear);
        c.zfar = float(gc.orthographic.zfar);
    } else {
        ctx_.warn(strf("camera %d has unknown type %s; skipped", ci, show(gc.type).c_str()));
        return;
    }
    copy_name(c.name, gc.name, strf("camera%zu", cameras.size()));
    double origin[3] = {0, 0, 0}, eye[3], fwd_l[3] = {0, 0, -1}, up_l[3] = {0, 1, 0}, fwd[3], up[3];
    xform_point(world, origin, eye);
    xform_dir(world, fwd_l, fwd);
    xform_dir(world, up_l, up);
    if (!normalize3(fwd))
        fwd[0] = 0, fwd[1] = 0, fwd[2] = -1;
    if (!normalize3(up))
        up[0] = 0, up[1] = 1, up[2] = 0;
    for (int k = 0; k < 3; k++) {
        c.eye[k] = float(eye[k]);
        c.forward[k] = float(fwd[k]);
        c.up[k] = float(up[k]);
    }
    cameras.push_back(c);
}

void Builder::visit(int node, const Mat4 &parent, int depth)
{
    if (depth > kMaxNodeDepth)
        fail("the node hierarchy is deeper than %d levels", kMaxNodeDepth);
    if (node < 0 || size_t(node) >= m_.nodes.size())
        fail("node %d does not exist (out of range)", node);
    if (visited_[size_t(node)])
        fail("node %d is reached twice from the scene (node cycle or shared subtree)", node);
    visited_[size_t(node)] = 1;
    const tinygltf::Node &n = m_.nodes[size_t(node)];
    const Mat4 world = mul(parent, node_local(n, node));
    for (int k = 0; k < 16; k++)
        if (!std::isfinite(world.m[k]))
            fail("node %d: world transform is not finite (NaN or Inf)", node);

    if (n.mesh >= 0)
        add_mesh(n.mesh, world);
    else if (n.mesh != -1)
        fail("node %d: mesh %d does not exist (out of range)", node, n.mesh);
    if (n.camera >= 0)
        add_camera(node, n.camera, world);
    else if (n.camera != -1)
        fail("node %d: camera %d does not exist (out of range)", node, n.camera);
    auto ext = n.extensions.find("KHR_lights_punctual");
    if (ext != n.extensions.end() && ext->second.IsObject() && ext->second.Has("light")) {
        const tinygltf::Value &v = ext->second.Get("light");
        double d = v.IsNumber() ? v.GetNumberAsDouble() : -1.0;
        if (!(d >= 0.0 && d < double(m_.lights.size())) || d != std::floor(d))
            fail("node %d: KHR_lights_punctual light %s does not exist (out of range)", node,
                 v.IsNumber() ? strf("%g", d).c_str() : "(not a number)");
        add_light(node, int(d), world);
    }
    for (int c : n.children)
        visit(c, world, depth + 1);
}

void Builder::build()
{
    std::string unsupported;
    for (const std::string &e : m_.extensionsRequired)
        if (!lpv_gltf::extension_supported(e))
            unsupported += (unsupported.empty() ? "" : ", ") + show(e);
    if (!unsupported.empty())
        fail("the file requires extension%s lpvd does not implement: %s (extensionsRequired)",
             unsupported.find(',') == std::string::npos ? "" : "s", unsupported.c_str());
    check_buffer_views();
    check_node_graph();
    convert_materials();

    std::vector<int> roots;
    int scene = m_.defaultScene;
    if (scene >= 0 && size_t(scene) >= m_.scenes.size())
        fail("default scene %d does not exist (out of range)", scene);
    if (scene < 0 && !m_.scenes.empty())
        scene = 0;
    if (scene >= 0) {
        roots = m_.scenes[size_t(scene)].nodes;
    } else {
        std::vector<unsigned char> is_child(m_.nodes.size(), 0);
        for (const auto &n : m_.nodes)
            for (int c : n.children)
                is_child[size_t(c)] = 1; /* in range: check_node_graph */
        for (size_t i = 0; i < m_.nodes.size(); i++)
            if (!is_child[i])
                roots.push_back(int(i));
    }
    visited_.assign(m_.nodes.size(), 0);
    const Mat4 id = identity();
    for (int r : roots)
        visit(r, id, 1);
    for (const std::string &w : lpv_gltf::unused_features(m_, scene))
        ctx_.warn(w);
}

/* ---- lpvd_medium (docs/scenes.md, "Media") ----------------------------- */
/* Read from the raw JSON with nlohmann rather than from tinygltf's Value,
 * which drops nulls from arrays and truncates large integers to int. Every
 * message names the field: "lpvd_medium.density.values[3]: ...". */
using Json = nlohmann::json;

/* A value from the file for a message, cut short. */
std::string brief(const Json &v)
{
    std::string d = v.dump(-1, ' ', false, Json::error_handler_t::replace);
    if (d.size() > 40)
        d = d.substr(0, 40) + "...";
    return d;
}

/* A finite number in [lo, hi], or a failure naming field. */
double medium_number(const Json &v, const std::string &field, double lo, double hi, const char *unit)
{
    if (!v.is_number())
        fail("%s: %s is not a number", field.c_str(), brief(v).c_str());
    double d = v.get<double>();
    if (!std::isfinite(d))
        fail("%s: %s is not finite", field.c_str(), brief(v).c_str());
    if (d < lo || d > hi)
        fail("%s: %g is out of range (must be %g .. %g%s)", field.c_str(), d, lo, hi, unit);
    return d;
}

void medium_rgb(const Json &m, const char *key, float out[3])
{
    const std::string field = std::string("lpvd_medium.") + key;
    auto it = m.find(key);
    if (it == m.end())
        fail("%s: missing (a number or [r,g,b] in 1/m; 0 for none)", field.c_str());
    const double hi = double(LPV_MEDIUM_SIGMA_MAX);
    if (it->is_number()) {
        float v = float(medium_number(*it, field, 0.0, hi, " 1/m"));
        out[0] = out[1] = out[2] = v;
        return;
    }
    if (!it->is_array())
        fail("%s: %s must be a number or an array [r,g,b] of numbers", field.c_str(), brief(*it).c_str());
    if (it->size() != 3)
        fail("%s: %zu values, [r,g,b] needs 3", field.c_str(), it->size());
    for (size_t k = 0; k < 3; k++)
        out[k] = float(medium_number((*it)[k], strf("%s[%zu]", field.c_str(), k), 0.0, hi, " 1/m"));
}

void medium_vec3(const Json &v, const std::string &field, float out[3])
{
    if (!v.is_array())
        fail("%s: %s must be an array [x,y,z] of numbers (m)", field.c_str(), brief(v).c_str());
    if (v.size() != 3)
        fail("%s: %zu values, [x,y,z] needs 3", field.c_str(), v.size());
    for (size_t k = 0; k < 3; k++) {
        const std::string f = strf("%s[%zu]", field.c_str(), k);
        const Json &c = v[k];
        if (!c.is_number())
            fail("%s: %s is not a number", f.c_str(), brief(c).c_str());
        const double d = c.get<double>();
        if (!std::isfinite(d) || std::fabs(d) > double(std::numeric_limits<float>::max()))
            fail("%s: %s is out of range (must be a finite float, m)", f.c_str(), brief(c).c_str());
        out[k] = float(d);
    }
}

void medium_unknown_keys(const Json &o, const char *field, std::initializer_list<const char *> known, Ctx &ctx)
{
    for (auto it = o.begin(); it != o.end(); ++it) {
        bool ok = false;
        for (const char *k : known)
            ok = ok || it.key() == k;
        if (!ok)
            ctx.warn(strf("%s.%s: unknown field, ignored", field, show(it.key()).c_str()));
    }
}

/* Parses and checks one lpvd_medium object into m (density into values). */
void parse_medium(const Json &j, lpv_medium &m, std::vector<float> &values, Ctx &ctx)
{
    memset(&m, 0, sizeof m);
    values.clear();
    if (!j.is_object())
        fail("lpvd_medium: %s must be an object {\"sigma_s\", \"sigma_a\", \"box\"?, \"density\"?}", brief(j).c_str());
    medium_unknown_keys(j, "lpvd_medium", {"sigma_s", "sigma_a", "box", "density"}, ctx);
    medium_rgb(j, "sigma_s", m.sigma_s);
    medium_rgb(j, "sigma_a", m.sigma_a);

    auto box = j.find("box");
    if (box != j.end()) {
        if (!box->is_object())
            fail("lpvd_medium.box: %s must be an object {\"min\":[x,y,z], \"max\":[x,y,z]}", brief(*box).c_str());
        medium_unknown_keys(*box, "lpvd_medium.box", {"min", "max"}, ctx);
        for (const char *k : {"min", "max"})
            if (!box->contains(k))
                fail("lpvd_medium.box.%s: missing ([x,y,z] in m)", k);
        medium_vec3((*box)["min"], "lpvd_medium.box.min", m.box_min);
        medium_vec3((*box)["max"], "lpvd_medium.box.max", m.box_max);
        static const char axis[] = "xyz";
        for (int k = 0; k < 3; k++)
            if (!(m.box_min[k] < m.box_max[k]))
                fail("lpvd_medium.box: min.%c %g is not below max.%c %g (the box must not be empty)", axis[k],
                     double(m.box_min[k]), axis[k], double(m.box_max[k]));
        m.has_box = 1;
    }

    auto den = j.find("density");
    if (den != j.end()) {
        if (!den->is_object())
            fail("lpvd_medium.density: %s must be an object {\"dims\":[nx,ny,nz], \"values\":[...]}",
                 brief(*den).c_str());
        if (!m.has_box)
            fail("lpvd_medium.density: needs a \"box\" to place it in (lpvd_medium.box is missing)");
        medium_unknown_keys(*den, "lpvd_medium.density", {"dims", "values"}, ctx);
        auto dims = den->find("dims");
        if (dims == den->end())
            fail("lpvd_medium.density.dims: missing ([nx,ny,nz], each 1 .. %d)", LPV_MEDIUM_DIMS_MAX);
        if (!dims->is_array() || dims->size() != 3)
            fail("lpvd_medium.density.dims: %s must be an array [nx,ny,nz] of 3 integers", brief(*dims).c_str());
        size_t count = 1;
        for (size_t k = 0; k < 3; k++) {
            const std::string f = strf("lpvd_medium.density.dims[%zu]", k);
            const Json &d = (*dims)[k];
            if (!d.is_number())
                fail("%s: %s is not a number", f.c_str(), brief(d).c_str());
            double v = d.get<double>();
            if (!(v >= 1.0 && v <= double(LPV_MEDIUM_DIMS_MAX)) || v != std::floor(v))
                fail("%s: %s must be an integer 1 .. %d", f.c_str(), brief(d).c_str(), LPV_MEDIUM_DIMS_MAX);
            m.dims[k] = int(v);
            count *= size_t(m.dims[k]);
        }
        auto vals = den->find("values");
        if (vals == den->end())
            fail("lpvd_medium.density.values: missing (%zu numbers for dims %dx%dx%d, x fastest)", count, m.dims[0],
                 m.dims[1], m.dims[2]);
        if (!vals->is_array())
            fail("lpvd_medium.density.values: %s must be an array of numbers", brief(*vals).c_str());
        if (vals->size() != count)
            fail("lpvd_medium.density.values: %zu values, dims %dx%dx%d need %zu", vals->size(), m.dims[0],
                 m.dims[1], m.dims[2], count);
        values.resize(count);
        for (size_t i = 0; i < count; i++) {
            const Json &v = (*vals)[i];
            if (!v.is_number())
                fail("lpvd_medium.density.values[%zu]: %s is not a number", i, brief(v).c_str());
            double d = v.get<double>();
            if (!std::isfinite(d) || d < 0.0 || d > double(LPV_MEDIUM_DENSITY_MAX))
                fail("lpvd_medium.density.values[%zu]: %s is out of range (must be finite, 0 .. %g)", i,
                     brief(v).c_str(), double(LPV_MEDIUM_DENSITY_MAX));
            values[i] = float(d);
        }
    }

    bool any = false;
    for (int k = 0; k < 3; k++)
        any = any || m.sigma_s[k] > 0.0f || m.sigma_a[k] > 0.0f;
    if (!any) { /* sigma_s = sigma_a = 0: no medium */
        memset(&m, 0, sizeof m);
        values.clear();
        return;
    }
    m.present = 1;
}

/* The medium of the scene that is loaded (scenes[scene].extras.lpvd_medium),
 * else of the document (extras.lpvd_medium). json is the file's JSON text. */
void read_medium(const char *json, size_t len, const tinygltf::Model &model, Ctx &ctx, lpv_medium &m,
                 std::vector<float> &values)
{
    memset(&m, 0, sizeof m);
    values.clear();
    static const char key[] = "lpvd_medium";
    if (!memmem(json, len, key, sizeof key - 1))
        return; /* the common case: no need to parse the JSON again */
    Json doc = Json::parse(json, json + len, nullptr, false);
    if (doc.is_discarded() || !doc.is_object())
        fail("invalid JSON while reading lpvd_medium");
    int scene = model.defaultScene;
    if (scene < 0 && !model.scenes.empty())
        scene = 0;
    const Json *found = nullptr;
    auto scenes = doc.find("scenes");
    if (scene >= 0 && scenes != doc.end() && scenes->is_array() && size_t(scene) < scenes->size()) {
        const Json &sc = (*scenes)[size_t(scene)];
        auto ex = sc.is_object() ? sc.find("extras") : sc.end();
        if (ex != sc.end() && ex->is_object() && ex->contains(key))
            found = &(*ex)[key];
    }
    auto ex = doc.find("extras");
    if (ex != doc.end() && ex->is_object() && ex->contains(key)) {
        if (found)
            ctx.warn(strf("both scene %d and the document carry extras.lpvd_medium; the scene's is used", scene));
        else
            found = &(*ex)[key];
    }
    if (found)
        parse_medium(*found, m, values, ctx);
}

/* ---- the common path ---------------------------------------------------- */
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

void load(const unsigned char *data, size_t size, Ctx &ctx, lpv_scene *out)
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
        fail("wrong magic: neither a .glb ('glTF' header) nor a JSON .gltf (first bytes %02x %02x %02x %02x)",
             data[0], size > 1 ? data[1] : 0, size > 2 ? data[2] : 0, size > 3 ? data[3] : 0);
    }

    size_t json_off = 0, json_len = size;
    if (is_glb)
        check_glb(data, size, &json_off, &json_len);
    scan_json(reinterpret_cast<const char *>(data) + json_off, json_len);

    tinygltf::TinyGLTF loader;
    tinygltf::FsCallbacks fs;
    fs.FileExists = fs_exists;
    fs.ExpandFilePath = fs_expand;
    fs.ReadWholeFile = fs_read;
    fs.WriteWholeFile = fs_write;
    fs.user_data = &ctx;
    loader.SetFsCallbacks(fs);
    loader.SetImageLoader(image_loader, &ctx);

    /* Compressed files as tinygltf 2.7 accepts them (gltf_compressed.hpp):
     * meshopt fallback buffers get placeholders, Draco primitives lose their
     * data-less "indices"; the compressed data is decoded instead. */
    const char *const json_text = reinterpret_cast<const char *>(data) + json_off; /* the file's own JSON */
    std::vector<unsigned char> rewritten;
    static const char meshopt_key[] = "EXT_meshopt_compression", draco_key[] = "KHR_draco_mesh_compression";
    std::string json2;
    if ((memmem(json_text, json_len, meshopt_key, sizeof meshopt_key - 1) ||
         memmem(json_text, json_len, draco_key, sizeof draco_key - 1)) &&
        lpv_gltf::tinygltf_compat_json(json_text, json_len, &json2)) {
        if (is_glb) {
            size_t jpad = (json2.size() + 3) & ~size_t(3);
            size_t rest = size - (json_off + json_len); /* the BIN chunk, if any */
            rewritten.assign(20 + jpad + rest, ' ');
            memcpy(rewritten.data(), data, 12);
            auto put32 = [&](size_t at, uint32_t v) {
                for (int k = 0; k < 4; k++)
                    rewritten[at + size_t(k)] = (unsigned char)(v >> (8 * k));
            };
            put32(8, uint32_t(rewritten.size()));
            put32(12, uint32_t(jpad));
            memcpy(rewritten.data() + 16, data + 16, 4);
            memcpy(rewritten.data() + 20, json2.data(), json2.size());
            if (rest)
                memcpy(rewritten.data() + 20 + jpad, data + json_off + json_len, rest);
        } else {
            rewritten.assign(json2.begin(), json2.end());
        }
        data = rewritten.data();
        size = rewritten.size();
    }

    tinygltf::Model model;
    ctx.model = &model;
    std::string terr, twarn;
    const std::string base = ctx.allow_external ? ctx.base_dir : std::string();
    bool ok;
    if (is_glb)
        ok = loader.LoadBinaryFromMemory(&model, &terr, &twarn, data, unsigned(size), base);
    else
        ok = loader.LoadASCIIFromString(&model, &terr, &twarn, reinterpret_cast<const char *>(data), unsigned(size),
                                        base);
    ctx.model = nullptr;
    if (!ctx.refusal.empty())
        fail("%s", ctx.refusal.c_str());
    if (!ctx.image_error.empty())
        fail("%s", ctx.image_error.c_str());
    if (!ok) {
        std::string t = one_line(terr);
        if (!ctx.missing.empty())
            fail("%s (missing buffer or image; tinygltf: %s)", ctx.missing.c_str(), t.c_str());
        fail("glTF rejected by tinygltf: %s", t.empty() ? "unknown error" : t.c_str());
    }
    if (!ctx.missing.empty())
        ctx.warn(ctx.missing + "; that image is ignored");
    if (!terr.empty())
        ctx.warn("tinygltf: " + one_line(terr));
    if (!twarn.empty())
        ctx.warn("tinygltf: " + one_line(twarn));

    for (size_t i = 0; i < ctx.override_count; ++i) {
        const lpv_gltf_node_override &o = ctx.overrides[i];
        if (o.node < 0 || size_t(o.node) >= model.nodes.size())
            fail("node override %zu: node %d does not exist (the file has %zu nodes)", i, o.node,
                 model.nodes.size());
        tinygltf::Node &n = model.nodes[size_t(o.node)];
        if (o.has_matrix) {
            n.matrix.assign(o.matrix, o.matrix + 16);
            n.translation.clear();
            n.rotation.clear();
            n.scale.clear();
            continue;
        }
        if ((o.has_translation || o.has_rotation || o.has_scale) && !n.matrix.empty()) {
            /* a node given as a matrix gets identity TRS parts it did not override */
            n.matrix.clear();
        }
        if (o.has_translation)
            n.translation.assign(o.translation, o.translation + 3);
        if (o.has_rotation)
            n.rotation.assign(o.rotation, o.rotation + 4);
        if (o.has_scale)
            n.scale.assign(o.scale, o.scale + 3);
    }

    Builder b(model, ctx);
    b.build();
    lpv_medium medium;
    std::vector<float> density;
    read_medium(json_text, json_len, model, ctx, medium, density);

    if (b.vertices.size() > UINT32_MAX || b.indices.size() > UINT32_MAX)
        fail("scene too large (absurd size)");
    /* Hand everything over as malloc'd C arrays; lpv_scene_free releases it. */
    out->vertices = c_array(b.vertices);
    out->vertex_count = uint32_t(b.vertices.size());
    out->indices = c_array(b.indices);
    out->index_count = uint32_t(b.indices.size());
    out->draws = c_array(b.draws);
    out->draw_count = uint32_t(b.draws.size());
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
        if (ctx.sink) {
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

} // namespace

extern "C" int lpv_gltf_load_file(const char *path, lpv_scene *out, char *err, size_t err_size)
{
    return lpv_gltf_load_file_w(path, out, nullptr, err, err_size);
}

extern "C" int lpv_gltf_load_file_w(const char *path, lpv_scene *out, lpv_gltf_warnings *warnings, char *err,
                                    size_t err_size)
{
    if (warnings)
        memset(warnings, 0, sizeof *warnings);
    if (err && err_size)
        err[0] = '\0';
    if (!out) {
        if (err && err_size)
            snprintf(err, err_size, "%s: no scene to load into", path ? path : "(null)");
        return -1;
    }
    memset(out, 0, sizeof *out);
    if (!path || !path[0]) {
        if (err && err_size)
            snprintf(err, err_size, "(null): no path given");
        return -1;
    }
    try {
        Ctx ctx;
        ctx.label = path;
        ctx.sink = warnings;
        std::string p(path);
        size_t slash = p.find_last_of('/');
        ctx.base_dir = slash == std::string::npos ? std::string(".") : (slash == 0 ? std::string("/") : p.substr(0, slash));

        int fd = open(path, O_RDONLY | O_CLOEXEC);
        if (fd < 0) {
            set_error(err, err_size, ctx.label, std::string("cannot open: ") + strerror(errno));
            return -1;
        }
        struct stat st;
        if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
            close(fd);
            set_error(err, err_size, ctx.label, "not a regular file");
            return -1;
        }
        if (uint64_t(st.st_size) > kMaxFileBytes) {
            close(fd);
            set_error(err, err_size, ctx.label,
                      strf("%lld bytes is over the %llu-byte limit (absurd size)", (long long)st.st_size,
                             (unsigned long long)kMaxFileBytes));
            return -1;
        }
        std::vector<unsigned char> data;
        try {
            data.resize(size_t(st.st_size));
        } catch (...) {
            close(fd);
            throw;
        }
        size_t got = 0;
        int read_errno = 0;
        while (got < data.size()) {
            ssize_t n = read(fd, data.data() + got, data.size() - got);
            if (n < 0 && errno == EINTR)
                continue;
            if (n < 0)
                read_errno = errno;
            if (n <= 0)
                break;
            got += size_t(n);
        }
        close(fd);
        if (read_errno) {
            set_error(err, err_size, ctx.label, std::string("cannot read: ") + strerror(read_errno));
            return -1;
        }
        data.resize(got);

        char *real = realpath(ctx.base_dir.c_str(), nullptr);
        if (real) {
            ctx.root_real = real;
            free(real);
            ctx.allow_external = true;
        }
        return run_load(data.data(), data.size(), ctx, out, err, err_size);
    } catch (const std::bad_alloc &) {
        if (err && err_size)
            snprintf(err, err_size, "%s: out of memory", path);
    } catch (...) {
        if (err && err_size)
            snprintf(err, err_size, "%s: unexpected error", path);
    }
    lpv_scene_free(out);
    return -1;
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
    if (warnings)
        memset(warnings, 0, sizeof *warnings);
    const char *name = label && label[0] ? label : "<memory>";
    if (err && err_size)
        err[0] = '\0';
    if (!out) {
        if (err && err_size)
            snprintf(err, err_size, "%s: no scene to load into", name);
        return -1;
    }
    memset(out, 0, sizeof *out);
    if (!data && size > 0) {
        if (err && err_size)
            snprintf(err, err_size, "%s: no data", name);
        return -1;
    }
    try {
        Ctx ctx;
        ctx.label = name;
        ctx.sink = warnings;
        ctx.overrides = nodes;
        ctx.override_count = nodes ? node_count : 0;
        if (base_dir) {
            char *real = realpath(base_dir, nullptr);
            if (!real) {
                set_error(err, err_size, ctx.label,
                          strf("base folder %s: %s", show(base_dir).c_str(), strerror(errno)));
                return -1;
            }
            ctx.root_real = real;
            free(real);
            ctx.base_dir = base_dir[0] ? base_dir : ".";
            ctx.allow_external = true;
        }
        static const unsigned char empty = 0;
        return run_load(size ? static_cast<const unsigned char *>(data) : &empty, size, ctx, out, err, err_size);
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
