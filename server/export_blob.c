/*
 * export_blob.c - immutable bytes with a reference count (export.h's
 * sv_blob): the volume a delta subscriber holds. Subscribers of one world in
 * step hold the same shq reconstruction (export_encode.c's shared
 * encodings); each keeps a reference instead of a 4.7 MB copy (3 x 32^3),
 * which on the 2-core machine cost 18-24 ms a subscriber per update, most
 * of it writing fresh pages. References are taken and dropped on the work
 * threads and the loop, so the count is atomic; the bytes never change after
 * sv_blob_new's caller filled them, before the first reference is shared.
 */
#include "export.h"

#include <stdlib.h>

sv_blob *sv_blob_new(size_t len, _Atomic uint64_t *held)
{
    sv_blob *b = malloc(sizeof *b + (len ? len : 1));
    if (!b)
        return NULL;
    atomic_init(&b->refs, 1);
    b->len = len;
    b->held = held;
    if (held)
        atomic_fetch_add(held, (uint64_t)len);
    return b;
}

sv_blob *sv_blob_ref(sv_blob *b)
{
    if (b)
        atomic_fetch_add(&b->refs, 1);
    return b;
}

void sv_blob_unref(sv_blob *b)
{
    if (!b || atomic_fetch_sub(&b->refs, 1) != 1)
        return;
    if (b->held)
        atomic_fetch_sub(b->held, (uint64_t)b->len);
    free(b);
}
