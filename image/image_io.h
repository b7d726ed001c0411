/*
 * image_io.h - reading and writing image files through OpenImageIO.
 *
 * Pixels are tightly packed rows, top row first. 8-bit data is written as is
 * (the caller has already encoded sRGB); float data is linear and is written
 * as 32-bit float (EXR). The format follows the file extension.
 */
#ifndef LPV_IMAGE_IO_H
#define LPV_IMAGE_IO_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* channels 1..4. Returns 0, or -1 with a message naming the file in err. */
int lpv_image_write_u8(const char *path, int width, int height, int channels, const uint8_t *pixels,
                       char *err, size_t err_size);
int lpv_image_write_f32(const char *path, int width, int height, int channels, const float *pixels,
                        char *err, size_t err_size);

/* Reads any format OpenImageIO knows as float, converting to `channels`
 * channels (missing ones 0, alpha 1). *pixels is malloc'd; free() it. */
int lpv_image_read_f32(const char *path, int channels, int *width, int *height, float **pixels,
                       char *err, size_t err_size);

/* In-memory encoding (for the daemon's FRAME messages): ext is "png" (8-bit
 * data) or "exr" (float data, written as 32-bit float). *out is malloc'd
 * (*out_len bytes); free() it. Returns 0, or -1 with a message in err. */
int lpv_image_encode_u8(const char *ext, int width, int height, int channels, const uint8_t *pixels,
                        uint8_t **out, size_t *out_len, char *err, size_t err_size);
int lpv_image_encode_f32(const char *ext, int width, int height, int channels, const float *pixels,
                         uint8_t **out, size_t *out_len, char *err, size_t err_size);

/* Resizes width x height pixels of `channels` floats (1..4) to dst_width x
 * dst_height through OpenImageIO's resize with a box filter one destination
 * pixel wide: each destination pixel is the average of the source area under
 * it, so values stay within the source's range (no ringing: HDR radiance
 * stays non-negative). Every channel, alpha included, is averaged on its own.
 * *out is malloc'd; free() it. Returns 0, or -1 with a message in err. */
int lpv_image_resize_f32(const float *pixels, int width, int height, int channels, int dst_width, int dst_height,
                         float **out, char *err, size_t err_size);

/* 1 if the path's extension is one lpv writes as float (".exr"), else 0. */
int lpv_image_is_float_format(const char *path);

#ifdef __cplusplus
}
#endif

#endif /* LPV_IMAGE_IO_H */
