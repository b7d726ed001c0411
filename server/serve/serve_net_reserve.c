/*
 * serve_net_reserve.c - the requests' memory (SPEC R7.5): a frame's payload
 * is reserved against --max-request-memory and the daemon's budget once its
 * header is in; a frame that does not fit waits, first come first served,
 * for handled requests or closed connections to free enough; a stalled
 * sender's reservation shrinks to what has arrived. The network layer's
 * design is in serve_net_internal.h.
 */
#include "serve.h"
#include "serve_net_internal.h"

/* Reserves the payload of the frame whose header has just been accepted
 * (R7.5). Returns 0 when c may read on, 1 when it must wait for memory. */
int sv_net_reserve_frame(sv_conn *c)
{
    sv_server *s = c->srv;
    uint64_t need = lpvp_parser_frame_payload(&c->parser);
    if (need == 0 || (c->reserved && !c->reserve_shrunk))
        return 0;
    const uint64_t more = need > c->reserved ? need - c->reserved : 0; /* a shrunk one holds what arrived */
    /* within --max-request-memory and the daemon's budget, whose other terms
     * always leave one --max-message free (serve_memory.h): so a frame waits
     * only for requests before it to be handled */
    if (sv_memory_held(&s->mem, SV_MEM_REQUESTS) + more > s->cfg.max_request_memory ||
        !sv_memory_fits(&s->mem, SV_MEM_REQUESTS, more))
        return 1;
    if (!c->reserved)
        c->payload_ms = sv_now_ms();
    c->reserved = need;
    c->reserve_shrunk = 0;
    sv_memory_add(&s->mem, SV_MEM_REQUESTS, more);
    return 0;
}

void sv_net_shrink_stalled(sv_conn *c, uint64_t now_ms)
{
    if (!c->reserved || c->reserve_shrunk || c->wait_memory || now_ms - c->payload_ms < SV_RESERVE_STALL_MS)
        return;
    const uint64_t have = lpvp_parser_payload_have(&c->parser);
    if (have >= c->reserved)
        return;
    const uint64_t freed = c->reserved - have;
    c->reserved = have;
    c->reserve_shrunk = 1;
    sv_net_release_request_bytes(c, freed); /* the frames waiting get it, first come first served */
}

void sv_net_release_request_bytes(sv_conn *c, uint64_t bytes)
{
    sv_server *s = c->srv;
    if (bytes == 0) /* nothing freed, nobody newly fits (every close comes here: keep it cheap under a flood) */
        return;
    const uint64_t held = sv_memory_held(&s->mem, SV_MEM_REQUESTS);
    sv_memory_sub(&s->mem, SV_MEM_REQUESTS, bytes < held ? bytes : held);
    /* first come, first served: a big frame waiting is not overtaken by smaller ones behind it */
    for (;;) {
        sv_conn *first = NULL;
        for (sv_conn *w = s->conns; w; w = w->next)
            if (w->wait_memory && !w->closing && !w->close_after_write &&
                (!first || w->wait_memory < first->wait_memory))
                first = w;
        if (!first || sv_net_reserve_frame(first) != 0)
            return;
        first->wait_memory = 0;
        s->net_resume_reading(first); /* sv_net_resume_reading, set by sv_net_listen */
    }
}

void sv_net_request_handled(sv_conn *c, uint64_t bytes)
{
    c->pending_bytes -= bytes;
    sv_net_release_request_bytes(c, bytes);
}
