/*
 * lpvc_stream.c - the C client's streams: the next VOLUME or FRAME a
 * subscription pushes (from the transport's queue or the socket), decoded
 * (lpvc_volume.c, lpvc_frame.c). Above the transport, so the transport never
 * calls the decoders that call it.
 */
#include <stdlib.h>
#include <string.h>

#include "lpvc_internal.h"

void lpvc_message_free(lpvc_message *m)
{
    if (!m)
        return;
    lpvc_volume_free(&m->volume);
    lpvc_frame_free(&m->frame);
    m->type = LPVC_MSG_NONE;
}

int lpvc_next_stream_message(lpvc *c, lpvc_message *out, int timeout_ms)
{
    if (!c)
        return -1;
    if (!out)
        return lpvci_fail(c, LPVC_ERR_USAGE, "out is NULL");
    memset(out, 0, sizeof *out);
    lpvci_clear_error(c);
    uint16_t type;
    json_t *body;
    uint8_t *att;
    size_t att_len;
    if (c->q_head) {
        lpvc_queued *q = c->q_head;
        c->q_head = q->next;
        if (!c->q_head)
            c->q_tail = NULL;
        type = q->type;
        body = q->body;
        att = q->att;
        att_len = q->att_len;
        free(q);
    } else {
        for (;;) {
            lpvci_rx r;
            if (lpvci_recv_frame(c, &r, timeout_ms < 0 ? -2 : timeout_ms) != 0)
                return -1;
            if (r.h.type == LPVP_VOLUME || r.h.type == LPVP_FRAME) {
                type = r.h.type;
                body = r.body;
                att = r.att;
                att_len = r.att_len;
                break;
            }
            if (r.h.type == LPVP_BYE_REPLY) {
                lpvci_rx_free(&r);
                lpvci_close_fd(c);
                out->type = LPVC_MSG_BYE;
                return 0;
            }
            if (r.h.type == LPVP_ERROR) {
                lpvci_take_error(c, r.body, 0);
                if (r.h.request_id == 0 && c->err_code == LPVP_E_SHUTTING_DOWN)
                    lpvci_close_fd(c);
                lpvci_rx_free(&r);
                return -1;
            }
            lpvci_fail(c, LPVC_ERR_PROTOCOL, "unexpected %s (type 0x%04x, request_id %u) in the stream",
                 lpvp_type_name(r.h.type), r.h.type, r.h.request_id);
            lpvci_rx_free(&r);
            return -1;
        }
    }
    lpvci_set_last_reply(c, body);
    int rc;
    if (type == LPVP_VOLUME) {
        out->type = LPVC_MSG_VOLUME;
        rc = lpvci_decode_volume(c, body, att, att_len, true, &out->volume);
        free(att);
    } else {
        out->type = LPVC_MSG_FRAME;
        rc = lpvci_decode_frame(c, body, att, att_len, &out->frame);
    }
    json_decref(body);
    if (rc != 0)
        lpvc_message_free(out);
    return rc;
}
