/*
 * volume_codec.h - payload helpers for the lpvd protocol: binary16
 * conversion, raw volume packing (SPEC R5.1), XOR deltas (R5.3), zstd
 * (R5.2, R6.1), and the volume header JSON (SPEC section 5). No I/O.
 * Part of the lpv_protocol library (see proto.h).
 */
#ifndef LPVP_VOLUME_CODEC_H
#define LPVP_VOLUME_CODEC_H

#include <stddef.h>
#include <stdint.h>
#include <jansson.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- binary16 (R5.4) ------------------------------------------------------ */

#define LPVP_HALF_MAX 65504.0f

/* fp32 -> IEEE binary16 bits, round to nearest, ties to even, by bit
 * manipulation (no _Float16). Finite values beyond the largest half (and
 * +-Inf) clamp to +-65504 (0x7BFF / 0xFBFF), never Inf; NaN gives +0.
 * Subnormal halves are produced correctly (gradual underflow); values below
 * half the smallest subnormal round to a signed zero. */
uint16_t lpvp_f32_to_f16(float f);

/* binary16 bits -> fp32, exact for every half (subnormals, +-0, +-Inf, NaN
 * payloads kept as quiet NaN). */
float lpvp_f16_to_f32(uint16_t h);

/* ---- Raw volumes (R5.1) --------------------------------------------------- */

#define LPVP_VALUES_PER_CELL 12  /* r0 r1 r2 r3 g0 g1 g2 g3 b0 b1 b2 b3 */

/* The SPEC strings of the volume header (section 5). LPVP_VOLUME_UNITS is
 * an LPV's (radiant intensity per cell); an iv volume's voxels hold radiance
 * (R5.14). */
#define LPVP_VOLUME_UNITS "W/sr"
#define LPVP_VOLUME_UNITS_RADIANCE "W/(m^2 sr)"
#define LPVP_VOLUME_LAYOUT "cell-major, x fastest; per cell r0 r1 r2 r3 g0 g1 g2 g3 b0 b1 b2 b3"
#define LPVP_VOLUME_SH "Y00, Y1-1 (y), Y10 (z), Y11 (x), no Condon-Shortley phase"

typedef enum lpvp_volume_format {
    LPVP_FMT_FP16 = 0,  /* "fp16": 2 bytes per value */
    LPVP_FMT_FP32 = 1   /* "fp32": 4 bytes per value */
} lpvp_volume_format;

typedef enum lpvp_compression {
    LPVP_COMP_NONE = 0, /* "none" */
    LPVP_COMP_ZSTD = 1, /* "zstd" (R5.2) */
    LPVP_COMP_SHQ = 2   /* "shq": quantised SH to an error bound, format fp32 (R5.16) */
} lpvp_compression;

/* The SPEC's names, indexed by the enums above (lpvp_get_enum takes them as its
 * choices): "fp16", "fp32"; "none", "zstd", "shq". */
extern const char *const lpvp_volume_format_names[2];
extern const char *const lpvp_compression_names[3];

/* Frame terms and formats (SPEC section 6). The terms' order is the engine's
 * lpv_frame_terms (full, indirect only, direct only). */
typedef enum lpvp_frame_terms {
    LPVP_TERMS_FULL = 0,     /* "full" */
    LPVP_TERMS_INDIRECT = 1, /* "indirect" */
    LPVP_TERMS_DIRECT = 2,   /* "direct" */
    LPVP_TERMS_AO = 3,       /* "ao": ambient occlusion (technique iv with iv_ao on) */
    LPVP_TERMS_COUNT = 4
} lpvp_frame_terms;
typedef enum lpvp_frame_format {
    LPVP_FRAME_RGBA8 = 0, /* "rgba8": 8-bit sRGB, zstd or none */
    LPVP_FRAME_PNG = 1,   /* "png" */
    LPVP_FRAME_EXR = 2,   /* "exr": linear radiance */
    LPVP_FRAME_FORMAT_COUNT = 3
} lpvp_frame_format;
extern const char *const lpvp_frame_terms_names[LPVP_TERMS_COUNT];
/* The units of an "ao" frame (a fraction, 1 = open) in every format. */
#define LPVP_FRAME_AO_UNITS "1"
extern const char *const lpvp_frame_format_names[LPVP_FRAME_FORMAT_COUNT];

/* The streams of SUBSCRIBE / UNSUBSCRIBE / ACK (R5.5): "volume", "frame". */
enum { LPVP_STREAM_VOLUME = 0, LPVP_STREAM_FRAME = 1, LPVP_STREAM_COUNT = 2 };
extern const char *const lpvp_stream_names[LPVP_STREAM_COUNT];

/* Name of a value / value of a name; parse returns 0 on success, -1 if unknown. */
const char *lpvp_volume_format_name(lpvp_volume_format fmt);
int lpvp_volume_format_parse(const char *s, lpvp_volume_format *out);
const char *lpvp_compression_name(lpvp_compression c);
int lpvp_compression_parse(const char *s, lpvp_compression *out);

/* Bytes of one value (2 or 4). */
size_t lpvp_volume_value_size(lpvp_volume_format fmt);

/* cells x 12 x value size: the raw_length; 0 on size_t overflow. */
size_t lpvp_volume_raw_size(size_t cells, lpvp_volume_format fmt);

/* cells12: cells x 12 floats, in the engine's LpvCell memory order (r then g
 * then b, each c0 y z x) which is the wire order (R5.1). out receives
 * lpvp_volume_raw_size(cells, fmt) bytes, little-endian. fp16 converts with
 * lpvp_f32_to_f16 (R5.4: clamped, NaN -> 0). fp32 sends NaN as 0 too and
 * keeps every other value bit for bit (including +-Inf). */
void lpvp_volume_pack(const float *cells12, size_t cells, lpvp_volume_format fmt, uint8_t *out);

/* The inverse: raw (lpvp_volume_raw_size bytes) -> cells x 12 floats. */
void lpvp_volume_unpack(const uint8_t *raw, size_t cells, lpvp_volume_format fmt, float *out);

/* Any count of values (a described layout, R5.11): raw (count x value size
 * bytes) -> count floats. */
void lpvp_values_unpack(const uint8_t *raw, size_t count, lpvp_volume_format fmt, float *out);

/* ---- XOR delta (R5.3) ----------------------------------------------------- */

/* dst[i] = a[i] ^ b[i] for i < n. dst may be a or b (in place). The delta of
 * volume V against base B is V ^ B; the client rebuilds V = delta ^ B. */
void lpvp_xor(uint8_t *dst, const uint8_t *a, const uint8_t *b, size_t n);

/* ---- zstd (R5.2, R6.1) ---------------------------------------------------- */

#define LPVP_ZSTD_DEFAULT_LEVEL 1  /* latency over ratio */

/* Worst-case compressed size of n bytes. */
size_t lpvp_zstd_bound(size_t n);

/* One zstd frame (content size recorded in the frame header, which
 * lpvp_zstd_decompress requires) of src[0..n) at `level` (zstd's range; 0
 * means LPVP_ZSTD_DEFAULT_LEVEL). Into a malloc'd buffer: returns 0 and
 * sets *out / *out_len, or -1 (out of memory, zstd error) with err set. */
int lpvp_zstd_compress(const void *src, size_t n, int level, uint8_t **out, size_t *out_len,
                       char *err, size_t err_n);

/* Same into dst[0..cap) (cap >= lpvp_zstd_bound(n) always suffices). Returns
 * the compressed size, or 0 on error with err set. */
size_t lpvp_zstd_compress_into(void *dst, size_t cap, const void *src, size_t n, int level,
                               char *err, size_t err_n);

/* Decompresses exactly one zstd frame occupying all of src[0..n). Refuses
 * (returns -1 with err set, *out untouched): a frame whose content size is
 * not recorded or exceeds max_out, garbage, a truncated frame, trailing
 * bytes, a content size that does not match the data. On success returns 0
 * with a malloc'd *out of *out_len bytes (never more than max_out; a
 * 0-length result is a valid 1-byte allocation). */
int lpvp_zstd_decompress(const void *src, size_t n, size_t max_out, uint8_t **out,
                         size_t *out_len, char *err, size_t err_n);

/* Same into dst, requiring the content size to be exactly `expect` bytes
 * (e.g. the header's raw_length); returns 0 or -1 with err set. */
int lpvp_zstd_decompress_exact(const void *src, size_t n, void *dst, size_t expect, char *err,
                               size_t err_n);

/* ---- Quantised SH, "shq" (R5.16) ------------------------------------------ */

/* The client's error bound (SUBSCRIBE / GET_VOLUME "error_bound", echoed in
 * the header): the largest change of a cell's lookup E_c(n), any normal n,
 * any channel c, as a fraction of the cell's magnitude
 * (lpvp_shq_cell_magnitude). */
#define LPVP_SHQ_BOUND_KEY "error_bound"
#define LPVP_SHQ_BOUND_MIN 0.001
#define LPVP_SHQ_BOUND_MAX 0.25
#define LPVP_SHQ_BOUND_DEFAULT 0.01

/* A cell's magnitude: max over channels of LOBE0 |c0| + LOBE1 |(c1, c2, c3)|,
 * the largest |E_c(n)| of R5.7's cosine-lobe lookup over all normals (in
 * the lookup's units before its 1 / cell_size^2). */
double lpvp_shq_cell_magnitude(const float v[LPVP_VALUES_PER_CELL]);

/* The largest |E_c(n)| of the difference of two cells, over all normals and
 * channels: what a client's lookup at the cell moves by from a to b. */
double lpvp_shq_cell_error(const float a[LPVP_VALUES_PER_CELL], const float b[LPVP_VALUES_PER_CELL]);

/* The boxes of cells a delta may move by blocks (R5.16 flag bit 2): each a
 * run of the values' cells that is a dims[0] x dims[1] x dims[2] box, x
 * fastest (a cascade, R5.6), in ascending order without overlap. */
#define LPVP_SHQ_MAX_REGIONS 16
typedef struct lpvp_shq_layout {
    int count; /* 0: no blocks */
    struct {
        uint64_t first;   /* the box's first cell in the values */
        uint32_t dims[3]; /* cells per axis, each >= 1 */
    } region[LPVP_SHQ_MAX_REGIONS];
} lpvp_shq_layout;

/* The layout of vi's merged values: one region per cascade (count 0 when the
 * values are not one volume per cascade, e.g. an octree's levels). */
struct lpvp_volume_info;
void lpvp_shq_layout_of(const struct lpvp_volume_info *vi, lpvp_shq_layout *out);

/* What an encoding sends: the cells re-sent and the blocks that move the
 * client's cells (a delta changes nothing when both are 0). */
typedef struct lpvp_shq_counts {
    size_t sent;
    size_t blocks;
} lpvp_shq_counts;

/* Encodes raw (a raw fp32 volume of raw_len bytes: `cells` cells of R5.1's
 * 12 values, then any bytes that follow them, e.g. an index) as one zstd
 * frame in a malloc'd *out. base NULL: a keyframe, every cell quantised.
 * base (the client's volume, raw_len bytes): a delta that re-sends only the
 * cells whose base is off raw's by more than bound x the cell's magnitude
 * (lpvp_shq_cell_error). With a layout (may be NULL) the delta may first
 * move the client's cells by a change per block of 3 x 3 x 3 cells (R5.16
 * bit 2), which lpvd sends when that is smaller. recon (raw_len bytes; may
 * be base) gets the volume the client rebuilds. *counts (may be NULL): what
 * was sent (all 0 on a delta: nothing changed beyond the bound). NaN is
 * sent as 0, values beyond +-1e30 clamp. Returns 0, or -1 with err set
 * (bound outside its range, no memory). */
int lpvp_shq_encode(const uint8_t *raw, size_t raw_len, size_t cells, const uint8_t *base, double bound,
                    const lpvp_shq_layout *layout, uint8_t *recon, uint8_t **out, size_t *out_len,
                    lpvp_shq_counts *counts, char *err, size_t err_n);

/* The inverse into raw_out (raw_len bytes; may equal base, a delta's base
 * of raw_len bytes; NULL for a keyframe). Checks every count against
 * cells and raw_len. *sent (may be NULL): the cells the message carried.
 * Returns 0 or -1 with err set. */
int lpvp_shq_decode(const void *att, size_t att_len, size_t raw_len, size_t cells, const uint8_t *base,
                    uint8_t *raw_out, size_t *sent, char *err, size_t err_n);

/* ---- Volume header JSON (SPEC section 5) ---------------------------------- */

#define LPVP_MAX_CASCADES 4  /* entries of "cascades" (SPEC R5.6) */
#define LPVP_MAX_LEVELS 9    /* entries of the description's "levels": an octree's (R5.13) */

/* One cascade's placement (SPEC R5.6). */
typedef struct lpvp_cascade_info {
    int64_t dims[3];             /* cells per axis, each >= 1 */
    double origin[3];            /* m, lower corner */
    double cell_size;            /* m, > 0 */
    uint64_t cells;              /* dims[0] x dims[1] x dims[2] */
} lpvp_cascade_info;

/* ---- Volume description (SPEC R5.9 - R5.13) ------------------------------ */

/* The version of the description's layout this library reads and writes
 * (R5.9). New techniques fill the same layout; only an incompatible change
 * of it bumps the version. */
#define LPVP_VOLUME_LAYOUT_VERSION 1

/* The header key of the description. */
#define LPVP_VOLUME_DESC_KEY "volume"

/* Values per cell a description may declare (R5.11), and the longest value
 * name this library keeps. */
#define LPVP_MAX_VALUES_PER_CELL 256
#define LPVP_MAX_VOLUMES_PER_LEVEL 64

/* The names of the 12 values of R5.1's layout, in order ("r.Y00", "r.Y1-1",
 * "r.Y10", "r.Y11", then g and b): SH bands 0-1 of each channel in the order
 * of LPVP_VOLUME_SH. The layout R5.7's lookup reads. */
extern const char *const lpvp_sh_value_names[LPVP_VALUES_PER_CELL];

/* A level's role (R5.10): "cascade" (levels blended as R5.7 says) or
 * "far_field" (a coarser level carrying on the light of the finer ones; the
 * server sums such levels), or "octree_level" (R5.13: a level of an octree,
 * level 0's box in cells 2^i times level 0's), or "iv_voxels" (R5.14: the
 * one level of technique iv, cubic voxels holding the radiance arriving at
 * their centres, looked up by R5.14's reconstruction). */
typedef enum lpvp_level_role {
    LPVP_ROLE_CASCADE = 0,
    LPVP_ROLE_FAR_FIELD = 1,
    LPVP_ROLE_OCTREE_LEVEL = 2,
    LPVP_ROLE_IV_VOXELS = 3,
    LPVP_ROLE_COUNT = 4
} lpvp_level_role;

/* R5.14: the description key of an iv volume's lookup parameter (the
 * session's effective iv_neighbours) and its range. */
#define LPVP_IV_NEIGHBOURS_KEY "iv_neighbours"
#define LPVP_IV_NEIGHBOURS_MIN 1
#define LPVP_IV_NEIGHBOURS_MAX 8

/* What GET_VOLUME's optional "content" asks for (R5.13): "merged" (the
 * default: the volume R5.1 - R5.12 describe), "levels" (a technique's
 * levels and index volume, e.g. the octree's) or "visibility" (R5.15: the
 * merged volume and the probes' visibility). */
#define LPVP_VOLUME_CONTENT_KEY "content"
typedef enum lpvp_volume_content {
    LPVP_CONTENT_MERGED = 0,
    LPVP_CONTENT_LEVELS = 1,
    LPVP_CONTENT_VISIBILITY = 2, /* R5.15: the merged volume and the probes' visibility */
    LPVP_CONTENT_COUNT = 3
} lpvp_volume_content;
extern const char *const lpvp_volume_content_names[LPVP_CONTENT_COUNT];
extern const char *const lpvp_level_role_names[LPVP_ROLE_COUNT];

/* An index volume (R5.12): value type and its size. */
#define LPVP_INDEX_VALUE_TYPE "u32"
#define LPVP_INDEX_VALUE_SIZE 4

/* The probes' visibility (R5.15): after the levels' values, a record of
 * values_per_probe f32 per probe (a probe a cell of every level). */
#define LPVP_VISIBILITY_KEY "visibility"
#define LPVP_VISIBILITY_VALUE_TYPE "f32"
#define LPVP_VISIBILITY_VALUE_SIZE 4
#define LPVP_VISIBILITY_MAX_IRRADIANCE_SIDE 16
#define LPVP_VISIBILITY_MAX_DISTANCE_SIDE 32
typedef struct lpvp_visibility_info {
    uint64_t probes;             /* the levels' cells together */
    int irradiance_side;         /* 1..LPVP_VISIBILITY_MAX_IRRADIANCE_SIDE */
    int distance_side;           /* 1..LPVP_VISIBILITY_MAX_DISTANCE_SIDE */
    uint64_t values_per_probe;   /* 4 + 3 irradiance_side^2 + 2 distance_side^2 */
    double bias_cells;           /* >= 0: the lookup's step along the normal, in cells */
    uint64_t raw_offset;         /* bytes into the raw volume: right after the levels' values */
    uint64_t raw_length;         /* probes x values_per_probe x 4 */
} lpvp_visibility_info;

typedef struct lpvp_index_info {
    int level;                   /* the level whose box it covers */
    int64_t dims[3];             /* entries per axis, each >= 1 */
    uint64_t cells;              /* dims' product */
    int values_per_cell;         /* u32 values per entry, >= 1 */
    uint64_t raw_offset;         /* bytes into the raw volume: right after the levels' values */
    uint64_t raw_length;         /* cells x values_per_cell x 4 */
} lpvp_index_info;

/* What a volume carries (R5.9 - R5.13). The levels' placement is the info's
 * cascades (R5.10 requires the two lists to agree), except an octree's
 * levels (R5.13), which are level_count / level below. */
typedef struct lpvp_volume_layout {
    int present;                 /* build: send the description; parse: the header had one (0: an
                                    older server, filled from the legacy keys as R5.1 describes) */
    int layout_version;          /* LPVP_VOLUME_LAYOUT_VERSION (0 when not present) */
    char technique[64];          /* the technique's name, e.g. "cascaded_lpv"; "" when not present */
    int far_field;               /* levels 1.. are far-field levels */
    lpvp_level_role role[LPVP_MAX_LEVELS];
    /* R5.13: content LPVP_CONTENT_LEVELS when the levels are an octree's
     * (role "octree_level"; the cascades then are level 0 alone): level_count
     * levels placed as lpvp_octree_level_place says. 0 otherwise: the levels
     * are the cascades. */
    lpvp_volume_content content;
    int level_count;
    lpvp_cascade_info level[LPVP_MAX_LEVELS];
    int volumes_per_level;       /* >= 1; 1: one (summed) volume per level */
    int values_per_cell;         /* 1..LPVP_MAX_VALUES_PER_CELL */
    int sh_values;               /* the values are lpvp_sh_value_names in order (build: send them) */
    char units[32];              /* the description's (and header's) units; "" = LPVP_VOLUME_UNITS */
    int has_index;
    lpvp_index_info index;       /* when has_index */
    /* R5.14 (role[0] LPVP_ROLE_IV_VOXELS): the reconstruction's voxels, 1..8 */
    int iv_neighbours;
    /* R5.15 (content LPVP_CONTENT_VISIBILITY): the probes' visibility */
    int has_visibility;
    lpvp_visibility_info visibility;
} lpvp_volume_layout;

typedef struct lpvp_volume_info {
    int64_t revision;            /* R3.3 */
    int64_t tick;
    lpvp_volume_format format;
    lpvp_compression compression;
    int keyframe;                /* 1: raw is the volume; 0: XOR delta vs base_tick (R5.3) */
    int64_t base_tick;           /* meaningful when keyframe == 0; -1 when absent */
    double error_bound;          /* compression LPVP_COMP_SHQ: the bound the message holds (R5.16) */
    int64_t dims[3];             /* cells per axis, each >= 1 */
    double origin[3];            /* m, lower corner */
    double cell_size;            /* m, > 0 */
    uint64_t raw_length;         /* bytes of the raw volume = cells x 12 x value size */
    /* The cascades, finest first (R5.6); dims/origin/cell_size above equal
     * cascades[0]. Parse always fills 1..LPVP_MAX_CASCADES. For build, 0
     * means one cascade described by dims/origin/cell_size above. */
    int cascade_count;
    lpvp_cascade_info cascades[LPVP_MAX_CASCADES];
    /* The description (R5.9 - R5.12). Build sends it when layout.present
     * (levels from the cascades, values from lpvp_sh_value_names when
     * sh_values); parse always fills it. */
    lpvp_volume_layout layout;
} lpvp_volume_info;

/* The 12-value SH layout of R5.1 for technique (one summed volume per
 * level, no index), roles from far_field; present set. */
void lpvp_volume_layout_sh(lpvp_volume_layout *l, const char *technique, int far_field, int levels);

/* R5.13's octree: the level count l = log2(n) + 1 of an octree over n^3
 * cells (n a power of two with l <= LPVP_MAX_LEVELS), else -1; and level i's
 * placement: level 0's origin, dims >> i, cell size 2^i x level 0's. */
int lpvp_octree_level_count(int64_t n);
void lpvp_octree_level_place(const lpvp_cascade_info *level0, int i, lpvp_cascade_info *out);

/* The "levels" layout of R5.13 for technique over level0 (cubic, a power of
 * two): every octree level of R5.1's 12 values and the index volume (one u32
 * per level-0 cell, the level its merged light comes from; raw_offset is
 * filled by lpvp_volume_header_build). Returns 0, or -1 with err set when
 * level0 has no octree. */
int lpvp_volume_layout_octree(lpvp_volume_layout *l, const char *technique, const lpvp_cascade_info *level0,
                              char *err, size_t err_n);

/* R5.14's layout for technique iv over level0 (its one level of voxels):
 * role "iv_voxels", far_field false, the 12 SH values in one volume, units
 * LPVP_VOLUME_UNITS_RADIANCE, the index over level 0 (one u32 per voxel: 1 =
 * it holds a surface; raw_offset is filled by lpvp_volume_header_build) and
 * iv_neighbours. Returns 0, or -1 with err set for neighbours outside 1..8. */
int lpvp_volume_layout_iv(lpvp_volume_layout *l, const char *technique, const lpvp_cascade_info *level0,
                          int neighbours, char *err, size_t err_n);

/* R5.15's layout: the SH layout of lpvp_volume_layout_sh (cascades, no
 * far field) with the probes' visibility after it, content
 * LPVP_CONTENT_VISIBILITY; its probe count and raw_offset are filled by
 * lpvp_volume_header_build. Returns 0, or -1 with err set for sides or a
 * bias out of range. */
int lpvp_volume_layout_visibility(lpvp_volume_layout *l, const char *technique, int levels, int irradiance_side,
                                  int distance_side, double bias_cells, char *err, size_t err_n);

/* Bytes after the levels' values: the index's (R5.12) or the visibility's
 * (R5.15), 0 when the layout has neither. */
uint64_t lpvp_volume_extra_bytes(const lpvp_volume_info *vi);

/* 1 when the layout is R5.14's (level 0 has the role "iv_voxels"). */
int lpvp_volume_layout_is_iv(const lpvp_volume_layout *l);

/* The layout's units: l->units, or LPVP_VOLUME_UNITS when that is empty. */
const char *lpvp_volume_layout_units(const lpvp_volume_layout *l);

/* Bytes of the levels' values: all cells x volumes_per_level x
 * values_per_cell x value size (0 on overflow or a bad layout). With
 * layout.present 0 and values_per_cell 0, the legacy 12 values. */
uint64_t lpvp_volume_values_bytes(const lpvp_volume_info *vi);

/* 0 when R5.7's lookup reads this layout (the SH values in W/sr, one volume
 * per level, no index); else -1 with err naming the layout (an iv volume's:
 * use R5.14's lookup, lpvp_volume_layout_iv_lookup_check). */
int lpvp_volume_layout_lookup_check(const lpvp_volume_layout *l, char *err, size_t err_n);

/* 0 when R5.14's lookup reads this layout (lpvp_volume_layout_is_iv, with
 * its index and iv_neighbours); else -1 with err naming the layout. */
int lpvp_volume_layout_iv_lookup_check(const lpvp_volume_layout *l, char *err, size_t err_n);

/* Cells of all levels together (0 if the count is out of range): the
 * octree's levels for content LPVP_CONTENT_LEVELS (R5.13), else the
 * cascades; with cascade_count 0, the cells of dims. */
uint64_t lpvp_volume_total_cells(const lpvp_volume_info *vi);

/* Index of the first cell of level (cascade) k in the raw volume (levels are
 * concatenated finest first, R5.6, R5.11): the sum of the cells of levels 0..k-1. */
uint64_t lpvp_volume_cascade_first_cell(const lpvp_volume_info *vi, int k);

/* Builds the header object (new reference; NULL if memory runs out) with
 * every field of section 5 (base_tick only for deltas; the description's
 * levels and index from the layout for content LPVP_CONTENT_LEVELS, R5.13,
 * the index's raw_offset = lpvp_volume_values_bytes), the "cascades" array
 * (R5.6; one entry from dims/origin/cell_size when cascade_count is 0) plus
 * the fixed "units", "layout" and "sh" strings. */
json_t *lpvp_volume_header_build(const lpvp_volume_info *vi);

/* Reads a header (client side). Checks types and ranges, that dims are
 * >= 1 with a product that fits, the "cascades" array (R5.6: 1..4 entries,
 * dims >= 1, cells == the dims' product, cell_size > 0, the top-level grid
 * equal to cascade 0), the description "volume" (R5.9 - R5.12: a layout
 * version this library knows, levels equal to the cascades, roles agreeing
 * with far_field, values naming values_per_cell distinct values, units as the
 * top level's, an index that fits; or R5.13's octree levels: one cascade,
 * log2(n) + 1 "octree_level" levels placed as lpvp_octree_level_place says,
 * far_field false, the index over level 0; or R5.14's iv voxels: one
 * cascade and one "iv_voxels" level equal to it, far_field false, the 12 SH
 * values in one volume, units "W/(m^2 sr)", the index over level 0 with one
 * value per voxel, iv_neighbours in 1..8), and that raw_length == the
 * levels' values (+ the index) as described. A header without "cascades" (an older
 * server) is read as one cascade equal to the grid; one without "volume" as
 * R5.1's 12 values (layout.present 0). Returns 0, or -1 with
 * "<field>: <what>" in err. */
int lpvp_volume_header_parse(const json_t *obj, lpvp_volume_info *vi, char *err, size_t err_n);

/* Client-side decoding of a VOLUME / GET_VOLUME attachment into the raw
 * volume raw_out (vi->raw_length bytes): zstd-decompresses if
 * vi->compression says so (exactly raw_length bytes, R5.2), then for a delta
 * (keyframe 0) XORs with base_raw (the raw bytes of tick vi->base_tick, same
 * length; R5.3). raw_out may equal base_raw (in-place update). Returns 0 or
 * -1 with err set (sizes disagree, zstd refused, delta without base). */
int lpvp_volume_decode(const lpvp_volume_info *vi, const void *attachment, size_t att_len,
                       const uint8_t *base_raw, size_t base_len, uint8_t *raw_out, char *err,
                       size_t err_n);

#ifdef __cplusplus
}
#endif

#endif /* LPVP_VOLUME_CODEC_H */
