/*
 * gltf_files.cpp - every file a glTF load reads (gltf_internal.hpp): the main
 * file, and the external URIs tinygltf asks for through our FsCallbacks, which
 * refuse ".." components, absolute paths and anything whose realpath leaves
 * the scene's folder before a single byte is read.
 */
#include "gltf_internal.hpp"

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
    /* O_NONBLOCK: opening a FIFO would otherwise wait for a writer forever;
     * fstat below refuses anything but a regular file */
    int fd = open(resolved.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
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
    int read_errno = 0;
    size_t got = read_fully(fd, out->data(), out->size(), &read_errno);
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

} // namespace

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
