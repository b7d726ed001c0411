/*
 * gltf_images.cpp - the images of a glTF file (gltf_internal.hpp): tinygltf's
 * image callback, which checks an image's bufferView range (tinygltf 2.7 does
 * not), reads PNG and JPEG sizes from their headers and counts them against
 * the load's budgets, and only once every image of the file is counted and
 * within them decodes to RGBA8 with stb (decode_images), as tinygltf would.
 */
#include "gltf_internal.hpp"

#include <climits>
#include <cstring>

#include <stb_image.h>

namespace lpv_gltf {

namespace {

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

/* A fatal image problem: the first one is kept for the load's message. */
bool refuse(Ctx *ctx, std::string *err, const std::string &problem)
{
    if (ctx->image_error.empty())
        ctx->image_error = problem;
    if (err)
        *err += ctx->image_error;
    return false;
}

std::string too_large(int image_idx, int w, int h)
{
    return strf("image %d is %dx%d texels", image_idx, w, h);
}

/* The image's size from its header, against the budgets, before anything is
 * decoded: false when it must not be decoded (over a budget: the load fails
 * with LIMIT once tinygltf is done, the later images' sizes still summed). */
bool within_budgets(Ctx *ctx, int image_idx, int w, int h)
{
    if ((w > ctx->max_side || h > ctx->max_side) && !ctx->over) {
        ctx->over = LPV_GLTF_OVER_TEXTURE;
        ctx->over_what = too_large(image_idx, w, h);
    }
    const uint64_t texels = uint64_t(w) * uint64_t(h);
    ctx->texels += texels;
    if (ctx->texels > ctx->max_texels && !ctx->over)
        ctx->over = LPV_GLTF_OVER_TEXELS;
    return take_bytes(*ctx, 4 * texels);
}

} // namespace

/* Reads an image's size from its header and counts it against the budgets
 * (Ctx), keeping the encoded bytes for decode_images; checks an image's
 * bufferView range, which tinygltf 2.7 does not. An image that cannot be read
 * is a defect of the file (SPEC R4.4), named by its index. */
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
        if (!ok)
            return refuse(ctx, err,
                          strf("image %d: its bufferView %d is out of range of its buffer", image_idx,
                               image->bufferView));
    }
    if (!bytes || size <= 0) {
        ctx->warn(strf("image %d has no data; texture ignored", image_idx));
        return true;
    }
    int w = 0, h = 0, comp = 0;
    /* Our own reading of PNG and JPEG headers first: stb refuses some large
     * images itself and would make them look merely corrupt. */
    if (!image_header_size(bytes, size_t(size), &w, &h) && !stbi_info_from_memory(bytes, size, &w, &h, &comp))
        return refuse(ctx, err,
                      strf("image %d: not a PNG or JPEG that can be read (%s)", image_idx,
                           stbi_failure_reason() ? stbi_failure_reason() : "unknown format"));
    if (w < 1 || h < 1)
        return refuse(ctx, err, strf("image %d: its header gives an empty size %dx%d", image_idx, w, h));
    if (!within_budgets(ctx, image_idx, w, h))
        return true; /* the load fails on the budget after tinygltf */
    /* Kept encoded (component 0) until every image's header has been counted:
     * decode_images runs only when the whole scene is within its budgets. */
    image->image.assign(bytes, bytes + size);
    image->width = w;
    image->height = h;
    image->component = 0;
    image->bits = 0;
    return true;
}

void decode_images(tinygltf::Model &model)
{
    for (size_t i = 0; i < model.images.size(); i++) {
        tinygltf::Image &img = model.images[i];
        if (img.component != 0 || img.image.empty())
            continue; /* no data (a warning already) */
        int w = 0, h = 0, comp = 0;
        unsigned char *px =
            stbi_load_from_memory(img.image.data(), int(img.image.size()), &w, &h, &comp, 4);
        if (!px || w != img.width || h != img.height) {
            const char *why = px ? "its size differs from its header's"
                                 : stbi_failure_reason() ? stbi_failure_reason() : "corrupt data";
            if (px)
                stbi_image_free(px);
            fail("image %zu could not be decoded (%s)", i, why);
        }
        try {
            img.image.assign(px, px + size_t(w) * size_t(h) * 4);
        } catch (...) {
            stbi_image_free(px);
            throw;
        }
        stbi_image_free(px);
        img.component = 4;
        img.bits = 8;
        img.pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    }
}

} // namespace lpv_gltf
