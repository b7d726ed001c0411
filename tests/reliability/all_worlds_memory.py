#!/usr/bin/env python3
"""all_worlds_memory.py - all worlds together stay within the daemon's memory budget (R7.6a).

Issue 31, item 5: each world stayed under --max-world-memory, but nothing
bounded them together (28 clients with large cameras passed 24 GiB). With
--max-memory 500 MiB (64 MiB of it kept free for one --max-message) and
--max-world-memory 300 MiB, three clients each tick
a world of about 0.22 GB (the built-in box, LPV grid 48, one cascade, a light
of their own so the worlds are not shared). Expected: the first two tick;
the third gets LIMIT naming --max-memory and what the other worlds hold;
after the first client leaves (BYE: its engine is destroyed), the third
ticks. HELLO says limits.max_memory.
"""

import sys
import time

from rel_common import harness, lc, hello, ok

MIB = 1 << 20
CONFIG = {"technique": "lpv", "grid": [48, 48, 48], "cascades": 1, "far_field": False, "normal_bins": False,
          "iterations": 4}


def client(ep, i):
    c = lc.Conn(ep, timeout=120)
    lim = hello(c).body["limits"]
    ok(c.request(lc.CONFIG, CONFIG, timeout=60), lc.CONFIG)
    ok(c.request(lc.LIGHT_SET, {"id": "own", "type": "point", "intensity": 1.0, "position": [0.1 * i, 1.0, 0.0]},
                 timeout=60), lc.LIGHT_SET)
    return c, lim


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("all_worlds_memory")
    # --max-message 64 MiB: the budget keeps one message free beside the worlds (serve_memory.h)
    extra = ["--max-memory", str(500 * MIB), "--max-world-memory", str(300 * MIB), "--max-message", str(64 * MIB)]
    with harness.Daemon(harness.find_lpvd(args.lpvd), extra=extra) as d:
        ep = ("unix", d.unix)
        conns = []
        for i in range(3):
            c, lim = client(ep, i)
            conns.append(c)
        rep.check(lim.get("max_memory") == 500 * MIB, "HELLO limits.max_memory is --max-memory", repr(lim.get("max_memory")))
        replies = [c.request(lc.TICK, {}, timeout=120) for c in conns]
        what = ["tick" if f.type == (lc.TICK | lc.REPLY) else "%s: %s" % (f.err_name, f.body.get("message", ""))
                for f in replies]
        rep.check(what[0] == "tick" and what[1] == "tick", "the first two worlds tick", "; ".join(what[:2])[:300])
        rep.check(replies[2].type == lc.ERROR and replies[2].err_name == "LIMIT" and "--max-memory" in what[2],
                  "the third gets LIMIT naming --max-memory", what[2][:400])
        rid = conns[0].send(lc.BYE, {})
        conns[0].recv_reply(rid, 30)
        conns[0].close()
        f = None
        for _ in range(50):  # the first world's destroy job runs on the GL thread
            f = conns[2].request(lc.TICK, {}, timeout=120)
            if f.type == (lc.TICK | lc.REPLY):
                break
            time.sleep(0.1)
        rep.check(f is not None and f.type == (lc.TICK | lc.REPLY), "after the first leaves, the third ticks",
                  repr(f)[:300])
        for c in conns[1:]:
            c.close()
        rep.check(d.alive(), "daemon alive")
        return rep.finish(d)


if __name__ == "__main__":
    sys.exit(main())
