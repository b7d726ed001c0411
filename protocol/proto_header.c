/*
 * proto_header.c - the frame limits (R2.5) and the 24-byte frame header:
 * its encoding, and the checks a received header passes before anything of
 * its body is read (R2.1-R2.5), so that an oversized or malformed frame is
 * refused from its first 24 bytes. See proto.h.
 */
#include "proto.h"
#include "proto_internal.h"

#include <string.h>

/* ---- Limits and header ---------------------------------------------------- */

void lpvp_limits_default(lpvp_limits *lim)
{
    lim->max_body = LPVP_DEFAULT_MAX_BODY;
    lim->max_message = LPVP_DEFAULT_MAX_MESSAGE;
    lim->no_attachment = 0;
}

lpvp_limits lpvp_limits_or_default(const lpvp_limits *lim)
{
    lpvp_limits l;
    if (lim)
        return *lim;
    lpvp_limits_default(&l);
    return l;
}

void lpvp_header_encode(const lpvp_header *h, uint8_t out[LPVP_HEADER_SIZE])
{
    memcpy(out, LPVP_MAGIC, LPVP_MAGIC_LEN);
    lpvp_put_u16(out + 4, h->version);
    lpvp_put_u16(out + 6, h->type);
    lpvp_put_u32(out + 8, h->request_id);
    lpvp_put_u32(out + 12, h->flags);
    lpvp_put_u32(out + 16, h->json_length);
    lpvp_put_u32(out + 20, h->attachment_length);
}

int lpvp_header_check(const uint8_t in[LPVP_HEADER_SIZE], const lpvp_limits *lim,
                      lpvp_header *h, char *err, size_t err_n)
{
    lpvp_limits l = lpvp_limits_or_default(lim);
    h->version = lpvp_get_u16(in + 4);
    h->type = lpvp_get_u16(in + 6);
    h->request_id = lpvp_get_u32(in + 8);
    h->flags = lpvp_get_u32(in + 12);
    h->json_length = lpvp_get_u32(in + 16);
    h->attachment_length = lpvp_get_u32(in + 20);
    if (err && err_n)
        err[0] = '\0';

    if (memcmp(in, LPVP_MAGIC, LPVP_MAGIC_LEN) != 0) { /* R2.2 */
        h->request_id = 0;
        lpvp_set_error(err, err_n, "bad magic %02x %02x %02x %02x (expected \"LPVD\")", in[0], in[1],
                in[2], in[3]);
        return LPVP_E_BAD_MAGIC;
    }
    if (h->version != LPVP_VERSION) { /* R2.3 */
        lpvp_set_error(err, err_n, "frame version %u not spoken (versions: [%d])", (unsigned)h->version,
                LPVP_VERSION);
        return LPVP_E_BAD_VERSION;
    }
    if (h->flags != 0) { /* R2.4 */
        lpvp_set_error(err, err_n, "flags 0x%08x must be 0", (unsigned)h->flags);
        return LPVP_E_BAD_FRAME;
    }
    if (h->json_length < LPVP_MIN_JSON_LENGTH) { /* R2.1 */
        lpvp_set_error(err, err_n, "json_length %u is less than 2 (the body is at least {})",
                (unsigned)h->json_length);
        return LPVP_E_BAD_FRAME;
    }
    if (h->json_length > l.max_body) { /* R2.5 */
        lpvp_set_error(err, err_n, "json_length %u exceeds the body limit %u", (unsigned)h->json_length,
                (unsigned)l.max_body);
        return LPVP_E_TOO_LARGE;
    }
    if ((uint64_t)h->json_length + h->attachment_length > l.max_message) { /* R2.5 */
        lpvp_set_error(err, err_n,
                "json_length %u + attachment_length %u exceeds the message limit %llu",
                (unsigned)h->json_length, (unsigned)h->attachment_length,
                (unsigned long long)l.max_message);
        return LPVP_E_TOO_LARGE;
    }
    if (l.no_attachment && h->attachment_length) { /* R2.5a */
        lpvp_set_error(err, err_n, "attachment_length %u: this frame may carry no attachment",
                (unsigned)h->attachment_length);
        return LPVP_E_TOO_LARGE;
    }
    return LPVP_E_NONE;
}

int lpvp_header_decode(const uint8_t in[LPVP_HEADER_SIZE], const lpvp_limits *lim,
                       lpvp_header *h, int *error_code)
{
    int code = lpvp_header_check(in, lim, h, NULL, 0);
    if (error_code)
        *error_code = code;
    return code == LPVP_E_NONE ? 0 : -1;
}
