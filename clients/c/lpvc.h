/*
 * lpvc.h - C client library for the lpvd daemon (wire protocol v1,
 * protocol/SPEC.md). One connection = one session; blocking sockets (Unix
 * socket path or HOST:PORT over TCP). Not thread-safe: use one lpvc per
 * thread.
 *
 *   char err[256];
 *   lpvc *c = lpvc_connect(NULL, NULL, err, sizeof err);   // default socket, HELLO
 *   if (!c) { fprintf(stderr, "%s\n", err); return 1; }
 *   if (lpvc_tick(c, NULL) != 0)
 *       fprintf(stderr, "%s (%d): %s\n", lpvc_error_name(c), lpvc_error_code(c),
 *               lpvc_error_message(c));
 *   lpvc_volume v = {0};
 *   lpvc_get_volume(c, NULL, &v);    // v.data: v.cells * 12 floats (W/sr)
 *   lpvc_volume_free(&v);
 *   lpvc_bye(c);
 *   lpvc_close(c);
 *
 * Conventions:
 *   - Every call returns 0 on success, -1 on failure; the failure is then in
 *     lpvc_error_code/name/message: an ERROR reply's SPEC code (1..15) and
 *     name (R3.4), or a client-side failure with a negative code
 *     (LPVC_ERR_IO "IO", LPVC_ERR_PROTOCOL "PROTOCOL", LPVC_ERR_USAGE "USAGE",
 *     LPVC_ERR_TIMEOUT "TIMEOUT", LPVC_ERR_CLOSED "CLOSED").
 *   - The JSON body of the last reply is kept: lpvc_last_reply() (valid until
 *     the next call on the connection) and lpvc_last_revision() (the
 *     "revision" of the last reply that carried one, R3.3).
 *   - Option structs are zero-initialised ({0}); a zero/NULL field means
 *     "not sent, server default". NULL for a whole struct means all defaults.
 *   - Stream messages (VOLUME, FRAME) arriving while a reply is awaited are
 *     queued and returned by lpvc_next_stream_message() in order.
 */
#ifndef LPVC_H
#define LPVC_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lpvc lpvc;

/* Client-side error codes (server errors are the SPEC's positive codes). */
enum {
    LPVC_ERR_IO = -1,        /* socket failure, connection closed */
    LPVC_ERR_PROTOCOL = -2,  /* the server sent something the SPEC forbids */
    LPVC_ERR_USAGE = -3,     /* bad arguments to this library */
    LPVC_ERR_TIMEOUT = -4,   /* lpvc_next_stream_message timed out */
    LPVC_ERR_CLOSED = -5     /* the server said BYE / SHUTTING_DOWN, or after lpvc_bye */
};

/* ---- Connection ----------------------------------------------------------- */

/* The daemon's default socket (R1.1): $XDG_RUNTIME_DIR/lpvd.sock, else
 * /tmp/lpvd-$UID.sock. Returns buf. */
const char *lpvc_default_address(char *buf, size_t n);

/* Connects and sends HELLO (with token when non-NULL). address: a Unix
 * socket path, "unix:PATH", "HOST:PORT", "tcp:HOST:PORT" ("[v6]:PORT"), or
 * NULL for the default socket. Returns NULL with a message in err on failure
 * (the server's ERROR name and message when HELLO was refused). */
lpvc *lpvc_connect(const char *address, const char *token, char *err, size_t n);

typedef struct lpvc_connect_desc {
    const char *address;      /* NULL: default socket */
    const char *token;        /* NULL: none */
    const char *client_name;  /* HELLO "client"; NULL: "lpvc" */
    int timeout_ms;           /* per-reply receive timeout; 0: wait forever */
} lpvc_connect_desc;
lpvc *lpvc_connect_with(const lpvc_connect_desc *desc, char *err, size_t n);

/* Closes the socket (without BYE) and frees everything. NULL is fine. */
void lpvc_close(lpvc *c);

/* The HELLO reply body (JSON text), e.g. its "session" and "limits". */
const char *lpvc_hello_reply(const lpvc *c);

int lpvc_error_code(const lpvc *c);
const char *lpvc_error_name(const lpvc *c);
const char *lpvc_error_message(const lpvc *c);
const char *lpvc_last_reply(const lpvc *c);
int64_t lpvc_last_revision(const lpvc *c);

/* ---- Requests (SPEC section 4) -------------------------------------------- */

/* SCENE_LOAD by path (resolved under the server's --scene-root, R4.3). */
int lpvc_scene_load_file(lpvc *c, const char *path);
/* SCENE_LOAD with .glb bytes as attachment (R4.4). */
int lpvc_scene_load_glb(lpvc *c, const void *glb, size_t size);
/* SCENE_UPDATE with a JSON object text {"nodes": [...], "materials": [...]}. */
int lpvc_scene_update(lpvc *c, const char *json);

typedef struct lpvc_light {
    const char *id;            /* required */
    const char *type;          /* "point" (NULL), "spot", "directional" */
    float intensity;           /* W/sr (point, spot) or W/m^2 (directional), as the server's units */
    const float *color;        /* [3] or NULL */
    const float *position;     /* [3] or NULL */
    const float *direction;    /* [3] or NULL */
    float range;               /* 0: not sent */
    float inner_cone;          /* radians; 0: not sent */
    float outer_cone;          /* radians; 0: not sent */
} lpvc_light;
int lpvc_light_set(lpvc *c, const lpvc_light *light);
int lpvc_light_remove(lpvc *c, const char *id);

typedef struct lpvc_camera {
    const float *eye;          /* [3], required unless scene_camera/scene_camera_name */
    const float *target;       /* [3], required unless ... */
    const float *up;           /* [3] or NULL */
    float fov_deg;             /* 0: not sent */
    int width, height;         /* 0: not sent */
    const char *scene_camera_name; /* {"camera": name}: a camera of the scene */
    int scene_camera;          /* {"camera": scene_camera - 1} when > 0 (1-based, so 0 = unset) */
} lpvc_camera;
int lpvc_camera_set(lpvc *c, const lpvc_camera *cam);

/* ---- Settings knobs (SPEC R4.12) --------------------------------------------
 * The daemon describes CONFIG's knobs in its HELLO reply ("knobs", built
 * from its settings table); the connection keeps that description, so this
 * library, lpvctl and the tests hold no list of knobs of their own. */
typedef enum lpvc_knob_type {
    LPVC_KNOB_INT = 0,      /* a JSON integer */
    LPVC_KNOB_NUMBER = 1,   /* a JSON number */
    LPVC_KNOB_BOOL = 2      /* a JSON boolean ("on" / "off" as text) */
} lpvc_knob_type;

typedef struct lpvc_knob {
    const char *name;       /* the CONFIG key, e.g. "damping" */
    lpvc_knob_type type;
    double min, max;        /* allowed values (int and number; bool: 0 and 1) */
    bool min_exclusive;     /* the value must be > min */
    double def;             /* the value a session starts with (bool: 0 or 1) */
    const char *default_text; /* the default in words ("auto", "the preset's (on)") */
    const char *unit;       /* "m", "texels", ... or "" */
    const char *note;       /* what special values mean ("0 = auto"), or "" */
    const char *help;       /* one line */
} lpvc_knob;

/* The description from HELLO: *knobs (may be NULL) receives the array, valid
 * while c lives; returns its length (0 from a server that sends none). */
size_t lpvc_knobs(const lpvc *c, const lpvc_knob **knobs);
/* The knob named name, or NULL. */
const lpvc_knob *lpvc_knob_find(const lpvc *c, const char *name);
/* The preset names the server offers (HELLO "presets"), *count of them. */
const char *const *lpvc_presets(const lpvc *c, size_t *count);
/* The GI techniques the server offers (HELLO "techniques", R4.14). */
const char *const *lpvc_techniques(const lpvc *c, size_t *count);

/* The allowed values in words: "an integer in 1..4096", "a number > 0 and <= 1",
 * "on or off". Returns buf. */
const char *lpvc_knob_expect(const lpvc_knob *k, char *buf, size_t n);
/* 0 when v is allowed (integral for ints, in range), else -1 with
 * "<name>: <why>" in err. */
int lpvc_knob_check(const lpvc_knob *k, double v, char *err, size_t n);
/* Text -> value: "on"/"off" (also "true"/"false") for bools, a decimal
 * number otherwise; then lpvc_knob_check. Returns 0, or -1 with err set. */
int lpvc_knob_parse(const lpvc_knob *k, const char *text, double *v, char *err, size_t n);

/* One knob to send: bools are 0 (false) or non-zero (true). */
typedef struct lpvc_setting {
    const char *name;
    double value;
} lpvc_setting;

typedef struct lpvc_config {
    int grid[3];               /* all 0: not sent */
    const float *bounds;       /* [6] x0 y0 z0 x1 y1 z1, or NULL */
    float tick_rate_hz;        /* 0: not sent */
    const char *technique;     /* one of lpvc_techniques(), or NULL: not sent (R4.14) */
    const char *preset;        /* one of lpvc_presets(), or NULL: not sent. The server applies it
                                  first; the knobs that are sent override its values */
    const lpvc_setting *settings; /* knobs of the description, each checked against it before sending
                                     (an unknown name or a value out of range fails with LPVC_ERR_USAGE) */
    size_t setting_count;
} lpvc_config;
int lpvc_config_set(lpvc *c, const lpvc_config *cfg);
/* CONFIG with a JSON object text (any field, including zeros). The reply
 * ({"revision", "config": {effective values}}) is lpvc_last_reply(). */
int lpvc_config_json(lpvc *c, const char *json);

/* TICK; *tick (may be NULL) receives the tick number. */
int lpvc_tick(lpvc *c, int64_t *tick);

enum lpvc_stream { LPVC_STREAM_VOLUME = 0, LPVC_STREAM_FRAME = 1 };
typedef struct lpvc_subscribe_desc {
    enum lpvc_stream stream;
    const char *format;        /* volume: "fp16"|"fp32"; frame: "rgba8"|"png"|"exr"; NULL: server default */
    const char *compression;   /* "zstd"|"none", volume also "shq" (R5.16); NULL: server default */
    double error_bound;        /* "shq": the bound (R5.16, 0.001..0.25); 0: the server's default */
    bool delta;                /* volume deltas (R5.3, R5.16); this library undoes them */
} lpvc_subscribe_desc;
int lpvc_subscribe(lpvc *c, const lpvc_subscribe_desc *desc);
int lpvc_unsubscribe(lpvc *c, enum lpvc_stream stream);

#define LPVC_MAX_CASCADES 4    /* entries of a volume header's "cascades" (SPEC R5.6) */
#define LPVC_MAX_LEVELS 9      /* entries of a description's "levels": an octree's (SPEC R5.13) */

/* One cascade of a decoded volume (SPEC R5.6). */
typedef struct lpvc_cascade {
    int dims[3];
    float origin[3];           /* m, lower corner */
    float cell_size;           /* m */
    size_t cells;              /* dims[0] * dims[1] * dims[2] */
    float *data;               /* cells * values_per_cell floats (x volumes_per_level) inside the
                                  volume's data (not to be freed) */
} lpvc_cascade;

/* A decoded volume (SPEC section 5): always float32 after decoding. The
 * top-level dims / origin / cell_size / cells are cascade 0's (the finest);
 * data holds every cascade's cells, cascade 0 first (total_cells in all). */
typedef struct lpvc_volume {
    int64_t revision, tick;
    int dims[3];
    float origin[3];
    float cell_size;
    size_t cells;              /* dims[0] * dims[1] * dims[2]: cascade 0's cells */
    float *data;               /* total_cells * volumes_per_level * values_per_cell floats; for R5.1's
                                  layout (sh_values) per cell r0..r3 g0..g3 b0..b3, x fastest, in units */
    char format[8];            /* wire format: "fp16" or "fp32" */
    char compression[8];       /* wire compression: "none", "zstd" or "shq" */
    double error_bound;        /* "shq": the bound every cell holds (R5.16); 0 otherwise */
    bool keyframe;             /* false: was a delta, already undone */
    int64_t base_tick;         /* delta base (-1 for keyframes) */
    char *header_json;         /* the header as received */
    int cascade_count;         /* 1..LPVC_MAX_CASCADES */
    lpvc_cascade cascades[LPVC_MAX_CASCADES]; /* finest first */
    size_t total_cells;        /* sum of the cascades' cells */
    char *plan_json;           /* the tick's plan (SPEC section 8) as JSON text; NULL if the header had none */
    /* What the volume carries (SPEC R5.9 - R5.12): the header's "volume"
     * description, or R5.1's layout from an older server's legacy keys. data
     * holds, per cascade (level), volumes_per_level volumes of cells x
     * values_per_cell floats; each cascade's data points at its first. The
     * values' names are in header_json ("volume"."values"). */
    int layout_version;        /* 0: the server sent no description */
    char technique[64];        /* e.g. "cascaded_lpv"; "" without a description */
    int values_per_cell;       /* 12 for R5.1's SH values */
    int volumes_per_level;     /* 1: one (summed) volume per level */
    bool far_field;            /* cascades 1.. are far-field levels the server sums (R5.10) */
    bool sh_values;            /* the values are R5.1's 12 SH values: the lookup below reads them */
    uint32_t *index;           /* the index volume (R5.12), index_count values; NULL when none */
    size_t index_count;
    int index_level;           /* the level it covers */
    int index_dims[3];
    int index_values_per_cell;
    /* GET_VOLUME's content (SPEC R5.13): "merged" (the volume above), or
     * "levels": every octree level (levels[k], level 0 first, each placed as
     * the header says and pointing into data; cascades[0] is level 0) and the
     * index volume above (per level-0 cell, the level its merged light comes
     * from). R5.7's lookup refuses a "levels" volume. */
    char content[16];          /* "merged", "levels" or "visibility" */
    int level_count;           /* "levels": 1..LPVC_MAX_LEVELS; "merged": 0 */
    lpvc_cascade levels[LPVC_MAX_LEVELS];
    /* The values' units ("W/sr": an LPV's intensity per cell; "W/(m^2 sr)":
     * technique iv's radiance at voxel centres). With iv_voxels (SPEC R5.14)
     * the volume is technique iv's one level of voxels (cascades[0]), index
     * says which voxels hold a surface (1) or not (0), and
     * lpvc_volume_irradiance reconstructs with iv_neighbours of them. */
    char units[32];
    bool iv_voxels;
    int iv_neighbours;         /* 1..8 with iv_voxels, else 0 */
    /* Content "visibility" (SPEC R5.15, technique probes): beside the
     * cascades' SH, every probe's record (a probe per cell, cascade 0's
     * first, x fastest), values_per_probe floats each: offset from the
     * cell's centre (m, 3), active (1 or 0), the irradiance map
     * (irradiance_side^2 texels of rgb, W/m^2), the distance map
     * (distance_side^2 texels of mean and mean square distance, m and
     * m^2). lpvc_volume_irradiance then weighs the probes as the server
     * does. NULL / 0 for any other volume. */
    float *visibility;
    size_t visibility_floats;
    int irradiance_side, distance_side, values_per_probe;
    float bias_cells;          /* the lookup's step along the normal, in cells */
} lpvc_volume;
void lpvc_volume_free(lpvc_volume *v);

typedef struct lpvc_volume_desc {
    const char *format;        /* "fp16" | "fp32"; NULL: "fp32" */
    const char *compression;   /* "zstd" | "none" | "shq" (R5.16, decoded to fp32); NULL: "zstd" */
    double error_bound;        /* "shq": the bound (R5.16); 0: the server's default */
    const char *content;       /* "merged" | "levels" (SPEC R5.13) | "visibility" (R5.15); NULL: "merged" */
} lpvc_volume_desc;
int lpvc_get_volume(lpvc *c, const lpvc_volume_desc *desc, lpvc_volume *out);

/* A frame (SPEC section 6). data: rgba8 pixels (decompressed, top row
 * first), or the complete PNG / EXR file. */
typedef struct lpvc_frame {
    int64_t revision, tick;
    int width, height;
    char format[8];            /* "rgba8" | "png" | "exr" */
    char terms[16];            /* "full" | "indirect" | "direct" | "ao" */
    unsigned char *data;
    size_t size;
    char *header_json;
    char *plan_json;           /* the tick's plan (SPEC section 8) as JSON text; NULL if the header had none */
} lpvc_frame;
void lpvc_frame_free(lpvc_frame *f);

typedef struct lpvc_frame_desc {
    const char *format;        /* "rgba8" | "png" | "exr"; NULL: server default */
    const char *compression;   /* rgba8 only: "zstd" | "none"; NULL: server default */
    const char *terms;         /* "full" | "indirect" | "direct" | "ao" (ambient occlusion, 1 = open, linear; only
                                  with technique iv and iv_ao on, else BAD_FIELD); NULL: server default */
    const char *exposure;      /* rgba8/png: "auto" or an EV such as "-2.5" (sent as a number);
                                  NULL: server default (auto). SPEC R6.4 */
    bool transparent;          /* rgba8/png: background alpha 0 instead of the opaque grey */
} lpvc_frame_desc;
int lpvc_get_frame(lpvc *c, const lpvc_frame_desc *desc, lpvc_frame *out);

/* QUERY_IRRADIANCE: points and normals are n * 3 floats each; rgb receives
 * n * 3 floats of irradiance in W/m^2. */
int lpvc_query_irradiance(lpvc *c, const float *points, const float *normals, size_t n, float *rgb);

/* STATS: *json receives the reply body, malloc'd (free() it). */
int lpvc_stats(lpvc *c, char **json);

/* BYE: waits for the reply; the socket is then closed (lpvc_close still
 * frees the object). */
int lpvc_bye(lpvc *c);

/* ACK a volume tick (no reply). lpvc_next_stream_message ACKs by itself
 * unless lpvc_set_auto_ack(c, false); either way it keeps the last four
 * streamed volumes, so a delta against any of them (once ACKed) decodes. */
int lpvc_ack(lpvc *c, int64_t tick);
void lpvc_set_auto_ack(lpvc *c, bool on);

/* Sends any request type with a JSON body text and attachment and waits for
 * its reply (escape hatch for tools and tests). The reply body is
 * lpvc_last_reply(); *att / *att_len (may be NULL) receive its attachment,
 * malloc'd. */
int lpvc_request_raw(lpvc *c, uint16_t type, const char *json, const void *attachment,
                     size_t att_len, void **att, size_t *att_n);

/* ---- Streams -------------------------------------------------------------- */

enum lpvc_message_type { LPVC_MSG_NONE = 0, LPVC_MSG_VOLUME, LPVC_MSG_FRAME, LPVC_MSG_BYE };
typedef struct lpvc_message {
    enum lpvc_message_type type;
    lpvc_volume volume;        /* LPVC_MSG_VOLUME */
    lpvc_frame frame;          /* LPVC_MSG_FRAME */
} lpvc_message;
void lpvc_message_free(lpvc_message *m);

/* Waits up to timeout_ms (< 0: forever) for the next VOLUME or FRAME after
 * SUBSCRIBE. Volumes are decoded (zstd, fp16, XOR delta against the acked
 * volume of base_tick, R5.3) and, with auto-ACK, acknowledged. A BYE from
 * the server gives type LPVC_MSG_BYE (and returns 0). Timeout: -1 with
 * LPVC_ERR_TIMEOUT. */
int lpvc_next_stream_message(lpvc *c, lpvc_message *out, int timeout_ms);

/* ---- Local lookup (SPEC R5.7, R5.14, R5.15; protocol/volume_lookup.h over core's oracles) ---- */

/* E(n) in W/m^2 at point p with normal n from a decoded volume, as the
 * server's QUERY_IRRADIANCE computes it: with several cascades, the finest
 * containing p, blended to the next coarser within the last 3 cells of its
 * border (SPEC R5.7); for technique iv's voxels (iv_voxels), R5.14's
 * reconstruction from the voxels around p and the index; for a probes'
 * volume with its visibility (content "visibility"), R5.15's lookup: the 8
 * probes around p weighted by their distance maps. Returns 0, or -1
 * with rgb zero for a volume whose layout neither lookup reads
 * (lpvc_volume_lookup_check says why). */
int lpvc_volume_irradiance(const lpvc_volume *v, const float p[3], const float n[3], float rgb[3]);

/* 0 when lpvc_volume_irradiance reads v's layout (R5.1's 12 SH values in
 * W/sr, one volume per level; or R5.14's iv voxels); else -1 with a message
 * naming the layout in err. */
int lpvc_volume_lookup_check(const lpvc_volume *v, char *err, size_t n);

/* The same from one cascade alone. */
void lpvc_cascade_irradiance(const lpvc_cascade *cs, const float p[3], const float n[3], float rgb[3]);

#ifdef __cplusplus
}
#endif

#endif /* LPVC_H */
