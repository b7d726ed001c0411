/*
 * lpvc_internal.h - what the C client library's files share (not installed,
 * not part of lpvc.h): the connection struct and the few functions one job
 * offers the others.
 *
 *   lpvc_transport.c  sockets, framing, request/reply matching, the stream
 *                     queue, connect / close, errors
 *   lpvc_requests.c   the requests of SPEC section 4 (scene, lights, camera,
 *                     config, tick, subscribe, ack, query, stats, bye, raw)
 *   lpvc_volume.c     volume decoding (SPEC section 5: the header's
 *                     description, zstd, fp16, XOR deltas and the
 *                     acknowledged-volume cache) and the R5.7 lookup wrappers
 *   lpvc_frame.c      frame decoding (SPEC section 6)
 *   lpvc_knobs.c      the daemon's knob description (R4.12)
 */
#ifndef LPVC_INTERNAL_H
#define LPVC_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <jansson.h>

#include "lpvc.h"
#include "lpvc_knobs.h"
#include "proto.h"

/* Streamed volumes kept as possible XOR delta bases (R5.3). The server
 * deltas against a tick we acknowledged; ACKs are asynchronous, so it may use
 * one that is not our newest. */
#define LPVC_KEEP_ACKED 4

/* A stream message (VOLUME, FRAME) that arrived while a reply was awaited. */
typedef struct lpvc_queued {
    struct lpvc_queued *next;
    uint16_t type;
    json_t *body;
    uint8_t *att;
    size_t att_len;
} lpvc_queued;

/* The raw bytes of a volume this client acknowledged (a delta base). */
typedef struct lpvc_acked {
    int64_t tick;       /* -1: empty slot */
    uint8_t *raw;
    size_t len;
    uint64_t age;
} lpvc_acked;

struct lpvc {
    int fd;
    uint32_t next_id;
    int timeout_ms;
    bool auto_ack;
    int err_code;
    char err_name[32];
    char err_msg[512];
    char *last_reply;
    int64_t last_revision;
    char *hello;
    lpvc_knobset knobs;     /* the server's knob description (HELLO, R4.12) */
    lpvc_queued *q_head, *q_tail;
    lpvc_acked acked[LPVC_KEEP_ACKED];
    uint64_t ack_clock;
};

/* ---- lpvc_transport.c ---------------------------------------------------- */

/* Records a failure (code: the SPEC's positive code or an LPVC_ERR_*) and
 * returns -1, so callers write `return lpvci_fail(...)`. */
#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
int lpvci_fail(lpvc *c, int code, const char *fmt, ...);
void lpvci_clear_error(lpvc *c);
void lpvci_close_fd(lpvc *c);

/* Sends one frame; returns its request_id, or 0 on failure. */
uint32_t lpvci_send_frame(lpvc *c, uint16_t type, const json_t *body, const void *att, size_t att_len);

/* Sends a request and waits for its reply; stream messages are queued.
 * On success *reply (if non-NULL) receives the reply body (owned by the
 * caller) and *ratt / *ratt_len its attachment (malloc'd, owned by the caller). */
int lpvci_request(lpvc *c, uint16_t type, const json_t *body, const void *att, size_t att_len, json_t **reply,
                  uint8_t **ratt, size_t *ratt_len);

/* lpvci_request for replies whose body only matters through lpvc_last_reply;
 * takes the body (NULL: out of memory). */
int lpvci_simple(lpvc *c, uint16_t type, json_t *body_stolen);

/* One received frame (lpvci_recv_frame). */
typedef struct lpvci_rx {
    lpvp_header h;
    json_t *body;
    uint8_t *att;
    size_t att_len;
} lpvci_rx;
/* Receives one frame. timeout_ms: -1 the connection's reply timeout, < -1
 * forever, >= 0 that many ms before the first byte. 0, or -1 with the error set. */
int lpvci_recv_frame(lpvc *c, lpvci_rx *out, int timeout_ms);
void lpvci_rx_free(lpvci_rx *r);
/* Keeps body as the last reply (lpvc_last_reply) and its revision. */
void lpvci_set_last_reply(lpvc *c, const json_t *body);
/* An ERROR frame: records its code, name and message; closes if it closes
 * (request_type: the request it answers, 0 for none). */
int lpvci_take_error(lpvc *c, const json_t *body, uint16_t request_type);

/* ---- lpvc_requests.c ----------------------------------------------------- */

/* text (NULL: "{}") as a JSON object, or NULL with a USAGE error naming what. */
json_t *lpvci_parse_object(lpvc *c, const char *text, const char *what);

/* ---- lpvc_volume.c ------------------------------------------------------- */

/* Decodes a volume header + attachment into out. stream: remember it as a
 * possible delta base and (with auto-ACK) ACK it. */
int lpvci_decode_volume(lpvc *c, const json_t *hdr, const uint8_t *att, size_t att_len, bool stream,
                        lpvc_volume *out);

/* ---- lpvc_frame.c -------------------------------------------------------- */

/* Decodes a frame header + attachment into out (takes ownership of att). */
int lpvci_decode_frame(lpvc *c, const json_t *hdr, uint8_t *att, size_t att_len, lpvc_frame *out);

#endif /* LPVC_INTERNAL_H */
