/*
 * serve.h - the internals of `lpvd serve` (the daemon), shared by its files:
 *
 *   serve.c          the command: flags, start-up, signals, shutdown; it
 *                    registers the session hooks (sv_session_hooks)
 *   serve_clock.c    sv_now_ms
 *   serve_net_*.c    libuv listeners, connections, frame reading, bounded writes
 *                    (one file per job: serve_net_internal.h lists them)
 *   serve_session.c  per-connection state and revisions; the replies are
 *                    serve_reply.c's, the dispatch serve_dispatch.c's, the
 *                    handlers in serve_hello.c, serve_scene.c,
 *                    serve_controls.c, serve_results.c and serve_streams.c
 *                    (serve_session_internal.h); serve_sub.c a delta
 *                    subscriber's bases
 *   serve_inputs.c   live scenes and the inputs snapshots that key worlds
 *   serve_world.c    worlds (shared computations) and the completions of
 *                    their jobs; they report to sessions through
 *                    sv_world_listener
 *   serve_gl.c       the GL thread and its job queue
 *   serve_encode_work.c  runs export.h's payload encoders (VOLUME / FRAME:
 *                    fp16, XOR delta, zstd, PNG, EXR) on libuv's work
 *                    threads, sends on the loop
 *   serve_limits.c   the daemon's limits, one row each
 * No circle of files (a file calls only files below it; docs/server.md,
 * "Files", has the order): where a lower layer must reach a higher one it
 * calls a function pointer the higher one registered (sv_session_hooks,
 * sv_server.net_resume_reading, sv_gl_start's jobs_done, sv_world_listener).
 * What a tick's result is and how it becomes a payload is export.h's
 * (export_result.c, export_encode.c), shared with lpvd batch.
 *
 * Threads: the libuv loop runs on the main thread and owns every structure
 * here except the fields marked "GL thread". One GL thread owns the GL context
 * and every lpv_engine; it takes sv_job's from a mutex-protected queue (worlds
 * take turns, serve_gl.c) and hands them back through a FIFO and a
 * uv_async_t. Reference counts are
 * only ever touched on the main thread. docs/server.md has the full picture.
 */
#ifndef LPVD_SERVE_H
#define LPVD_SERVE_H

#include <pthread.h>
#include <stddef.h>
#include <stdint.h>

#include <jansson.h>
#include <uv.h>

#include "context.h"
#include "proto.h"
#include "engine.h"
#include "export.h"
#include "gltf_load.h"
#include "hash.h"
#include "serve_memory.h"
#include "memory_budget.h"
#include "scene.h"
#include "settings.h"
#include "tonemap.h"
#include "view.h"
#include "volume_codec.h"

/* Message types, error codes (LPVP_*), their names and the frame constants
 * are the protocol library's (proto.h); the names of formats, compressions,
 * terms and streams too (volume_codec.h). The content hash is core's
 * (hash.h). */

typedef struct sv_server sv_server;
typedef struct sv_conn sv_conn;
typedef struct sv_world sv_world;
typedef struct sv_job sv_job;

/* ---- configuration ------------------------------------------------------ */
/* --max-tick-cost's default, in cell-steps (core/tick_cost.h): about 4 s of
 * propagation on llvmpipe with 2 cores (25,165,824 cell-steps took 2 s). */
#define SV_DEFAULT_MAX_TICK_COST 40000000

/* The limits' defaults, ranges and help are rows of serve_limits.c. */
typedef struct sv_config {
    char socket_path[256];   /* "" = no Unix socket */
    int want_unix;
    char listen_host[128];   /* "" = no TCP */
    int listen_port;
    char token[512];         /* "" = none */
    int has_token;
    char scene_root[4096];   /* realpath, "" = none */
    const char *scene_file;  /* --scene */
    uint64_t max_body;       /* bytes of JSON, default 1 MiB */
    uint64_t max_message;    /* json + attachment, default 256 MiB */
    uint64_t max_queue;      /* bytes queued for writing per connection */
    uint64_t max_request_memory; /* request bytes held, all connections (R7.5); >= max_message */
    uint64_t max_scenes_memory;  /* bytes of all live scenes together (R4.5c); >= max_scene_bytes */
    uint64_t max_world_memory;   /* GPU storage of one world's engine (R7.6) */
    uint64_t max_memory;         /* worlds, scenes, requests and replies together; 0 = half the
                                    machine's memory (serve_memory.h) */
    double max_tick_ms;          /* a world whose ticks after a change took longer is refused them (0 = off) */
    int max_clients;
    uint64_t max_triangles;
    int max_texture;
    uint64_t max_scene_texels; /* decoded texels of one scene's images, from their headers */
    uint64_t max_scene_bytes;  /* RAM one parsed scene may take (file, buffers, RGBA8 texels, model) */
    int max_grid;
    double max_tick_rate;
    uint64_t max_tick_cost;  /* cell-steps one tick may cost (core/tick_cost.h) */
    double idle_timeout;     /* seconds since the last complete frame (R4.9) */
    /* Before HELLO (R2.5a, R4.1a): a connection that has not yet said HELLO
     * (with the token where one is required) may send frames of at most
     * max_preauth_body bytes of JSON and no attachment, must say HELLO within
     * handshake_timeout seconds, and is one of at most max_preauth such
     * connections; only HELLO makes it count against max_clients. */
    uint64_t max_preauth_body;
    double handshake_timeout; /* 0 = no deadline */
    int max_preauth;
    lpv_backend backend;
    lpv_settings settings;   /* default CONFIG */
    double tick_rate;        /* default tick_rate_hz */
} sv_config;

/* QUERY_IRRADIANCE's largest count (HELLO limits.max_query_points): the
 * request's count x 24 bytes plus its JSON within --max-message, and the
 * reply's count x 12 bytes plus its header and JSON within --max-queue.
 * SV_QUERY_*_ROOM: bytes kept for the JSON (and the reply's header). */
#define SV_QUERY_BODY_ROOM 64u
#define SV_QUERY_REPLY_ROOM 256u
uint64_t sv_query_points_by_message(const sv_config *cfg);
uint64_t sv_query_points_by_queue(const sv_config *cfg);
uint64_t sv_max_query_points(const sv_config *cfg); /* serve_limits.c */
/* 0 when the least any scene needs under settings s (resolved) with
 * light_faces light faces fits one world (core/memory_budget.h,
 * lpv_memory_need_floor); else -1 with err (CONFIG's ERROR LIMIT). */
struct sv_server;
int sv_memory_floor_check(const struct sv_server *s, const lpv_settings *st, int light_faces, char *err, size_t n);
/* The largest cubic grid up to n cells a side that one world can hold: one
 * LPV cascade without far field, one point light (six faces) at the sessions'
 * default RSM and shadow sizes (n when it fits). */
int sv_grid_that_fits(const struct sv_server *s, int n);
/* A frame whose sender sends nothing for this long keeps, of its
 * reservation against --max-request-memory, only what has arrived; the rest
 * goes to the frames waiting, and the sender waits its turn for it when it
 * sends again (R7.5; four headers declaring 256 MiB and nothing after had held
 * the whole budget until the idle timeout). */
#define SV_RESERVE_STALL_MS 2000u
/* Connections that have not said HELLO (R4.1a): past --max-preauth the
 * oldest of the peer holding the most of them goes, but only once it has
 * had SV_PREAUTH_GRACE_MS to say HELLO and has nothing waiting to be read
 * (a burst of clients connecting at once is let in); at
 * SV_PREAUTH_HARD_FACTOR x --max-preauth it goes whatever its age. */
#define SV_PREAUTH_GRACE_MS 1000u
/* Connections the kernel queues before the loop accepts them (capped by
 * net.core.somaxconn): a connect flood filling a short queue made other
 * clients' connect fail with EAGAIN before lpvd saw them. */
#define SV_LISTEN_BACKLOG 4096
/* Scene loads (parsing) running at once on libuv's 4 workers; the others
 * are kept for encodings (GET_VOLUME, GET_FRAME, queries), which four
 * clients re-parsing a 68 MB scene had delayed by 5-7 s (issue 31, item 6). */
#define SV_MAX_LOADS 2
/* --max-tick-ms's default: a world whose tick after a change of its inputs
 * (its second such tick or later: the first after a load or a settings
 * change also does one-time work) took longer on the GL thread is refused
 * such ticks (LIMIT) until its settings, scene or camera size change: a
 * bound on the GL time one world takes from the others (another client's
 * wait is bounded by the yield points, SV_GL_SLICE_MS). 5 s: a bound on the
 * pathological (an iv tick of 45 s), loose enough for the default settings
 * under a sanitizer on 2 cores. */
#define SV_DEFAULT_MAX_TICK_MS 5000
/* The GL thread's yield points (serve_gl.c): a world's tick or render stops
 * at the first yield point after SV_GL_SLICE_MS of GL time and the queued
 * jobs of other worlds run there, for up to SV_GL_YIELD_MS, before it goes
 * on; so a cheap job waits about one slice per heavy job ahead of it, not
 * the heavy job's whole length (issue 31, item 2). Jobs run at a yield point
 * may yield in turn, SV_GL_MAX_DEPTH deep at most. */
#define SV_GL_SLICE_MS 100.0
#define SV_GL_YIELD_MS 400.0
#define SV_GL_MAX_DEPTH 4

/* Drops the scene loads still waiting for a worker (their requests were
 * answered SHUTTING_DOWN): at shutdown. */
void sv_scene_loads_drop(struct sv_server *s);
#define SV_PREAUTH_HARD_FACTOR 4
void sv_net_shrink_stalled(sv_conn *c, uint64_t now_ms); /* serve_net_reserve.c */
/* Takes c out of the server's pre-HELLO list (HELLO succeeded, or c is
 * closing); no-op when it is not in it (serve_net_conn.c). */
void sv_net_preauth_leave(sv_conn *c);
/* Blocks over this come from their own mapping, given back when freed (serve.c). */
#define SV_MMAP_THRESHOLD (256 * 1024)
/* Reply bytes a connection may have queued before HELLO: its replies are a
 * few ERRORs of ~100 bytes each, so a peer that sends small frames and never
 * reads is dropped here instead of at --max-queue (R2.5a). */
#define SV_PREAUTH_MAX_QUEUE (64u << 10)

/* ---- scenes: parsed glTF, shared by every session that loaded the same bytes */
/* A scene's pose: its animations at a time (SCENE_UPDATE "animation",
 * SPEC R4.4c); unset: the file's static pose. */
typedef struct sv_pose {
    int set;
    double time;                                 /* s */
    char animation[LPV_GLTF_ANIMATION_NAME_LEN]; /* name or index; "" every animation */
} sv_pose;

typedef struct sv_scene {
    int refs;
    uint64_t hash;          /* content hash (bytes + node overrides + pose), 0 = built-in */
    lpv_scene scene;        /* parsed, default light ensured */
    uint8_t *glb;           /* the bytes (NULL for the built-in scene) */
    size_t glb_size;
    char *base_dir;         /* folder for external URIs, relative to the scene root (path loads), or NULL */
    lpv_gltf_node_override *nodes; /* SCENE_UPDATE node transforms applied at load */
    size_t node_count;
    sv_pose pose;           /* SCENE_UPDATE animation time applied at load (before the nodes) */
    uint64_t bytes;         /* the file + lpv_scene_bytes: what it counts against --max-scenes-memory */
    struct sv_scene *next;  /* server's list of live scenes */
} sv_scene;

/* An immutable snapshot of everything a world computes from. */
typedef struct sv_inputs {
    int refs;
    sv_scene *scene;        /* ref */
    lpv_material *materials;
    uint32_t material_count;
    lpv_light *lights;      /* name = the light's id */
    uint32_t light_count;
    lpv_settings settings;  /* as given (zero = default) */
    double tick_rate;
    lpv_view view;
    uint8_t *key;           /* what identifies a world */
    size_t key_len;
    uint64_t key_hash;
} sv_inputs;


struct sv_world {
    int refs;               /* sessions attached */
    uint64_t id;
    uint64_t gen;           /* bumped when the inputs change in place */
    sv_inputs *inputs;      /* ref */
    sv_result *latest;      /* ref, NULL before the first tick */
    uv_timer_t timer;
    int timer_init;
    double timer_rate;
    int periodic_pending;   /* a periodic tick job is queued or running */
    sv_job *queued_tick;    /* the newest tick job submitted, until it completes;
                               TICK requests join it while the GL thread has not
                               started it (sv_world_join_tick) */
    uint64_t ticks_computed, ticks_coalesced; /* STATS world_ticks_* */
    int jobs;               /* jobs queued or running for this world */
    int dying;              /* refs == 0, destroy job queued */
    sv_server *srv;
    sv_world *next;
    /* GL thread only */
    lpv_gl_context *gl_ctx; /* the world's own context: its GL state survives
                               another world's jobs run while its own waits
                               at a yield point (serve_gl.c) */
    lpv_engine *engine;
    int gl_busy;            /* a job of this world is running or waiting at a yield point */
    uint64_t gl_applied_gen;
    int gl_has_applied;
    uint64_t gl_mem_bytes;  /* the engine's storage after its last job (GL thread; its part of SV_MEM_WORLDS) */
    /* what its ticks really took on the GL thread (GL thread only; serve_gl.c) */
    double gl_change_ms;    /* the last tick after a change of its inputs (what a light move costs) */
    uint64_t gl_change_sig; /* the settings, scene and view size that tick ran with */
    uint64_t gl_seen_sig;   /* those of its last tick */
    sv_inputs *gl_applied;  /* borrowed: only compared by content */
    lpv_settings gl_settings;
    lpv_view gl_view;
    uint64_t gl_scene_sig;
    uint64_t gl_ticks;      /* its latest tick's number (serve_gl.c: server-wide, increasing) */
    uint64_t gl_ticked_gen;
    int gl_ticked;
};

/* ---- jobs for the GL thread -------------------------------------------- */
typedef enum sv_job_kind {
    SV_JOB_TICK = 1,
    SV_JOB_RENDER,
    SV_JOB_CONTENT,         /* GET_VOLUME content "levels" or "visibility": read back on request, not every tick */
    SV_JOB_QUERY,
    SV_JOB_DESTROY,
    SV_JOB_QUIT,
} sv_job_kind;

/* A TICK request that joined a tick job queued by another request (coalescing). */
typedef struct sv_waiter {
    sv_conn *conn;          /* ref */
    uint32_t request_id;
    struct sv_waiter *next;
} sv_waiter;

struct sv_job {
    sv_job_kind kind;
    sv_world *world;
    sv_inputs *inputs;      /* ref (world->inputs at submission) */
    uint64_t gen;
    sv_conn *conn;          /* ref, NULL for periodic ticks */
    uint32_t request_id;
    int periodic;
    int started;            /* taken by the GL thread; under srv->mu */
    int cancelled;          /* no request, subscriber or timer wants it: the GL thread skips it (under
                               srv->mu; sv_gl_cancel) */
    sv_waiter *joined;      /* tick: more requests answered by this job, in order */
    double yielded_ms;      /* GL thread: time other worlds' jobs ran at its yield points,
                               not billed to it (gl_yield) */
    unsigned terms_mask;    /* tick: which frames to render (1 << terms); under srv->mu until started */
    int terms;              /* render */
    lpv_display display;    /* render: how an rgba8/png frame is shown */
    float *points;          /* query: 6n floats */
    size_t count;
    /* results */
    int status;             /* 0 ok, else an LPVP_E_ code */
    char err[512];
    sv_result *result;      /* tick, levels */
    float *rgba;            /* render */
    int width, height;
    float *out;             /* query: 3n floats */
    uint64_t tick;          /* render/query: the tick answered from */
    sv_job *next;
};

/* ---- connections = sessions ------------------------------------------- */
typedef struct sv_request {
    uint16_t type;
    uint32_t request_id;
    char *json;             /* NUL-terminated */
    size_t json_len;
    uint8_t *att;
    size_t att_len;
    struct sv_request *next;
} sv_request;


#define SV_SENT_KEEP 4

typedef struct sv_sub {
    int on;
    sv_volume_coding vol;   /* volume: format, compression, bound (default fp16 + zstd) */
    int zstd;               /* frame: compression */
    int delta;              /* volume only */
    int fmt;                /* frame: 0 rgba8, 1 png, 2 exr */
    int terms;              /* frame terms */
    lpv_display display;    /* frame: exposure and background of rgba8/png */
    sv_sent sent[SV_SENT_KEEP];
    sv_sent acked;          /* raw == NULL: none (or lent to the encoding in flight) */
    uint32_t epoch;         /* bumped by sv_sub_clear: a lent base is no longer this subscription's */
} sv_sub;

struct sv_wreq; /* one frame being written (serve_net_write.c) */

/* How a world reports back to the sessions that use it, so the world layer
 * (serve_world.c) never calls up into the session layer: the session layer
 * points each connection's listener at its callbacks when the session starts
 * (sv_session_open). Both run on the loop thread: from done_async, or from
 * sv_gl_stop for the jobs it drops at shutdown. */
typedef struct sv_world_listener {
    /* c's request request_id, answered by job j (the job's own request, then
     * each one that joined it, in arrival order), is done: reply, then go on
     * with c's next request. */
    void (*job_done)(sv_job *j, sv_conn *c, uint32_t request_id);
    /* A tick of c's world produced r: called for each session attached to the
     * world after every reply of that tick. */
    void (*tick_result)(sv_conn *c, sv_result *r);
} sv_world_listener;

enum { SV_STREAM_NONE = -1, SV_STREAM_VOLUME = 0, SV_STREAM_FRAME = 1 };

/* What the network layer (serve_net_*.c) and the request handlers call of
 * the session layer above them: the daemon registers them at start
 * (serve.c) before it listens, so that no file below the dispatcher calls
 * up into it by name (docs/architecture.md: no circle of files). */
typedef struct sv_session_hooks {
    void (*open)(sv_conn *c); /* accepted: its session starts (sv_session_open) */
    void (*free)(sv_conn *c); /* closed: its session's state goes (sv_session_free) */
    /* requests pending, or a busy request answered: handle the next ones,
     * in order (sv_session_pump) */
    void (*pump)(sv_conn *c);
} sv_session_hooks;

struct sv_conn {
    int refs;
    uint64_t id;
    sv_server *srv;
    union {
        uv_stream_t stream;
        uv_pipe_t pipe;
        uv_tcp_t tcp;
    } h;
    int closing, closed;
    int close_after_write;  /* close when the write queue drains */
    char peer[96];
    char peer_key[96];      /* who is at the other end, for the pre-HELLO quota: "pid N" (Unix) or the address */
    /* reading */
    lpvp_parser parser;
    uint8_t rbuf[65536];
    int reading;
    uint64_t close_deadline_ms;
    sv_request *pending_head, *pending_tail;
    size_t pending_count, pending_bytes;
    uint64_t reserved;      /* payload of the frame being read, held against --max-request-memory */
    uint64_t wait_memory;   /* reading stopped until that reservation fits (R7.5): its turn, 0 = not waiting */
    uint64_t payload_ms;    /* when the frame being read last got payload bytes (or its header) */
    int reserve_shrunk;     /* the reservation was cut to what had arrived (a stalled sender, R7.5) */
    int busy;               /* a request is being processed asynchronously */
    int work_inflight;      /* that request runs on a libuv worker (a scene load): it cannot be cancelled */
    uint32_t work_request_id;
    uint64_t idle_since_ms; /* when the last complete frame arrived or the last busy request was answered:
                               R4.9's idle time counts from the later (sv_session_answered) */
    uint64_t accepted_ms;   /* when the connection was accepted (--handshake-timeout) */
    /* writing */
    size_t wq_bytes;        /* bytes handed to uv_write, not yet completed */
    size_t wq_count;
    int stream_inflight[2];
    struct sv_wreq *stream_pending[2]; /* newest unsent stream message */
    uint64_t bytes_sent;
    uint64_t stream_dropped;
    uint64_t stream_unchanged; /* VOLUMEs not sent: an shq delta with nothing beyond the bound (R5.16) */
    /* encoding on the work threads (serve_encode_work.c), per stream: one in
     * flight, and the newest result waiting for it (a newer replaces it) */
    int enc_busy[2];
    sv_result *enc_next[2]; /* ref */
    /* session */
    const sv_world_listener *listener; /* how its world reports to it */
    int hello;
    uint64_t revision;
    sv_scene *scene;        /* ref */
    lpv_material *materials;
    uint32_t material_count;
    lpv_light *lights;
    uint32_t light_count;
    lpv_settings settings;
    double tick_rate;
    lpv_view view;
    int view_explicit;      /* CAMERA_SET with eye/target was given */
    int view_camera;        /* CAMERA_SET with a scene camera: index, else -1 */
    int view_w, view_h;
    sv_world *world;        /* ref */
    uint64_t world_gen;
    sv_sub subs[2];
    sv_conn *next, *prev;   /* in the server's conns */
    sv_conn *pre_prev, *pre_next; /* in the server's preauth list while in_preauth */
    int in_preauth;
};

struct sv_server {
    sv_config cfg;
    uv_loop_t *loop;
    uv_pipe_t unix_listener;
    uv_tcp_t tcp_listener;
    int unix_on, tcp_on;
    uv_signal_t sigterm, sigint, sighup;
    uv_timer_t idle_timer;
    uv_timer_t stop_timer;
    uv_async_t done_async;
    uv_async_cb gl_jobs_done; /* done_async's callback (sv_gl_start) */
    int stopping;
    uv_timer_t exit_timer;  /* SIGTERM: the most it waits for worker threads (SV_SHUTDOWN_WAIT_MS) */
    int works_inflight;     /* requests running on libuv workers, all sessions */
    sv_conn *conns;
    int conn_count;
    /* the open connections that have not said HELLO, also in conns: the
     * pre-HELLO quota looks at these only, so a connect flood that makes
     * conns long costs each accept no more than the quota (R4.1a) */
    sv_conn *preauth;
    int preauth_count;
    /* scene loads on libuv's workers: at most SV_MAX_LOADS at once, the rest
     * wait here in order (serve_scene.c), so encodings always find a worker */
    int loads_running;
    struct load_work *loads_wait_head, *loads_wait_tail;
    uint64_t memory_waits;  /* turns handed out to connections waiting for request memory */
    sv_session_hooks session; /* set at start (serve.c) */
    /* serve_net_read.c's sv_net_resume_reading, set by sv_net_listen: the
     * requests' memory (serve_net_reserve.c, below reading) resumes a
     * connection whose frame now fits through it */
    void (*net_resume_reading)(sv_conn *c);
    uint64_t next_conn_id;
    sv_world *worlds;
    int world_count;
    uint64_t next_world_id;
    sv_scene *scenes;
    sv_scene *builtin;      /* the default scene */
    int root_fd;            /* --scene-root, opened once at start: paths open beneath it (-1: none) */
    /* GL thread */
    pthread_t gl_thread;
    int gl_started;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    sv_job *jobs_head, *jobs_tail;
    size_t jobs_queued;
    uint64_t gl_last_world; /* id of the world whose job the GL thread took last (fair turns) */
    /* the jobs the GL thread has started and not finished: [0] runs, each
     * later one ran at a yield point of the one before (serve_gl.c); under mu */
    sv_job *gl_stack[SV_GL_MAX_DEPTH];
    int gl_depth;
    uint64_t gl_jobs_between; /* jobs run at another world's yield point (STATS) */
    sv_job *done_head, *done_tail;
    int gl_ready;           /* 1 ok, -1 failed */
    char gl_err[1100];      /* "no OpenGL 4.5 context: " + the backends' reasons (1024) */
    char gl_backend[32];
    char gl_renderer[256];
    lpv_gl_context *gl_ctx;
    lpv_memory_limits gl_limits; /* the GL's, with --max-world-memory as the budget (sv_gl_start) */
    /* what the worlds, scenes, requests and replies hold, against
     * --max-memory (R7.6a, serve_memory.h) */
    sv_memory mem;
    /* counters */
    uint64_t bytes_sent;
    uint64_t ticks;         /* ticks computed, all worlds */
    uint64_t volumes_encoded; /* volume encodings on the work threads (STATS "encode") */
    uint64_t bases_refused;   /* delta bases not kept: over the memory budget (STATS "encode", R7.6a) */
    uint64_t volume_encode_ns; /* their CPU time on the work threads */
    uint64_t ticks_coalesced; /* TICK requests answered by another request's tick */
    uint64_t ticks_cancelled; /* ticks skipped or abandoned because every requester had gone */
    uint64_t requests;
    int exit_code;
};

/* serve_clock.c */
uint64_t sv_now_ms(void);

/* the network layer (serve_net_*.c) */
/* serve_net_listen.c */
int sv_net_listen(sv_server *s, char *err, size_t n);
void sv_net_stop_listening(sv_server *s);
/* serve_net_write.c */
/* Sends one frame. stream: SV_STREAM_* (a stream message replaces an unsent
 * older one of its stream). Returns 0, or -1 when the connection was closed
 * (over its write cap, or already closing). body is consumed (decref'd),
 * att_owned is freed. */
int sv_send(sv_conn *c, uint16_t type, uint32_t request_id, json_t *body, uint8_t *att_owned, size_t att_len,
            int stream); /* att_owned: malloc'd, freed by sv_send */
int sv_send_error(sv_conn *c, uint32_t request_id, int code, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
void sv_conn_unref(sv_conn *c);
/* serve_net_conn.c */
void sv_conn_close(sv_conn *c);
void sv_conn_close_after_write(sv_conn *c);
/* serve_net_read.c */
void sv_net_resume_reading(sv_conn *c);
/* serve_net_reserve.c */
/* A pending request of c (bytes = json + attachment) is taken to be handled:
 * its bytes leave --max-request-memory and waiting connections may go on. */
void sv_net_request_handled(sv_conn *c, uint64_t bytes);
/* serve_net_accept.c */
/* A HELLO that passed the version and token checks: admits c as one of
 * --max-clients sessions (0), or sends ERROR LIMIT for request_id, closes c
 * and returns -1 (R4.1a). */
int sv_net_admit_session(sv_conn *c, uint32_t request_id);

/* serve_session.c */
void sv_session_init(sv_conn *c);        /* the session's state, its world */
void sv_session_free(sv_conn *c);        /* on close: detach, free state */
/* serve_dispatch.c: what the daemon registers as its sv_session_hooks */
void sv_session_open(sv_conn *c);        /* its world's listener, then sv_session_init */
void sv_session_pump(sv_conn *c);        /* processes pending requests in order */
/* A request of c (request_id) starts / ends running on a libuv worker. */
void sv_session_work_begin(sv_conn *c, uint32_t request_id);
void sv_session_work_end(sv_conn *c);
/* The busy request of c has its reply queued: the next may run, and the
 * idle timeout (R4.9) counts from now. A tick longer than the timeout
 * otherwise left its session idle the moment it was answered, and the
 * idle timer could close it before the client's next request arrived. */
void sv_session_answered(sv_conn *c);
/* SIGTERM, after the GL thread has answered its jobs: every request of c not
 * yet answered gets ERROR SHUTTING_DOWN in order, then BYE; c closes once
 * that is written (R3.1, R7.4). */
void sv_session_shutdown(sv_conn *c);

/* serve_gl.c */
/* jobs_done: what done_async runs on the loop for the finished jobs (the
 * world layer's sv_world_jobs_done, above this one), and sv_gl_stop at the
 * end. */
int sv_gl_start(sv_server *s, uv_async_cb jobs_done, char *err, size_t n);
void sv_gl_stop(sv_server *s);
void sv_job_submit(sv_server *s, sv_job *j);
sv_job *sv_job_new(sv_job_kind kind, sv_world *w);
void sv_job_free(sv_job *j);
size_t sv_jobs_queued(sv_server *s);
void sv_job_reply_all(sv_job *j);        /* the job's request and every one that joined it */
/* Marks w's jobs that wanted(j, arg) says nobody wants any more: the GL
 * thread skips those not started (no GL time), abandons a running tick at
 * its next yield point, and they complete with no result. Destroy jobs are
 * never cancelled. Loop thread. */
void sv_gl_cancel(sv_server *s, sv_world *w, int (*wanted)(const sv_job *j, void *arg), void *arg);

/* serve_world.c */
sv_inputs *sv_inputs_build(sv_conn *c);
void sv_inputs_unref(sv_inputs *in);
void sv_inputs_release(sv_server *s, sv_inputs *in); /* unref; the scene too with the last ref */
void sv_world_jobs_done(uv_async_t *a);  /* done_async: finished jobs, on the loop */
void sv_world_attach(sv_conn *c, sv_inputs *in); /* consumes in */
void sv_world_detach(sv_conn *c);
void sv_world_unref(sv_world *w);
void sv_scene_unref(sv_server *s, sv_scene *sc);
sv_scene *sv_scene_intern(sv_server *s, sv_scene *sc); /* dedupe by hash */
/* 1 when sc is already live or fits in --max-scenes-memory next to the live
 * scenes; else 0 with the LIMIT message in err. */
int sv_scene_fits(sv_server *s, const sv_scene *sc, char *err, size_t n);
unsigned sv_world_terms_mask(sv_world *w);
void sv_world_update_timer(sv_world *w);
int sv_world_join_tick(sv_world *w, sv_conn *c, uint32_t request_id); /* 1: joined a queued tick */

/* serve_controls.c: 0 when resolved settings s cost at most --max-tick-cost
 * a tick, else -1 with a message naming the cost, the budget and what to
 * lower (CONFIG's LIMIT, and the default CONFIG at start). */
int sv_tick_cost_check(const sv_config *cfg, const lpv_settings *s, char *err, size_t n);

/* the loop's side of a subscription (serve_sub.c) */
void sv_sub_clear(sv_sub *sub);
void sv_sub_ack(sv_sub *sub, uint64_t tick);
void sv_sub_remember(sv_sub *sub, const sv_sent *sent);

#endif
