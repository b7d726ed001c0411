// image_oiio.cpp - image_io.h on top of OpenImageIO 2.4.
//
// Conventions (beyond image_io.h):
//   - The on-disk format follows the extension, and so does the sample type:
//     float formats (lpv_image_is_float_format: ".exr") are written as 32-bit
//     float, everything else as 8-bit. Values are never re-encoded: u8 data
//     written to an EXR is stored as value/255, float data written to a PNG is
//     clamped to [0, 1] and quantized as is (no sRGB curve is applied; encode
//     first and use lpv_image_write_u8 for display images).
//   - 8-bit files are tagged "oiio:ColorSpace" = "sRGB" (the caller encoded
//     them); float files "Linear".
//   - Alpha is never premultiplied or divided out: pixels go to and come from
//     the file as stored (straight alpha in PNG).
//   - lpv_image_read_f32 returns the stored values normalized to float (an
//     8-bit PNG gives k/255, not linearized). Channel conversion uses the
//     layouts 1 = Y, 2 = YA, 3 = RGB, 4 = RGBA: a one-channel (grey) source
//     fills every colour channel, missing colour channels are 0, missing
//     alpha is 1, and a colour source read as one channel gives its first.
//   - No C++ exception leaves this file; every error names the file and
//     carries OpenImageIO's message.
#include "image_io.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

namespace {

using OIIO::ImageInput;
using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

void set_err(char *err, size_t err_size, const std::string &msg)
{
    if (err && err_size)
        std::snprintf(err, err_size, "%s", msg.c_str());
}

// Trims OIIO's multi-line messages to one line for our error strings.
std::string one_line(std::string s)
{
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r'))
        s.pop_back();
    for (char &c : s)
        if (c == '\n' || c == '\r')
            c = ' ';
    return s.empty() ? std::string("no details from OpenImageIO") : s;
}

bool check_size(const char *path, int width, int height, int channels, const void *pixels, char *err,
                size_t err_size)
{
    if (!path || !path[0]) {
        set_err(err, err_size, "image: no file name");
        return false;
    }
    if (width <= 0 || height <= 0 || width > (1 << 16) || height > (1 << 16)) {
        set_err(err, err_size, std::string(path) + ": bad image size " + std::to_string(width) + "x" +
                                   std::to_string(height));
        return false;
    }
    if (channels < 1 || channels > 4) {
        set_err(err, err_size, std::string(path) + ": bad channel count " + std::to_string(channels) + " (1..4)");
        return false;
    }
    if (!pixels) {
        set_err(err, err_size, std::string(path) + ": no pixels");
        return false;
    }
    return true;
}

// The spec every written image gets, file or in-memory, so the daemon's PNG
// and EXR frames are encoded exactly like `lpvd render`'s files: 8-bit sRGB,
// or linear float for the formats lpv_image_is_float_format names. Our alpha
// is straight (unassociated), as PNG stores it: OIIO must not un-premultiply;
// EXR is written as is. The same pixels give the same bytes: OpenImageIO's
// EXR writer stamps the current time into a "DateTime" attribute unless the
// spec has one, so the spec names none (empty), and a batch job's shards, a
// re-run or the daemon's frame cache get byte-identical files.
ImageSpec output_spec(const char *name, int width, int height, int channels)
{
    const bool is_float = lpv_image_is_float_format(name) != 0;
    ImageSpec spec(width, height, channels, is_float ? TypeDesc::FLOAT : TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", is_float ? "Linear" : "sRGB");
    spec.attribute("DateTime", "");
    if (!is_float)
        spec.attribute("oiio:UnassociatedAlpha", 1);
    if (channels == 2)
        spec.alpha_channel = 1;
    else if (channels == 4)
        spec.alpha_channel = 3;
    return spec;
}

// Writes pixels of type `src_type` to path; the file's sample type follows the
// extension.
int write_image(const char *path, int width, int height, int channels, TypeDesc src_type, const void *pixels,
                char *err, size_t err_size)
{
    if (!check_size(path, width, height, channels, pixels, err, err_size))
        return -1;
    try {
        auto out = ImageOutput::create(path);
        if (!out) {
            set_err(err, err_size, std::string(path) + ": no image writer for this file type: " +
                                       one_line(OIIO::geterror()));
            return -1;
        }
        ImageSpec spec = output_spec(path, width, height, channels);
        if (!out->open(path, spec)) {
            set_err(err, err_size, std::string(path) + ": cannot open for writing: " + one_line(out->geterror()));
            return -1;
        }
        if (!out->write_image(src_type, pixels)) {
            std::string e = one_line(out->geterror());
            out->close();
            set_err(err, err_size, std::string(path) + ": write failed: " + e);
            return -1;
        }
        if (!out->close()) {
            set_err(err, err_size, std::string(path) + ": close failed: " + one_line(out->geterror()));
            return -1;
        }
        return 0;
    } catch (const std::exception &e) {
        set_err(err, err_size, std::string(path) + ": " + e.what());
    } catch (...) {
        set_err(err, err_size, std::string(path) + ": unknown error while writing");
    }
    return -1;
}

} // namespace

extern "C" int lpv_image_write_u8(const char *path, int width, int height, int channels, const uint8_t *pixels,
                                  char *err, size_t err_size)
{
    return write_image(path, width, height, channels, TypeDesc::UINT8, pixels, err, err_size);
}

extern "C" int lpv_image_write_f32(const char *path, int width, int height, int channels, const float *pixels,
                                   char *err, size_t err_size)
{
    return write_image(path, width, height, channels, TypeDesc::FLOAT, pixels, err, err_size);
}

extern "C" int lpv_image_read_f32(const char *path, int channels, int *width, int *height, float **pixels,
                                  char *err, size_t err_size)
{
    if (pixels)
        *pixels = nullptr;
    if (!path || !path[0]) {
        set_err(err, err_size, "image: no file name");
        return -1;
    }
    if (channels < 1 || channels > 4 || !width || !height || !pixels) {
        set_err(err, err_size, std::string(path) + ": bad arguments (channels must be 1..4)");
        return -1;
    }
    try {
        // Keep alpha as stored (straight for PNG) instead of premultiplying.
        ImageSpec config;
        config.attribute("oiio:UnassociatedAlpha", 1);
        auto in = ImageInput::open(path, &config);
        if (!in) {
            set_err(err, err_size, std::string(path) + ": cannot read image: " + one_line(OIIO::geterror()));
            return -1;
        }
        const ImageSpec &spec = in->spec();
        const int w = spec.width, h = spec.height, nch = spec.nchannels;
        if (w <= 0 || h <= 0 || nch <= 0 || spec.depth > 1) {
            set_err(err, err_size, std::string(path) + ": unsupported image (" + std::to_string(w) + "x" +
                                       std::to_string(h) + "x" + std::to_string(spec.depth) + ", " +
                                       std::to_string(nch) + " channels)");
            in->close();
            return -1;
        }
        const size_t npix = (size_t)w * (size_t)h;
        std::vector<float> src(npix * (size_t)nch);
        if (!in->read_image(0, 0, 0, nch, TypeDesc::FLOAT, src.data())) {
            std::string e = one_line(in->geterror());
            in->close();
            set_err(err, err_size, std::string(path) + ": read failed: " + e);
            return -1;
        }
        in->close();

        // Source layout: which channels are colour, which is alpha.
        int src_alpha = (spec.alpha_channel >= 0 && spec.alpha_channel < nch) ? spec.alpha_channel : -1;
        if (src_alpha < 0 && (nch == 2 || nch == 4))
            src_alpha = nch - 1; // YA / RGBA without the tag
        int src_color[3] = {-1, -1, -1};
        int src_color_n = 0;
        for (int c = 0; c < nch && src_color_n < 3; c++)
            if (c != src_alpha)
                src_color[src_color_n++] = c;

        const int dst_color_n = channels >= 3 ? 3 : 1;
        const bool dst_alpha = channels == 2 || channels == 4;
        int map[4] = {-1, -1, -1, -1}; // source channel per destination channel; -1: 0, -2: 1
        for (int c = 0; c < dst_color_n; c++) {
            if (src_color_n == 0)
                map[c] = -1;
            else if (src_color_n == 1)
                map[c] = src_color[0];
            else
                map[c] = c < src_color_n ? src_color[c] : -1;
        }
        if (dst_alpha)
            map[channels - 1] = src_alpha >= 0 ? src_alpha : -2;

        float *dst = static_cast<float *>(std::malloc(npix * (size_t)channels * sizeof(float)));
        if (!dst) {
            set_err(err, err_size, std::string(path) + ": out of memory");
            return -1;
        }
        for (size_t i = 0; i < npix; i++) {
            const float *s = &src[i * (size_t)nch];
            float *d = dst + i * (size_t)channels;
            for (int c = 0; c < channels; c++)
                d[c] = map[c] >= 0 ? s[map[c]] : (map[c] == -2 ? 1.0f : 0.0f);
        }
        *width = w;
        *height = h;
        *pixels = dst;
        return 0;
    } catch (const std::exception &e) {
        set_err(err, err_size, std::string(path) + ": " + e.what());
    } catch (...) {
        set_err(err, err_size, std::string(path) + ": unknown error while reading");
    }
    return -1;
}

extern "C" int lpv_image_is_float_format(const char *path)
{
    if (!path)
        return 0;
    const char *dot = std::strrchr(path, '.');
    const char *slash = std::strrchr(path, '/');
    if (!dot || (slash && dot < slash))
        return 0;
    std::string ext(dot + 1);
    for (char &c : ext)
        c = (char)std::tolower((unsigned char)c);
    return ext == "exr" ? 1 : 0;
}

// ---- in-memory encoding (the daemon's FRAME payloads) ----------------------
namespace {

int encode_image(const char *ext, int width, int height, int channels, TypeDesc src_type, const void *pixels,
                 uint8_t **out, size_t *out_len, char *err, size_t err_size)
{
    std::string name = std::string("frame.") + (ext ? ext : "");
    if (!out || !out_len) {
        set_err(err, err_size, name + ": no output buffer");
        return -1;
    }
    *out = nullptr;
    *out_len = 0;
    if (!check_size(name.c_str(), width, height, channels, pixels, err, err_size))
        return -1;
    try {
        OIIO::Filesystem::IOVecOutput vec;
        auto img = ImageOutput::create(name, &vec);
        if (!img || !img->supports("ioproxy")) {
            set_err(err, err_size, name + ": no in-memory image writer for this type: " + one_line(OIIO::geterror()));
            return -1;
        }
        ImageSpec spec = output_spec(name.c_str(), width, height, channels);
        OIIO::Filesystem::IOProxy *proxy = &vec;
        spec.attribute("oiio:ioproxy", TypeDesc::PTR, &proxy);
        if (!img->open(name, spec)) {
            set_err(err, err_size, name + ": cannot encode: " + one_line(img->geterror()));
            return -1;
        }
        if (!img->write_image(src_type, pixels)) {
            std::string e = one_line(img->geterror());
            img->close();
            set_err(err, err_size, name + ": encoding failed: " + e);
            return -1;
        }
        if (!img->close()) {
            set_err(err, err_size, name + ": encoding failed: " + one_line(img->geterror()));
            return -1;
        }
        const std::vector<unsigned char> &buf = vec.buffer();
        uint8_t *p = static_cast<uint8_t *>(std::malloc(buf.size() ? buf.size() : 1));
        if (!p) {
            set_err(err, err_size, name + ": out of memory");
            return -1;
        }
        if (!buf.empty())
            std::memcpy(p, buf.data(), buf.size());
        *out = p;
        *out_len = buf.size();
        return 0;
    } catch (const std::exception &e) {
        set_err(err, err_size, name + ": " + e.what());
    } catch (...) {
        set_err(err, err_size, name + ": unknown error while encoding");
    }
    return -1;
}

} // namespace

extern "C" int lpv_image_encode_u8(const char *ext, int width, int height, int channels, const uint8_t *pixels,
                                   uint8_t **out, size_t *out_len, char *err, size_t err_size)
{
    return encode_image(ext, width, height, channels, TypeDesc::UINT8, pixels, out, out_len, err, err_size);
}

extern "C" int lpv_image_encode_f32(const char *ext, int width, int height, int channels, const float *pixels,
                                    uint8_t **out, size_t *out_len, char *err, size_t err_size)
{
    return encode_image(ext, width, height, channels, TypeDesc::FLOAT, pixels, out, out_len, err, err_size);
}

// ---- resizing (the batch report's thumbnails) --------------------------------

extern "C" int lpv_image_resize_f32(const float *pixels, int width, int height, int channels, int dst_width,
                                    int dst_height, float **out, char *err, size_t err_size)
{
    if (out)
        *out = nullptr;
    if (!out) {
        set_err(err, err_size, "resize: no output buffer");
        return -1;
    }
    if (!check_size("resize source", width, height, channels, pixels, err, err_size) ||
        !check_size("resize destination", dst_width, dst_height, channels, pixels, err, err_size))
        return -1;
    try {
        ImageSpec src_spec(width, height, channels, TypeDesc::FLOAT);
        // Wraps the caller's pixels without copying; resize only reads them.
        OIIO::ImageBuf src(src_spec, const_cast<float *>(pixels));
        OIIO::ImageBuf dst(ImageSpec(dst_width, dst_height, channels, TypeDesc::FLOAT));
        if (!OIIO::ImageBufAlgo::resize(dst, src, "box", 1.0f)) {
            set_err(err, err_size, "resize: " + one_line(dst.geterror()));
            return -1;
        }
        const size_t n = (size_t)dst_width * (size_t)dst_height * (size_t)channels;
        float *p = static_cast<float *>(std::malloc(n * sizeof(float)));
        if (!p) {
            set_err(err, err_size, "resize: out of memory");
            return -1;
        }
        if (!dst.get_pixels(dst.roi(), TypeDesc::FLOAT, p)) {
            std::free(p);
            set_err(err, err_size, "resize: " + one_line(dst.geterror()));
            return -1;
        }
        *out = p;
        return 0;
    } catch (const std::exception &e) {
        set_err(err, err_size, std::string("resize: ") + e.what());
    } catch (...) {
        set_err(err, err_size, "resize: unknown error");
    }
    return -1;
}
