/*
 * volume_layout.c - what a volume carries (SPEC R5.9 - R5.15): the value
 * and role names, the layout of each kind of volume (SH cascades, the
 * octree's levels with an index, iv's voxels with an index, the probes'
 * cascades with their visibility), its units, its byte sizes and the
 * checks a lookup needs. See volume_codec.h.
 */
#include "volume_codec.h"
#include "proto.h"
#include "volume_codec_internal.h"
#include "probes_record.h" /* R5.15's record is the engine's */

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* ---- Volume description (SPEC R5.9 - R5.12) ------------------------------ */

/* R5.1's order: per channel c0 (Y00), then y (Y1-1), z (Y10), x (Y11), as
 * LPVP_VOLUME_SH says. */
const char *const lpvp_sh_value_names[LPVP_VALUES_PER_CELL] = {
    "r.Y00", "r.Y1-1", "r.Y10", "r.Y11", "g.Y00", "g.Y1-1", "g.Y10", "g.Y11",
    "b.Y00", "b.Y1-1", "b.Y10", "b.Y11"};
const char *const lpvp_level_role_names[LPVP_ROLE_COUNT] = {[LPVP_ROLE_CASCADE] = "cascade",
                                                            [LPVP_ROLE_FAR_FIELD] = "far_field",
                                                            [LPVP_ROLE_OCTREE_LEVEL] = "octree_level",
                                                            [LPVP_ROLE_IV_VOXELS] = "iv_voxels"};
const char *const lpvp_volume_content_names[LPVP_CONTENT_COUNT] = {[LPVP_CONTENT_MERGED] = "merged",
                                                                   [LPVP_CONTENT_LEVELS] = "levels",
                                                                   [LPVP_CONTENT_VISIBILITY] = "visibility"};

void lpvp_volume_layout_sh(lpvp_volume_layout *l, const char *technique, int far_field, int levels)
{
    memset(l, 0, sizeof *l);
    l->present = 1;
    l->layout_version = LPVP_VOLUME_LAYOUT_VERSION;
    snprintf(l->technique, sizeof l->technique, "%s", technique ? technique : "");
    l->far_field = far_field != 0;
    for (int k = 0; k < LPVP_MAX_LEVELS; k++)
        l->role[k] = (l->far_field && k > 0 && k < levels) ? LPVP_ROLE_FAR_FIELD : LPVP_ROLE_CASCADE;
    l->volumes_per_level = 1;
    l->values_per_cell = LPVP_VALUES_PER_CELL;
    l->sh_values = 1;
}

int lpvp_octree_level_count(int64_t n)
{
    int l = 1;
    if (n < 1 || (n & (n - 1)) != 0)
        return -1;
    while ((n >> (l - 1)) > 1)
        l++;
    return l <= LPVP_MAX_LEVELS ? l : -1;
}

void lpvp_octree_level_place(const lpvp_cascade_info *level0, int i, lpvp_cascade_info *out)
{
    *out = *level0;
    out->cells = 1;
    for (int a = 0; a < 3; a++) {
        out->dims[a] = level0->dims[a] >> i;
        out->cells *= (uint64_t)(out->dims[a] > 0 ? out->dims[a] : 0);
    }
    out->cell_size = ldexp(level0->cell_size, i);
}

/* The one-value-per-cell index volume (SPEC R5.13, R5.14) over level 0. */
static void layout_index_over(lpvp_volume_layout *l, const lpvp_cascade_info *level0)
{
    l->has_index = 1;
    l->index.level = 0;
    for (int a = 0; a < 3; a++)
        l->index.dims[a] = level0->dims[a];
    l->index.cells = level0->cells;
    l->index.values_per_cell = 1;
    l->index.raw_length = level0->cells * LPVP_INDEX_VALUE_SIZE;
}

int lpvp_volume_layout_octree(lpvp_volume_layout *l, const char *technique, const lpvp_cascade_info *level0,
                              char *err, size_t err_n)
{
    int count = lpvp_octree_level_count(level0->dims[0]);
    if (count < 0 || level0->dims[1] != level0->dims[0] || level0->dims[2] != level0->dims[0]) {
        lpvp_set_error(err, err_n, "a grid of %lldx%lldx%lld cells has no octree of at most %d levels (it needs a cube "
                       "of a power of two)", (long long)level0->dims[0], (long long)level0->dims[1],
                       (long long)level0->dims[2], LPVP_MAX_LEVELS);
        return -1;
    }
    lpvp_volume_layout_sh(l, technique, 0, 1);
    l->content = LPVP_CONTENT_LEVELS;
    l->level_count = count;
    for (int i = 0; i < count; i++) {
        lpvp_octree_level_place(level0, i, &l->level[i]);
        l->role[i] = LPVP_ROLE_OCTREE_LEVEL;
    }
    layout_index_over(l, level0);
    return 0;
}

int lpvp_volume_layout_iv(lpvp_volume_layout *l, const char *technique, const lpvp_cascade_info *level0,
                          int neighbours, char *err, size_t err_n)
{
    if (neighbours < LPVP_IV_NEIGHBOURS_MIN || neighbours > LPVP_IV_NEIGHBOURS_MAX) {
        lpvp_set_error(err, err_n, "%s %d is outside %d..%d", LPVP_IV_NEIGHBOURS_KEY, neighbours,
                       LPVP_IV_NEIGHBOURS_MIN, LPVP_IV_NEIGHBOURS_MAX);
        return -1;
    }
    lpvp_volume_layout_sh(l, technique, 0, 1);
    l->role[0] = LPVP_ROLE_IV_VOXELS;
    snprintf(l->units, sizeof l->units, "%s", LPVP_VOLUME_UNITS_RADIANCE);
    layout_index_over(l, level0);
    l->iv_neighbours = neighbours;
    return 0;
}

int lpvp_volume_layout_visibility(lpvp_volume_layout *l, const char *technique, int levels, int irradiance_side,
                                  int distance_side, double bias_cells, char *err, size_t err_n)
{
    if (irradiance_side < 1 || irradiance_side > LPVP_VISIBILITY_MAX_IRRADIANCE_SIDE || distance_side < 1 ||
        distance_side > LPVP_VISIBILITY_MAX_DISTANCE_SIDE || !(bias_cells >= 0.0) || !isfinite(bias_cells)) {
        lpvp_set_error(err, err_n, "probes' visibility with maps of %d and %d texels a side and a bias of %g cells: "
                       "the sides must be in 1..%d and 1..%d, the bias finite and >= 0", irradiance_side,
                       distance_side, bias_cells, LPVP_VISIBILITY_MAX_IRRADIANCE_SIDE,
                       LPVP_VISIBILITY_MAX_DISTANCE_SIDE);
        return -1;
    }
    lpvp_volume_layout_sh(l, technique, 0, levels);
    l->content = LPVP_CONTENT_VISIBILITY;
    l->has_visibility = 1;
    l->visibility.irradiance_side = irradiance_side;
    l->visibility.distance_side = distance_side;
    l->visibility.values_per_probe = lpv_probes_record_values(irradiance_side, distance_side);
    l->visibility.bias_cells = bias_cells;
    return 0;
}

uint64_t lpvp_volume_extra_bytes(const lpvp_volume_info *vi)
{
    if (vi->layout.has_index)
        return vi->layout.index.raw_length;
    if (vi->layout.has_visibility)
        return lpvp_volume_total_cells(vi) * vi->layout.visibility.values_per_probe * LPVP_VISIBILITY_VALUE_SIZE;
    return 0;
}

int lpvp_volume_layout_is_iv(const lpvp_volume_layout *l)
{
    return l->present && l->content == LPVP_CONTENT_MERGED && l->role[0] == LPVP_ROLE_IV_VOXELS;
}

const char *lpvp_volume_layout_units(const lpvp_volume_layout *l)
{
    return l->units[0] ? l->units : LPVP_VOLUME_UNITS;
}

uint64_t lpvp_volume_values_bytes(const lpvp_volume_info *vi)
{
    uint64_t vpc = vi->layout.values_per_cell, vpl = vi->layout.volumes_per_level;
    if (!vi->layout.present && vpc == 0) { /* an info filled by hand before descriptions: R5.1 */
        vpc = LPVP_VALUES_PER_CELL;
        vpl = 1;
    }
    if (vpc < 1 || vpc > LPVP_MAX_VALUES_PER_CELL || vpl < 1 || vpl > LPVP_MAX_VOLUMES_PER_LEVEL)
        return 0;
    uint64_t cells = lpvp_volume_total_cells(vi);
    uint64_t per = vpc * vpl * (uint64_t)lpvp_volume_value_size(vi->format);
    if (cells > (((uint64_t)1 << 62) / per))
        return 0;
    return cells * per;
}

int lpvp_volume_layout_lookup_check(const lpvp_volume_layout *l, char *err, size_t err_n)
{
    if (lpvp_volume_layout_is_iv(l)) {
        lpvp_set_error(err, err_n,
                       "volume of technique \"%s\" is %s voxels holding radiance (%s) with an index of the voxels "
                       "that hold a surface, not R5.1's cascades R5.7's lookup reads: use R5.14's lookup",
                       l->technique, lpvp_level_role_names[LPVP_ROLE_IV_VOXELS], lpvp_volume_layout_units(l));
        return -1;
    }
    if (l->content == LPVP_CONTENT_LEVELS) {
        lpvp_set_error(err, err_n,
                       "volume of content \"%s\" (technique \"%s\": its %d levels and index volume) is not the merged "
                       "grid R5.7's lookup reads: ask GET_VOLUME with content \"%s\"",
                       lpvp_volume_content_names[LPVP_CONTENT_LEVELS], l->technique, l->level_count,
                       lpvp_volume_content_names[LPVP_CONTENT_MERGED]);
        return -1;
    }
    if ((l->sh_values || (!l->present && l->values_per_cell == 0)) && l->volumes_per_level <= 1 && !l->has_index &&
        strcmp(lpvp_volume_layout_units(l), LPVP_VOLUME_UNITS) == 0)
        return 0;
    lpvp_set_error(err, err_n,
                   "volume layout of technique \"%s\" (layout_version %d, %d values per cell%s, %d volumes per "
                   "level%s, units %s) is not R5.1's 12 SH values in one volume per level, the only layout R5.7's "
                   "lookup reads", l->technique, l->layout_version, l->values_per_cell,
                   l->sh_values ? ", the SH values" : "", l->volumes_per_level,
                   l->has_index ? ", with an index volume" : "", lpvp_volume_layout_units(l));
    return -1;
}

int lpvp_volume_layout_iv_lookup_check(const lpvp_volume_layout *l, char *err, size_t err_n)
{
    if (lpvp_volume_layout_is_iv(l) && l->sh_values && l->volumes_per_level == 1 && l->has_index &&
        l->index.level == 0 && l->index.values_per_cell == 1 && l->iv_neighbours >= LPVP_IV_NEIGHBOURS_MIN &&
        l->iv_neighbours <= LPVP_IV_NEIGHBOURS_MAX)
        return 0;
    lpvp_set_error(err, err_n,
                   "volume layout of technique \"%s\" (%s, %d values per cell, %d volumes per level%s) is not "
                   "R5.14's %s voxels, the only layout R5.14's lookup reads", l->technique[0] ? l->technique : "?",
                   l->content == LPVP_CONTENT_LEVELS ? "content \"levels\"" : "content \"merged\"",
                   l->values_per_cell, l->volumes_per_level, l->has_index ? ", with an index" : ", no index",
                   lpvp_level_role_names[LPVP_ROLE_IV_VOXELS]);
    return -1;
}

/* ---- Cells (the cascades or the octree's levels a volume holds) ---------- */

int lpvp_cascades_of(const lpvp_volume_info *vi, lpvp_cascade_info *out)
{
    if (vi->cascade_count == 0) {
        memset(out, 0, sizeof *out);
        out->cells = 1;
        for (int i = 0; i < 3; i++) {
            out->dims[i] = vi->dims[i];
            out->origin[i] = vi->origin[i];
            out->cells *= (uint64_t)(vi->dims[i] > 0 ? vi->dims[i] : 0);
        }
        out->cell_size = vi->cell_size;
        return 1;
    }
    if (vi->cascade_count < 0 || vi->cascade_count > LPVP_MAX_CASCADES)
        return -1;
    for (int k = 0; k < vi->cascade_count; k++)
        out[k] = vi->cascades[k];
    return vi->cascade_count;
}

/* The levels the raw volume holds: the octree's (R5.13) or the cascades. */
static int levels_of(const lpvp_volume_info *vi, lpvp_cascade_info *out)
{
    if (vi->layout.content != LPVP_CONTENT_LEVELS)
        return lpvp_cascades_of(vi, out);
    if (vi->layout.level_count < 1 || vi->layout.level_count > LPVP_MAX_LEVELS)
        return -1;
    for (int k = 0; k < vi->layout.level_count; k++)
        out[k] = vi->layout.level[k];
    return vi->layout.level_count;
}

uint64_t lpvp_volume_total_cells(const lpvp_volume_info *vi)
{
    lpvp_cascade_info c[LPVP_MAX_LEVELS];
    int n = levels_of(vi, c);
    uint64_t total = 0;
    for (int k = 0; k < n; k++)
        total += c[k].cells;
    return n < 0 ? 0 : total;
}

uint64_t lpvp_volume_cascade_first_cell(const lpvp_volume_info *vi, int k)
{
    lpvp_cascade_info c[LPVP_MAX_LEVELS];
    int n = levels_of(vi, c);
    uint64_t first = 0;
    for (int i = 0; i < k && i < n; i++)
        first += c[i].cells;
    return first;
}
