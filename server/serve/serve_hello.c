/*
 * serve_hello.c - HELLO, the first request of every session: the protocol
 * version (SPEC R4.1), the --token check (R4.2), and the reply that tells the
 * client the server's limits, knobs and presets (R4.12). Until it succeeds,
 * dispatch (serve_dispatch.c) answers every other request with
 * HELLO_REQUIRED. A HELLO that passes the token check takes one of the
 * --max-clients slots, or gets LIMIT and the connection closes (R4.1a).
 */
#include "serve_session_internal.h"

#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "settings_json.h"
#include "serve_limits.h"

static int token_equal(const char *a, size_t alen, const char *b, size_t blen)
{
    /* constant time in the secret's length: every byte of b is visited */
    unsigned diff = (unsigned)(alen ^ blen);
    for (size_t i = 0; i < blen; ++i) {
        unsigned char x = i < alen ? (unsigned char)a[i] : 0;
        diff |= x ^ (unsigned char)b[i];
    }
    return diff == 0;
}

/* R5.16: the volume compressions this server sends and shq's error bounds,
 * for a client to choose from in SUBSCRIBE / GET_VOLUME. */
static json_t *volume_codecs(void)
{
    json_t *names = json_array();
    for (int i = 0; names && i < 3; ++i)
        json_array_append_new(names, json_string(lpvp_compression_names[i]));
    return json_pack("{s:o, s:{s:f, s:f, s:f}}", "compression", names, LPVP_SHQ_BOUND_KEY, "min", LPVP_SHQ_BOUND_MIN,
                     "max", LPVP_SHQ_BOUND_MAX, "default", LPVP_SHQ_BOUND_DEFAULT);
}

void sv_do_hello(sv_conn *c, sv_request *r, json_t *j)
{
    sv_server *s = c->srv;
    char err[256];
    int64_t v = 0;
    if (lpvp_get_int(j, "version", 1, INT32_MIN, INT32_MAX, &v, err, sizeof err) != LPVP_FIELD_OK) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
        return;
    }
    if (v != LPVP_VERSION) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_VERSION, 1, "HELLO version %lld is not spoken; this server speaks 1",
                  (long long)v);
        return;
    }
    const char *client = NULL, *token = NULL;
    size_t tlen = 0;
    if (lpvp_get_string(j, "client", 0, 256, &client, NULL, err, sizeof err) == LPVP_FIELD_BAD) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
        return;
    }
    int tst = lpvp_get_string(j, "token", 0, 4096, &token, &tlen, err, sizeof err);
    if (s->cfg.has_token) {
        if (tst != LPVP_FIELD_OK ||
            !token_equal(token, tlen, s->cfg.token, strlen(s->cfg.token))) {
            sv_reply_err(c, r->request_id, LPVP_E_UNAUTHORIZED, 0, "%s",
                      tst == LPVP_FIELD_OK ? "wrong token" : "this server requires a token in HELLO (\"token\")");
            return;
        }
    } else if (tst == LPVP_FIELD_BAD) {
        sv_reply_err(c, r->request_id, LPVP_E_BAD_FIELD, 0, "%s", err);
        return;
    }
    if (sv_net_admit_session(c, r->request_id) != 0)
        return;
    c->hello = 1;
    sv_net_preauth_leave(c);
    char server[64];
    snprintf(server, sizeof server, "lpvd %s", LPVD_VERSION);
    json_t *lim = json_object(); /* every limit of serve_limits.c's table, and what follows from them */
    if (lim) {
        sv_limits_hello(&s->cfg, lim);
        json_object_set_new(lim, "max_query_points", json_integer((json_int_t)sv_max_query_points(&s->cfg)));
    }
    json_t *b = json_pack("{s:i, s:s, s:I, s:o, s:s, s:s, s:I}", "version", LPVP_VERSION, "server", server, "session",
                          (json_int_t)c->id, "limits", lim, "backend", s->gl_backend, "gl_renderer", s->gl_renderer,
                          "revision", (json_int_t)c->revision);
    /* R4.12, R4.14: CONFIG's knobs, presets and techniques, described from core's tables so no client keeps a
     * copy */
    if (b && (json_object_set_new(b, "knobs", lpvd_knobs_json(&s->cfg.settings, s->cfg.max_texture)) != 0 ||
              json_object_set_new(b, "presets", lpvd_presets_json()) != 0 ||
              json_object_set_new(b, "techniques", lpvd_techniques_json()) != 0 ||
              json_object_set_new(b, "volume_codecs", volume_codecs()) != 0)) {
        json_decref(b);
        b = NULL;
    }
    sv_reply(c, LPVP_HELLO, r->request_id, b);
}
