/*
 * serve_clock.c - the daemon's clock (sv_now_ms): milliseconds of
 * CLOCK_MONOTONIC. A file of its own at the bottom of the daemon, so the
 * network layer's timestamps do not make it call up into the command
 * (serve.c) that sits on top of everything.
 */
#include "serve.h"

#include <time.h>

uint64_t sv_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000u + (uint64_t)ts.tv_nsec / 1000000u;
}
