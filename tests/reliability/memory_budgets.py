#!/usr/bin/env python3
"""memory_budgets.py - the daemon-wide scene budget and the per-world GPU budget (R4.5c, R7.6).

Each bounds a term of docs/server.md's "Worst-case memory"; scaled down here.

1. --max-scene-bytes 600000 --max-scenes-memory 1200000: two sessions load two different scenes of about
   530 kB each (430 kB before vertices carried COLOR_0); a third different scene gets LIMIT naming --max-scenes-memory (before: loaded, with no
   bound on the scenes of all sessions together); the third session can still load a scene already live
   (counted once); once the second session leaves, its scene's bytes are free and the third scene loads.
2. --max-world-memory 1048576: a TICK whose engine would need more (shadow maps, RSMs) gets LIMIT with a
   message naming --max-world-memory (before: each world could take half of the machine's RAM).
"""

import sys

from rel_common import harness, lc, hello

SCENE_BYTES = 600000
SCENES_MEMORY = 1200000


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("memory_budgets")
    d = harness.Daemon(harness.find_lpvd(args.lpvd),
                       extra=["--max-scene-bytes", str(SCENE_BYTES), "--max-scenes-memory", str(SCENES_MEMORY),
                              "--max-world-memory", str(1 << 20)])
    d.start()
    try:
        ep = ("unix", d.unix)
        a, b, c = (lc.Conn(ep, timeout=60) for _ in range(3))
        for x in (a, b, c):
            h = hello(x)
        lim = h.body["limits"]
        rep.check(lim.get("max_scenes_memory") == SCENES_MEMORY and lim.get("max_world_memory") == 1 << 20,
                  "HELLO lists max_scenes_memory and max_world_memory", repr(lim))
        s1, s2, s3 = lc.triangles_glb(2000), lc.triangles_glb(2001), lc.triangles_glb(2002)
        ra = a.request(lc.SCENE_LOAD, {}, s1, timeout=60)
        rb = b.request(lc.SCENE_LOAD, {}, s2, timeout=60)
        rep.check(ra.type == lc.SCENE_LOAD | lc.REPLY and rb.type == lc.SCENE_LOAD | lc.REPLY,
                  "two different scenes within the budget load", "%r / %r" % (ra, rb))
        rc = c.request(lc.SCENE_LOAD, {}, s3, timeout=60)
        rep.check(rc.err_name == "LIMIT" and "--max-scenes-memory" in rc.body.get("message", ""),
                  "a third different scene gets LIMIT naming --max-scenes-memory", repr(rc))
        rc = c.request(lc.SCENE_LOAD, {}, s1, timeout=60)
        rep.check(rc.type == lc.SCENE_LOAD | lc.REPLY, "a scene already live loads (counted once)", repr(rc))
        b.close()
        st = None
        for _ in range(50):  # the server sees the close on its next loop turn
            st = c.request(lc.SCENE_LOAD, {}, s3, timeout=60)
            if st.type == lc.SCENE_LOAD | lc.REPLY:
                break
        rep.check(st.type == lc.SCENE_LOAD | lc.REPLY, "after the second session left, the third scene loads",
                  repr(st))
        t = a.request(lc.TICK, {}, timeout=120)
        msg = t.body.get("message", "") if t.type == lc.ERROR else ""
        rep.check(t.err_name == "LIMIT" and "--max-world-memory" in msg,
                  "a tick whose engine needs more than --max-world-memory is refused, naming it", repr(t)[:300])
        rep.check(a.request(lc.STATS, {}, timeout=30).type == lc.STATS | lc.REPLY, "the session still answers")
        return rep.finish(d)
    finally:
        d.kill()


if __name__ == "__main__":
    sys.exit(main())
