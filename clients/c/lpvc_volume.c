/*
 * lpvc_volume.c - the C client's volumes (SPEC section 5): decoding a
 * VOLUME / GET_VOLUME header and attachment (zstd, fp16 and XOR deltas come
 * from protocol/volume_codec.h), the acknowledged volumes kept as delta bases
 * (R5.3), GET_VOLUME, and the local lookup (R5.7, R5.14 for technique iv's
 * voxels, R5.15 for the probes with their visibility; protocol/volume_lookup.h).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lpvc_internal.h"
#include "volume_codec.h"
#include "volume_lookup.h"

/* ---- volumes --------------------------------------------------------------- */

_Static_assert(LPVC_MAX_LEVELS == LPVP_MAX_LEVELS, "lpvc.h's LPVC_MAX_LEVELS is the protocol's LPVP_MAX_LEVELS");

void lpvc_volume_free(lpvc_volume *v)
{
    if (!v)
        return;
    free(v->data);
    free(v->index);
    free(v->visibility);
    free(v->header_json);
    free(v->plan_json);
    memset(v, 0, sizeof *v);
}

static lpvc_acked *find_acked(lpvc *c, int64_t tick)
{
    for (int i = 0; i < LPVC_KEEP_ACKED; i++)
        if (c->acked[i].tick == tick && c->acked[i].raw)
            return &c->acked[i];
    return NULL;
}

/* Keeps raw (taking ownership) as the acknowledged volume of tick. */
static void remember_acked(lpvc *c, int64_t tick, uint8_t *raw, size_t len)
{
    lpvc_acked *slot = find_acked(c, tick);
    if (!slot) {
        slot = &c->acked[0];
        for (int i = 0; i < LPVC_KEEP_ACKED; i++) {
            if (c->acked[i].tick < 0) {
                slot = &c->acked[i];
                break;
            }
            if (c->acked[i].age < slot->age)
                slot = &c->acked[i];
        }
    }
    free(slot->raw);
    slot->tick = tick;
    slot->raw = raw;
    slot->len = len;
    slot->age = ++c->ack_clock;
}

int lpvci_decode_volume(lpvc *c, const json_t *hdr, const uint8_t *att, size_t att_len, bool stream,
                        lpvc_volume *out)
{
    memset(out, 0, sizeof *out);
    lpvp_volume_info vi;
    char err[256];
    if (lpvp_volume_header_parse(hdr, &vi, err, sizeof err) != 0)
        return lpvci_fail(c, LPVC_ERR_PROTOCOL, "bad volume header: %s", err);
    /* every cascade's cells (R5.6); the parse checked raw_length against them */
    size_t cells = (size_t)lpvp_volume_total_cells(&vi);
    const lpvc_acked *base = NULL;
    if (!vi.keyframe) {
        base = find_acked(c, vi.base_tick);
        if (!base)
            return lpvci_fail(c, LPVC_ERR_PROTOCOL, "delta against tick %lld, which this client did not acknowledge or no longer holds",
                        (long long)vi.base_tick);
        if (base->len != vi.raw_length)
            return lpvci_fail(c, LPVC_ERR_PROTOCOL, "delta of %llu bytes against a base of %zu bytes",
                        (unsigned long long)vi.raw_length, base->len);
    }
    /* decoded by the description (R5.11): per level, its volumes of cells x
     * values_per_cell values; the parse checked raw_length against it */
    const lpvp_volume_layout *lay = &vi.layout;
    size_t per_cell = (size_t)lay->values_per_cell * (size_t)lay->volumes_per_level;
    size_t values = cells * per_cell;
    const lpvp_index_info *ix = lay->has_index ? &lay->index : NULL;
    size_t index_count = ix ? (size_t)ix->cells * (size_t)ix->values_per_cell : 0;
    uint8_t *raw = malloc(vi.raw_length ? (size_t)vi.raw_length : 1);
    float *data = malloc((values ? values : 1) * sizeof(float));
    uint32_t *index = ix ? malloc((index_count ? index_count : 1) * sizeof(uint32_t)) : NULL;
    const lpvp_visibility_info *vis = lay->has_visibility ? &lay->visibility : NULL;
    size_t vis_count = vis ? (size_t)(vis->raw_length / LPVP_VISIBILITY_VALUE_SIZE) : 0;
    float *visibility = vis ? malloc((vis_count ? vis_count : 1) * sizeof(float)) : NULL;
    if (!raw || !data || (ix && !index) || (vis && !visibility)) {
        free(raw);
        free(data);
        free(index);
        free(visibility);
        return lpvci_fail(c, LPVC_ERR_IO, "out of memory for a %zu-cell volume", cells);
    }
    if (lpvp_volume_decode(&vi, att, att_len, base ? base->raw : NULL, base ? base->len : 0, raw, err, sizeof err) != 0) {
        free(raw);
        free(data);
        free(index);
        free(visibility);
        return lpvci_fail(c, LPVC_ERR_PROTOCOL, "cannot decode the volume: %s", err);
    }
    lpvp_values_unpack(raw, values, vi.format, data);
    for (size_t i = 0; i < index_count; i++) /* R5.12: little-endian u32 whatever the format */
        index[i] = lpvp_get_u32(raw + ix->raw_offset + LPVP_INDEX_VALUE_SIZE * i);
    for (size_t i = 0; i < vis_count; i++) { /* R5.15: little-endian f32 whatever the format */
        const uint32_t u = lpvp_get_u32(raw + vis->raw_offset + LPVP_VISIBILITY_VALUE_SIZE * i);
        memcpy(&visibility[i], &u, sizeof u);
    }
    if (vis) {
        out->visibility = visibility;
        out->visibility_floats = vis_count;
        out->irradiance_side = vis->irradiance_side;
        out->distance_side = vis->distance_side;
        out->values_per_probe = (int)vis->values_per_probe;
        out->bias_cells = (float)vis->bias_cells;
    }

    out->revision = vi.revision;
    out->tick = vi.tick;
    for (int a = 0; a < 3; a++) {
        out->dims[a] = (int)vi.dims[a];
        out->origin[a] = (float)vi.origin[a];
    }
    out->cell_size = (float)vi.cell_size;
    out->cells = (size_t)vi.dims[0] * (size_t)vi.dims[1] * (size_t)vi.dims[2];
    out->data = data;
    out->total_cells = cells;
    out->cascade_count = vi.cascade_count;
    for (int k = 0; k < vi.cascade_count && k < LPVC_MAX_CASCADES; k++) {
        lpvc_cascade *cs = &out->cascades[k];
        for (int a = 0; a < 3; a++) {
            cs->dims[a] = (int)vi.cascades[k].dims[a];
            cs->origin[a] = (float)vi.cascades[k].origin[a];
        }
        cs->cell_size = (float)vi.cascades[k].cell_size;
        cs->cells = (size_t)vi.cascades[k].cells;
        cs->data = data + per_cell * (size_t)lpvp_volume_cascade_first_cell(&vi, k);
    }
    snprintf(out->content, sizeof out->content, "%s", lpvp_volume_content_names[lay->content]);
    for (int k = 0; lay->content == LPVP_CONTENT_LEVELS && k < lay->level_count && k < LPVC_MAX_LEVELS; k++) {
        lpvc_cascade *lv = &out->levels[k];
        for (int a = 0; a < 3; a++) {
            lv->dims[a] = (int)lay->level[k].dims[a];
            lv->origin[a] = (float)lay->level[k].origin[a];
        }
        lv->cell_size = (float)lay->level[k].cell_size;
        lv->cells = (size_t)lay->level[k].cells;
        lv->data = data + per_cell * (size_t)lpvp_volume_cascade_first_cell(&vi, k);
        out->level_count = k + 1;
    }
    out->layout_version = lay->layout_version;
    snprintf(out->technique, sizeof out->technique, "%s", lay->technique);
    out->values_per_cell = lay->values_per_cell;
    out->volumes_per_level = lay->volumes_per_level;
    out->far_field = lay->far_field != 0;
    out->sh_values = lay->sh_values != 0;
    out->index = index;
    out->index_count = index_count;
    snprintf(out->units, sizeof out->units, "%s", lpvp_volume_layout_units(lay));
    out->iv_voxels = lpvp_volume_layout_is_iv(lay) != 0;
    out->iv_neighbours = out->iv_voxels ? lay->iv_neighbours : 0;
    if (ix) {
        out->index_level = ix->level;
        for (int a = 0; a < 3; a++)
            out->index_dims[a] = (int)ix->dims[a];
        out->index_values_per_cell = ix->values_per_cell;
    }
    if (json_is_object(json_object_get(hdr, "plan")))
        out->plan_json = json_dumps(json_object_get(hdr, "plan"), JSON_COMPACT);
    snprintf(out->format, sizeof out->format, "%s", lpvp_volume_format_name(vi.format));
    snprintf(out->compression, sizeof out->compression, "%s", lpvp_compression_name(vi.compression));
    out->error_bound = vi.compression == LPVP_COMP_SHQ ? vi.error_bound : 0.0;
    out->keyframe = vi.keyframe != 0;
    out->base_tick = vi.keyframe ? -1 : vi.base_tick;
    out->header_json = json_dumps(hdr, JSON_COMPACT);

    if (stream) {
        /* Kept as a possible delta base whether it is ACKed here or later by
         * the caller (lpvc_ack with auto-ACK off). */
        remember_acked(c, vi.tick, raw, (size_t)vi.raw_length);
        return c->auto_ack ? lpvc_ack(c, vi.tick) : 0;
    }
    free(raw);
    return 0;
}

int lpvc_get_volume(lpvc *c, const lpvc_volume_desc *desc, lpvc_volume *out)
{
    if (!c)
        return -1;
    if (!out)
        return lpvci_fail(c, LPVC_ERR_USAGE, "out is NULL");
    memset(out, 0, sizeof *out);
    lpvc_volume_desc d = {0};
    if (desc)
        d = *desc;
    json_t *o = json_pack("{s:s, s:s}", "format", d.format ? d.format : lpvp_volume_format_names[LPVP_FMT_FP32],
                          "compression", d.compression ? d.compression : lpvp_compression_names[LPVP_COMP_ZSTD]);
    if (o && d.error_bound > 0.0 && json_object_set_new(o, LPVP_SHQ_BOUND_KEY, json_real(d.error_bound)) != 0) {
        json_decref(o);
        o = NULL;
    }
    if (o && d.content && json_object_set_new(o, LPVP_VOLUME_CONTENT_KEY, json_string(d.content)) != 0) {
        json_decref(o);
        o = NULL;
    }
    if (!o)
        return lpvci_fail(c, LPVC_ERR_IO, "out of memory");
    json_t *reply = NULL;
    uint8_t *att = NULL;
    size_t att_len = 0;
    int rc = lpvci_request(c, LPVP_GET_VOLUME, o, NULL, 0, &reply, &att, &att_len);
    json_decref(o);
    if (rc == 0)
        rc = lpvci_decode_volume(c, reply, att, att_len, false, out);
    json_decref(reply);
    free(att);
    return rc;
}

/* ---- local lookup: SPEC R5.7, R5.14 and R5.15, the protocol library's (volume_lookup.h) ----- */

static lpvp_lookup_cascade lookup_cascade(const lpvc_cascade *cs)
{
    lpvp_lookup_cascade l = {.dims = {cs->dims[0], cs->dims[1], cs->dims[2]},
                             .origin = {cs->origin[0], cs->origin[1], cs->origin[2]},
                             .cell_size = cs->cell_size,
                             .cells = cs->data};
    return l;
}

void lpvc_cascade_irradiance(const lpvc_cascade *cs, const float p[3], const float n[3], float rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    if (!cs)
        return;
    lpvp_lookup_cascade l = lookup_cascade(cs);
    lpvp_cascade_irradiance(&l, p, n, rgb);
}

/* The layout the lookup reads, as the protocol library words its refusal. A
 * volume built by hand (no layout_version, values_per_cell 0) is R5.1's. */
static lpvp_volume_layout layout_of(const lpvc_volume *v)
{
    lpvp_volume_layout l;
    memset(&l, 0, sizeof l);
    l.present = v->layout_version != 0 || v->values_per_cell != 0;
    l.layout_version = v->layout_version;
    snprintf(l.technique, sizeof l.technique, "%s", v->technique);
    l.values_per_cell = v->values_per_cell;
    l.volumes_per_level = v->volumes_per_level;
    l.sh_values = v->sh_values;
    l.has_index = v->index != NULL;
    l.content = LPVP_CONTENT_MERGED;
    for (int k = 0; k < LPVP_CONTENT_COUNT; k++)
        if (strcmp(v->content, lpvp_volume_content_names[k]) == 0)
            l.content = (lpvp_volume_content)k;
    l.has_visibility = v->visibility != NULL;
    l.level_count = v->level_count;
    snprintf(l.units, sizeof l.units, "%s", v->units);
    if (v->iv_voxels) { /* R5.14: its one level and the index over it */
        l.role[0] = LPVP_ROLE_IV_VOXELS;
        l.iv_neighbours = v->iv_neighbours;
        l.index.level = v->index_level;
        l.index.values_per_cell = v->index_values_per_cell;
    }
    return l;
}

int lpvc_volume_lookup_check(const lpvc_volume *v, char *err, size_t n)
{
    if (!v || !v->data) {
        snprintf(err, n, "no volume data");
        return -1;
    }
    lpvp_volume_layout l = layout_of(v);
    if (lpvp_volume_layout_is_iv(&l)) {
        if (lpvp_volume_layout_iv_lookup_check(&l, err, n) != 0)
            return -1;
        if (v->cascade_count != 1 || v->index_count != v->cascades[0].cells) {
            snprintf(err, n, "iv volume of %d levels with an index of %zu voxels (R5.14: one level, one per voxel)",
                     v->cascade_count, v->index_count);
            return -1;
        }
        return 0;
    }
    return lpvp_volume_layout_lookup_check(&l, err, n);
}

int lpvc_volume_irradiance(const lpvc_volume *v, const float p[3], const float n[3], float rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    char err[8];
    if (lpvc_volume_lookup_check(v, err, sizeof err) != 0)
        return -1;
    if (v->visibility) { /* R5.15 */
        lpvp_lookup_probes pr = {.count = v->cascade_count, .records = v->visibility,
                                 .irradiance_side = v->irradiance_side, .distance_side = v->distance_side,
                                 .bias_cells = v->bias_cells};
        if (pr.count < 1 || pr.count > LPVC_MAX_CASCADES ||
            v->visibility_floats != v->total_cells * (size_t)v->values_per_probe)
            return -1;
        for (int k = 0; k < pr.count; k++)
            pr.levels[k] = lookup_cascade(&v->cascades[k]);
        return lpvp_probes_irradiance(&pr, p, n, rgb);
    }
    if (v->iv_voxels) { /* R5.14 */
        const lpvc_cascade *cs = &v->cascades[0];
        const lpvp_lookup_iv iv = {.dims = {cs->dims[0], cs->dims[1], cs->dims[2]},
                                   .origin = {cs->origin[0], cs->origin[1], cs->origin[2]},
                                   .cell_size = cs->cell_size,
                                   .cells = cs->data,
                                   .held = v->index,
                                   .neighbours = v->iv_neighbours};
        return lpvp_iv_irradiance(&iv, p, n, rgb);
    }
    lpvp_lookup_cascade l[LPVC_MAX_CASCADES];
    int count = v->cascade_count;
    if (count < 1 || count > LPVC_MAX_CASCADES) { /* a volume built by hand: the grid alone */
        l[0] = (lpvp_lookup_cascade){.dims = {v->dims[0], v->dims[1], v->dims[2]},
                                     .origin = {v->origin[0], v->origin[1], v->origin[2]},
                                     .cell_size = v->cell_size,
                                     .cells = v->data};
        count = 1;
    } else {
        for (int k = 0; k < count; k++)
            l[k] = lookup_cascade(&v->cascades[k]);
    }
    return lpvp_volume_irradiance(l, count, p, n, rgb);
}
