/*
 * serve_results.c - the requests answered from the session's world: TICK,
 * GET_VOLUME, GET_FRAME, QUERY_IRRADIANCE and STATS, and the replies of the
 * GL jobs they submit (sv_session_job_done, which the world calls through
 * its listener when a job comes back to the loop). A request that needs the
 * GL thread keeps the session busy until its reply is queued (R3.2).
 */
#include "serve_session_internal.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "probes_record.h" /* R5.15: a probe's record, its size */
#include "stats_json.h"

/* The tick's stats in the one shape of lpvd_tick_stats_json (stats_json.h). */
static json_t *tick_stats(const sv_result *r)
{
    int one = r->cascade_count < 1;
    return lpvd_tick_stats_json(&r->stats, &r->plan, one ? &r->grid : r->cascades, one ? 1 : r->cascade_count,
                                r->tick_ms);
}

static int world_current(sv_conn *c)
{
    return c->world && c->world->latest && c->world->latest->gen == c->world_gen;
}

static void submit(sv_conn *c, sv_job *j)
{
    j->conn = c;
    c->refs++;
    c->busy = 1;
    sv_job_submit(c->srv, j);
}

void sv_do_tick(sv_conn *c, sv_request *r)
{
    if (c->world && sv_world_join_tick(c->world, c, r->request_id)) { /* shared with a queued tick (R7.2) */
        c->busy = 1;
        return;
    }
    sv_job *j = c->world ? sv_job_new(SV_JOB_TICK, c->world) : NULL;
    if (!j) {
        sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "out of memory");
        return;
    }
    j->request_id = r->request_id;
    j->terms_mask = sv_world_terms_mask(c->world);
    c->world->queued_tick = j;
    submit(c, j);
}

/* GET_FRAME's and SUBSCRIBE frame's "exposure" ("auto" or an EV number) and
 * "transparent" (SPEC R6.4). Returns LPVP_FIELD_BAD with err on a bad value. */
int sv_get_display(const json_t *j, lpv_display *d, char *err, size_t n)
{
    lpv_display_default(d);
    const json_t *e = json_object_get(j, "exposure");
    if (e) {
        char v[64];
        if (json_is_string(e))
            snprintf(v, sizeof v, "%s", json_string_value(e));
        else if (json_is_number(e))
            snprintf(v, sizeof v, "%.9g", json_number_value(e));
        else
            snprintf(v, sizeof v, "(not a string or number)");
        if (lpv_exposure_parse(v, d, err, n) != 0)
            return LPVP_FIELD_BAD;
    }
    return lpvp_get_bool(j, "transparent", 0, &d->transparent, err, n) == LPVP_FIELD_BAD ? LPVP_FIELD_BAD
                                                                                         : LPVP_FIELD_OK;
}

int sv_terms_check(const sv_conn *c, int terms, char *err, size_t n)
{
    if (terms != LPVP_TERMS_AO)
        return 0;
    lpv_settings s = c->settings;
    lpv_settings_resolve(&s);
    char why[256];
    if (lpv_ao_check(&s, s.technique, why, sizeof why) == 0)
        return 0;
    snprintf(err, n, "terms: \"%s\": %s (CONFIG them first)", lpvp_frame_terms_names[LPVP_TERMS_AO], why);
    return -1;
}

/* R5.15: the probes' records alone over max_queue, or over the memory
 * budget's room for replies, are answered LIMIT before the read-back, which
 * would hold them twice (the records, then the frame). 1 when answered. */
static int visibility_too_big(sv_conn *c, sv_request *r, const sv_result *latest)
{
    const lpv_volume_desc *d = &latest->stats.volume;
    const uint64_t bytes =
        (uint64_t)latest->cell_count * lpv_probes_record_values(d->irradiance_side, d->visibility_side) * 4u;
    if (bytes > c->srv->cfg.max_queue) {
        sv_reply_err(c, r->request_id, LPVP_E_LIMIT, 0,
                     "%s \"%s\": %zu probes' records are %llu bytes, over this server's per-client queue limit of "
                     "%llu bytes (--max-queue); not read back: ask for a smaller grid or fewer cascades",
                     LPVP_VOLUME_CONTENT_KEY, lpvp_volume_content_names[LPVP_CONTENT_VISIBILITY], latest->cell_count,
                     (unsigned long long)bytes, (unsigned long long)c->srv->cfg.max_queue);
        return 1;
    }
    if (!sv_memory_fits(&c->srv->mem, SV_MEM_REPLIES, bytes)) {
        char mem[SV_MEMORY_DESCRIBE_SIZE];
        sv_memory_describe(&c->srv->mem, mem, sizeof mem);
        sv_reply_err(c, r->request_id, LPVP_E_LIMIT, 0,
                     "%s \"%s\": %zu probes' records are %llu bytes, more than %s has room for; not read back",
                     LPVP_VOLUME_CONTENT_KEY, lpvp_volume_content_names[LPVP_CONTENT_VISIBILITY], latest->cell_count,
                     (unsigned long long)bytes, mem);
        return 1;
    }
    return 0;
}

void sv_do_get_volume(sv_conn *c, sv_request *r, json_t *j)
{
    char err[512];
    int content = LPVP_CONTENT_MERGED;
    sv_volume_coding how = {0};
    if (sv_volume_coding_parse(j, &how, err, sizeof err) != 0 ||
        lpvp_get_enum(j, LPVP_VOLUME_CONTENT_KEY, 0, lpvp_volume_content_names, LPVP_CONTENT_COUNT, &content, err,
                      sizeof err) == LPVP_FIELD_BAD) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
        return;
    }
    if (!world_current(c)) {
        sv_reply_err(c, r->request_id, LPVP_E_NOT_READY, 0,
                  "no volume yet for this session's current scene, lights, camera and config: send TICK first");
        return;
    }
    const sv_result *latest = c->world->latest;
    if (content == LPVP_CONTENT_MERGED) { /* packed and compressed on a work thread; the session is busy until
                                             the reply is queued */
        sv_reply_volume(c, r->request_id, c->world->latest, content, &how);
        return;
    }
    if (how.comp == LPVP_COMP_SHQ) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0,
                     "compression: \"shq\" codes the merged volume only (R5.16); ask \"zstd\" for content \"%s\"",
                     lpvp_volume_content_names[content]);
        return;
    }
    const char *t = latest->stats.volume.technique;
    if (content == LPVP_CONTENT_LEVELS && !latest->stats.volume.index_levels) { /* R5.13: only a technique with levels */
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0,
                     "%s: \"%s\" needs a technique with levels and an index volume; this session's "
                     "volume comes from technique \"%s\", whose volume is its merged content \"%s\" only",
                     LPVP_VOLUME_CONTENT_KEY, lpvp_volume_content_names[LPVP_CONTENT_LEVELS], t ? t : "?",
                     lpvp_volume_content_names[LPVP_CONTENT_MERGED]);
        return;
    }
    if (content == LPVP_CONTENT_VISIBILITY && latest->stats.volume.visibility_side <= 0) { /* R5.15: probes only */
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0,
                     "%s: \"%s\" needs a technique whose probes have visibility (\"probes\"); this session's "
                     "volume comes from technique \"%s\", which has none",
                     LPVP_VOLUME_CONTENT_KEY, lpvp_volume_content_names[LPVP_CONTENT_VISIBILITY], t ? t : "?");
        return;
    }
    if (content == LPVP_CONTENT_VISIBILITY && visibility_too_big(c, r, latest))
        return;
    /* read back on the GL thread for this request alone (a tick does not read them) */
    sv_job *jb = sv_job_new(SV_JOB_CONTENT, c->world);
    if (!jb) {
        sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "out of memory");
        return;
    }
    jb->request_id = r->request_id;
    jb->count = (size_t)how.fp16 | ((size_t)how.comp << 4) |
                ((size_t)content << 8); /* read in gl_content and job_done */
    submit(c, jb);
}

void sv_do_get_frame(sv_conn *c, sv_request *r, json_t *j)
{
    char err[512];
    int fmt = LPVP_FRAME_PNG, comp = LPVP_COMP_NONE, terms = LPVP_TERMS_FULL;
    lpv_display display;
    if (lpvp_get_enum(j, "format", 0, lpvp_frame_format_names, LPVP_FRAME_FORMAT_COUNT, &fmt, err, sizeof err) == LPVP_FIELD_BAD ||
        lpvp_get_enum(j, "compression", 0, lpvp_compression_names, 2, &comp, err, sizeof err) == LPVP_FIELD_BAD ||
        lpvp_get_enum(j, "terms", 0, lpvp_frame_terms_names, LPVP_TERMS_COUNT, &terms, err, sizeof err) == LPVP_FIELD_BAD ||
        sv_get_display(j, &display, err, sizeof err) == LPVP_FIELD_BAD || sv_terms_check(c, terms, err, sizeof err)) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
        return;
    }
    if (!world_current(c)) {
        sv_reply_err(c, r->request_id, LPVP_E_NOT_READY, 0,
                  "no tick yet for this session's current scene, lights, camera and config: send TICK first");
        return;
    }
    sv_result *res = c->world->latest;
    if (res->frames[terms]) { /* rendered with the tick already: encoded on a work thread */
        sv_reply_frame(c, r->request_id, res, NULL, res->width, res->height, fmt, comp == LPVP_COMP_ZSTD, terms,
                       &display, res->tick);
        return;
    }
    sv_job *jb = sv_job_new(SV_JOB_RENDER, c->world);
    if (!jb) {
        sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "out of memory");
        return;
    }
    jb->request_id = r->request_id;
    jb->terms = terms;
    jb->display = display;
    jb->count = (size_t)fmt | ((size_t)(comp == LPVP_COMP_ZSTD) << 4); /* encoding choice, read back in job_done */
    submit(c, jb);
}

void sv_do_query(sv_conn *c, sv_request *r, json_t *j)
{
    char err[512];
    int64_t count = 0;
    const sv_config *cfg = &c->srv->cfg;
    if (lpvp_get_int(j, "count", 1, 0, (int64_t)sv_query_points_by_message(cfg), &count, err, sizeof err) !=
        LPVP_FIELD_OK) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
        return;
    }
    if ((uint64_t)count > sv_query_points_by_queue(cfg)) { /* refused before it is computed (issue 31, item 10) */
        sv_reply_err(c, r->request_id, LPVP_E_LIMIT, 0,
                     "count %lld: the reply (%lld x 12 bytes) would be over this server's per-client queue limit of "
                     "%llu bytes (--max-queue); at most %llu points a query (HELLO limits.max_query_points)",
                     (long long)count, (long long)count, (unsigned long long)cfg->max_queue,
                     (unsigned long long)sv_max_query_points(cfg));
        return;
    }
    if (r->att_len != (size_t)count * 24) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0,
                  "attachment: expected count x 24 = %lld bytes (px py pz nx ny nz float32 per point), got %zu",
                  (long long)count * 24, r->att_len);
        return;
    }
    if (!world_current(c)) {
        sv_reply_err(c, r->request_id, LPVP_E_NOT_READY, 0,
                  "no tick yet for this session's current scene, lights, camera and config: send TICK first");
        return;
    }
    sv_job *jb = sv_job_new(SV_JOB_QUERY, c->world);
    float *pts = malloc(count ? (size_t)count * 24 : 1);
    if (!jb || !pts) {
        free(pts);
        sv_job_free(jb);
        sv_reply_err(c, r->request_id, LPVP_E_INTERNAL, 0, "out of memory");
        return;
    }
    for (int64_t i = 0; i < count * 6; ++i) { /* little-endian float32 */
        uint32_t u = lpvp_get_u32(r->att + i * 4);
        float f;
        memcpy(&f, &u, 4);
        pts[i] = f;
    }
    jb->points = pts;
    jb->count = (size_t)count;
    jb->request_id = r->request_id;
    submit(c, jb);
}

void sv_do_stats(sv_conn *c, sv_request *r)
{
    sv_server *s = c->srv;
    json_t *stages = json_array(), *plan = json_object();
    if (c->world && c->world->latest) {
        const sv_result *res = c->world->latest;
        json_decref(plan);
        plan = tick_stats(res);
        json_decref(stages); /* STATS keeps a top-level copy of the tick's stages (SPEC section 4) */
        stages = json_deep_copy(json_object_get(plan, "stages"));
        if (!plan || !stages) { /* out of memory: answer with what is left */
            json_decref(stages);
            stages = json_array();
            if (!plan)
                plan = json_object();
        }
        json_object_set_new(plan, "tick", json_integer((json_int_t)res->tick));
        json_object_set_new(plan, "current", json_boolean(res->gen == c->world_gen));
    }
    json_object_set_new(plan, "backend", json_string(s->gl_backend));
    json_object_set_new(plan, "gl_renderer", json_string(s->gl_renderer));
    json_object_set_new(plan, "config", sv_config_json(c));
    size_t pend = 0, wq = 0, drops = 0, unchanged = 0;
    int sessions = 0;
    for (sv_conn *o = s->conns; o; o = o->next) {
        pend += o->pending_count;
        wq += o->wq_bytes;
        drops += o->stream_dropped;
        unchanged += o->stream_unchanged;
        if (o->hello)
            sessions++;
    }
    int shared = 0;
    if (c->world)
        shared = c->world->refs;
    json_t *b = json_pack(
        "{s:o, s:o, s:i, s:i, s:i, s:{s:I, s:I, s:I, s:I, s:I, s:I}, s:I, s:I, s:I, s:I, s:i, s:I}", "stages", stages,
        "plan", plan, "clients", s->conn_count, "sessions", sessions, "worlds", s->world_count, "queues", "gl_jobs",
        (json_int_t)sv_jobs_queued(s), "requests_pending", (json_int_t)pend, "write_bytes", (json_int_t)wq,
        "session_requests_pending", (json_int_t)c->pending_count, "session_write_bytes", (json_int_t)c->wq_bytes,
        "stream_dropped", (json_int_t)drops, "bytes_sent", (json_int_t)s->bytes_sent, "session_bytes_sent",
        (json_int_t)c->bytes_sent, "ticks", (json_int_t)s->ticks, "world_ticks",
        (json_int_t)(c->world && c->world->latest ? c->world->latest->tick : 0), "world_sessions", shared,
        "revision", (json_int_t)c->revision);
    json_object_set_new(b, "stream_unchanged", json_integer((json_int_t)unchanged)); /* R5.16 */
    json_object_set_new(b, "encode", json_pack("{s:I, s:f, s:I}", "volumes", (json_int_t)s->volumes_encoded, "volume_cpu_ms",
                                               (double)s->volume_encode_ns / 1e6, "bases_refused",
                                               (json_int_t)s->bases_refused));
    json_object_set_new(b, "session_stream_unchanged", json_integer((json_int_t)c->stream_unchanged));
    /* R7.5: request bytes held for all connections, against --max-request-memory */
    json_object_set_new(json_object_get(b, "queues"), "request_bytes",
                        json_integer((json_int_t)sv_memory_held(&s->mem, SV_MEM_REQUESTS)));
    /* R7.6a: the daemon's one budget and what each term holds */
    json_t *mem = json_pack("{s:I}", "budget", (json_int_t)s->mem.budget);
    for (int t = 0; mem && t < SV_MEM_TERMS; ++t)
        json_object_set_new(mem, sv_mem_term_name((sv_mem_term)t),
                            json_integer((json_int_t)sv_memory_held(&s->mem, (sv_mem_term)t)));
    if (mem)
        json_object_set_new(b, "memory", mem);
    /* tick coalescing (R7.2): computed ticks vs TICK requests answered by a tick queued for another */
    json_object_set_new(b, "ticks_computed", json_integer((json_int_t)s->ticks));
    json_object_set_new(b, "ticks_coalesced", json_integer((json_int_t)s->ticks_coalesced));
    /* fair GL time: ticks skipped or abandoned because every request for them
     * had gone; jobs run at another world's yield point (serve_gl.c) */
    json_object_set_new(b, "ticks_cancelled", json_integer((json_int_t)s->ticks_cancelled));
    pthread_mutex_lock(&s->mu);
    const uint64_t between = s->gl_jobs_between;
    pthread_mutex_unlock(&s->mu);
    json_object_set_new(b, "gl_jobs_between", json_integer((json_int_t)between));
    json_object_set_new(b, "world_ticks_computed", json_integer((json_int_t)(c->world ? c->world->ticks_computed : 0)));
    json_object_set_new(b, "world_ticks_coalesced",
                        json_integer((json_int_t)(c->world ? c->world->ticks_coalesced : 0)));
    sv_reply(c, LPVP_STATS, r->request_id, b);
}

/* ---- completions of GL jobs ---------------------------------------------- */
void sv_session_job_done(sv_job *j, sv_conn *c, uint32_t request_id)
{
    sv_session_answered(c);
    if (c->closing || c->close_after_write)
        return;
    if (j->status) {
        sv_reply_err(c, request_id, j->status, 0, "%s", j->err);
    } else if (j->kind == SV_JOB_TICK) {
        json_t *b = sv_rev_body(c);
        json_object_set_new(b, "tick", json_integer((json_int_t)j->result->tick));
        json_object_set_new(b, "stats", tick_stats(j->result));
        sv_reply(c, LPVP_TICK, request_id, b);
    } else if (j->kind == SV_JOB_RENDER) { /* the frame passes to the encoding on a work thread */
        float *rgba = j->rgba;
        j->rgba = NULL;
        sv_reply_frame(c, request_id, NULL, rgba, j->width, j->height, (int)(j->count & 15), (int)(j->count >> 4),
                       j->terms, &j->display, j->tick);
    } else if (j->kind == SV_JOB_CONTENT) { /* so do the levels or the visibility */
        const sv_volume_coding how = {.fp16 = (int)(j->count & 15), .comp = (int)((j->count >> 4) & 15)};
        sv_reply_volume(c, request_id, j->result, (int)(j->count >> 8), &how);
    } else if (j->kind == SV_JOB_QUERY) { /* so do the answers, packed there */
        float *out = j->out;
        j->out = NULL;
        sv_reply_query(c, request_id, out, j->count, j->tick);
    }
    sv_session_go_on(c); /* a reply encoding keeps the session busy: nothing is taken before it is queued */
}
