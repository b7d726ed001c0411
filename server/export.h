/*
 * export.h - a tick's result as the wire sees it: read back from the engine
 * on the GL context's thread (sv_result, export_result.c) and encoded as a
 * VOLUME / GET_VOLUME or FRAME / GET_FRAME payload (SPEC sections 5 and 6,
 * export_encode.c); the volumes delta subscribers hold are shared by
 * reference (sv_blob, export_blob.c). The daemon (serve_*.c) and lpvd batch's volume output
 * (batch_render.c) both export through it; it knows nothing of sessions,
 * sockets or jobs.
 */
#ifndef LPVD_EXPORT_H
#define LPVD_EXPORT_H

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include <jansson.h>

#include "engine.h"
#include "plan.h"
#include "proto.h"
#include "tonemap.h"
#include "volume_codec.h"

/* How a volume goes on the wire (SPEC section 5): zero-initialised is fp32,
 * uncompressed. */
typedef struct sv_volume_coding {
    int fp16;               /* format fp16, else fp32 (shq is always fp32) */
    int comp;               /* lpvp_compression: none, zstd, shq */
    double bound;           /* shq: the client's error bound (R5.16) */
} sv_volume_coding;

/* Bytes that never change once filled, shared by reference (export_blob.c):
 * the volume a delta subscriber holds, one copy for every subscriber that
 * holds the same. held (NULL: none) counts the bytes of every live blob made
 * with it (the daemon's memory term "bases", R7.6a). */
typedef struct sv_blob {
    atomic_int refs;
    size_t len;
    _Atomic uint64_t *held;
    uint8_t bytes[];
} sv_blob;

/* refs 1 and len bytes to fill before the blob is shared; NULL without memory. */
sv_blob *sv_blob_new(size_t len, _Atomic uint64_t *held);
sv_blob *sv_blob_ref(sv_blob *b);
void sv_blob_unref(sv_blob *b); /* NULL: nothing */

typedef struct sv_sent {   /* a VOLUME sent to a delta subscriber, not yet ACKed */
    uint64_t tick;
    int dims[3];
    sv_volume_coding how;   /* a base serves only a volume coded the same way */
    sv_blob *raw;           /* a reference: the raw volume the client holds (shq: its reconstruction) */
    uint64_t lineage;       /* shq: equal lineages, equal raw bytes (export_encode.c) */
} sv_sent;

/* A delta subscriber's encoding (shq, R5.16, or XOR, R5.3), or an shq
 * reply's keyframe, kept for the next subscriber that holds the same volume
 * (export_encode.c): a world's subscribers in step share one. */
#define SV_SHARED_ENCODINGS 4
typedef struct sv_shared_enc {
    int used;
    int pending;            /* being encoded on a work thread: the others wait for it */
    int keeps;              /* a subscriber's: recon is the client's volume (a reply's keeps none) */
    uint64_t from;          /* the base's lineage; 0: a keyframe */
    sv_volume_coding how;
    int outcome;            /* 0: sent; 1: nothing to send */
    int keyframe;
    uint64_t lineage;       /* the client's volume after it */
    uint8_t *att;
    size_t att_len;
    size_t counted;         /* of att_len, the bytes in the encodings' count (sv_encode_memory) */
    sv_blob *recon;         /* a reference: the client's volume after it */
} sv_shared_enc;

/* Where an encoding counts the memory it keeps (the daemon's terms "bases"
 * and "encodings", R7.6a); NULL (lpvd batch): nowhere, and every cache is
 * kept. */
typedef struct sv_encode_memory {
    _Atomic uint64_t *bases;     /* the volumes subscribers hold (sv_blob's held) */
    _Atomic uint64_t *encodings; /* the attachments a result keeps for the next subscriber or reply */
    uint64_t encodings_limit;    /* the most *encodings may reach: a cache that would pass it is not kept */
} sv_encode_memory;

/* The product of one tick: immutable once handed to the main thread. */
typedef struct sv_result {
    int refs;
    uint64_t tick;          /* world tick number, 1.. */
    uint64_t gen;           /* world generation it was computed for */
    lpv_grid grid;          /* cascade 0 (the finest) */
    int cascade_count;      /* 1..LPVP_MAX_CASCADES */
    lpv_grid cascades[LPVP_MAX_CASCADES]; /* finest first; every cascade has grid.dims */
    float *cells;           /* cells * 12 floats: every cascade's, cascade 0 first */
    size_t cell_count;      /* all cascades' cells */
    /* GET_VOLUME content "levels" (SPEC R5.13), in a result of
     * sv_result_take_content (levels) only: every level's cells (level_cells x 12
     * floats, level 0 first, as lpv_engine_read_volumes gives them) and the
     * index (one per cell of cascade 0); NULL / 0 in a tick's result. */
    float *levels;
    size_t level_cells;
    uint32_t *index;
    size_t index_count;
    /* GET_VOLUME content "visibility" (SPEC R5.15), in a result of
     * sv_result_take_content only: every probe's record
     * (lpv_engine_read_visibility), beside the merged cells. */
    float *visibility;
    size_t visibility_floats;
    /* Technique iv (SPEC R5.14): per voxel of the grid, 1 when it holds a
     * surface (IvVoxel.normal[3] > 0), the index every iv volume carries;
     * NULL / 0 for the other techniques. */
    uint32_t *iv_held;
    size_t iv_held_count;
    float *frames[LPVP_TERMS_COUNT]; /* rgba float per lpv_frame_terms, NULL if not rendered */
    int width, height;
    lpv_engine_stats stats;
    lpv_plan plan;          /* the plan of this tick, snapshotted with stats */
    double tick_ms;         /* wall time of the tick on the GL thread */
    /* main thread: keyframe attachments already encoded, [fp16][zstd] */
    uint8_t *enc[2][2];
    size_t enc_len[2][2];
    size_t enc_counted[2][2];      /* of enc_len, the bytes in *enc_held */
    _Atomic uint64_t *enc_held;    /* the encodings' count the caches' counted bytes are in */
    sv_shared_enc shared[SV_SHARED_ENCODINGS]; /* under export_encode.c's lock, as enc */
    int shared_next;
} sv_result;

sv_result *sv_result_ref(sv_result *r);
void sv_result_unref(sv_result *r);
/* The engine's last tick read back (export_result.c): every cascade's
 * accumulated volume, the imperfect volume's occupancy when the technique
 * has it, the frames of terms_mask (bit t: lpv_frame_terms t) at width x
 * height, stats and plan; refs 1, tick and gen 0 (the caller's). NULL with a
 * message in err. On the GL context's thread. */
sv_result *sv_result_take(lpv_engine *e, int width, int height, unsigned terms_mask, char *err, size_t n);
/* What GET_VOLUME's content (SPEC R5.13, R5.15) needs beyond a tick's
 * result, read on request only, with the grid, stats and plan (no frames):
 * LPVP_CONTENT_LEVELS the octree's levels and index (no merged cells),
 * LPVP_CONTENT_VISIBILITY the merged cells and the probes' visibility. NULL
 * with err for a technique without them. */
sv_result *sv_result_take_content(lpv_engine *e, int content, char *err, size_t n);

/* GET_VOLUME's and SUBSCRIBE's "format", "compression" and "error_bound"
 * (SPEC R5.16) into how (default fp16 + zstd); 0, or -1 with err set
 * ("<key>: <what>", for BAD_FIELD). */
int sv_volume_coding_parse(const json_t *j, sv_volume_coding *how, char *err, size_t n);

/* Thread-safe (export_encode.c): the daemon runs them on libuv's work
 * threads, lpvd batch on its own. */
/* Volume reply/stream body + attachment. A delta subscriber's encoding passes
 * keep: it gets the volume the client will hold (a reference in raw, its
 * tick, coding and lineage, for sv_sub_remember), and a delta against base
 * (its ACKed volume) when base fits; else keep and base are NULL. A new
 * volume's bytes are counted in mem's bases while it lives; one shared with
 * another subscriber's is counted once. The attachments r keeps for the
 * next subscriber or reply are counted in mem's encodings until r is freed,
 * and not kept where they would pass its limit. Returns 0, -1 with err
 * set, or 1 for an shq delta with nothing beyond the bound to send (R5.16:
 * nothing is sent; *body, *att and keep->raw are NULL). */
int sv_encode_volume(sv_result *r, int content, const sv_volume_coding *how, const sv_sent *base, sv_sent *keep,
                     const sv_encode_memory *mem, uint64_t revision, json_t **body, uint8_t **att, size_t *att_len,
                     char *err, size_t n);
/* plan: the plan of the tick the frame shows, sent as "plan" (NULL: none). */
int sv_encode_frame(const float *rgba, int w, int h, int fmt, int zstd, int terms, const lpv_display *display,
                    uint64_t revision,
                    uint64_t tick, const lpv_plan *plan, json_t **body, uint8_t **att, size_t *att_len,
                    char *err, size_t n);

#endif /* LPVD_EXPORT_H */
