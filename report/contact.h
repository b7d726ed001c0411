/*
 * contact.h - the contact sheet: every item of a batch job as one tile of a
 * grid, in report order (row by row).
 *
 * Tiles are LPV_BATCH_THUMB_SIZE square, LPV_BATCH_CONTACT_GAP pixels apart
 * and from the edges, min(items, LPV_BATCH_CONTACT_COLUMNS) to a row; a sheet
 * shows the first LPV_BATCH_CONTACT_MAX items. So for k = min(items, MAX)
 * tiles, c = min(k, COLUMNS) columns and r = ceil(k / c) rows:
 *   width  = c * THUMB_SIZE + (c + 1) * GAP
 *   height = r * THUMB_SIZE + (r + 1) * GAP
 * An item's thumbnail sits centred on a dark grey tile (its alpha composited
 * over it); a failed item's tile is dark red; an ok item without a thumbnail
 * keeps the plain grey tile.
 */
#ifndef LPV_BATCH_CONTACT_H
#define LPV_BATCH_CONTACT_H

#include <stddef.h>
#include <stdint.h>

#include "thumbs.h"

#define LPV_BATCH_CONTACT_COLUMNS 8
#define LPV_BATCH_CONTACT_GAP 4
#define LPV_BATCH_CONTACT_MAX 256 /* tiles; about 2 k x 8.3 k pixels at most */

/* The colours (sRGB): between tiles, a tile, a failed item's tile. */
#define LPV_BATCH_CONTACT_GAP_RGB 16, 16, 16
#define LPV_BATCH_CONTACT_TILE_RGB 40, 40, 40
#define LPV_BATCH_CONTACT_FAILED_RGB 110, 20, 20

typedef struct lpv_batch_contact {
    int width, height;
    int columns, rows;
    size_t tiles;  /* min(items, LPV_BATCH_CONTACT_MAX) */
    uint8_t *rgb;  /* width x height RGB8 */
} lpv_batch_contact;

/* The sheet's tile count and size for a job of `items` items (0: 0 x 0). */
void lpv_batch_contact_size(size_t items, size_t *tiles, int *width, int *height);

/* An empty sheet for `items` items (at least 1). Returns 0, or -1 with a
 * message in err. lpv_batch_contact_free(c) in both cases. */
int lpv_batch_contact_init(lpv_batch_contact *c, size_t items, char *err, size_t err_size);

/* Tile i (ignored when i >= c->tiles): the thumbnail, or the failed colour. */
void lpv_batch_contact_put(lpv_batch_contact *c, size_t i, const lpv_batch_thumb *t);
void lpv_batch_contact_put_failed(lpv_batch_contact *c, size_t i);

/* Writes the sheet as a PNG. Returns 0, or -1 with a message in err. */
int lpv_batch_contact_write(const lpv_batch_contact *c, const char *path, char *err, size_t err_size);
void lpv_batch_contact_free(lpv_batch_contact *c);

#endif
