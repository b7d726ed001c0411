#!/usr/bin/env python3
"""loads_and_encodes.py - scene loads do not take every worker from the encodings (issue 31, item 6).

Scene loads (parsing) and the encodings of GET_VOLUME, GET_FRAME and query
replies ran on the same four libuv workers, so four clients re-parsing a
large scene delayed another client's small GET_VOLUME by 5 s and a one-point
query by 7 s. Now at most SV_MAX_LOADS (2) loads run at once and the others
wait their turn. Four clients each load a 2 000 000-triangle scene (72 MB, a
second or more of parsing each on the 2-core machine); while they load,
client Q, ticked before, asks GET_VOLUME and a one-point QUERY_IRRADIANCE.
Expected, by order of arrival and not by a clock: Q's two replies arrive
before any of the four loads is answered (before, the four loads held the
four workers and Q's encodings waited for the first to end); every load is
answered.
"""

import os
import struct
import sys
import threading
import time

from rel_common import harness, lc, hello, ok, scene_session
from sigterm_load import big_glb

TRIANGLES = 2000000
LOADERS = 4


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("loads_and_encodes")
    with harness.Daemon(harness.find_lpvd(args.lpvd), scene_root=True) as d:
        big_glb(os.path.join(d.scene_root, "big.glb"), TRIANGLES)
        ep = ("unix", d.unix)
        q = scene_session(ep)
        ok(q.request(lc.TICK, {}, timeout=120), lc.TICK)
        loaders = []
        for _ in range(LOADERS):
            c = lc.Conn(ep, timeout=300)
            hello(c)
            loaders.append(c)
        done = []  # (time, what)
        lock = threading.Lock()

        def load(c, i):
            f = c.request(lc.SCENE_LOAD, {"path": "big.glb"}, timeout=300)
            with lock:
                done.append((time.monotonic(), "load %d %s" % (i, "ok" if f.type == (lc.SCENE_LOAD | lc.REPLY)
                                                                else f.err_name)))

        threads = [threading.Thread(target=load, args=(c, i)) for i, c in enumerate(loaders)]
        for t in threads:
            t.start()
        time.sleep(0.3)  # the loads are on the workers
        f = q.request(lc.GET_VOLUME, {"format": "fp16", "compression": "zstd"}, timeout=300)
        with lock:
            done.append((time.monotonic(), "GET_VOLUME %s" % ("ok" if f.type == (lc.GET_VOLUME | lc.REPLY) else f)))
        pt = struct.pack("<6f", 0.0, 0.5, 0.0, 0.0, 1.0, 0.0)
        f = q.request(lc.QUERY_IRRADIANCE, {"count": 1}, pt, timeout=300)
        with lock:
            done.append((time.monotonic(), "QUERY %s" % ("ok" if f.type == (lc.QUERY_IRRADIANCE | lc.REPLY) else f)))
        for t in threads:
            t.join(300)
        order = [w for _, w in sorted(done)]
        print("order of the replies: %s" % ", ".join(order))
        loads = [w for w in order if w.startswith("load")]
        rep.check(len(loads) == LOADERS and all(w.endswith("ok") for w in loads), "every load is answered", str(loads))
        first_load = min(i for i, w in enumerate(order) if w.startswith("load"))
        gv = order.index(next(w for w in order if w.startswith("GET_VOLUME")))
        qr = order.index(next(w for w in order if w.startswith("QUERY")))
        rep.check(gv < first_load and qr < first_load and order[gv].endswith("ok") and order[qr].endswith("ok"),
                  "GET_VOLUME and a one-point query are answered before any of %d loads" % LOADERS,
                  ", ".join(order))
        for c in loaders + [q]:
            c.close()
        rep.check(d.alive(), "daemon alive")
        return rep.finish(d)


if __name__ == "__main__":
    sys.exit(main())
