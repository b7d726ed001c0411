/*
 * gltf_files.cpp - every file a glTF load reads (gltf_internal.hpp): the main
 * file, and the external URIs tinygltf asks for through our FsCallbacks, which
 * refuse ".." components and absolute paths, and open the rest beneath the
 * scene's folder descriptor with no symbolic link on the way, in one step
 * (core/open_beneath.h): nothing outside the folder is ever opened. The one
 * exception is a load of the invoking user's own file (lpv_gltf_load_file_user:
 * lpvd render, lpvd-reference, the benchmarks), whose URIs open where they
 * point, as any program the user runs would open them: real projects keep
 * their images in ../textures.
 */
#include "gltf_internal.hpp"

extern "C" {
#include "open_beneath.h"
}

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace lpv_gltf {

namespace {

/* Reads up to size bytes of fd into p, through EINTR; returns how many came.
 * *read_errno is the error that stopped it early (0: end of file). */
size_t read_fully(int fd, unsigned char *p, size_t size, int *read_errno)
{
    size_t got = 0;
    *read_errno = 0;
    while (got < size) {
        ssize_t n = read(fd, p + got, size - got);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0)
            *read_errno = errno;
        if (n <= 0)
            break;
        got += size_t(n);
    }
    return got;
}

enum PathCheck { PATH_OK, PATH_REFUSED, PATH_MISSING };

/* Decides whether tinygltf may touch `candidate` (= kBaseTag joined with the
 * URI, already percent-decoded) and opens it beneath the scene's folder in
 * the same step (no window for a swap): *fd is the open regular file. */
PathCheck open_external(Ctx *ctx, const std::string &candidate, int *fd)
{
    *fd = -1;
    if (!ctx->allow_external) {
        if (ctx->refusal.empty())
            ctx->refusal = "external URI " + show_uri(candidate) +
                           " refused: data loaded from memory without a base folder may only use "
                           "data: URIs and the GLB BIN chunk (anything else would be outside)";
        return PATH_REFUSED;
    }
    const std::string prefix = std::string(kBaseTag) + "/";
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
            ctx->refusal = "external URI " + show_uri(rel) + " contains a NUL byte (refused)";
        return PATH_REFUSED;
    }
    if (ctx->user_paths) { /* lpv_gltf_load_file_user: where the URI says, as the user could open it */
        int f = rel[0] == '/' ? open(rel.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK)
                              : openat(ctx->dir_fd, rel.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
        struct stat st;
        if (f < 0 || fstat(f, &st) != 0 || !S_ISREG(st.st_mode)) {
            int e = f < 0 ? errno : 0;
            if (f >= 0)
                close(f);
            if (ctx->missing.empty())
                ctx->missing = "external file " + show_uri(rel) +
                               (f >= 0 ? std::string(" is not a regular file")
                                       : e == ENOENT ? std::string(" not found")
                                                     : " cannot be opened: " + std::string(strerror(e)));
            return PATH_MISSING;
        }
        *fd = f;
        return PATH_OK;
    }
    if (rel[0] == '/') {
        if (ctx->refusal.empty())
            ctx->refusal = "external URI " + show_uri(rel) +
                           " is an absolute path, outside the scene's folder (refused)";
        return PATH_REFUSED;
    }
    if (lpv_path_stays_beneath(rel.c_str()) != 0) {
        if (ctx->refusal.empty())
            ctx->refusal = "external URI " + show_uri(rel) +
                           " leaves the scene's folder through \"..\" (outside; refused)";
        return PATH_REFUSED;
    }
    int f = lpv_open_beneath(ctx->dir_fd, rel.c_str(), O_RDONLY);
    if (f < 0) {
        int e = errno;
        if (e == ELOOP || e == EXDEV) {
            if (ctx->refusal.empty())
                ctx->refusal = "external URI " + show_uri(rel) +
                               " goes through a symbolic link (refused: links could lead outside the scene's "
                               "folder)";
            return PATH_REFUSED;
        }
        if (ctx->missing.empty())
            ctx->missing = "external file " + show_uri(rel) +
                           (e == ENOENT ? std::string(" not found") : " cannot be opened: " + std::string(strerror(e)));
        return PATH_MISSING;
    }
    struct stat st;
    if (fstat(f, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(f);
        if (ctx->missing.empty())
            ctx->missing = "external file " + show_uri(rel) + " is not a regular file";
        return PATH_MISSING;
    }
    *fd = f;
    return PATH_OK;
}

std::string fs_expand(const std::string &path, void *)
{
    return path; /* no ~ or $VAR expansion (tinygltf's default runs wordexp) */
}

bool fs_exists(const std::string &path, void *user)
{
    int fd = -1;
    if (open_external(static_cast<Ctx *>(user), path, &fd) != PATH_OK)
        return false;
    close(fd);
    return true;
}

bool fs_read(std::vector<unsigned char> *out, std::string *err, const std::string &path, void *user)
{
    Ctx *ctx = static_cast<Ctx *>(user);
    int fd = -1;
    if (open_external(ctx, path, &fd) != PATH_OK) {
        if (err)
            *err += "refused or missing";
        return false;
    }
    const std::string rel = path.substr(std::string(kBaseTag).size() + 1);
    struct stat st;
    if (fstat(fd, &st) != 0 || uint64_t(st.st_size) > kMaxFileBytes) {
        close(fd);
        if (ctx->missing.empty())
            ctx->missing = "external file " + show_uri(rel) + " is larger than " + std::to_string(kMaxFileBytes) +
                           " bytes";
        return false;
    }
    if (!take_bytes(*ctx, uint64_t(st.st_size))) { /* over the RAM budget: not read (the load fails with LIMIT) */
        close(fd);
        if (err)
            *err += "over the scene's memory budget";
        return false;
    }
    try {
        out->resize(size_t(st.st_size));
    } catch (...) {
        close(fd);
        throw;
    }
    int read_errno = 0;
    size_t got = read_fully(fd, out->data(), out->size(), &read_errno);
    close(fd);
    if (got != out->size()) {
        if (ctx->missing.empty())
            ctx->missing = "external file " + show_uri(rel) + " could not be read completely";
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

} // namespace

const char *const kBaseTag = "."; /* files show as "./uri" in tinygltf's messages */

bool take_bytes(Ctx &ctx, uint64_t n)
{
    ctx.bytes += n;
    if (ctx.bytes > ctx.max_bytes && !ctx.over)
        ctx.over = LPV_GLTF_OVER_BYTES;
    return !ctx.over_budget();
}

void set_fs_callbacks(tinygltf::TinyGLTF &loader, Ctx *ctx)
{
    tinygltf::FsCallbacks fs;
    fs.FileExists = fs_exists;
    fs.ExpandFilePath = fs_expand;
    fs.ReadWholeFile = fs_read;
    fs.WriteWholeFile = fs_write;
    fs.user_data = ctx;
    loader.SetFsCallbacks(fs);
}

std::string read_main_file(const char *path, std::vector<unsigned char> *data)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC | O_NONBLOCK); /* a FIFO must not block the load: fstat refuses it */
    if (fd < 0)
        return std::string("cannot open: ") + strerror(errno);
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        return "not a regular file";
    }
    if (uint64_t(st.st_size) > kMaxFileBytes) {
        close(fd);
        return strf("%lld bytes is over the %llu-byte limit (absurd size)", (long long)st.st_size,
                    (unsigned long long)kMaxFileBytes);
    }
    try {
        data->resize(size_t(st.st_size));
    } catch (...) {
        close(fd);
        throw;
    }
    int read_errno = 0;
    size_t got = read_fully(fd, data->data(), data->size(), &read_errno);
    close(fd);
    if (read_errno)
        return std::string("cannot read: ") + strerror(read_errno);
    data->resize(got);
    return "";
}

} // namespace lpv_gltf
