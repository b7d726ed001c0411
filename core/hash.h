/*
 * hash.h - FNV-1a (64-bit) over bytes, chained: the one content hash of the
 * tree (the daemon's scene and world keys, the engine's geometry signature).
 * Not cryptographic: it names content the process already trusts, to find
 * equal copies quickly. In core, the lowest layer, so every layer above can
 * use the same one.
 */
#ifndef LPV_HASH_H
#define LPV_HASH_H

#include <stddef.h>
#include <stdint.h>

#define LPV_HASH_INIT 1469598103934665603ull /* FNV-1a 64-bit offset basis */

/* h chained over data[0..n): start with LPV_HASH_INIT. */
static inline uint64_t lpv_hash_bytes(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; ++i) {
        h ^= p[i];
        h *= 1099511628211ull; /* FNV-1a 64-bit prime */
    }
    return h;
}

#endif /* LPV_HASH_H */
