/*
 * gltf_messages.cpp - how the glTF adapter words its problems (gltf_internal.hpp):
 * printf-style formatting, the Failure that refuses a file, names and URIs
 * from the file for a message (never other file contents), the warnings, each line once,
 * and a name from the file cut to fit the scene's fixed-size names.
 */
#include "gltf_internal.hpp"

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <cstring>

namespace lpv_gltf {

namespace {

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

} // namespace

std::string strf(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    std::string s = vformat(fmt, ap);
    va_end(ap);
    return s;
}

[[noreturn]] void fail(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    std::string s = vformat(fmt, ap);
    va_end(ap);
    throw Failure{s};
}

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

std::string show_uri(const std::string &s)
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

std::string show(const std::string &s)
{
    bool ident = !s.empty() && s.size() <= 64;
    for (unsigned char c : s)
        ident = ident && ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_');
    return ident ? "\"" + s + "\"" : strf("(a %zu-byte name that is not an identifier, not shown)", s.size());
}

std::string tinygltf_text(const std::string &s)
{
    std::string out, line;
    auto flush = [&]() {
        size_t cut = line.find(" name = "); /* tinygltf quotes an object's name from the file there */
        if (cut != std::string::npos)
            line.resize(cut);
        if (!line.empty())
            out += (out.empty() ? "" : "; ") + line;
        line.clear();
    };
    for (char c : s) {
        if (c == '\n' || c == '\r')
            flush();
        else
            line += c;
    }
    flush();
    return out;
}

void Ctx::warn(const std::string &w)
{
    if (std::find(warnings.begin(), warnings.end(), w) != warnings.end())
        return;
    if (warnings.size() < kMaxWarnings)
        warnings.push_back(w);
    else
        warnings_dropped++;
}

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

} // namespace lpv_gltf
