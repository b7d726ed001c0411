/*
 * serve_sub.c - a delta subscriber's bases (the loop's side of
 * export_encode.c's deltas): the volumes sent that it may ACK and the one it
 * did. A file of its own below the streams (serve_streams.c), the encodings
 * (serve_encode_work.c) and the session state (serve_session.c), which all
 * keep or drop them, so none of those calls another for it.
 */
#include "serve.h"

#include <stdlib.h>
#include <string.h>

void sv_sub_clear(sv_sub *sub)
{
    sub->epoch++; /* an encoding in flight no longer hands its base back (sv_sub_restore_base) */
    for (int i = 0; i < SV_SENT_KEEP; ++i) {
        sv_blob_unref(sub->sent[i].raw);
        sub->sent[i].raw = NULL;
    }
    sv_blob_unref(sub->acked.raw);
    sub->acked.raw = NULL;
}

void sv_sub_ack(sv_sub *sub, uint64_t tick)
{
    for (int i = 0; i < SV_SENT_KEEP; ++i) {
        if (sub->sent[i].raw && sub->sent[i].tick == tick) {
            sv_blob_unref(sub->acked.raw);
            sub->acked = sub->sent[i];
            sub->sent[i].raw = NULL;
            /* older unacknowledged volumes can never become a base now */
            for (int k = 0; k < SV_SENT_KEEP; ++k)
                if (sub->sent[k].raw && sub->sent[k].tick < tick) {
                    sv_blob_unref(sub->sent[k].raw);
                    sub->sent[k].raw = NULL;
                }
            return;
        }
    }
}

/* Keeps sent (its raw reference taken) as a volume sent to sub that it may ACK. */
void sv_sub_remember(sv_sub *sub, const sv_sent *sent)
{
    int slot = 0;
    for (int i = 0; i < SV_SENT_KEEP; ++i) {
        if (!sub->sent[i].raw) {
            slot = i;
            break;
        }
        if (sub->sent[i].tick < sub->sent[slot].tick)
            slot = i;
    }
    sv_blob_unref(sub->sent[slot].raw);
    sub->sent[slot] = *sent;
}
