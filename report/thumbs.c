/* thumbs.c - thumbnails of a batch item's image (thumbs.h). */
#include "thumbs.h"

#include "image_io.h"
#include "tonemap.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static int has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), e = strlen(ext);
    return n > e && strcasecmp(path + n - e, ext) == 0;
}

const char *lpv_batch_image_output(json_t *line)
{
    size_t i;
    json_t *out;
    json_array_foreach(json_object_get(line, "outputs"), i, out)
    {
        const char *kind = json_string_value(json_object_get(out, "kind"));
        const char *path = json_string_value(json_object_get(out, "path"));
        if (!kind || !path || (strcmp(kind, "image") != 0 && strcmp(kind, "exr") != 0))
            continue;
        if (has_ext(path, ".png") || has_ext(path, ".exr"))
            return path;
    }
    return NULL;
}

void lpv_batch_thumb_size(int width, int height, int *tw, int *th)
{
    const int s = LPV_BATCH_THUMB_SIZE;
    if (width <= s && height <= s) {
        *tw = width;
        *th = height;
    } else if (width >= height) {
        *tw = s;
        *th = (int)lround((double)height * s / width);
    } else {
        *th = s;
        *tw = (int)lround((double)width * s / height);
    }
    if (*tw < 1)
        *tw = 1;
    if (*th < 1)
        *th = 1;
}

int lpv_batch_thumb_make(const char *path, lpv_batch_thumb *t, char *err, size_t err_size)
{
    memset(t, 0, sizeof *t);
    int w = 0, h = 0;
    float *full = NULL;
    if (lpv_image_read_f32(path, 4, &w, &h, &full, err, err_size) != 0)
        return -1;
    const int radiance = lpv_image_is_float_format(path);
    const float ev = radiance ? lpv_exposure_meter_ev(full, (size_t)w * (size_t)h) : 0.0f;
    int tw, th;
    lpv_batch_thumb_size(w, h, &tw, &th);
    float *small = full;
    if (tw != w || th != h) {
        if (lpv_image_resize_f32(full, w, h, 4, tw, th, &small, err, err_size) != 0) {
            free(full);
            return -1;
        }
        free(full);
    }
    const size_t n = (size_t)tw * (size_t)th;
    uint8_t *rgba = malloc(n * 4);
    if (!rgba) {
        free(small);
        snprintf(err, err_size, "%s: out of memory for a %dx%d thumbnail", path, tw, th);
        return -1;
    }
    if (radiance) {
        lpv_display d;
        lpv_display_default(&d);
        d.exposure_auto = 0;
        d.exposure_ev = ev;
        lpv_display_rgba8(small, n, &d, rgba);
    } else {
        for (size_t i = 0; i < n * 4; i++) {
            float v = small[i];
            v = v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f; /* NaN too */
            rgba[i] = (uint8_t)lrintf(v * 255.0f);
        }
    }
    free(small);
    t->width = tw;
    t->height = th;
    t->rgba = rgba;
    return 0;
}

void lpv_batch_thumb_free(lpv_batch_thumb *t)
{
    if (!t)
        return;
    free(t->rgba);
    memset(t, 0, sizeof *t);
}
