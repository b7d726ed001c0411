/*
 * serve_net_internal.h - what the files of the daemon's network layer share,
 * and nothing outside it includes (serve.h is the daemon's common header and
 * declares what the rest of the daemon calls):
 *
 *   serve_net_listen.c   the listeners (Unix socket, TCP)
 *   serve_net_accept.c   accepting connections; the pre-HELLO list and the
 *                        --max-preauth and --max-clients quotas
 *   serve_net_read.c     frame reading into pending requests
 *   serve_net_reserve.c  the requests' memory (--max-request-memory)
 *   serve_net_write.c    bounded writes (sv_send)
 *   serve_net_conn.c     closing connections, the last reference
 *                        (sv_conn_unref) and the pre-HELLO list
 *
 * Each file uses only those listed below it (no circle of files); what the
 * layer calls up into, the sessions above it and the reading of a
 * connection whose frame now fits, it calls through function pointers set
 * at start (sv_session_hooks in serve.h, sv_server.net_resume_reading).
 *
 * The network side of `lpvd serve`, all on the libuv loop: listeners (Unix
 * socket, TCP), connections, frame reading through the protocol's
 * incremental parser (protocol/proto.h), and bounded writes.
 *
 * Back-pressure: reading stops while a connection has too many requests
 * waiting (SV_MAX_PENDING) and resumes when they drain; replies count
 * against the connection's write cap (--max-queue, default 64 MiB plus one
 * message) and a client over it is disconnected; stream messages (VOLUME,
 * FRAME) keep at most one frame in flight and one unsent per stream, a newer
 * one replacing the unsent older one (SPEC R5.5).
 *
 * Memory (SPEC R7.5): every connection's requests together hold at most
 * --max-request-memory bytes. A frame's payload is reserved once its header
 * is in; a connection whose frame does not fit stops being read (it holds
 * the header and at most one read buffer) until handled requests free
 * enough. A reserved frame is always read to its end, so reservations never
 * wait on each other: memory is freed by requests being handled, or by
 * connections closing (a trickling one at --idle-timeout).
 *
 * Before HELLO (SPEC R2.5a, R4.1a) a connection is held to the pre-auth
 * limits: frames of at most --max-preauth-body bytes of JSON and no
 * attachment (refused from the header, before the body is read), each frame
 * dispatched before the next header is looked at (so the limits change the
 * moment HELLO succeeds, even for frames pipelined behind it), replies capped
 * at SV_PREAUTH_MAX_QUEUE, and at most --max-preauth such connections; only a
 * HELLO that passes the token check takes one of the --max-clients slots.
 */
#ifndef LPVD_SERVE_NET_INTERNAL_H
#define LPVD_SERVE_NET_INTERNAL_H

#include "serve.h"

/* ---- connections (serve_net_conn.c) ---- */
/* One frame being written (serve_net_write.c); its struct is here because
 * a connection's last reference frees its unsent stream frames
 * (sv_conn_unref). */
typedef struct sv_wreq {
    uv_write_t req;
    sv_conn *c;
    uint8_t *head;
    size_t head_len;
    uint8_t *att;
    size_t att_len;
    int stream;
    sv_memory *mem;   /* the daemon's budget, once the frame counts in its replies' term */
    uint64_t counted;
} sv_wreq;

/* Frees w and takes it out of the daemon's replies' memory. */
void sv_net_wreq_free(sv_wreq *w);
/* Puts c in the server's pre-HELLO list (sv_net_preauth_leave takes it out). */
void sv_net_preauth_join(sv_conn *c);

/* ---- reading (serve_net_read.c) ---- */
/* The frame limits of a connection, before and after HELLO (R2.5a). */
lpvp_limits sv_net_conn_limits(const sv_server *s, int authenticated);
/* libuv's read callbacks of a connection (uv_read_start). */
void sv_net_on_alloc(uv_handle_t *h, size_t suggested, uv_buf_t *buf);
void sv_net_on_read(uv_stream_t *st, ssize_t nread, const uv_buf_t *buf);

/* ---- the requests' memory (serve_net_reserve.c) ---- */
/* Reserves the payload of the frame whose header is in (R7.5): 0 when c
 * may read on, 1 when it must wait for memory. */
int sv_net_reserve_frame(sv_conn *c);
/* Requests of c handled or dropped: their bytes leave the budget, and
 * connections waiting for memory are reserved for and resumed in order. */
void sv_net_release_request_bytes(sv_conn *c, uint64_t bytes);

/* ---- accepting (serve_net_accept.c) ---- */
/* A listener's connection callback (uv_listen). */
void sv_net_on_connection(uv_stream_t *server, int status);

#endif
