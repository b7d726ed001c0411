#!/usr/bin/env python3
"""world_churn.py - worlds that tick with lights and go away give their memory back.

Issue 31, item 1: every world that ticked with a light kept 20-26 MiB of the
daemon's memory after its session left (two buffers the engine's destroy did
not delete, and glibc keeping freed blocks in its heap), so a daemon serving
short sessions grew without bound. Each cycle here is one session on the
built-in box: HELLO, CONFIG (lpv, octree and iv in turn, rsm_size 256),
LIGHT_SET of a point light, two TICKs, BYE. After WARMUP cycles the daemon's
VmRSS is recorded; after CYCLES more it must not have grown by more than
BOUND_MIB (the leak alone was 20 MiB a cycle; an ASan build's quarantine keeps
up to 256 MiB of freed blocks, so it gets that much more). A session holding
its own world lives throughout and must still tick.
"""

import sys
import time

from rel_common import harness, lc, hello, ok, scene_session

WARMUP = 12
CYCLES = 30
BOUND_MIB = 64
TECHNIQUES = ("lpv", "octree", "iv")


def cycle(ep, i):
    c = lc.Conn(ep, timeout=120)
    try:
        hello(c)
        config = {"technique": TECHNIQUES[i % len(TECHNIQUES)], "rsm_size": 256}
        ok(c.request(lc.CONFIG, config, timeout=120), lc.CONFIG)
        light = {"id": "lamp", "type": "point", "intensity": 50.0, "position": [0.0, 1.0, 0.1 * (i % 5)]}
        ok(c.request(lc.LIGHT_SET, light, timeout=120), lc.LIGHT_SET)
        for _ in range(2):
            ok(c.request(lc.TICK, {}, timeout=120), lc.TICK)
        rid = c.send(lc.BYE, {})
        f = c.recv_reply(rid, 60)
        if f.type != lc.BYE_REPLY:
            raise RuntimeError("BYE reply %r" % f)
    finally:
        c.close()


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("world_churn")
    with harness.Daemon(harness.find_lpvd(args.lpvd)) as d:
        ep = ("unix", d.unix)
        keeper = scene_session(ep)
        ok(keeper.request(lc.TICK, {}, timeout=60), lc.TICK)
        errors = []
        for i in range(WARMUP + CYCLES):
            if i == WARMUP:
                time.sleep(0.5)  # the last world's destroy job runs on the GL thread
                rss0 = d.rss_kib()
                t0 = time.monotonic()
            try:
                cycle(ep, i)
            except Exception as e:
                errors.append("cycle %d: %s" % (i, e))
                if len(errors) > 5:
                    break
        dt = time.monotonic() - t0
        time.sleep(0.5)
        rss1 = d.rss_kib()
        bound = BOUND_MIB + (256 if d.asan else 0)
        rep.check(not errors, "%d sessions with a light, ticked, gone, without error" % (WARMUP + CYCLES),
                  "; ".join(errors[:3]) if errors else "%.1f s for the last %d" % (dt, CYCLES))
        rep.check(rss1 - rss0 < bound * 1024, "VmRSS growth < %d MiB over %d worlds after %d" % (bound, CYCLES, WARMUP),
                  "%.1f MiB -> %.1f MiB (%+.1f MiB, %+.2f MiB a world)" %
                  (rss0 / 1024.0, rss1 / 1024.0, (rss1 - rss0) / 1024.0, (rss1 - rss0) / 1024.0 / CYCLES))
        try:
            ok(keeper.request(lc.TICK, {}, timeout=60), lc.TICK)
            rep.check(True, "the long-lived session still ticks")
        except Exception as e:
            rep.check(False, "the long-lived session still ticks", str(e))
        keeper.close()
        rep.check(d.alive(), "daemon alive")
        return rep.finish(d)


if __name__ == "__main__":
    sys.exit(main())
