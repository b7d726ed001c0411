/*
 * volume_header_build.c - the VOLUME header's JSON from an
 * lpvp_volume_info (SPEC R5.1, R5.9 - R5.15): placement, cascades or
 * levels, the description object, the index or the probes' visibility. See volume_codec.h.
 */
#include "volume_codec.h"
#include "proto.h"
#include "volume_codec_internal.h"

#include <math.h>
#include <string.h>

/* The description object (R5.9): levels from the cascades, values from the
 * SH names (the only values this library builds). */
static json_t *placement_json(const lpvp_cascade_info *c);
static json_t *index_json(const lpvp_volume_info *vi);
static json_t *visibility_json(const lpvp_volume_info *vi);

static json_t *layout_json(const lpvp_volume_info *vi, json_t *cascades)
{
    const lpvp_volume_layout *l = &vi->layout;
    json_t *levels = NULL, *values = json_array();
    if (l->content == LPVP_CONTENT_LEVELS) { /* R5.13: the octree's levels */
        levels = json_array();
        for (int k = 0; levels && k < l->level_count && k < LPVP_MAX_LEVELS; k++) {
            if (json_array_append_new(levels, placement_json(&l->level[k])) != 0) {
                json_decref(levels);
                levels = NULL;
            }
        }
    } else {
        levels = json_deep_copy(cascades);
    }
    json_t *o = json_object();
    int bad = !levels || !values || !o || !l->sh_values || l->values_per_cell != LPVP_VALUES_PER_CELL;
    for (size_t k = 0; !bad && k < json_array_size(levels); k++) {
        int r = l->role[k] >= 0 && l->role[k] < LPVP_ROLE_COUNT ? (int)l->role[k] : LPVP_ROLE_CASCADE;
        bad |= json_object_set_new(json_array_get(levels, k), "role", json_string(lpvp_level_role_names[r])) != 0;
    }
    for (int i = 0; !bad && i < LPVP_VALUES_PER_CELL; i++)
        bad |= json_array_append_new(values, json_string(lpvp_sh_value_names[i])) != 0;
    if (!bad) {
        bad |= json_object_set_new(o, "layout_version", json_integer(l->layout_version)) != 0;
        bad |= json_object_set_new(o, "technique", json_string(l->technique)) != 0;
        bad |= json_object_set_new(o, "levels", levels) != 0;
        levels = NULL;
        bad |= json_object_set_new(o, "far_field", json_boolean(l->far_field)) != 0;
        bad |= json_object_set_new(o, "volumes_per_level", json_integer(l->volumes_per_level)) != 0;
        bad |= json_object_set_new(o, "values_per_cell", json_integer(l->values_per_cell)) != 0;
        bad |= json_object_set_new(o, "values", values) != 0;
        values = NULL;
        bad |= json_object_set_new(o, "units", json_string(lpvp_volume_layout_units(l))) != 0;
        bad |= json_object_set_new(o, "index", l->has_index ? index_json(vi) : json_null()) != 0;
        if (lpvp_volume_layout_is_iv(l)) /* R5.14 */
            bad |= json_object_set_new(o, LPVP_IV_NEIGHBOURS_KEY, json_integer(l->iv_neighbours)) != 0;
        if (l->has_visibility) /* R5.15 */
            bad |= json_object_set_new(o, LPVP_VISIBILITY_KEY, visibility_json(vi)) != 0;
    }
    json_decref(levels);
    json_decref(values);
    if (bad) {
        json_decref(o);
        return NULL;
    }
    return o;
}

/* ---- Volume header -------------------------------------------------------- */

static json_t *vec_json(const double *v, size_t n)
{
    json_t *a = json_array();
    for (size_t i = 0; a && i < n; i++) {
        if (json_array_append_new(a, json_real(isfinite(v[i]) ? v[i] : 0.0)) != 0) {
            json_decref(a);
            return NULL;
        }
    }
    return a;
}

/* One level's (cascade's) placement: dims, origin, cell_size, cells. */
static json_t *placement_json(const lpvp_cascade_info *c)
{
    return json_pack("{s:[I,I,I], s:o, s:f, s:I}", "dims", (json_int_t)c->dims[0], (json_int_t)c->dims[1],
                     (json_int_t)c->dims[2], "origin", vec_json(c->origin, 3), "cell_size",
                     isfinite(c->cell_size) ? c->cell_size : 0.0, "cells", (json_int_t)c->cells);
}

/* The index object (R5.12), right after the levels' values. */
static json_t *index_json(const lpvp_volume_info *vi)
{
    const lpvp_index_info *ix = &vi->layout.index;
    uint64_t length = ix->cells * (uint64_t)ix->values_per_cell * LPVP_INDEX_VALUE_SIZE;
    return json_pack("{s:i, s:[I,I,I], s:i, s:s, s:I, s:I}", "level", ix->level, "dims", (json_int_t)ix->dims[0],
                     (json_int_t)ix->dims[1], (json_int_t)ix->dims[2], "values_per_cell", ix->values_per_cell,
                     "value_type", LPVP_INDEX_VALUE_TYPE, "raw_offset", (json_int_t)lpvp_volume_values_bytes(vi),
                     "raw_length", (json_int_t)length);
}

/* The probes' visibility (R5.15), right after the levels' values: a probe
 * per cell of every level. */
static json_t *visibility_json(const lpvp_volume_info *vi)
{
    const lpvp_visibility_info *v = &vi->layout.visibility;
    const uint64_t probes = lpvp_volume_total_cells(vi);
    return json_pack("{s:I, s:i, s:i, s:I, s:s, s:f, s:I, s:I}", "probes", (json_int_t)probes, "irradiance_side",
                     v->irradiance_side, "distance_side", v->distance_side, "values_per_probe",
                     (json_int_t)v->values_per_probe, "value_type", LPVP_VISIBILITY_VALUE_TYPE, "bias_cells",
                     isfinite(v->bias_cells) ? v->bias_cells : 0.0, "raw_offset",
                     (json_int_t)lpvp_volume_values_bytes(vi), "raw_length", (json_int_t)lpvp_volume_extra_bytes(vi));
}

static json_t *cascades_json(const lpvp_volume_info *vi)
{
    lpvp_cascade_info c[LPVP_MAX_CASCADES];
    int n = lpvp_cascades_of(vi, c);
    json_t *a = json_array();
    if (!a || n < 0) {
        json_decref(a);
        return NULL;
    }
    for (int k = 0; k < n; k++) {
        json_t *e = placement_json(&c[k]);
        if (!e || json_array_append_new(a, e) != 0) {
            json_decref(a);
            return NULL;
        }
    }
    return a;
}

json_t *lpvp_volume_header_build(const lpvp_volume_info *vi)
{
    json_t *o = json_object();
    json_t *grid = json_object();
    json_t *dims = json_array();
    int bad = !o || !grid || !dims;
    for (int i = 0; !bad && i < 3; i++)
        bad |= json_array_append_new(dims, json_integer(vi->dims[i])) != 0;
    if (!bad) {
        bad |= json_object_set_new(grid, "dims", dims) != 0;
        dims = NULL;
        bad |= json_object_set_new(grid, "origin", vec_json(vi->origin, 3)) != 0;
        bad |= json_object_set_new(grid, "cell_size",
                                   json_real(isfinite(vi->cell_size) ? vi->cell_size : 0.0)) != 0;
    }
    if (!bad) {
        bad |= json_object_set_new(o, "revision", json_integer(vi->revision)) != 0;
        bad |= json_object_set_new(o, "tick", json_integer(vi->tick)) != 0;
        bad |= json_object_set_new(o, "format",
                                   json_string(lpvp_volume_format_name(vi->format))) != 0;
        bad |= json_object_set_new(o, "compression",
                                   json_string(lpvp_compression_name(vi->compression))) != 0;
        bad |= json_object_set_new(o, "keyframe", json_boolean(vi->keyframe)) != 0;
        if (vi->compression == LPVP_COMP_SHQ) /* R5.16 */
            bad |= json_object_set_new(o, LPVP_SHQ_BOUND_KEY, json_real(vi->error_bound)) != 0;
        if (!vi->keyframe)
            bad |= json_object_set_new(o, "base_tick", json_integer(vi->base_tick)) != 0;
        bad |= json_object_set_new(o, "grid", grid) != 0;
        grid = NULL;
        json_t *cascades = cascades_json(vi);
        bad |= json_object_set_new(o, "cascades", cascades) != 0;
        bad |= json_object_set_new(o, "units", json_string(lpvp_volume_layout_units(&vi->layout))) != 0;
        bad |= json_object_set_new(o, "layout", json_string(LPVP_VOLUME_LAYOUT)) != 0;
        bad |= json_object_set_new(o, "sh", json_string(LPVP_VOLUME_SH)) != 0;
        bad |= json_object_set_new(o, "raw_length", json_integer((json_int_t)vi->raw_length)) != 0;
        if (!bad && vi->layout.present)
            bad |= json_object_set_new(o, LPVP_VOLUME_DESC_KEY, layout_json(vi, cascades)) != 0;
    }
    json_decref(dims);
    json_decref(grid);
    if (bad) {
        json_decref(o);
        return NULL;
    }
    return o;
}
