#!/usr/bin/env python3
"""daemon_memory.py - one memory budget for worlds, scenes, requests and replies (issue 31, daemon-wide memory; R7.6a).

Before, --max-memory bounded the worlds' storage only; scenes, requests and
replies had bounds of their own, none counted with the others, so their sum
at the defaults was about 98 GiB whatever the machine. Now all four are
terms of one budget (--max-memory, by default half of the machine's memory),
and the terms but requests leave one --max-message free, so a request can
always be read once the requests before it are handled.

A first daemon (a large budget) measures what a ticked default world holds
(STATS memory.worlds, W) and the size of its EXR frame (R). A second runs
with --max-message 16 MiB and --max-memory 16 MiB + W + R/2:
  1. HELLO limits.max_memory is the flag; STATS memory has the budget and
     each term;
  2. the world ticks (STATS memory.worlds is W), a small GET_VOLUME is
     sent, the EXR frame gets LIMIT naming --max-memory (it would take the
     replies over the budget);
  3. another session's SCENE_LOAD of a scene larger than R/2 gets LIMIT
     naming --max-memory; after the first session leaves (its world goes),
     the same load succeeds;
  4. at rest requests and replies hold 0 bytes.
"""

import sys
import time

from rel_common import harness, lc, hello, ok

MIB = 1 << 20


def memory(c):
    return ok(c.request(lc.STATS, {}, timeout=60), lc.STATS).body.get("memory") or {}


def own_world(c):
    """A light of its own: the session's world is not shared with a session at the defaults."""
    ok(c.request(lc.LIGHT_SET, {"id": "own", "type": "point", "intensity": 1.0, "position": [0.2, 1.0, 0.1]},
                 timeout=60), lc.LIGHT_SET)


def probe(lpvd):
    with harness.Daemon(lpvd, quiet=True) as d:
        c = lc.Conn(("unix", d.unix), timeout=120)
        hello(c)
        own_world(c)
        ok(c.request(lc.TICK, {}, timeout=120), lc.TICK)
        w = memory(c).get("worlds")
        r = len(ok(c.request(lc.GET_FRAME, {"format": "exr"}, timeout=120), lc.GET_FRAME).att)
        c.close()
        return w, r


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("daemon_memory")
    lpvd = harness.find_lpvd(args.lpvd)
    w, r = probe(lpvd)
    if not isinstance(w, int) or w <= 0:
        rep.check(False, "STATS memory.worlds after a tick", repr(w))
        return rep.finish(None)
    budget = 16 * MIB + w + r // 2
    with harness.Daemon(lpvd, extra=["--max-message", str(16 * MIB), "--max-memory", str(budget)]) as d:
        ep = ("unix", d.unix)
        a = lc.Conn(ep, timeout=120)
        lim = hello(a).body["limits"]
        rep.check(lim.get("max_memory") == budget, "HELLO limits.max_memory is --max-memory",
                  "%r, flag %d" % (lim.get("max_memory"), budget))
        m = memory(a)
        rep.check(m.get("budget") == budget and all(k in m for k in ("worlds", "scenes", "requests", "replies")),
                  "STATS memory has the budget and each term", repr(m))
        own_world(a)
        f = a.request(lc.TICK, {}, timeout=120)
        rep.check(f.type == (lc.TICK | lc.REPLY), "the world ticks within the budget", repr(f)[:300])
        m = memory(a)
        rep.check(m.get("worlds") == w, "STATS memory.worlds is the world's storage", "%r, expected %d" % (m, w))
        f = a.request(lc.GET_VOLUME, {"format": "fp16", "compression": "zstd"}, timeout=120)
        rep.check(f.type == (lc.GET_VOLUME | lc.REPLY), "a small reply is sent", repr(f)[:200])
        f = a.request(lc.GET_FRAME, {"format": "exr"}, timeout=120)
        msg = f.body.get("message", "") if f.type == lc.ERROR else ""
        rep.check(f.type == lc.ERROR and f.err_name == "LIMIT" and "--max-memory" in msg,
                  "an EXR frame of %d bytes, over what the budget leaves, gets LIMIT naming --max-memory" % r,
                  (msg or repr(f))[:400])

        b = lc.Conn(ep, timeout=120)
        hello(b)
        scene = lc.triangles_glb(max(2000, r // 100))
        f = b.request(lc.SCENE_LOAD, {}, scene, timeout=120)
        msg = f.body.get("message", "") if f.type == lc.ERROR else ""
        rep.check(f.type == lc.ERROR and f.err_name == "LIMIT" and "--max-memory" in msg,
                  "a scene larger than what the budget leaves gets LIMIT naming --max-memory",
                  (msg or repr(f))[:400])
        rid = a.send(lc.BYE, {})
        a.recv_reply(rid, 30)
        a.close()
        f = None
        for _ in range(100):  # the world's destroy job runs on the GL thread
            f = b.request(lc.SCENE_LOAD, {}, scene, timeout=120)
            if f.type == (lc.SCENE_LOAD | lc.REPLY):
                break
            time.sleep(0.1)
        rep.check(f is not None and f.type == (lc.SCENE_LOAD | lc.REPLY),
                  "after the first session leaves, the scene loads", repr(f)[:300])
        m = memory(b)
        rep.check(m.get("requests") == 0 and m.get("replies") == 0 and m.get("scenes", 0) > 0,
                  "at rest: requests and replies 0, the scene counted", repr(m))
        b.close()
        rep.check(d.alive(), "daemon alive")
        return rep.finish(d)


if __name__ == "__main__":
    sys.exit(main())
