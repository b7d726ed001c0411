#!/usr/bin/env python3
"""idle_after_reply.py - a tick longer than the idle timeout leaves the client the whole timeout (R4.9).

The idle timer spared a session while its request ran, but counted its
idle time from the request's arrival: the moment a tick longer than
--idle-timeout was answered, the session was already "idle", and the
timer (once a second) closed it before the client's next request came in.
The client saw its next request reset (the conformance suite's R7.6 case
at max_grid failed so under ASan). Expected: with --idle-timeout 2, after
a tick that took longer than 2 s, a request sent 1.2 s after the reply is
answered, and only a session silent for the whole timeout after that gets
BYE.
"""

import sys
import time

from rel_common import harness, lc, ok, scene_session

IDLE_S = 2.0
WAIT_S = 1.2  # under IDLE_S, over the idle timer's 1 s period: the old rule closed the session every time


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("idle_after_reply")
    d = harness.Daemon(harness.find_lpvd(args.lpvd), idle_timeout=IDLE_S)
    d.start()
    try:
        c = scene_session(("unix", d.unix))
        # a warmup of every probe is the longest tick the default limits
        # allow; grow the grid until one takes longer than the timeout
        took = 0.0
        for n in (16, 24, 32, 48):
            f = c.request(lc.CONFIG, {"technique": "probes", "grid": [n] * 3})
            if f.type == lc.ERROR:
                break
            t0 = time.monotonic()
            ok(c.request(lc.TICK, {}, timeout=240), lc.TICK, "TICK at %d^3 probes" % n)
            took = time.monotonic() - t0
            if took > IDLE_S * 1.25:
                break
            time.sleep(0.05)  # a frame every tick: the session never idles here
        if took <= IDLE_S * 1.25:
            print("idle_after_reply: no tick took longer than %g s here (the longest %.2f s): nothing to show"
                  % (IDLE_S * 1.25, took))
            rep.check(True, "skipped: this machine ticks faster than the idle timeout")
            return rep.finish(d)
        time.sleep(WAIT_S)
        try:
            f = c.request(lc.STATS, {}, timeout=30)
            rep.check(f.type == lc.STATS | lc.REPLY,
                      "a request %.1f s after a %.2f s tick's reply (--idle-timeout %g) is answered" % (WAIT_S, took, IDLE_S),
                      "" if f.type == lc.STATS | lc.REPLY else "got %r" % (f,))
        except (lc.Closed, OSError) as e:
            rep.check(False, "a request %.1f s after a %.2f s tick's reply (--idle-timeout %g) is answered"
                      % (WAIT_S, took, IDLE_S), "the session was closed: %s" % e)
            return rep.finish(d)
        # still an idle timeout: silent for longer than it, BYE
        t0 = time.monotonic()
        try:
            f = c.recv(timeout=IDLE_S + 5.0)
            quiet = time.monotonic() - t0
            rep.check(f.type == lc.BYE_REPLY and f.rid == 0 and quiet >= IDLE_S - 0.1,
                      "silent afterwards: BYE after %.2f s" % quiet, "got %r" % (f,))
        except Exception as e:  # noqa: BLE001 - any failure to see BYE is the finding
            rep.check(False, "silent afterwards: BYE within %g s" % (IDLE_S + 5.0), repr(e))
        return rep.finish(d)
    finally:
        d.kill()


if __name__ == "__main__":
    sys.exit(main())
