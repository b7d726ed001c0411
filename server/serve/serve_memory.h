/*
 * serve_memory.h - the daemon's one memory budget (issue 31, "daemon-wide
 * memory"; SPEC R7.6a): the worlds' storage, the live scenes, the requests
 * being read and the replies queued, the subscribers' bases and
 * the results' encoding caches, each term counted where it is taken
 * and given back, all of them together within --max-memory (default: half
 * of the machine's memory, or of the cgroup's limit when that is lower).
 *
 * Requests are the one term that waits instead of being refused (R7.5: a
 * frame is left unread until memory frees), so the other terms leave room
 * for one largest message (--max-message): a frame can always be read once
 * the requests before it are handled, whatever the worlds, scenes and
 * replies hold. The worlds' term is written on the GL thread, the bases
 * (sv_blob's count, export.h) wherever a volume is made or let go, the
 * others on the loop; each is an atomic counter.
 */
#ifndef SV_MEMORY_H
#define SV_MEMORY_H

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

typedef enum sv_mem_term {
    SV_MEM_WORLDS,   /* each world's engine storage after its last job (lpv_engine_memory_bytes) */
    SV_MEM_SCENES,   /* sv_scene.bytes of every live scene, once each */
    SV_MEM_REQUESTS, /* request bytes reserved or pending, every connection (R7.5) */
    SV_MEM_REPLIES,  /* reply and stream bytes queued for writing, every connection */
    SV_MEM_BASES,    /* the volumes delta subscribers hold (sent, ACKed), once each however many share one */
    SV_MEM_ENCODINGS, /* the encodings a tick's result keeps for the next subscriber or reply (export.h) */
    SV_MEM_TERMS
} sv_mem_term;

typedef struct sv_memory {
    uint64_t budget;     /* --max-memory, else half the machine's */
    uint64_t headroom;   /* what the terms but requests leave free: --max-message */
    char source[96];     /* "--max-memory N" or "half of the machine's 23.4 GB" */
    _Atomic uint64_t held[SV_MEM_TERMS];
} sv_memory;

/* Sets the budget: flag_bytes when nonzero, else half of the machine's
 * memory (sv_memory_machine). Returns -1, with err, when the budget does not
 * leave room for one message of headroom bytes. */
int sv_memory_init(sv_memory *m, uint64_t flag_bytes, uint64_t headroom, char *err, size_t err_size);

/* The machine's memory: physical RAM, or the cgroup's memory limit when that
 * is lower (a container's). */
uint64_t sv_memory_machine(void);

void sv_memory_add(sv_memory *m, sv_mem_term t, uint64_t bytes);
void sv_memory_sub(sv_memory *m, sv_mem_term t, uint64_t bytes);
uint64_t sv_memory_held(const sv_memory *m, sv_mem_term t);
uint64_t sv_memory_total(const sv_memory *m);

/* Whether `more` bytes of term t fit: every term's bytes plus more within
 * the budget, and, for every term but requests, the headroom left. */
int sv_memory_fits(const sv_memory *m, sv_mem_term t, uint64_t more);

/* What term t may hold at most now (its own bytes included): the budget
 * less the others' and, but for requests, the headroom. */
uint64_t sv_memory_room(const sv_memory *m, sv_mem_term t);

/* "the daemon's memory budget (--max-memory N): worlds 1.2 GB, scenes ...,
 * requests ..., replies ..." for refusals; a buffer of
 * SV_MEMORY_DESCRIBE_SIZE holds it whole (the source is at most 95 bytes). */
#define SV_MEMORY_DESCRIBE_SIZE 384
void sv_memory_describe(const sv_memory *m, char *buf, size_t size);

const char *sv_mem_term_name(sv_mem_term t);

#endif /* SV_MEMORY_H */
