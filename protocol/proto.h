/*
 * proto.h - the lpvd wire protocol, version 1: constants, frame header
 * encode/decode, an incremental frame parser, frame building, and JSON body
 * parsing with field getters.
 *
 * Pure encode/decode: no I/O, no sockets, no threads, no global state (every
 * function is reentrant). protocol/SPEC.md is the contract; comments cite its
 * requirement numbers (R2.1 ...). docs/protocol.md is the guide for client
 * writers. Library target: lpv_protocol (links jansson and zstd).
 *
 * Conventions:
 *   - Error codes are the SPEC section 3 codes (enum lpvp_error); 0 = none.
 *   - Functions that fail write a human-readable message into (err, err_n)
 *     when err is non-NULL; the message is always NUL-terminated (if err_n>0)
 *     and names the offending field/value, ready to be the "message" of an
 *     ERROR body (R3.4, R2.9).
 *   - Built frames are malloc'd; the caller free()s them.
 */
#ifndef LPVP_PROTO_H
#define LPVP_PROTO_H

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <jansson.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__) || defined(__clang__)
#define LPVP_PRINTF(fmt_idx, arg_idx) __attribute__((format(printf, fmt_idx, arg_idx)))
#else
#define LPVP_PRINTF(fmt_idx, arg_idx)
#endif

/* ---- Constants (SPEC section 2) ------------------------------------------ */

#define LPVP_MAGIC "LPVD"           /* bytes 0..3 of every frame (R2.2) */
#define LPVP_MAGIC_LEN 4
#define LPVP_VERSION 1              /* the only frame/HELLO version spoken (R2.3, R4.1) */
#define LPVP_HEADER_SIZE 24         /* R2.1 */
#define LPVP_MIN_JSON_LENGTH 2      /* R2.1: at least "{}" */

/* Default limits (R2.5). */
#define LPVP_DEFAULT_MAX_BODY ((uint32_t)1 << 20)        /* 1 MiB of JSON */
#define LPVP_DEFAULT_MAX_MESSAGE ((uint64_t)256 << 20)   /* 256 MiB json + attachment */

/* Message types (SPEC section 4). A reply has type = request | LPVP_REPLY_BIT
 * (R3.1); ERROR is 0xFFFF. */
enum lpvp_type {
    LPVP_HELLO = 0x0001,
    LPVP_SCENE_LOAD = 0x0002,
    LPVP_SCENE_UPDATE = 0x0003,
    LPVP_LIGHT_SET = 0x0004,
    LPVP_LIGHT_REMOVE = 0x0005,
    LPVP_CAMERA_SET = 0x0006,
    LPVP_CONFIG = 0x0007,
    LPVP_TICK = 0x0008,
    LPVP_SUBSCRIBE = 0x0009,
    LPVP_UNSUBSCRIBE = 0x000A,
    LPVP_GET_VOLUME = 0x000B,
    LPVP_GET_FRAME = 0x000C,
    LPVP_QUERY_IRRADIANCE = 0x000D,
    LPVP_STATS = 0x000E,
    LPVP_BYE = 0x000F,
    LPVP_ACK = 0x0010,        /* has no reply */
    LPVP_VOLUME = 0x0101,     /* server -> client stream, request_id 0 (section 5) */
    LPVP_FRAME = 0x0102,      /* server -> client stream, request_id 0 (section 6) */
    LPVP_REPLY_BIT = 0x8000,
    LPVP_ERROR = 0xFFFF
};
#define LPVP_REPLY(type) ((uint16_t)((type) | LPVP_REPLY_BIT))
#define LPVP_BYE_REPLY LPVP_REPLY(LPVP_BYE) /* 0x800F, also the unsolicited BYE (R4.9, R7.4) */

/* ERROR codes (SPEC R3.4 table). */
enum lpvp_error {
    LPVP_E_NONE = 0,             /* not an error; never sent */
    LPVP_E_BAD_MAGIC = 1,        /* closes */
    LPVP_E_BAD_VERSION = 2,      /* closes (frame version, R2.3); body lists "versions" */
    LPVP_E_BAD_FRAME = 3,        /* closes: non-zero flags, json_length < 2 */
    LPVP_E_TOO_LARGE = 4,        /* closes */
    LPVP_E_BAD_JSON = 5,
    LPVP_E_UNKNOWN_TYPE = 6,
    LPVP_E_BAD_FIELD = 7,
    LPVP_E_UNAUTHORIZED = 8,     /* closes */
    LPVP_E_HELLO_REQUIRED = 9,
    LPVP_E_NOT_READY = 10,
    LPVP_E_SCENE_INVALID = 11,
    LPVP_E_PATH_REFUSED = 12,
    LPVP_E_LIMIT = 13,
    LPVP_E_INTERNAL = 14,
    LPVP_E_SHUTTING_DOWN = 15,   /* closes */
    LPVP_E_COUNT = 16            /* one past the last code */
};

/* "HELLO", "SCENE_LOAD", ..., "ERROR"; replies are "HELLO_REPLY" etc.;
 * "BYE_REPLY" for 0x800F. Unknown types give "UNKNOWN" (never NULL). */
const char *lpvp_type_name(uint16_t type);

/* 1 if type is a request a client may send (0x0001..0x0010), else 0. A server
 * answers any other type with UNKNOWN_TYPE (R2.8). */
int lpvp_type_is_request(uint16_t type);

/* 1 if the request type gets a reply (every request but ACK, R3.1). */
int lpvp_type_has_reply(uint16_t type);

/* "BAD_MAGIC" ... "SHUTTING_DOWN" (R3.4); "UNKNOWN" for other codes. */
const char *lpvp_error_name(int code);

/* 1 if the server closes the connection after sending this ERROR (the
 * "closes" column of R3.4: BAD_MAGIC, BAD_VERSION, BAD_FRAME, TOO_LARGE,
 * UNAUTHORIZED, SHUTTING_DOWN), else 0. Note: a HELLO with an unspoken body
 * version also gets BAD_VERSION but does NOT close (R4.1); the caller handles
 * that exception. */
int lpvp_error_closes(int code);

/* ---- Limits (R2.5) -------------------------------------------------------- */

typedef struct lpvp_limits {
    uint32_t max_body;     /* max json_length (default 1 MiB) */
    uint64_t max_message;  /* max json_length + attachment_length (default 256 MiB) */
    int no_attachment;     /* 1: any attachment_length > 0 is TOO_LARGE (a server before HELLO, R2.5a);
                              0 (default): only max_message bounds it */
} lpvp_limits;

/* Fills the defaults above. Every function taking a const lpvp_limits *
 * accepts NULL to mean the defaults. */
void lpvp_limits_default(lpvp_limits *lim);

/* ---- Header (R2.1-R2.5) --------------------------------------------------- */

typedef struct lpvp_header {
    uint16_t version;            /* LPVP_VERSION */
    uint16_t type;               /* enum lpvp_type */
    uint32_t request_id;         /* chosen by the client, echoed by the reply (R3.1) */
    uint32_t flags;              /* 0 (R2.4) */
    uint32_t json_length;        /* >= 2 (R2.1) */
    uint32_t attachment_length;
} lpvp_header;

/* Writes the 24-byte header (magic "LPVD" + the fields, little-endian, R1.3).
 * The magic is always written; h->version is written as given. */
void lpvp_header_encode(const lpvp_header *h, uint8_t out[LPVP_HEADER_SIZE]);

/* Decodes and validates a 24-byte header against lim (NULL = defaults).
 * Returns 0 when the frame may be read, -1 otherwise with *error_code set to
 * the SPEC code to send (then close: all of these close):
 *   magic != "LPVD"                         -> LPVP_E_BAD_MAGIC   (R2.2)
 *   version != 1                            -> LPVP_E_BAD_VERSION (R2.3)
 *   flags != 0                              -> LPVP_E_BAD_FRAME   (R2.4)
 *   json_length < 2                         -> LPVP_E_BAD_FRAME   (R2.1)
 *   json_length > max_body, or
 *   json_length + attachment_length > max_message -> LPVP_E_TOO_LARGE (R2.5)
 *   attachment_length > 0 with no_attachment -> LPVP_E_TOO_LARGE (R2.5a)
 * checked in that order. *h is filled in every case, except that on BAD_MAGIC
 * h->request_id is set to 0 (R2.2: the reply carries request_id 0); on every
 * other error h->request_id is the one to echo. error_code may be NULL; it is
 * set to LPVP_E_NONE on success. */
int lpvp_header_decode(const uint8_t in[LPVP_HEADER_SIZE], const lpvp_limits *lim,
                       lpvp_header *h, int *error_code);

/* Same as lpvp_header_decode, also writing a message for the ERROR body,
 * e.g. "json_length 4294967295 exceeds the body limit 1048576".
 * Returns the error code (0 = ok). */
int lpvp_header_check(const uint8_t in[LPVP_HEADER_SIZE], const lpvp_limits *lim,
                      lpvp_header *h, char *err, size_t err_n);

/* ---- Incremental frame parser (R2.1-R2.6) ----------------------------------
 * Feed it the bytes of a stream as they arrive, in chunks of any size
 * (including 1 byte); it yields one complete frame at a time.
 *
 *   lpvp_parser p; lpvp_parser_init(&p, &limits);
 *   while ((n = recv(fd, buf, sizeof buf, 0)) > 0) {
 *       size_t off = 0;
 *       while (off < n) {
 *           size_t used; lpvp_frame f;
 *           int st = lpvp_parser_feed(&p, buf + off, n - off, &used, &f);
 *           off += used;
 *           if (st == LPVP_PARSE_FRAME) handle(&f);        // before the next feed
 *           else if (st == LPVP_PARSE_ERROR) { send ERROR p.error_code with
 *               request_id p.error_request_id and message p.error_message; close; }
 *       }
 *   }
 *   lpvp_parser_free(&p);
 *
 * Safety: memory held is at most min(what the header promises, the limits),
 * and grows only with bytes actually received (a header promising 256 MiB
 * followed by a trickle costs only what arrived, doubling as it grows), so a
 * hostile peer cannot make it allocate memory it has not sent. A header is
 * validated (lpvp_header_check) before any of its body is buffered (R2.5).
 * The magic is checked byte by byte as it arrives, so a stream that does not
 * start with "LPVD" fails at its first wrong byte (R2.2).
 * After an ERROR the parser stays failed: every later feed returns
 * LPVP_PARSE_ERROR again, consuming nothing (all header errors close).
 * A stream ending mid-frame simply never yields it (R2.6);
 * lpvp_parser_mid_frame() tells whether bytes of an unfinished frame are held.
 * The parser does not look inside the body: JSON validity (BAD_JSON, R2.7)
 * and unknown types (R2.8) are the caller's checks, and neither closes. */

enum lpvp_parse_status {
    LPVP_PARSE_NEED_MORE = 0,   /* every byte consumed; no complete frame yet */
    LPVP_PARSE_FRAME = 1,       /* *frame is complete; *consumed may be < len */
    LPVP_PARSE_ERROR = -1       /* see error_code / error_message; close */
};

typedef struct lpvp_frame {
    lpvp_header header;
    const char *body;            /* header.json_length bytes, NOT NUL-terminated */
    size_t body_len;             /* == header.json_length */
    const uint8_t *attachment;   /* header.attachment_length bytes (NULL if 0) */
    size_t attachment_len;       /* == header.attachment_length */
} lpvp_frame;
/* Lifetime of body/attachment: until the next lpvp_parser_feed or
 * lpvp_parser_free on the same parser. When a frame's whole payload (body +
 * attachment) lies in the `data` given to one feed (the common case; its
 * header may have come in an earlier feed), they point into `data` itself
 * (no copy), so `data` must also stay unchanged while the frame is used. */

typedef struct lpvp_parser {
    lpvp_limits limits;
    /* public, read-only after LPVP_PARSE_ERROR: */
    int error_code;              /* SPEC code (LPVP_E_*) */
    uint32_t error_request_id;   /* request_id to put in the ERROR reply (0 for BAD_MAGIC) */
    char error_message[192];     /* message for the ERROR body */
    uint64_t frames;             /* complete frames yielded so far */
    uint64_t bytes;              /* bytes consumed so far */
    /* private: */
    uint8_t hdr[LPVP_HEADER_SIZE];
    size_t hdr_have;             /* header bytes held (0..24) */
    lpvp_header header;          /* valid when hdr_have == 24 */
    uint8_t *buf;                /* body + attachment being assembled */
    size_t buf_cap;
    size_t buf_have;
    int failed;
} lpvp_parser;

/* lim NULL = defaults. Never fails (no allocation). */
void lpvp_parser_init(lpvp_parser *p, const lpvp_limits *lim);

/* Payload bytes (body + attachment) of the frame being read that have
 * arrived so far; 0 before its header is complete. */
uint64_t lpvp_parser_payload_have(const lpvp_parser *p);

/* Consumes bytes from data[0..len) up to the end of the first frame
 * completed by them. Returns an enum lpvp_parse_status; *consumed is the
 * number of bytes used: len on NEED_MORE; up to the end of the frame on
 * FRAME; up to the offending byte on the first ERROR (the header's 24 bytes,
 * or the first wrong magic byte); 0 on every call after a failure.
 * frame may be NULL only if the caller does not care about frames.
 * LPVP_PARSE_ERROR also when memory runs out (code LPVP_E_INTERNAL, which
 * R3.4 does not list as closing, but the stream position is lost: close). */
int lpvp_parser_feed(lpvp_parser *p, const void *data, size_t len, size_t *consumed,
                     lpvp_frame *frame);

/* 1 if the parser holds bytes of an incomplete frame (a stream closing now
 * would be closing mid-frame, R2.6). */
int lpvp_parser_mid_frame(const lpvp_parser *p);

/* The payload bytes (json + attachment) its header declared, of the frame
 * whose header was accepted and whose payload has not all arrived yet; 0
 * between frames. A server can reserve memory for it before reading on. */
uint64_t lpvp_parser_frame_payload(const lpvp_parser *p);

/* Frees the buffer; the parser may be lpvp_parser_init'ed again. */
void lpvp_parser_free(lpvp_parser *p);

/* ---- Building frames ------------------------------------------------------ */

/* A complete frame: header + json (json_len bytes; json NULL means "{}") +
 * attachment (att_len bytes, may be NULL if att_len is 0). version 1,
 * flags 0. Returns a malloc'd buffer of *out_len bytes, or NULL if memory
 * runs out or a length does not fit in 32 bits. Does not validate the JSON. */
uint8_t *lpvp_frame_build(uint16_t type, uint32_t request_id, const char *json, size_t json_len,
                          const void *attachment, size_t att_len, size_t *out_len);

/* Header + json only, with attachment_length = att_len: for sending a large
 * attachment from its own buffer (writev) without copying it. */
uint8_t *lpvp_frame_build_head(uint16_t type, uint32_t request_id, const char *json,
                               size_t json_len, size_t att_len, size_t *out_len);

/* As lpvp_frame_build with body serialised compactly (body NULL = {}).
 * body is not stolen (the caller keeps its reference). NULL if body cannot
 * be serialised (it must be an object). */
uint8_t *lpvp_frame_build_json(uint16_t type, uint32_t request_id, const json_t *body,
                               const void *attachment, size_t att_len, size_t *out_len);

/* The ERROR body {"code": code, "name": lpvp_error_name(code), "message": ...}
 * (R3.4); for LPVP_E_BAD_VERSION it also carries "versions": [1] (R2.3, R4.1).
 * A new reference (NULL only if memory runs out); add fields before building. */
json_t *lpvp_error_body(int code, const char *fmt, ...) LPVP_PRINTF(2, 3);

/* ---- Addresses (SPEC R1.1) ----------------------------------------------- */

/* The default Unix socket: $XDG_RUNTIME_DIR/lpvd.sock when that variable
 * names an existing absolute folder, else /tmp/lpvd-$UID.sock. The daemon and
 * the C clients use this one rule so they always meet. */
void lpvp_default_socket_path(char *out, size_t n);

/* Splits "HOST:PORT", "[IPv6]:PORT", ":PORT" or "PORT" into a host (brackets
 * removed; empty or absent = "127.0.0.1") and a port 0..65535. Returns 0, or
 * -1 with a message naming the address. */
int lpvp_split_host_port(const char *s, char *host, size_t host_n, unsigned *port, char *err, size_t err_n);

/* printf-formats a message into err (nothing when err is NULL or err_n 0):
 * how every function of this library reports what was wrong. */
void lpvp_set_error(char *err, size_t err_n, const char *fmt, ...) LPVP_PRINTF(3, 4);
json_t *lpvp_error_vbody(int code, const char *fmt, va_list ap);

/* A complete ERROR frame (type 0xFFFF) with lpvp_error_body(code, fmt, ...).
 * request_id: the request's (R3.1), 0 for BAD_MAGIC (R2.2) and unsolicited
 * errors. malloc'd, *out_len bytes; NULL if memory runs out. */
uint8_t *lpvp_error_build(uint32_t request_id, int code, size_t *out_len, const char *fmt, ...)
    LPVP_PRINTF(4, 5);

/* ---- Body parsing (R2.7) -------------------------------------------------- */

/* Parses a frame body. Returns a new reference to a JSON object, or NULL with
 * a message in err (the caller answers ERROR BAD_JSON, connection stays open)
 * when the bytes are not valid UTF-8 (jansson checks), not valid JSON (RFC
 * 8259; trailing garbage refused), not an object, contain "\u0000", repeat a
 * key within one object, or nest deeper than jansson's limit. */
json_t *lpvp_body_parse(const char *body, size_t len, char *err, size_t err_n);

/* ---- Field getters (R2.9) --------------------------------------------------
 * Each looks up obj[key] (obj must be an object; a non-object obj counts as
 * "field absent"). Return values: */
enum lpvp_field_status {
    LPVP_FIELD_OK = 0,      /* *out set */
    LPVP_FIELD_ABSENT = 1,  /* optional field not present; *out untouched (preset defaults) */
    LPVP_FIELD_BAD = -1     /* wrong type, out of range, or required and missing:
                               err holds "<key>: <what>" -> ERROR BAD_FIELD */
};
/* JSON null counts as present with the wrong type (not as absent). On
 * LPVP_FIELD_BAD *out is untouched (arrays: possibly partially written). */

/* Integer in [min, max]. A JSON real with an integral value (e.g. 512.0) is
 * accepted; 1.5 is not. */
int lpvp_get_int(const json_t *obj, const char *key, int required, int64_t min, int64_t max,
                 int64_t *out, char *err, size_t err_n);

/* Number (integer or real) in [min, max]; always finite (JSON has no NaN/Inf;
 * checked anyway). */
int lpvp_get_number(const json_t *obj, const char *key, int required, double min, double max,
                    double *out, char *err, size_t err_n);

/* As lpvp_get_number, stored as float; min/max must be representable. */
int lpvp_get_float(const json_t *obj, const char *key, int required, double min, double max,
                   float *out, char *err, size_t err_n);

/* JSON true/false only (not 0/1). *out = 0 or 1. */
int lpvp_get_bool(const json_t *obj, const char *key, int required, int *out, char *err,
                  size_t err_n);

/* String of at most max_len bytes (UTF-8 already checked by the parser, no
 * NUL inside). *out is borrowed from obj (valid while obj lives); *out_len
 * may be NULL. */
int lpvp_get_string(const json_t *obj, const char *key, int required, size_t max_len,
                    const char **out, size_t *out_len, char *err, size_t err_n);

/* String that must be one of choices[0..n_choices); *out = its index.
 * The message lists the choices: "format: expected one of \"fp16\", \"fp32\"". */
int lpvp_get_enum(const json_t *obj, const char *key, int required,
                  const char *const *choices, size_t n_choices, int *out, char *err,
                  size_t err_n);

/* Array of exactly `count` numbers, each in [min, max] (e.g. vec3: count 3,
 * vec4: 4, mat4 column-major: 16, bounds: 6). */
int lpvp_get_numbers(const json_t *obj, const char *key, int required, size_t count, double min,
                     double max, double *out, char *err, size_t err_n);
int lpvp_get_floats(const json_t *obj, const char *key, int required, size_t count, double min,
                    double max, float *out, char *err, size_t err_n);

/* Array of exactly `count` integers in [min, max] (e.g. "grid": [3]). */
int lpvp_get_ints(const json_t *obj, const char *key, int required, size_t count, int64_t min,
                  int64_t max, int64_t *out, char *err, size_t err_n);

/* A nested object / an array of at most max_len elements; *out borrowed. */
int lpvp_get_object(const json_t *obj, const char *key, int required, const json_t **out,
                    char *err, size_t err_n);
int lpvp_get_array(const json_t *obj, const char *key, int required, size_t max_len,
                   const json_t **out, char *err, size_t err_n);

/* Prepends a printf-formatted prefix to the message already in err, for
 * fields of nested objects: after lpvp_get_floats(node, "matrix", ...) fails
 * with "matrix: ...", lpvp_err_prefix(err, n, "nodes[%zu].", i) makes it
 * "nodes[3].matrix: ...". Truncates safely. */
void lpvp_err_prefix(char *err, size_t err_n, const char *fmt, ...) LPVP_PRINTF(3, 4);

/* ---- Little-endian helpers (R1.3) ----------------------------------------- */

static inline void lpvp_put_u16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
}
static inline void lpvp_put_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}
static inline uint16_t lpvp_get_u16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (p[1] << 8));
}
static inline uint32_t lpvp_get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
           ((uint32_t)p[3] << 24);
}
/* 1 when the host stores numbers as the wire does (R1.3): a raw volume's
 * bytes are then its floats in memory. */
static inline int lpvp_host_little_endian(void)
{
    const uint16_t one = 1;
    uint8_t b;
    memcpy(&b, &one, 1);
    return b == 1;
}
static inline void lpvp_put_u64(uint8_t *p, uint64_t v)
{
    lpvp_put_u32(p, (uint32_t)v);
    lpvp_put_u32(p + 4, (uint32_t)(v >> 32));
}
static inline uint64_t lpvp_get_u64(const uint8_t *p)
{
    return (uint64_t)lpvp_get_u32(p) | ((uint64_t)lpvp_get_u32(p + 4) << 32);
}

#ifdef __cplusplus
}
#endif

#endif /* LPVP_PROTO_H */
