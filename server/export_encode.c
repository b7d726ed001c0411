/*
 * export_encode.c - the payloads of VOLUME / GET_VOLUME (SPEC section 5) and
 * FRAME / GET_FRAME (section 6), through protocol/volume_codec.h: fp16/fp32
 * packing, XOR deltas against the last volume a subscriber ACKed, zstd; and
 * frames as tone-mapped rgba8, PNG or EXR (in-memory, image/image_io.h), the
 * ao term as a linear fraction. A volume carries every cascade (R5.6,
 * cascade 0 first), or technique iv's voxels and their index (R5.14), and
 * on request the octree's levels (R5.13) or the probes' visibility (R5.15);
 * both headers carry the tick's "plan" (lpvd_plan_json).
 *
 * The daemon runs the encoders on libuv's work threads (serve_encode_work.c):
 * they read only immutable results and what they are given, and the one
 * shared thing they write, a result's keyframe cache, is under enc_mu. A
 * subscriber's state (its ACKed base, the volumes it may ACK) is the
 * daemon's (serve_streams.c): the caller hands the base in and remembers the
 * raw volume that comes out.
 */
#include "export.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

#include "image_io.h"
#include "stats_json.h"
#include "tonemap.h"
#include "volume_codec.h"

/* Guards every sv_result's enc / enc_len (the keyframe cache) and shared
 * (the subscribers' shared encodings): encoders of one result run on several work
 * threads at once. enc_cv: a shared encoding was filled or given up. */
static pthread_mutex_t enc_mu = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t enc_cv = PTHREAD_COND_INITIALIZER;

_Static_assert((int)LPVP_TERMS_AO == (int)LPV_TERMS_AO && (int)LPVP_TERMS_DIRECT == (int)LPV_TERMS_DIRECT_ONLY,
               "the protocol's frame terms are the engine's");

/* An index volume (R5.12) as little-endian u32 at ix. */
static void pack_index(uint8_t *ix, const uint32_t *index, size_t count)
{
    for (size_t i = 0; i < count; ++i)
        lpvp_put_u32(ix + LPVP_INDEX_VALUE_SIZE * i, index[i]);
}

/* The levels payload (SPEC R5.13): every octree level's 12 values, then the
 * index volume as little-endian u32 at vi's index offset. */
static void pack_levels(const sv_result *r, const lpvp_volume_info *vi, uint8_t *raw)
{
    lpvp_volume_pack(r->levels, r->level_cells, vi->format, raw);
    pack_index(raw + lpvp_volume_values_bytes(vi), r->index, r->index_count);
}

/* The probes' visibility (SPEC R5.15) as little-endian f32 at at. */
static void pack_visibility(uint8_t *at, const float *v, size_t count)
{
    for (size_t i = 0; i < count; ++i) {
        uint32_t u;
        memcpy(&u, &v[i], sizeof u);
        lpvp_put_u32(at + LPVP_VISIBILITY_VALUE_SIZE * i, u);
    }
}

/* A copy of r's cached keyframe attachment [fp16][zstd] in *att, or 0
 * when none is cached (or no memory for the copy). */
static int cache_copy(sv_result *r, int fp16, int zstd, uint8_t **att, size_t *att_len)
{
    int got = 0;
    pthread_mutex_lock(&enc_mu);
    const uint8_t *c = r->enc[fp16 ? 1 : 0][zstd ? 1 : 0];
    size_t len = r->enc_len[fp16 ? 1 : 0][zstd ? 1 : 0];
    if (c) {
        *att = malloc(len ? len : 1);
        if (*att) {
            memcpy(*att, c, len);
            *att_len = len;
            got = 1;
        }
    }
    pthread_mutex_unlock(&enc_mu);
    return got;
}

/* Counts len more bytes of r's caches in mem's encodings (under enc_mu):
 * 1, or 0 when they would pass its limit (the cache is then not kept). No
 * mem: nothing counted, always 1. */
static int cache_count(sv_result *r, const sv_encode_memory *mem, size_t len, size_t *counted)
{
    *counted = 0;
    if (!mem || !mem->encodings)
        return 1;
    uint64_t cur = atomic_load_explicit(mem->encodings, memory_order_relaxed);
    do {
        if (cur + len < cur || cur + len > mem->encodings_limit)
            return 0;
    } while (!atomic_compare_exchange_weak_explicit(mem->encodings, &cur, cur + len, memory_order_relaxed,
                                                    memory_order_relaxed));
    r->enc_held = mem->encodings; /* one daemon, one count */
    *counted = len;
    return 1;
}

/* A cache's counted bytes given back (under enc_mu). */
static void cache_uncount(sv_result *r, size_t *counted)
{
    if (*counted && r->enc_held)
        atomic_fetch_sub_explicit(r->enc_held, *counted, memory_order_relaxed);
    *counted = 0;
}

/* Caches a copy of att as r's keyframe [fp16][zstd], unless another encoder
 * got there first or it does not fit mem's encodings. */
static void cache_put(sv_result *r, const sv_encode_memory *mem, int fp16, int zstd, const uint8_t *att, size_t len)
{
    pthread_mutex_lock(&enc_mu);
    const int f = fp16 ? 1 : 0, z = zstd ? 1 : 0;
    uint8_t **c = &r->enc[f][z];
    if (!*c && cache_count(r, mem, len, &r->enc_counted[f][z])) {
        *c = malloc(len ? len : 1);
        if (*c) {
            memcpy(*c, att, len);
            r->enc_len[f][z] = len;
        } else {
            cache_uncount(r, &r->enc_counted[f][z]);
        }
    }
    pthread_mutex_unlock(&enc_mu);
}

int sv_volume_coding_parse(const json_t *j, sv_volume_coding *how, char *err, size_t n)
{
    int fmt = -1, comp = LPVP_COMP_ZSTD;
    double bound = LPVP_SHQ_BOUND_DEFAULT;
    if (lpvp_get_enum(j, "format", 0, lpvp_volume_format_names, 2, &fmt, err, n) == LPVP_FIELD_BAD ||
        lpvp_get_enum(j, "compression", 0, lpvp_compression_names, 3, &comp, err, n) == LPVP_FIELD_BAD)
        return -1;
    int has_bound = lpvp_get_number(j, LPVP_SHQ_BOUND_KEY, 0, LPVP_SHQ_BOUND_MIN, LPVP_SHQ_BOUND_MAX, &bound, err, n);
    if (has_bound == LPVP_FIELD_BAD)
        return -1;
    if (comp == LPVP_COMP_SHQ && fmt == LPVP_FMT_FP16) {
        snprintf(err, n, "format: compression \"shq\" decodes to \"fp32\" (R5.16); omit format or ask \"fp32\"");
        return -1;
    }
    if (comp != LPVP_COMP_SHQ && has_bound == LPVP_FIELD_OK) {
        snprintf(err, n, "%s: only compression \"shq\" takes an error bound (R5.16)", LPVP_SHQ_BOUND_KEY);
        return -1;
    }
    how->comp = comp;
    how->fp16 = comp != LPVP_COMP_SHQ && fmt != LPVP_FMT_FP32; /* default fp16 */
    how->bound = comp == LPVP_COMP_SHQ ? bound : 0.0;
    return 0;
}

/* ---- shq (R5.16) ---------------------------------------------------------- */

/* A lineage names the volume a subscriber holds: the hash of its bytes
 * (XXH3, 64 bits; 0 is kept for "a keyframe"). Subscribers of a world that
 * hold the same volume (they got the same keyframe, from whichever tick,
 * and the same deltas since) share one encoding of the next tick and one
 * reference-counted copy of the volume it leaves them with (sv_blob): a
 * hundred subscribers in step cost one encoding, a hundred copies of the
 * compressed attachment, and one volume. */
static uint64_t lineage_of(const uint8_t *raw, size_t len)
{
    uint64_t h = XXH3_64bits(raw, len);
    return h ? h : 1;
}

/* A copy of what an encoding of r coded as `how` against lineage `from`
 * made (the outcome in *outcome), or a claim on making it. Returns 1 when found;
 * else 0 with *claim the slot this encoder now fills (shared_fill, or
 * shared_release on failure), or -1 when every slot is being filled by an
 * encoding of something else (then it encodes for itself alone). An
 * encoding of the same thing in flight on another work thread is waited
 * for, not repeated: a world's subscribers in step reach the work threads
 * together, and each repeat would cost an encoding and a volume of its own.
 * A delta's header names this subscriber's base tick (base_tick), which may
 * differ from the one the encoding had: the same volume, acknowledged as
 * another tick. */
static int shared_take(sv_result *r, uint64_t from, int64_t base_tick, const sv_volume_coding *how,
                       lpvp_volume_info *vi, sv_sent *keep, uint8_t **att, size_t *att_len, int *outcome, int *claim)
{
    *claim = -1;
    pthread_mutex_lock(&enc_mu);
    for (;;) {
        int i, waited = 0;
        for (i = 0; i < SV_SHARED_ENCODINGS; ++i) {
            const sv_shared_enc *s = &r->shared[i];
            /* a reply's keyframe keeps no client volume for a subscriber to hold */
            if (s->used && s->from == from && s->how.comp == how->comp && s->how.fp16 == how->fp16 &&
                s->how.bound == how->bound && (!keep || s->keeps))
                break;
        }
        if (i < SV_SHARED_ENCODINGS && r->shared[i].pending) {
            pthread_cond_wait(&enc_cv, &enc_mu);
            waited = 1;
        } else if (i < SV_SHARED_ENCODINGS) {
            const sv_shared_enc *s = &r->shared[i];
            uint8_t *a = s->att_len ? malloc(s->att_len) : NULL;
            if (s->att_len && !a)
                break; /* encode it again, unshared */
            if (a)
                memcpy(a, s->att, s->att_len);
            if (keep && s->recon) {
                keep->raw = sv_blob_ref(s->recon);
                keep->lineage = s->lineage;
            }
            *att = a;
            *att_len = s->att_len;
            vi->keyframe = s->keyframe;
            vi->base_tick = s->keyframe ? -1 : base_tick;
            *outcome = s->outcome;
            pthread_mutex_unlock(&enc_mu);
            return 1;
        }
        if (waited)
            continue; /* filled or released meanwhile: look again */
        /* claim the oldest slot not being filled */
        for (int k = 0; k < SV_SHARED_ENCODINGS && *claim < 0; ++k) {
            int j = (r->shared_next + k) % SV_SHARED_ENCODINGS;
            if (!r->shared[j].pending)
                *claim = j;
        }
        if (*claim >= 0) {
            sv_shared_enc *s = &r->shared[*claim];
            r->shared_next = (*claim + 1) % SV_SHARED_ENCODINGS;
            free(s->att);
            cache_uncount(r, &s->counted);
            sv_blob_unref(s->recon);
            *s = (sv_shared_enc){.used = 1, .pending = 1, .keeps = keep != NULL, .from = from, .how = *how};
        }
        break;
    }
    pthread_mutex_unlock(&enc_mu);
    return 0;
}

/* The claimed slot given up (the encoding failed): whoever waits on it
 * encodes for itself. */
static void shared_release(sv_result *r, int claim)
{
    if (claim < 0)
        return;
    pthread_mutex_lock(&enc_mu);
    r->shared[claim] = (sv_shared_enc){0};
    pthread_cond_broadcast(&enc_cv);
    pthread_mutex_unlock(&enc_mu);
}

/* The claimed slot filled with a copy of the attachment and a reference to
 * the client's volume, for the subscribers that hold the same base; given
 * up when the copy does not fit mem's encodings. */
static void shared_fill(sv_result *r, const sv_encode_memory *mem, int claim, const lpvp_volume_info *vi,
                        const sv_sent *keep, const uint8_t *att, size_t att_len, int outcome)
{
    if (claim < 0)
        return;
    size_t counted = 0;
    pthread_mutex_lock(&enc_mu);
    const int fits = cache_count(r, mem, att_len, &counted);
    pthread_mutex_unlock(&enc_mu);
    if (!fits) { /* not kept: the waiters encode for themselves */
        shared_release(r, claim);
        return;
    }
    uint8_t *a = att_len ? malloc(att_len) : NULL;
    if (att_len && !a) {
        pthread_mutex_lock(&enc_mu);
        cache_uncount(r, &counted);
        pthread_mutex_unlock(&enc_mu);
        shared_release(r, claim);
        return;
    }
    if (a)
        memcpy(a, att, att_len);
    pthread_mutex_lock(&enc_mu);
    sv_shared_enc *s = &r->shared[claim];
    s->counted = counted;
    s->pending = 0;
    s->outcome = outcome;
    s->keyframe = vi->keyframe;
    s->lineage = keep ? keep->lineage : 0;
    s->att = a;
    s->att_len = att_len;
    s->recon = keep ? sv_blob_ref(keep->raw) : NULL;
    pthread_cond_broadcast(&enc_cv);
    pthread_mutex_unlock(&enc_mu);
}

/* The base a delta may use: coded the same way, of the same layout, another
 * tick (not necessarily an older one: a session that moves to another
 * world, R7.2, meets that world's tick numbers, and the client rebuilds
 * from whichever tick it acknowledged). */
static const sv_sent *delta_base(const sv_result *r, const sv_sent *base, const sv_volume_coding *how,
                                 size_t raw_len)
{
    const int shq = how->comp == LPVP_COMP_SHQ;
    if (base && base->raw && (base->how.comp == LPVP_COMP_SHQ) == shq && base->how.fp16 == how->fp16 &&
        base->how.bound == how->bound && base->raw->len == raw_len &&
        memcmp(base->dims, r->grid.dims, sizeof base->dims) == 0 && base->tick != r->tick)
        return base;
    return NULL;
}

/* raw (fp32) as shq: a delta against base when delta_base allows it, else a
 * keyframe; the client's volume and its lineage in keep (NULL: a reply).
 * Returns 0, 1 for a delta with nothing to send, -1 with err. */
static int encode_shq(lpvp_volume_info *vi, const uint8_t *raw, size_t raw_len, double bound,
                      const sv_sent *base, sv_sent *keep, _Atomic uint64_t *held, uint8_t **att, size_t *att_len,
                      char *err, size_t n)
{
    const size_t cells = (size_t)(lpvp_volume_values_bytes(vi) / (LPVP_VALUES_PER_CELL * 4));
    const uint8_t *b = base ? base->raw->bytes : NULL;
    sv_blob *rb = sv_blob_new(raw_len, keep ? held : NULL);
    uint8_t *recon = rb ? rb->bytes : NULL;
    lpvp_shq_layout lay;
    lpvp_shq_layout_of(vi, &lay);
    lpvp_shq_counts sent = {0, 0};
    if (!recon || lpvp_shq_encode(raw, raw_len, cells, b, bound, &lay, recon, att, att_len, &sent, err, n) != 0) {
        if (!recon)
            snprintf(err, n, "out of memory for a %zu-byte volume", raw_len);
        sv_blob_unref(rb);
        return -1;
    }
    /* Many cells re-sent: a keyframe, whose cells are predicted from each
     * other (R5.16 bit 1), may be smaller; send whichever is. Below a
     * quarter of the cells the delta always was (the box's LPV: a keyframe
     * is 1.7 bytes a cell, a re-sent cell 3 - 4), so only then are both
     * encoded. */
    if (b && sent.sent > cells / 4) {
        sv_blob *kb = sv_blob_new(raw_len, keep ? held : NULL);
        uint8_t *katt = NULL;
        size_t katt_len = 0;
        lpvp_shq_counts ksent = {0, 0};
        if (!kb ||
            lpvp_shq_encode(raw, raw_len, cells, NULL, bound, NULL, kb->bytes, &katt, &katt_len, &ksent, err, n) != 0) {
            if (!kb)
                snprintf(err, n, "out of memory for a %zu-byte volume", raw_len);
            sv_blob_unref(kb);
            sv_blob_unref(rb);
            free(*att);
            *att = NULL;
            return -1;
        }
        if (katt_len < *att_len) {
            free(*att);
            *att = katt;
            *att_len = katt_len;
            sent = ksent;
            sv_blob_unref(rb);
            rb = kb;
            recon = kb->bytes;
            b = NULL;
        } else {
            free(katt);
            sv_blob_unref(kb);
        }
    }
    const size_t values = cells * LPVP_VALUES_PER_CELL * 4;
    if (b && sent.sent == 0 && sent.blocks == 0 && memcmp(recon + values, b + values, raw_len - values) == 0) {
        free(*att); /* nothing beyond the bound: nothing sent, the client's base stands */
        *att = NULL;
        *att_len = 0;
        sv_blob_unref(rb);
        return 1;
    }
    if (b) {
        vi->keyframe = 0;
        vi->base_tick = (int64_t)base->tick;
    }
    if (keep) {
        keep->raw = rb;
        keep->lineage = lineage_of(recon, raw_len);
    } else {
        sv_blob_unref(rb);
    }
    return 0;
}

int sv_encode_volume(sv_result *r, int content, const sv_volume_coding *how, const sv_sent *base, sv_sent *keep,
                     const sv_encode_memory *mem, uint64_t revision, json_t **body, uint8_t **att, size_t *att_len,
                     char *err, size_t n)
{
    _Atomic uint64_t *held = mem ? mem->bases : NULL;
    if (keep) {
        memset(keep, 0, sizeof *keep);
        keep->tick = r->tick;
        memcpy(keep->dims, r->grid.dims, sizeof keep->dims);
        keep->how = *how;
    }
    *att = NULL;
    *att_len = 0;
    const int shq = how->comp == LPVP_COMP_SHQ;
    const int fp16 = !shq && how->fp16, zstd = how->comp == LPVP_COMP_ZSTD;
    lpvp_volume_format fmt = fp16 ? LPVP_FMT_FP16 : LPVP_FMT_FP32;
    const int levels = content == LPVP_CONTENT_LEVELS;
    const int visibility = content == LPVP_CONTENT_VISIBILITY;
    const int merged = !levels && !visibility; /* the keyframe cache and deltas hold it alone */
    lpvp_volume_info vi;
    memset(&vi, 0, sizeof vi);
    vi.revision = (int64_t)revision;
    vi.tick = (int64_t)r->tick;
    vi.format = fmt;
    vi.compression = shq ? LPVP_COMP_SHQ : zstd ? LPVP_COMP_ZSTD : LPVP_COMP_NONE;
    vi.error_bound = shq ? how->bound : 0.0;
    vi.keyframe = 1;
    vi.base_tick = -1;
    for (int i = 0; i < 3; ++i) {
        vi.dims[i] = r->grid.dims[i];
        vi.origin[i] = r->grid.origin[i];
    }
    vi.cell_size = r->grid.cell_size;
    vi.cascade_count = r->cascade_count < 1 ? 1 : r->cascade_count;
    for (int k = 0; k < vi.cascade_count; ++k) {
        const lpv_grid *g = r->cascade_count < 1 ? &r->grid : &r->cascades[k];
        lpvp_cascade_info *ci = &vi.cascades[k];
        for (int i = 0; i < 3; ++i) {
            ci->dims[i] = g->dims[i];
            ci->origin[i] = g->origin[i];
        }
        ci->cell_size = g->cell_size;
        ci->cells = lpv_grid_cell_count(g);
    }
    /* What the volume carries (R5.9 - R5.11), from the technique's own
     * description of the tick's volume (snapshotted with the tick's stats).
     * The cells are the engine's summed read-back (lpv_engine_read_grid): one
     * volume per level whatever its normal bins, R5.1's 12 values a cell. */
    const lpv_volume_desc *d = &r->stats.volume;
    if (!d->technique || d->values_per_cell != LPVP_VALUES_PER_CELL) {
        snprintf(err, n, "the tick's volume is described as %d values per cell of technique %s; this encoder sends "
                 "R5.1's %d", d->values_per_cell, d->technique ? d->technique : "(none)", LPVP_VALUES_PER_CELL);
        return -1;
    }
    size_t raw_len;
    if (levels) { /* R5.13: the octree's levels (cascades: level 0 alone) and its index */
        vi.cascade_count = 1;
        if (!r->levels || lpvp_volume_layout_octree(&vi.layout, d->technique, &vi.cascades[0], err, n) != 0) {
            if (!r->levels)
                snprintf(err, n, "%s: technique \"%s\" has no levels to send", LPVP_VOLUME_CONTENT_KEY, d->technique);
            return -1;
        }
        raw_len = (size_t)(lpvp_volume_values_bytes(&vi) + vi.layout.index.raw_length);
        if (lpvp_volume_total_cells(&vi) != r->level_cells || vi.layout.index.cells != r->index_count) {
            snprintf(err, n, "the tick kept %zu level cells and %zu index entries, its octree has %llu and %llu",
                     r->level_cells, r->index_count, (unsigned long long)lpvp_volume_total_cells(&vi),
                     (unsigned long long)vi.layout.index.cells);
            return -1;
        }
    } else if (visibility) { /* R5.15: the probes' SH, then their visibility */
        if (!r->visibility || d->visibility_side <= 0 ||
            lpvp_volume_layout_visibility(&vi.layout, d->technique, vi.cascade_count, d->irradiance_side,
                                          d->visibility_side, d->visibility_bias_cells, err, n) != 0) {
            if (!r->visibility || d->visibility_side <= 0)
                snprintf(err, n, "%s: technique \"%s\" has no visibility to send", LPVP_VOLUME_CONTENT_KEY,
                         d->technique);
            return -1;
        }
        if (lpvp_volume_total_cells(&vi) != r->cell_count ||
            r->visibility_floats != r->cell_count * vi.layout.visibility.values_per_probe) {
            snprintf(err, n, "the tick kept %zu visibility values for %zu probes of %llu values", r->visibility_floats,
                     r->cell_count, (unsigned long long)vi.layout.visibility.values_per_probe);
            return -1;
        }
        raw_len = (size_t)(lpvp_volume_values_bytes(&vi) + lpvp_volume_extra_bytes(&vi));
    } else if (d->kind == LPV_LEVELS_IV_VOXELS) { /* R5.14: the voxels' radiance, then which hold a surface */
        if (vi.cascade_count != 1 || !r->iv_held || r->iv_held_count != r->cell_count) {
            snprintf(err, n, "technique \"%s\": the tick kept %zu of the %zu voxels' occupancy over %d levels",
                     d->technique, r->iv_held_count, r->cell_count, vi.cascade_count);
            return -1;
        }
        if (lpvp_volume_layout_iv(&vi.layout, d->technique, &vi.cascades[0], d->iv_neighbours, err, n) != 0)
            return -1;
        raw_len = (size_t)(lpvp_volume_values_bytes(&vi) + vi.layout.index.raw_length);
    } else {
        lpvp_volume_layout_sh(&vi.layout, d->technique, d->far_field, vi.cascade_count);
        raw_len = lpvp_volume_raw_size(r->cell_count, fmt); /* all cascades' cells (R5.6) */
    }
    vi.raw_length = raw_len;

    /* the keyframe cache and XOR deltas (R5.3) hold the merged content only */
    if (!merged)
        keep = NULL;
    if (merged && !shq && !keep && cache_copy(r, fp16, zstd, att, att_len)) /* another session had it encoded */
        goto header;
    /* another subscriber that holds the same volume had it encoded (or an
     * shq reply's keyframe) */
    const sv_sent *dbase = keep ? delta_base(r, base, how, raw_len) : NULL;
    const uint64_t from = dbase ? dbase->lineage : 0;
    int outcome = 0, claim = -1;
    if (merged && (shq || keep) &&
        shared_take(r, from, dbase ? (int64_t)dbase->tick : -1, how, &vi, keep, att, att_len, &outcome, &claim)) {
        if (outcome == 1)
            return 1;
        goto header;
    }
    /* shq reads the cells where they are when they are the raw fp32 volume
     * (no index after them; the codec sends NaN as 0 itself): 4.7 MB less to
     * write at 3 x 32^3 */
    const int in_place = shq && merged && raw_len == r->cell_count * LPVP_VALUES_PER_CELL * 4 &&
                         lpvp_host_little_endian();
    /* an XOR subscriber keeps the packed volume itself as its next base */
    sv_blob *kept = !shq && keep ? sv_blob_new(raw_len, held) : NULL;
    uint8_t *raw = in_place ? NULL : kept ? kept->bytes : !shq && keep ? NULL : malloc(raw_len ? raw_len : 1);
    if (!in_place && !raw) {
        shared_release(r, claim);
        snprintf(err, n, "out of memory for a %zu-byte volume", raw_len);
        return -1;
    }
    if (in_place) {
        /* nothing to pack */
    } else if (levels) {
        pack_levels(r, &vi, raw);
    } else {
        lpvp_volume_pack(r->cells, r->cell_count, fmt, raw);
        if (vi.layout.has_index) /* R5.14 */
            pack_index(raw + lpvp_volume_values_bytes(&vi), r->iv_held, r->iv_held_count);
        if (visibility) /* R5.15 */
            pack_visibility(raw + lpvp_volume_values_bytes(&vi), r->visibility, r->visibility_floats);
    }

    if (shq) {
        int rc = encode_shq(&vi, in_place ? (const uint8_t *)r->cells : raw, raw_len, how->bound, dbase, keep,
                            held, att, att_len, err, n);
        free(raw);
        if (rc >= 0)
            shared_fill(r, mem, claim, &vi, keep, *att, *att_len, rc);
        else
            shared_release(r, claim);
        if (rc != 0)
            return rc;
        goto header;
    }
    uint8_t *payload = raw; /* what gets compressed / sent */
    uint8_t *delta = NULL;
    if (kept) {
        raw = NULL; /* kept->bytes, freed with kept */
        keep->lineage = lineage_of(kept->bytes, raw_len);
    }
    if (dbase) {
        delta = malloc(raw_len ? raw_len : 1);
        if (delta) {
            lpvp_xor(delta, payload, dbase->raw->bytes, raw_len);
            payload = delta;
            vi.keyframe = 0;
            vi.base_tick = (int64_t)dbase->tick;
        }
    }
    if (vi.keyframe && merged && cache_copy(r, fp16, zstd, att, att_len)) {
        /* cached meanwhile */
    } else if (zstd) {
        uint8_t *z = NULL;
        size_t zlen = 0;
        if (lpvp_zstd_compress(payload, raw_len, 0, &z, &zlen, err, n) != 0) {
            free(raw);
            sv_blob_unref(kept);
            free(delta);
            shared_release(r, claim);
            return -1;
        }
        *att = z;
        *att_len = zlen;
    } else if (payload == delta) {
        *att = delta;
        delta = NULL;
        *att_len = raw_len;
    } else if (!kept) {
        *att = raw;
        raw = NULL;
        *att_len = raw_len;
    } else { /* sent and remembered: two copies */
        *att = malloc(raw_len ? raw_len : 1);
        if (!*att) {
            sv_blob_unref(kept);
            shared_release(r, claim);
            snprintf(err, n, "out of memory for a %zu-byte volume", raw_len);
            return -1;
        }
        memcpy(*att, payload, raw_len);
        *att_len = raw_len;
    }
    free(delta);
    free(raw);
    if (keep) { /* the subscriber remembers it (sv_sub_remember); the others in step share it */
        keep->raw = kept;
        shared_fill(r, mem, claim, &vi, keep, *att, *att_len, 0);
    }
    if (vi.keyframe && merged && *att)
        cache_put(r, mem, fp16, zstd, *att, *att_len);
header:
    *body = lpvp_volume_header_build(&vi);
    if (*body && json_object_set_new(*body, "plan", lpvd_plan_json(&r->plan)) != 0) {
        json_decref(*body);
        *body = NULL;
    }
    if (!*body) {
        free(*att);
        *att = NULL;
        snprintf(err, n, "out of memory");
        return -1;
    }
    return 0;
}

/* The ao term for display (rgba8, png; SPEC section 6): a fraction, not
 * light, so no exposure, tone or sRGB curve: each channel 255 x the value
 * clamped to 0..1; pixels without geometry get the display's background (or
 * alpha 0 when transparent) as R6.4's. */
static void fraction_rgba8(const float *rgba, size_t n, const lpv_display *d, uint8_t *out)
{
    for (size_t i = 0; i < n; ++i) {
        float a = rgba[i * 4 + 3];
        a = isfinite(a) ? fminf(fmaxf(a, 0.0f), 1.0f) : 0.0f;
        for (int c = 0; c < 3; ++c) {
            float v = rgba[i * 4 + (size_t)c];
            v = isfinite(v) ? fminf(fmaxf(v, 0.0f), 1.0f) : 0.0f;
            float x = d->transparent ? v : a * v + (1.0f - a) * fminf(fmaxf(d->background[c], 0.0f), 1.0f);
            out[i * 4 + (size_t)c] = (uint8_t)lrintf(255.0f * x);
        }
        out[i * 4 + 3] = d->transparent ? (uint8_t)lrintf(255.0f * a) : 255;
    }
}

int sv_encode_frame(const float *rgba, int w, int h, int fmt, int zstd, int terms, const lpv_display *display,
                    uint64_t revision, uint64_t tick, const lpv_plan *plan, json_t **body, uint8_t **att, size_t *att_len, char *err, size_t n)
{
    size_t px = (size_t)w * (size_t)h;
    float ev = 0.0f;
    uint8_t *data = NULL;
    size_t len = 0;
    if (fmt == LPVP_FRAME_EXR) {
        if (lpv_image_encode_f32("exr", w, h, 4, rgba, &data, &len, err, n) != 0)
            return -1;
        zstd = 0;
    } else {
        uint8_t *rgba8 = malloc(px ? px * 4 : 1);
        if (!rgba8) {
            snprintf(err, n, "out of memory for a %dx%d frame", w, h);
            return -1;
        }
        if (terms == LPVP_TERMS_AO)
            fraction_rgba8(rgba, px, display, rgba8);
        else
            ev = lpv_display_rgba8(rgba, px, display, rgba8);
        if (fmt == LPVP_FRAME_PNG) {
            int rc = lpv_image_encode_u8("png", w, h, 4, rgba8, &data, &len, err, n);
            free(rgba8);
            if (rc != 0)
                return -1;
            zstd = 0;
        } else {
            data = rgba8;
            len = px * 4;
        }
    }
    size_t raw_len = len;
    if (zstd) {
        uint8_t *z = NULL;
        size_t zlen = 0;
        if (lpvp_zstd_compress(data, len, 0, &z, &zlen, err, n) != 0) {
            free(data);
            return -1;
        }
        free(data);
        data = z;
        len = zlen;
    }
    *att = data;
    *att_len = len;
    *body = json_pack("{s:I, s:I, s:s, s:s, s:i, s:i, s:s, s:s, s:I}", "revision", (json_int_t)revision, "tick",
                      (json_int_t)tick, "format", lpvp_frame_format_names[fmt], "compression",
                      lpvp_compression_name(zstd ? LPVP_COMP_ZSTD : LPVP_COMP_NONE), "width", w,
                      "height", h, "terms", lpvp_frame_terms_names[terms], "units",
                      terms == LPVP_TERMS_AO ? LPVP_FRAME_AO_UNITS : fmt == LPVP_FRAME_EXR ? "W/(m^2 sr)" : "sRGB",
                      "raw_length", (json_int_t)raw_len);
    if (*body && fmt != LPVP_FRAME_EXR && terms == LPVP_TERMS_AO &&
        json_object_set_new(*body, "transparent", json_boolean(display->transparent)) != 0) {
        json_decref(*body);
        *body = NULL;
    }
    if (*body && fmt != LPVP_FRAME_EXR && terms != LPVP_TERMS_AO &&
        (json_object_set_new(*body, "exposure_ev", json_real(ev)) != 0 ||
         json_object_set_new(*body, "exposure", json_string(display->exposure_auto ? "auto" : "fixed")) != 0 ||
         json_object_set_new(*body, "transparent", json_boolean(display->transparent)) != 0)) {
        json_decref(*body);
        *body = NULL;
    }
    if (*body && plan && json_object_set_new(*body, "plan", lpvd_plan_json(plan)) != 0) {
        json_decref(*body);
        *body = NULL;
    }
    if (!*body) {
        free(data);
        *att = NULL;
        snprintf(err, n, "out of memory");
        return -1;
    }
    return 0;
}
