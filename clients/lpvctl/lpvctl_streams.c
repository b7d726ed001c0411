/*
 * lpvctl_streams.c - subscribe and unsubscribe: the VOLUME and FRAME
 * streams' headers printed, and their messages saved.
 */
#include <stdio.h>
#include <string.h>

#include "lpvctl.h"

static int stream_of(const char *s, enum lpvc_stream *out)
{
    if (strcmp(s, "volume") == 0)
        *out = LPVC_STREAM_VOLUME;
    else if (strcmp(s, "frame") == 0)
        *out = LPVC_STREAM_FRAME;
    else
        return -1;
    return 0;
}

enum { SUB_DELTA, SUB_TICK, SUB_FORMAT, SUB_COMPRESSION, SUB_BOUND, SUB_N, SUB_WAIT, SUB_OUTPUT, SUB_COUNT };
static const lpv_flag SUB_FLAGS[SUB_COUNT] = {
    [SUB_DELTA] = {"delta", 0, NULL, ""},
    [SUB_TICK] = {"tick", 0, NULL, ""},
    [SUB_FORMAT] = {"format", 0, "F", ""},
    [SUB_COMPRESSION] = {"compression", 0, "zstd|none|shq", ""},
    [SUB_BOUND] = {"error-bound", 0, "E", ""},
    [SUB_N] = {"count", 'n', "COUNT", ""},
    [SUB_WAIT] = {"wait", 0, "MS", ""},
    [SUB_OUTPUT] = {"output", 'o', "PREFIX", ""},
};

int cmd_subscribe(int argc, char **argv)
{
    lpvc_subscribe_desc d = {0};
    long count = 1, wait_ms = -1;
    int tick = 0;
    const char *prefix = NULL;
    lpv_flags p;
    int idx, r, streams = 0;
    const char *v;
    if (args_begin(&p, argc, argv, SUB_FLAGS, SUB_COUNT) != 0)
        return 2;
    while ((r = args_next(&p, SUB_FLAGS, &idx, &v)) > 0) {
        switch (idx) {
        case -1:
            if (streams++ || stream_of(v, &d.stream) != 0)
                return usage_error("unexpected argument '%s' (the stream is volume or frame)", v);
            break;
        case SUB_DELTA: d.delta = true; break;
        case SUB_TICK: tick = 1; break;
        case SUB_FORMAT: d.format = v; break;
        case SUB_COMPRESSION: d.compression = v; break;
        case SUB_BOUND:
            if (parse_error_bound(v, &d.error_bound) != 0)
                return 2;
            break;
        case SUB_N:
            if (parse_int(v, 1, 1L << 30, &count) != 0)
                return usage_error("bad count '%s'", v);
            break;
        case SUB_WAIT:
            if (parse_int(v, 0, 1L << 30, &wait_ms) != 0)
                return usage_error("bad --wait '%s' (ms)", v);
            break;
        case SUB_OUTPUT: prefix = v; break;
        }
    }
    if (r < 0)
        return 2;
    /* R5.16: an shq delta subscriber gets no VOLUME for a tick that moved
     * nothing beyond its bound, so a TICK is not always answered by one */
    const int quiet_ticks = tick && d.delta && d.compression && strcmp(d.compression, "shq") == 0;
    if (quiet_ticks && wait_ms < 0)
        wait_ms = 5000;
    if (lpvc_subscribe(g_c, &d) != 0)
        return server_error();
    print_reply();
    for (long i = 0; i < count; i++) {
        if (tick && lpvc_tick(g_c, NULL) != 0)
            return server_error();
        lpvc_message m;
        if (lpvc_next_stream_message(g_c, &m, (int)wait_ms) != 0) {
            if (quiet_ticks && lpvc_error_code(g_c) == LPVC_ERR_TIMEOUT) {
                printf("VOLUME: none within %ld ms of the TICK (shq: nothing moved beyond the bound)\n", wait_ms);
                continue;
            }
            return server_error();
        }
        if (m.type == LPVC_MSG_BYE) {
            printf("subscribe: the server said BYE\n");
            return 0;
        }
        char path[4096];
        int rc = 0;
        if (m.type == LPVC_MSG_VOLUME) {
            printf("VOLUME: %s\n", m.volume.header_json);
            if (prefix) {
                snprintf(path, sizeof path, "%s-%lld.bin", prefix, (long long)m.volume.tick);
                rc = save_volume(&m.volume, path);
            }
        } else {
            printf("FRAME: %s\n", m.frame.header_json);
            if (prefix) {
                snprintf(path, sizeof path, "%s-%lld.%s", prefix, (long long)m.frame.tick,
                         strcmp(m.frame.format, "rgba8") == 0 ? "rgba" : m.frame.format);
                rc = write_file(path, m.frame.data, m.frame.size);
            }
        }
        fflush(stdout);
        lpvc_message_free(&m);
        if (rc != 0)
            return 1;
    }
    return 0;
}

int cmd_unsubscribe(int argc, char **argv)
{
    enum lpvc_stream s = LPVC_STREAM_VOLUME;
    if (argc > 2 || (argc == 2 && stream_of(argv[1], &s) != 0))
        return usage_error("expected volume or frame%s", NULL);
    if (lpvc_unsubscribe(g_c, s) != 0)
        return server_error();
    print_reply();
    return 0;
}
