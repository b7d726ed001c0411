/*
 * octree_settings.c - the octree's own rule on the settings, beyond each
 * knob's range (lpv_settings_validate calls it through the registry).
 */
#include <stdio.h>

#include "octree_rules.h"

int lpv_octree_validate(const lpv_settings *s, char *err, size_t err_size)
{
    const int n = s->grid_dims[0]; /* a full octree halves one cube down to one cell */
    if (n != s->grid_dims[1] || n != s->grid_dims[2] || n < 1 || (n & (n - 1)) != 0) {
        if (err && err_size)
            snprintf(err, err_size, "technique octree needs a cubic grid of a power of two cells per axis (grid %dx%dx%d)",
                     s->grid_dims[0], s->grid_dims[1], s->grid_dims[2]);
        return -1;
    }
    return 0;
}
