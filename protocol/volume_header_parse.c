/*
 * volume_header_parse.c - a VOLUME header read and checked against SPEC
 * section 5 (lpvp_volume_header_parse), and a payload decoded with it
 * (lpvp_volume_decode): every size, placement and layout is checked before
 * anything is allocated or copied. See volume_codec.h.
 */
#include "volume_codec.h"
#include "proto.h"
#include "volume_codec_internal.h"
#include "probes_record.h" /* R5.15's record is the engine's */

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Local getters (volume_codec does not depend on proto.c's). */
static int need_int(const json_t *o, const char *key, long long min, long long *out, char *err,
                    size_t err_n)
{
    json_t *v = json_object_get(o, key);
    if (!json_is_integer(v)) {
        lpvp_set_error(err, err_n, "%s: expected an integer", key);
        return -1;
    }
    if (json_integer_value(v) < min) {
        lpvp_set_error(err, err_n, "%s: %lld is less than %lld", key, (long long)json_integer_value(v),
                min);
        return -1;
    }
    *out = (long long)json_integer_value(v);
    return 0;
}

static int same_real(double a, double b)
{
    return fabs(a - b) <= 1e-9 * (fabs(a) > fabs(b) ? fabs(a) : fabs(b)) + 1e-12;
}

/* "cascades" (R5.6) into vi->lpv.cascades; the grid fields are already read.
 * Absent: one cascade equal to the grid (a server before cascades). */
static int parse_cascades(const json_t *obj, lpvp_volume_info *vi, char *err, size_t err_n)
{
    const json_t *a = json_object_get(obj, "cascades");
    uint64_t total = 0;
    if (!a) {
        vi->cascade_count = 0;
        lpvp_cascades_of(vi, &vi->cascades[0]);
        vi->cascade_count = 1;
        return 0;
    }
    if (!json_is_array(a) || json_array_size(a) < 1 || json_array_size(a) > LPVP_MAX_CASCADES) {
        lpvp_set_error(err, err_n, "cascades: expected an array of 1 to %d cascades", LPVP_MAX_CASCADES);
        return -1;
    }
    vi->cascade_count = (int)json_array_size(a);
    for (int k = 0; k < vi->cascade_count; k++) {
        const json_t *c = json_array_get(a, (size_t)k), *d, *v;
        lpvp_cascade_info *ci = &vi->cascades[k];
        uint64_t cells = 1;
        if (!json_is_object(c)) {
            lpvp_set_error(err, err_n, "cascades[%d]: expected an object", k);
            return -1;
        }
        d = json_object_get(c, "dims");
        if (!json_is_array(d) || json_array_size(d) != 3) {
            lpvp_set_error(err, err_n, "cascades[%d].dims: expected an array of 3 integers", k);
            return -1;
        }
        for (size_t i = 0; i < 3; i++) {
            v = json_array_get(d, i);
            if (!json_is_integer(v) || json_integer_value(v) < 1 ||
                json_integer_value(v) > (1 << 20)) {
                lpvp_set_error(err, err_n, "cascades[%d].dims[%zu]: expected an integer in [1, 1048576]",
                               k, i);
                return -1;
            }
            ci->dims[i] = json_integer_value(v);
            if (cells > ((uint64_t)1 << 62) / (uint64_t)ci->dims[i]) {
                lpvp_set_error(err, err_n, "cascades[%d].dims: too many cells", k);
                return -1;
            }
            cells *= (uint64_t)ci->dims[i];
        }
        d = json_object_get(c, "origin");
        if (!json_is_array(d) || json_array_size(d) != 3) {
            lpvp_set_error(err, err_n, "cascades[%d].origin: expected an array of 3 numbers", k);
            return -1;
        }
        for (size_t i = 0; i < 3; i++) {
            v = json_array_get(d, i);
            if (!json_is_number(v) || !isfinite(json_number_value(v))) {
                lpvp_set_error(err, err_n, "cascades[%d].origin[%zu]: expected a number", k, i);
                return -1;
            }
            ci->origin[i] = json_number_value(v);
        }
        v = json_object_get(c, "cell_size");
        if (!json_is_number(v) || !(json_number_value(v) > 0.0) || !isfinite(json_number_value(v))) {
            lpvp_set_error(err, err_n, "cascades[%d].cell_size: expected a positive number", k);
            return -1;
        }
        ci->cell_size = json_number_value(v);
        v = json_object_get(c, "cells");
        if (!json_is_integer(v) || json_integer_value(v) < 0 ||
            (uint64_t)json_integer_value(v) != cells) {
            lpvp_set_error(err, err_n, "cascades[%d].cells: expected %llu (the product of its dims)", k,
                           (unsigned long long)cells);
            return -1;
        }
        ci->cells = cells;
        if (total > ((uint64_t)1 << 62) - cells) {
            lpvp_set_error(err, err_n, "cascades: too many cells");
            return -1;
        }
        total += cells;
    }
    for (int i = 0; i < 3; i++) {
        if (vi->cascades[0].dims[i] != vi->dims[i]) {
            lpvp_set_error(err, err_n, "grid.dims: differs from cascades[0].dims");
            return -1;
        }
        if (!same_real(vi->cascades[0].origin[i], vi->origin[i])) {
            lpvp_set_error(err, err_n, "grid.origin: differs from cascades[0].origin");
            return -1;
        }
    }
    if (!same_real(vi->cascades[0].cell_size, vi->cell_size)) {
        lpvp_set_error(err, err_n, "grid.cell_size: differs from cascades[0].cell_size");
        return -1;
    }
    if ((uint64_t)(size_t)total != total) {
        lpvp_set_error(err, err_n, "cascades: too many cells");
        return -1;
    }
    return 0;
}

/* 1 when a level object e has ci's dims, origin, cell_size and cells. */
static int level_matches(const json_t *e, const lpvp_cascade_info *ci)
{
    const json_t *dims = json_object_get(e, "dims"), *org = json_object_get(e, "origin"), *v;
    int same = json_is_array(dims) && json_array_size(dims) == 3 && json_is_array(org) && json_array_size(org) == 3;
    for (size_t i = 0; same && i < 3; i++) {
        same = json_is_integer(json_array_get(dims, i)) && json_integer_value(json_array_get(dims, i)) == ci->dims[i] &&
               json_is_number(json_array_get(org, i)) &&
               same_real(json_number_value(json_array_get(org, i)), ci->origin[i]);
    }
    v = json_object_get(e, "cell_size");
    same = same && json_is_number(v) && same_real(json_number_value(v), ci->cell_size);
    v = json_object_get(e, "cells");
    return same && json_is_integer(v) && (uint64_t)json_integer_value(v) == ci->cells;
}

/* 1 when levels[0] has the role `role` ("octree_level": R5.13, "iv_voxels": R5.14). */
static int levels_have_role(const json_t *levels, int role)
{
    const json_t *r = json_object_get(json_array_get(levels, 0), "role");
    return json_is_array(levels) && json_is_string(r) && strcmp(json_string_value(r), lpvp_level_role_names[role]) == 0;
}

/* R5.13: an octree's levels over cascades[0] (the only cascade), every one
 * placed as lpvp_octree_level_place says, far_field false. */
static int parse_octree_levels(const json_t *d, lpvp_volume_info *vi, char *err, size_t err_n)
{
    lpvp_volume_layout *l = &vi->layout;
    const char *K = LPVP_VOLUME_DESC_KEY, *OL = lpvp_level_role_names[LPVP_ROLE_OCTREE_LEVEL];
    const json_t *a = json_object_get(d, "levels");
    const lpvp_cascade_info *c0 = &vi->cascades[0];
    if (vi->cascade_count != 1) {
        lpvp_set_error(err, err_n, "cascades: %d entries, but \"%s\" levels need exactly one, level 0", vi->cascade_count,
                       OL);
        return -1;
    }
    int count = lpvp_octree_level_count(c0->dims[0]);
    if (count < 0 || c0->dims[1] != c0->dims[0] || c0->dims[2] != c0->dims[0]) {
        lpvp_set_error(err, err_n, "%s.levels: \"%s\" levels over a %lldx%lldx%lld level 0, which has no octree of at "
                       "most %d levels (a cube of a power of two)", K, OL, (long long)c0->dims[0], (long long)c0->dims[1],
                       (long long)c0->dims[2], LPVP_MAX_LEVELS);
        return -1;
    }
    if (json_array_size(a) != (size_t)count) {
        lpvp_set_error(err, err_n, "%s.levels: %zu \"%s\" levels, but an octree over %lld^3 cells has %d (log2(n) + 1)",
                       K, json_array_size(a), OL, (long long)c0->dims[0], count);
        return -1;
    }
    if (l->far_field) {
        lpvp_set_error(err, err_n, "%s.far_field: true with \"%s\" levels (an octree has no far field)", K, OL);
        return -1;
    }
    for (int k = 0; k < count; k++) {
        const json_t *e = json_array_get(a, (size_t)k), *r = json_object_get(e, "role");
        lpvp_cascade_info want;
        lpvp_octree_level_place(c0, k, &want);
        if (!json_is_object(e) || !level_matches(e, &want)) {
            lpvp_set_error(err, err_n, "%s.levels[%d]: dims, origin, cell_size and cells differ from octree level %d "
                           "(level 0's origin, dims n >> %d, cell size 2^%d x level 0's)", K, k, k, k, k);
            return -1;
        }
        if (!json_is_string(r) || strcmp(json_string_value(r), OL) != 0) {
            lpvp_set_error(err, err_n, "%s.levels[%d].role: expected \"%s\" (level 0's role)", K, k, OL);
            return -1;
        }
        l->level[k] = want;
        l->role[k] = LPVP_ROLE_OCTREE_LEVEL;
    }
    l->content = LPVP_CONTENT_LEVELS;
    l->level_count = count;
    return 0;
}

/* R5.14: technique iv's one level of voxels, equal to cascades[0] (the only
 * cascade), far_field false, and its lookup's iv_neighbours. The cells, units
 * and index are checked after parse_cells (iv_checks). */
static int parse_iv_levels(const json_t *d, lpvp_volume_info *vi, char *err, size_t err_n)
{
    lpvp_volume_layout *l = &vi->layout;
    const char *K = LPVP_VOLUME_DESC_KEY, *IV = lpvp_level_role_names[LPVP_ROLE_IV_VOXELS];
    const json_t *a = json_object_get(d, "levels"), *v;
    if (vi->cascade_count != 1 || json_array_size(a) != 1) {
        lpvp_set_error(err, err_n, "%s.levels: %zu levels over %d cascades, but \"%s\" is exactly one level over "
                       "one cascade (R5.14)", K, json_array_size(a), vi->cascade_count, IV);
        return -1;
    }
    if (!json_is_object(json_array_get(a, 0)) || !level_matches(json_array_get(a, 0), &vi->cascades[0])) {
        lpvp_set_error(err, err_n, "%s.levels[0]: dims, origin, cell_size and cells differ from cascades[0]", K);
        return -1;
    }
    if (l->far_field) {
        lpvp_set_error(err, err_n, "%s.far_field: true with \"%s\" levels (an iv volume has no far field)", K, IV);
        return -1;
    }
    v = json_object_get(d, LPVP_IV_NEIGHBOURS_KEY);
    if (!json_is_integer(v) || json_integer_value(v) < LPVP_IV_NEIGHBOURS_MIN ||
        json_integer_value(v) > LPVP_IV_NEIGHBOURS_MAX) {
        lpvp_set_error(err, err_n, "%s.%s: expected an integer in [%d, %d] with \"%s\" levels (R5.14)", K,
                       LPVP_IV_NEIGHBOURS_KEY, LPVP_IV_NEIGHBOURS_MIN, LPVP_IV_NEIGHBOURS_MAX, IV);
        return -1;
    }
    l->iv_neighbours = (int)json_integer_value(v);
    l->role[0] = LPVP_ROLE_IV_VOXELS;
    return 0;
}

/* R5.14 after parse_cells: the 12 SH values in one volume, radiance units,
 * the index over level 0 with one value per voxel. */
static int iv_checks(lpvp_volume_info *vi, char *err, size_t err_n)
{
    const lpvp_volume_layout *l = &vi->layout;
    const lpvp_cascade_info *c0 = &vi->cascades[0];
    const char *K = LPVP_VOLUME_DESC_KEY, *IV = lpvp_level_role_names[LPVP_ROLE_IV_VOXELS];
    if (!l->sh_values || l->volumes_per_level != 1) {
        lpvp_set_error(err, err_n, "%s.values: \"%s\" levels hold R5.1's 12 SH values in one volume per level "
                       "(got %d values, %d volumes; R5.14)", K, IV, l->values_per_cell, l->volumes_per_level);
        return -1;
    }
    if (strcmp(lpvp_volume_layout_units(l), LPVP_VOLUME_UNITS_RADIANCE) != 0) {
        lpvp_set_error(err, err_n, "%s.units: \"%s\" with \"%s\" levels, expected \"%s\" (radiance; R5.14)", K,
                       lpvp_volume_layout_units(l), IV, LPVP_VOLUME_UNITS_RADIANCE);
        return -1;
    }
    if (!l->has_index || l->index.level != 0 || l->index.values_per_cell != 1 || l->index.dims[0] != c0->dims[0] ||
        l->index.dims[1] != c0->dims[1] || l->index.dims[2] != c0->dims[2]) {
        lpvp_set_error(err, err_n, "%s.index: \"%s\" levels need the index over level 0 (level 0, dims [%lld, "
                       "%lld, %lld], values_per_cell 1: which voxels hold a surface; R5.14)", K, IV,
                       (long long)c0->dims[0], (long long)c0->dims[1], (long long)c0->dims[2]);
        return -1;
    }
    return 0;
}

static int parse_cells(const json_t *obj, const json_t *d, lpvp_volume_info *vi, char *err, size_t err_n);

/* The description (R5.9 - R5.12) into vi->layout; the cascades are already
 * read. Absent: R5.1's 12 values (layout.present 0). Each MUST-reject rule of
 * R5.9 - R5.12 is one check here, its message naming the field. */
static int parse_visibility(const json_t *v, lpvp_volume_info *vi, char *err, size_t err_n);
static int parse_layout(const json_t *obj, lpvp_volume_info *vi, char *err, size_t err_n)
{
    lpvp_volume_layout *l = &vi->layout;
    const json_t *d = json_object_get(obj, LPVP_VOLUME_DESC_KEY), *v, *a;
    const char *K = LPVP_VOLUME_DESC_KEY;
    char key[96];
    if (!d) {
        lpvp_volume_layout_sh(l, "", 0, vi->cascade_count);
        l->present = 0;
        l->layout_version = 0;
        return 0;
    }
    memset(l, 0, sizeof *l);
    l->present = 1;
    if (!json_is_object(d)) {
        lpvp_set_error(err, err_n, "%s: expected an object", K);
        return -1;
    }
    snprintf(key, sizeof key, "%s.layout_version", K);
    v = json_object_get(d, "layout_version");
    if (!json_is_integer(v)) {
        lpvp_set_error(err, err_n, "%s: expected an integer", key);
        return -1;
    }
    if (json_integer_value(v) != LPVP_VOLUME_LAYOUT_VERSION) {
        lpvp_set_error(err, err_n, "%s: %lld is not a layout this client reads (it reads %d)", key,
                       (long long)json_integer_value(v), LPVP_VOLUME_LAYOUT_VERSION);
        return -1;
    }
    l->layout_version = (int)json_integer_value(v);
    v = json_object_get(d, "technique");
    if (!json_is_string(v) || json_string_length(v) == 0 || json_string_length(v) >= sizeof l->technique) {
        lpvp_set_error(err, err_n, "%s.technique: expected a name of 1 to %zu characters", K,
                       sizeof l->technique - 1);
        return -1;
    }
    snprintf(l->technique, sizeof l->technique, "%s", json_string_value(v));
    v = json_object_get(d, "far_field");
    if (!json_is_boolean(v)) {
        lpvp_set_error(err, err_n, "%s.lpv.far_field: expected true or false", K);
        return -1;
    }
    l->far_field = json_is_true(v);

    a = json_object_get(d, "levels");
    if (json_object_get(d, LPVP_VISIBILITY_KEY) &&
        (levels_have_role(a, LPVP_ROLE_OCTREE_LEVEL) || levels_have_role(a, LPVP_ROLE_IV_VOXELS))) {
        lpvp_set_error(err, err_n, "%s.%s: only a probes' volume of cascades has visibility (R5.15), not \"%s\" or "
                       "\"%s\" levels", K, LPVP_VISIBILITY_KEY, lpvp_level_role_names[LPVP_ROLE_OCTREE_LEVEL],
                       lpvp_level_role_names[LPVP_ROLE_IV_VOXELS]);
        return -1;
    }
    if (levels_have_role(a, LPVP_ROLE_OCTREE_LEVEL))
        return parse_octree_levels(d, vi, err, err_n) != 0 ? -1 : parse_cells(obj, d, vi, err, err_n);
    if (levels_have_role(a, LPVP_ROLE_IV_VOXELS))
        return parse_iv_levels(d, vi, err, err_n) != 0 || parse_cells(obj, d, vi, err, err_n) != 0
                   ? -1
                   : iv_checks(vi, err, err_n);
    /* R5.10: the levels are the cascades, each with a role agreeing with far_field */
    if (!json_is_array(a) || json_array_size(a) != (size_t)vi->cascade_count) {
        lpvp_set_error(err, err_n, "%s.levels: expected an array of %d levels (one per cascade)", K,
                       vi->cascade_count);
        return -1;
    }
    for (int k = 0; k < vi->cascade_count; k++) {
        const json_t *e = json_array_get(a, (size_t)k);
        const lpvp_cascade_info *ci = &vi->cascades[k];
        if (!json_is_object(e)) {
            lpvp_set_error(err, err_n, "%s.levels[%d]: expected an object", K, k);
            return -1;
        }
        if (!level_matches(e, ci)) {
            lpvp_set_error(err, err_n, "%s.levels[%d]: dims, origin, cell_size and cells differ from cascades[%d]", K,
                           k, k);
            return -1;
        }
        v = json_object_get(e, "role");
        int role = -1;
        for (int r = 0; json_is_string(v) && r < LPVP_ROLE_COUNT; r++)
            if (strcmp(json_string_value(v), lpvp_level_role_names[r]) == 0)
                role = r;
        if (role < 0) {
            lpvp_set_error(err, err_n, "%s.levels[%d].role: expected \"%s\", \"%s\", \"%s\" or \"%s\"", K, k,
                           lpvp_level_role_names[LPVP_ROLE_CASCADE], lpvp_level_role_names[LPVP_ROLE_FAR_FIELD],
                           lpvp_level_role_names[LPVP_ROLE_OCTREE_LEVEL], lpvp_level_role_names[LPVP_ROLE_IV_VOXELS]);
            return -1;
        }
        int want = (l->far_field && k > 0) ? LPVP_ROLE_FAR_FIELD : LPVP_ROLE_CASCADE;
        if (role != want) {
            lpvp_set_error(err, err_n, "%s.levels[%d].role: \"%s\" with far_field %s (level 0 is a \"%s\"; levels "
                           "1.. are \"%s\" exactly when far_field is true)", K, k, lpvp_level_role_names[role],
                           l->far_field ? "true" : "false", lpvp_level_role_names[LPVP_ROLE_CASCADE],
                           lpvp_level_role_names[LPVP_ROLE_FAR_FIELD]);
            return -1;
        }
        l->role[k] = (lpvp_level_role)role;
    }
    if (parse_cells(obj, d, vi, err, err_n) != 0)
        return -1;
    v = json_object_get(d, LPVP_VISIBILITY_KEY);
    return v ? parse_visibility(v, vi, err, err_n) : 0;
}

/* R5.15: the probes' visibility after the cascades' SH values. */
static int parse_visibility(const json_t *v, lpvp_volume_info *vi, char *err, size_t err_n)
{
    lpvp_volume_layout *l = &vi->layout;
    lpvp_visibility_info *vis = &l->visibility;
    const char *K = LPVP_VOLUME_DESC_KEY "." LPVP_VISIBILITY_KEY;
    char key[96];
    long long x;
    if (!json_is_object(v)) {
        lpvp_set_error(err, err_n, "%s: expected an object", K);
        return -1;
    }
    if (l->far_field || !l->sh_values || l->volumes_per_level != 1 || l->has_index) {
        lpvp_set_error(err, err_n, "%s: the probes' visibility goes with cascades of R5.1's 12 values in one volume "
                       "a level, no far field and no index", K);
        return -1;
    }
    snprintf(key, sizeof key, "%s.irradiance_side", K);
    if (need_int(v, "irradiance_side", 1, &x, err, err_n) != 0 || x > LPVP_VISIBILITY_MAX_IRRADIANCE_SIDE) {
        lpvp_set_error(err, err_n, "%s: expected an integer in [1, %d]", key, LPVP_VISIBILITY_MAX_IRRADIANCE_SIDE);
        return -1;
    }
    vis->irradiance_side = (int)x;
    snprintf(key, sizeof key, "%s.distance_side", K);
    if (need_int(v, "distance_side", 1, &x, err, err_n) != 0 || x > LPVP_VISIBILITY_MAX_DISTANCE_SIDE) {
        lpvp_set_error(err, err_n, "%s: expected an integer in [1, %d]", key, LPVP_VISIBILITY_MAX_DISTANCE_SIDE);
        return -1;
    }
    vis->distance_side = (int)x;
    vis->values_per_probe = lpv_probes_record_values(vis->irradiance_side, vis->distance_side);
    snprintf(key, sizeof key, "%s.values_per_probe", K);
    if (need_int(v, "values_per_probe", 1, &x, err, err_n) != 0 || (uint64_t)x != vis->values_per_probe) {
        lpvp_set_error(err, err_n, "%s: expected %llu (4 + 3 irradiance_side^2 + 2 distance_side^2)", key,
                       (unsigned long long)vis->values_per_probe);
        return -1;
    }
    vis->probes = lpvp_volume_total_cells(vi);
    snprintf(key, sizeof key, "%s.probes", K);
    if (need_int(v, "probes", 1, &x, err, err_n) != 0 || (uint64_t)x != vis->probes) {
        lpvp_set_error(err, err_n, "%s: expected %llu (a probe per cell of every level)", key,
                       (unsigned long long)vis->probes);
        return -1;
    }
    const json_t *t = json_object_get(v, "value_type");
    if (!json_is_string(t) || strcmp(json_string_value(t), LPVP_VISIBILITY_VALUE_TYPE) != 0) {
        lpvp_set_error(err, err_n, "%s.value_type: expected \"%s\"", K, LPVP_VISIBILITY_VALUE_TYPE);
        return -1;
    }
    t = json_object_get(v, "bias_cells");
    if (!json_is_number(t) || !(json_number_value(t) >= 0.0) || !isfinite(json_number_value(t))) {
        lpvp_set_error(err, err_n, "%s.bias_cells: expected a finite number >= 0", K);
        return -1;
    }
    vis->bias_cells = json_number_value(t);
    const uint64_t values = lpvp_volume_values_bytes(vi);
    snprintf(key, sizeof key, "%s.raw_offset", K);
    if (need_int(v, "raw_offset", 0, &x, err, err_n) != 0 || (uint64_t)x != values) {
        lpvp_set_error(err, err_n, "%s: expected %llu (right after the levels' values)", key,
                       (unsigned long long)values);
        return -1;
    }
    vis->raw_offset = values;
    l->has_visibility = 1;
    l->content = LPVP_CONTENT_VISIBILITY;
    const uint64_t want = lpvp_volume_extra_bytes(vi);
    snprintf(key, sizeof key, "%s.raw_length", K);
    if (need_int(v, "raw_length", 0, &x, err, err_n) != 0 || (uint64_t)x != want) {
        lpvp_set_error(err, err_n, "%s: expected %llu (probes x values_per_probe x %d bytes)", key,
                       (unsigned long long)want, LPVP_VISIBILITY_VALUE_SIZE);
        return -1;
    }
    vis->raw_length = want;
    return 0;
}

/* R5.11, R5.12: what a cell holds, units, the index. */
static int parse_cells(const json_t *obj, const json_t *d, lpvp_volume_info *vi, char *err, size_t err_n)
{
    lpvp_volume_layout *l = &vi->layout;
    const json_t *v, *a;
    const char *K = LPVP_VOLUME_DESC_KEY;
    long long x;
    char key[96];

    /* R5.11: what a cell holds */
    snprintf(key, sizeof key, "%s.volumes_per_level", K);
    if (need_int(d, "volumes_per_level", 1, &x, err, err_n) != 0 || x > LPVP_MAX_VOLUMES_PER_LEVEL) {
        lpvp_set_error(err, err_n, "%s: expected an integer in [1, %d]", key, LPVP_MAX_VOLUMES_PER_LEVEL);
        return -1;
    }
    l->volumes_per_level = (int)x;
    snprintf(key, sizeof key, "%s.values_per_cell", K);
    if (need_int(d, "values_per_cell", 1, &x, err, err_n) != 0 || x > LPVP_MAX_VALUES_PER_CELL) {
        lpvp_set_error(err, err_n, "%s: expected an integer in [1, %d]", key, LPVP_MAX_VALUES_PER_CELL);
        return -1;
    }
    l->values_per_cell = (int)x;
    a = json_object_get(d, "values");
    if (!json_is_array(a) || json_array_size(a) != (size_t)l->values_per_cell) {
        lpvp_set_error(err, err_n, "%s.values: expected an array of values_per_cell (%d) names", K,
                       l->values_per_cell);
        return -1;
    }
    l->sh_values = l->values_per_cell == LPVP_VALUES_PER_CELL;
    for (size_t i = 0; i < json_array_size(a); i++) {
        v = json_array_get(a, i);
        if (!json_is_string(v) || json_string_length(v) == 0) {
            lpvp_set_error(err, err_n, "%s.values[%zu]: expected a non-empty name", K, i);
            return -1;
        }
        for (size_t j = 0; j < i; j++) {
            if (strcmp(json_string_value(v), json_string_value(json_array_get(a, j))) == 0) {
                lpvp_set_error(err, err_n, "%s.values[%zu]: \"%s\" is named twice (also values[%zu])", K, i,
                               json_string_value(v), j);
                return -1;
            }
        }
        if (l->sh_values && strcmp(json_string_value(v), lpvp_sh_value_names[i]) != 0)
            l->sh_values = 0;
    }
    v = json_object_get(d, "units");
    const json_t *top_units = json_object_get(obj, "units");
    if (!json_is_string(v) || (json_is_string(top_units) && !json_equal(v, top_units))) {
        lpvp_set_error(err, err_n, "%s.units: expected a string equal to the header's \"units\"", K);
        return -1;
    }
    if (json_string_length(v) >= sizeof l->units) {
        lpvp_set_error(err, err_n, "%s.units: \"%s\" is longer than the units this client knows", K,
                       json_string_value(v));
        return -1;
    }
    snprintf(l->units, sizeof l->units, "%s", json_string_value(v));

    /* R5.12: an index volume after the levels' values */
    v = json_object_get(d, "index");
    if (v && !json_is_null(v)) {
        lpvp_index_info *ix = &l->index;
        if (!json_is_object(v)) {
            lpvp_set_error(err, err_n, "%s.index: expected null or an object", K);
            return -1;
        }
        snprintf(key, sizeof key, "%s.index.level", K);
        int level_count = l->content == LPVP_CONTENT_LEVELS ? l->level_count : vi->cascade_count;
        if (need_int(v, "level", 0, &x, err, err_n) != 0 || x >= level_count) {
            lpvp_set_error(err, err_n, "%s: expected a level in [0, %d]", key, level_count - 1);
            return -1;
        }
        ix->level = (int)x;
        const json_t *dims = json_object_get(v, "dims");
        if (!json_is_array(dims) || json_array_size(dims) != 3) {
            lpvp_set_error(err, err_n, "%s.index.dims: expected an array of 3 integers", K);
            return -1;
        }
        ix->cells = 1;
        for (size_t i = 0; i < 3; i++) {
            const json_t *e = json_array_get(dims, i);
            if (!json_is_integer(e) || json_integer_value(e) < 1 || json_integer_value(e) > (1 << 20)) {
                lpvp_set_error(err, err_n, "%s.index.dims[%zu]: expected an integer in [1, 1048576]", K, i);
                return -1;
            }
            ix->dims[i] = json_integer_value(e);
            ix->cells *= (uint64_t)ix->dims[i];
        }
        snprintf(key, sizeof key, "%s.index.values_per_cell", K);
        if (need_int(v, "values_per_cell", 1, &x, err, err_n) != 0 || x > LPVP_MAX_VALUES_PER_CELL) {
            lpvp_set_error(err, err_n, "%s: expected an integer in [1, %d]", key, LPVP_MAX_VALUES_PER_CELL);
            return -1;
        }
        ix->values_per_cell = (int)x;
        const json_t *vt = json_object_get(v, "value_type");
        if (!json_is_string(vt) || strcmp(json_string_value(vt), LPVP_INDEX_VALUE_TYPE) != 0) {
            lpvp_set_error(err, err_n, "%s.index.value_type: expected \"%s\"", K, LPVP_INDEX_VALUE_TYPE);
            return -1;
        }
        uint64_t values = lpvp_volume_values_bytes(vi);
        snprintf(key, sizeof key, "%s.index.raw_offset", K);
        if (need_int(v, "raw_offset", 0, &x, err, err_n) != 0 || (uint64_t)x != values) {
            lpvp_set_error(err, err_n, "%s: expected %llu (right after the levels' values)", key,
                           (unsigned long long)values);
            return -1;
        }
        ix->raw_offset = (uint64_t)x;
        uint64_t want = ix->cells * (uint64_t)ix->values_per_cell * LPVP_INDEX_VALUE_SIZE;
        snprintf(key, sizeof key, "%s.index.raw_length", K);
        if (need_int(v, "raw_length", 0, &x, err, err_n) != 0 || (uint64_t)x != want) {
            lpvp_set_error(err, err_n, "%s: expected %llu (dims' product x values_per_cell x %d bytes)", key,
                           (unsigned long long)want, LPVP_INDEX_VALUE_SIZE);
            return -1;
        }
        ix->raw_length = want;
        l->has_index = 1;
    }
    if (l->content == LPVP_CONTENT_LEVELS &&
        (!l->has_index || l->index.level != 0 || l->index.values_per_cell != 1 ||
         l->index.dims[0] != vi->cascades[0].dims[0] || l->index.dims[1] != vi->cascades[0].dims[1] ||
         l->index.dims[2] != vi->cascades[0].dims[2])) {
        lpvp_set_error(err, err_n, "%s.index: \"%s\" levels need the index volume over level 0 (level 0, dims [%lld, "
                       "%lld, %lld], values_per_cell 1)", K, lpvp_level_role_names[LPVP_ROLE_OCTREE_LEVEL],
                       (long long)vi->cascades[0].dims[0], (long long)vi->cascades[0].dims[1],
                       (long long)vi->cascades[0].dims[2]);
        return -1;
    }
    return 0;
}

int lpvp_volume_header_parse(const json_t *obj, lpvp_volume_info *vi, char *err, size_t err_n)
{
    long long x;
    json_t *v, *grid, *a;
    size_t cells = 1;
    memset(vi, 0, sizeof *vi);
    vi->base_tick = -1;
    if (!json_is_object(obj)) {
        lpvp_set_error(err, err_n, "volume header: not an object");
        return -1;
    }
    if (need_int(obj, "revision", 0, &x, err, err_n))
        return -1;
    vi->revision = x;
    if (need_int(obj, "tick", 0, &x, err, err_n))
        return -1;
    vi->tick = x;
    if (lpvp_volume_format_parse(json_string_value(json_object_get(obj, "format")),
                                 &vi->format) != 0) {
        lpvp_set_error(err, err_n, "format: expected \"fp16\" or \"fp32\"");
        return -1;
    }
    if (lpvp_compression_parse(json_string_value(json_object_get(obj, "compression")),
                               &vi->compression) != 0) {
        lpvp_set_error(err, err_n, "compression: expected \"zstd\", \"shq\" or \"none\"");
        return -1;
    }
    if (vi->compression == LPVP_COMP_SHQ) { /* R5.16 */
        if (vi->format != LPVP_FMT_FP32) {
            lpvp_set_error(err, err_n, "format: \"shq\" decodes to \"fp32\", the header says \"%s\"",
                           lpvp_volume_format_name(vi->format));
            return -1;
        }
        v = json_object_get(obj, LPVP_SHQ_BOUND_KEY);
        if (!json_is_number(v) || !(json_number_value(v) >= LPVP_SHQ_BOUND_MIN) ||
            !(json_number_value(v) <= LPVP_SHQ_BOUND_MAX)) {
            lpvp_set_error(err, err_n, "%s: expected a number in %g..%g with compression \"shq\"",
                           LPVP_SHQ_BOUND_KEY, LPVP_SHQ_BOUND_MIN, LPVP_SHQ_BOUND_MAX);
            return -1;
        }
        vi->error_bound = json_number_value(v);
    }
    v = json_object_get(obj, "keyframe");
    if (!json_is_boolean(v)) {
        lpvp_set_error(err, err_n, "keyframe: expected true or false");
        return -1;
    }
    vi->keyframe = json_is_true(v);
    if (!vi->keyframe) {
        if (need_int(obj, "base_tick", 0, &x, err, err_n))
            return -1;
        vi->base_tick = x;
    }
    grid = json_object_get(obj, "grid");
    if (!json_is_object(grid)) {
        lpvp_set_error(err, err_n, "grid: expected an object");
        return -1;
    }
    a = json_object_get(grid, "dims");
    if (!json_is_array(a) || json_array_size(a) != 3) {
        lpvp_set_error(err, err_n, "grid.dims: expected an array of 3 integers");
        return -1;
    }
    for (size_t i = 0; i < 3; i++) {
        json_t *d = json_array_get(a, i);
        if (!json_is_integer(d) || json_integer_value(d) < 1 ||
            json_integer_value(d) > (1 << 20)) {
            lpvp_set_error(err, err_n, "grid.dims[%zu]: expected an integer in [1, 1048576]", i);
            return -1;
        }
        vi->dims[i] = json_integer_value(d);
        if (cells > ((size_t)-1) / (size_t)vi->dims[i]) {
            lpvp_set_error(err, err_n, "grid.dims: too many cells");
            return -1;
        }
        cells *= (size_t)vi->dims[i];
    }
    a = json_object_get(grid, "origin");
    if (!json_is_array(a) || json_array_size(a) != 3) {
        lpvp_set_error(err, err_n, "grid.origin: expected an array of 3 numbers");
        return -1;
    }
    for (size_t i = 0; i < 3; i++) {
        json_t *d = json_array_get(a, i);
        if (!json_is_number(d)) {
            lpvp_set_error(err, err_n, "grid.origin[%zu]: expected a number", i);
            return -1;
        }
        vi->origin[i] = json_number_value(d);
    }
    v = json_object_get(grid, "cell_size");
    if (!json_is_number(v) || !(json_number_value(v) > 0.0) || !isfinite(json_number_value(v))) {
        lpvp_set_error(err, err_n, "grid.cell_size: expected a positive number");
        return -1;
    }
    vi->cell_size = json_number_value(v);
    if (parse_cascades(obj, vi, err, err_n) != 0 || parse_layout(obj, vi, err, err_n) != 0)
        return -1;
    cells = (size_t)lpvp_volume_total_cells(vi);
    if (need_int(obj, "raw_length", 0, &x, err, err_n))
        return -1;
    vi->raw_length = (uint64_t)x;
    {
        /* R5.6 / R5.11: the levels' values as described, then the index (R5.12) */
        uint64_t values = lpvp_volume_values_bytes(vi);
        uint64_t index = lpvp_volume_extra_bytes(vi); /* the index (R5.12) or the visibility (R5.15) */
        uint64_t expect = values + index;
        if (values == 0 || (uint64_t)(size_t)expect != expect || expect != vi->raw_length) {
            lpvp_set_error(err, err_n,
                           "raw_length: %llu, but %zu cells x %d volumes x %d values of %s%s need %llu bytes", x,
                           cells, vi->layout.volumes_per_level, vi->layout.values_per_cell,
                           lpvp_volume_format_name(vi->format), index ? " + the index or visibility" : "",
                           (unsigned long long)expect);
            return -1;
        }
    }
    return 0;
}

int lpvp_volume_decode(const lpvp_volume_info *vi, const void *attachment, size_t att_len,
                       const uint8_t *base_raw, size_t base_len, uint8_t *raw_out, char *err,
                       size_t err_n)
{
    size_t raw_len = (size_t)vi->raw_length;
    if ((uint64_t)raw_len != vi->raw_length) {
        lpvp_set_error(err, err_n, "raw_length %llu does not fit in memory",
                (unsigned long long)vi->raw_length);
        return -1;
    }
    if (!vi->keyframe && (!base_raw || base_len != raw_len)) {
        lpvp_set_error(err, err_n, "delta against tick %lld without a base volume of %zu bytes",
                (long long)vi->base_tick, raw_len);
        return -1;
    }
    if (vi->compression == LPVP_COMP_SHQ) { /* R5.16: the levels' SH values quantised, then the rest */
        uint64_t values = lpvp_volume_values_bytes(vi);
        int vpc = vi->layout.present ? vi->layout.values_per_cell : LPVP_VALUES_PER_CELL;
        if (vpc != LPVP_VALUES_PER_CELL || vi->format != LPVP_FMT_FP32 || values > raw_len) {
            lpvp_set_error(err, err_n, "shq carries R5.1's %d fp32 values per cell; the header has %d in %s",
                           LPVP_VALUES_PER_CELL, vpc, lpvp_volume_format_name(vi->format));
            return -1;
        }
        return lpvp_shq_decode(attachment, att_len, raw_len, (size_t)(values / (LPVP_VALUES_PER_CELL * 4)),
                               vi->keyframe ? NULL : base_raw, raw_out, NULL, err, err_n);
    }
    if (vi->compression == LPVP_COMP_ZSTD) {
        if (!vi->keyframe && raw_out == base_raw) {
            /* In place: decompress aside, then XOR into the base. */
            uint8_t *tmp = malloc(raw_len ? raw_len : 1);
            if (!tmp) {
                lpvp_set_error(err, err_n, "out of memory (%zu bytes)", raw_len);
                return -1;
            }
            if (lpvp_zstd_decompress_exact(attachment, att_len, tmp, raw_len, err, err_n) != 0) {
                free(tmp);
                return -1;
            }
            lpvp_xor(raw_out, tmp, base_raw, raw_len);
            free(tmp);
            return 0;
        }
        if (lpvp_zstd_decompress_exact(attachment, att_len, raw_out, raw_len, err, err_n) != 0)
            return -1;
    } else {
        if (att_len != raw_len) {
            lpvp_set_error(err, err_n, "attachment of %zu bytes, raw_length is %zu", att_len, raw_len);
            return -1;
        }
        if (vi->keyframe) {
            if (raw_len)
                memmove(raw_out, attachment, raw_len);
            return 0;
        }
        lpvp_xor(raw_out, attachment, base_raw, raw_len);
        return 0;
    }
    if (!vi->keyframe)
        lpvp_xor(raw_out, raw_out, base_raw, raw_len);
    return 0;
}
