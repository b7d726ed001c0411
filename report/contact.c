/* contact.c - the contact sheet of a batch job (contact.h). */
#include "contact.h"

#include "image_io.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void grid(size_t items, size_t *tiles, int *cols, int *rows)
{
    size_t k = items < LPV_BATCH_CONTACT_MAX ? items : LPV_BATCH_CONTACT_MAX;
    size_t c = k < LPV_BATCH_CONTACT_COLUMNS ? k : LPV_BATCH_CONTACT_COLUMNS;
    *tiles = k;
    *cols = (int)c;
    *rows = c ? (int)((k + c - 1) / c) : 0;
}

static int extent(int n)
{
    return n ? n * LPV_BATCH_THUMB_SIZE + (n + 1) * LPV_BATCH_CONTACT_GAP : 0;
}

void lpv_batch_contact_size(size_t items, size_t *tiles, int *width, int *height)
{
    int cols, rows;
    grid(items, tiles, &cols, &rows);
    *width = extent(cols);
    *height = extent(rows);
}

static void fill(lpv_batch_contact *c, int x0, int y0, int w, int h, const uint8_t rgb[3])
{
    for (int y = y0; y < y0 + h; y++)
        for (int x = x0; x < x0 + w; x++)
            memcpy(c->rgb + ((size_t)y * (size_t)c->width + (size_t)x) * 3, rgb, 3);
}

/* Top-left corner of tile i. */
static void tile_origin(const lpv_batch_contact *c, size_t i, int *x, int *y)
{
    int col = (int)(i % (size_t)c->columns), row = (int)(i / (size_t)c->columns);
    *x = LPV_BATCH_CONTACT_GAP + col * (LPV_BATCH_THUMB_SIZE + LPV_BATCH_CONTACT_GAP);
    *y = LPV_BATCH_CONTACT_GAP + row * (LPV_BATCH_THUMB_SIZE + LPV_BATCH_CONTACT_GAP);
}

int lpv_batch_contact_init(lpv_batch_contact *c, size_t items, char *err, size_t err_size)
{
    memset(c, 0, sizeof *c);
    if (items == 0) {
        snprintf(err, err_size, "contact sheet: no items");
        return -1;
    }
    grid(items, &c->tiles, &c->columns, &c->rows);
    c->width = extent(c->columns);
    c->height = extent(c->rows);
    c->rgb = malloc((size_t)c->width * (size_t)c->height * 3);
    if (!c->rgb) {
        snprintf(err, err_size, "contact sheet: out of memory for %dx%d pixels", c->width, c->height);
        return -1;
    }
    static const uint8_t gap[3] = {LPV_BATCH_CONTACT_GAP_RGB}, tile[3] = {LPV_BATCH_CONTACT_TILE_RGB};
    fill(c, 0, 0, c->width, c->height, gap);
    for (size_t i = 0; i < c->tiles; i++) {
        int x, y;
        tile_origin(c, i, &x, &y);
        fill(c, x, y, LPV_BATCH_THUMB_SIZE, LPV_BATCH_THUMB_SIZE, tile);
    }
    return 0;
}

void lpv_batch_contact_put(lpv_batch_contact *c, size_t i, const lpv_batch_thumb *t)
{
    if (i >= c->tiles || !t || !t->rgba || t->width > LPV_BATCH_THUMB_SIZE || t->height > LPV_BATCH_THUMB_SIZE)
        return;
    int x0, y0;
    tile_origin(c, i, &x0, &y0);
    x0 += (LPV_BATCH_THUMB_SIZE - t->width) / 2;
    y0 += (LPV_BATCH_THUMB_SIZE - t->height) / 2;
    for (int y = 0; y < t->height; y++)
        for (int x = 0; x < t->width; x++) {
            const uint8_t *s = t->rgba + ((size_t)y * (size_t)t->width + (size_t)x) * 4;
            uint8_t *d = c->rgb + ((size_t)(y0 + y) * (size_t)c->width + (size_t)(x0 + x)) * 3;
            for (int k = 0; k < 3; k++) /* "over" in sRGB values: good enough for a preview */
                d[k] = (uint8_t)((s[k] * s[3] + d[k] * (255 - s[3]) + 127) / 255);
        }
}

void lpv_batch_contact_put_failed(lpv_batch_contact *c, size_t i)
{
    if (i >= c->tiles)
        return;
    static const uint8_t red[3] = {LPV_BATCH_CONTACT_FAILED_RGB};
    int x, y;
    tile_origin(c, i, &x, &y);
    fill(c, x, y, LPV_BATCH_THUMB_SIZE, LPV_BATCH_THUMB_SIZE, red);
}

int lpv_batch_contact_write(const lpv_batch_contact *c, const char *path, char *err, size_t err_size)
{
    return lpv_image_write_u8(path, c->width, c->height, 3, c->rgb, err, err_size);
}

void lpv_batch_contact_free(lpv_batch_contact *c)
{
    if (!c)
        return;
    free(c->rgb);
    memset(c, 0, sizeof *c);
}
