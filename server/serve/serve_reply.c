/*
 * serve_reply.c - the replies every request handler sends: a REPLY, an
 * ERROR (which closes the connection when its code does, R3.4), and the
 * {"revision"} body. Below the session layer's files, above only the
 * network's writes, so a handler replying never calls up into another.
 */
#include "serve_session_internal.h"

#include <stdarg.h>
#include <stdio.h>

void sv_reply_err(sv_conn *c, uint32_t rid, int code, int noclose, const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    sv_send(c, LPVP_ERROR, rid, lpvp_error_body(code, "%s", msg), NULL, 0, SV_STREAM_NONE);
    /* SHUTTING_DOWN closes, but not yet: the requests queued behind this one
     * get their own, then BYE (sv_session_shutdown closes, R7.4) */
    if (!noclose && lpvp_error_closes(code) && code != LPVP_E_SHUTTING_DOWN)
        sv_conn_close_after_write(c);
}

void sv_reply(sv_conn *c, uint16_t type, uint32_t rid, json_t *body)
{
    sv_send(c, LPVP_REPLY(type), rid, body ? body : json_object(), NULL, 0, SV_STREAM_NONE);
}

json_t *sv_rev_body(sv_conn *c)
{
    return json_pack("{s:I}", "revision", (json_int_t)c->revision);
}
