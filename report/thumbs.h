/*
 * thumbs.h - a batch item's thumbnail: its first PNG or EXR image output,
 * scaled to fit LPV_BATCH_THUMB_SIZE square (aspect kept, never enlarged).
 */
#ifndef LPV_BATCH_THUMBS_H
#define LPV_BATCH_THUMBS_H

#include <stddef.h>
#include <stdint.h>

#include <jansson.h>

#define LPV_BATCH_THUMB_SIZE 256 /* the longer side of a thumbnail, at most */

typedef struct lpv_batch_thumb {
    int width, height;
    uint8_t *rgba; /* width x height RGBA8 (straight alpha, sRGB), malloc'd */
} lpv_batch_thumb;

/* The "path" of the first entry of a manifest line's "outputs" whose "kind"
 * is "image" or "exr" and whose path ends in .png or .exr (any case), or
 * NULL. The string belongs to line. */
const char *lpv_batch_image_output(json_t *line);

/* The size a width x height image gets as a thumbnail. */
void lpv_batch_thumb_size(int width, int height, int *thumb_width, int *thumb_height);

/* Reads the image at path and makes its thumbnail (scaled through
 * lpv_image_resize_f32). A PNG keeps its 8-bit values; an EXR's radiance is
 * shown as `lpvd render` would write it as PNG: the exposure metered on the
 * full image, then the tone curve and background of lpv_display_rgba8.
 * Returns 0, or -1 with a message in err (t zeroed). */
int lpv_batch_thumb_make(const char *path, lpv_batch_thumb *t, char *err, size_t err_size);
void lpv_batch_thumb_free(lpv_batch_thumb *t);

#endif
