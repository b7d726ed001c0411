#!/usr/bin/env python3
"""encode_offloop.py - nothing heavy on the event loop, no reply over --max-queue (issue 14, item 4).

Before, GET_FRAME's PNG / EXR encoding (and GET_VOLUME's packing and zstd)
ran on the libuv loop: a 4096x4096 frame took 14-17 s there and every other
client's STATS waited for it; and a reply larger than --max-queue was sent
anyway (a 155 MB EXR with --max-queue 64 MiB). Expected:

1. while one client's 2048x2048 PNG GET_FRAME encodes, another client's
   STATS is answered in under a quarter of that GET_FRAME's round trip
   (a ratio, not a wall-clock bound: it holds on a loaded 2-core box; before,
   the STATS waited for the whole encoding, a ratio near 1);
2. with --max-queue 1 MiB, a GET_VOLUME (fp32, uncompressed: about 3 MB) and
   a GET_FRAME (rgba8 1024x1024: 4 MiB) get ERROR LIMIT naming --max-queue
   instead of the reply, the connection stays open, and a small reply still
   comes.
"""

import sys
import threading
import time

from rel_common import harness, lc, hello, ok, scene_session

SIDE = 2048


def stats_during_encode(rep, ep):
    a = scene_session(ep, timeout=300)
    b = scene_session(ep)
    ok(a.request(lc.CAMERA_SET, {"eye": [0, 1, 3.5], "target": [0, 1, 0], "width": SIDE, "height": SIDE}),
       lc.CAMERA_SET)
    # frames rendered with the tick (so GET_FRAME is encoding alone, no GL)
    ok(a.request(lc.SUBSCRIBE, {"stream": "frame", "format": "rgba8"}), lc.SUBSCRIBE)
    ok(a.request(lc.TICK, {}, timeout=300), lc.TICK, "TICK at %dx%d" % (SIDE, SIDE))
    ok(b.request(lc.TICK, {}, timeout=300), lc.TICK)
    got = {}

    def get_frame():
        t0 = time.monotonic()
        rid = a.send(lc.GET_FRAME, {"format": "png"})
        f = a.recv_reply(rid, timeout=300)
        got["frame"] = (time.monotonic() - t0, f)

    th = threading.Thread(target=get_frame)
    th.start()
    time.sleep(0.05)  # the GET_FRAME is being encoded
    t0 = time.monotonic()
    ok(b.request(lc.STATS, {}, timeout=300), lc.STATS)
    dt_stats = time.monotonic() - t0
    th.join(300)
    dt_frame, f = got["frame"]
    ok(f, lc.GET_FRAME, "GET_FRAME png %dx%d" % (SIDE, SIDE))
    rep.check(f.body.get("width") == SIDE and len(f.att) > 0, "the %dx%d PNG arrives" % (SIDE, SIDE),
              "%d bytes in %.2f s" % (len(f.att), dt_frame))
    rep.check(dt_stats < dt_frame / 4, "another client's STATS is answered while the PNG encodes",
              "STATS %.3f s, GET_FRAME %.2f s (before: STATS waited for the encoding)" % (dt_stats, dt_frame))
    a.close()
    b.close()


def over_queue(rep, lpvd):
    d = harness.Daemon(lpvd, extra=["--max-queue", str(1 << 20)])
    d.start()
    try:
        ep = ("unix", d.unix)
        c = scene_session(ep, config=dict(lc.SMALL_CONFIG, grid=[32, 32, 32]))
        ok(c.request(lc.CAMERA_SET, {"eye": [0, 1, 3.5], "target": [0, 1, 0], "width": 1024, "height": 1024}),
           lc.CAMERA_SET)
        ok(c.request(lc.TICK, {}, timeout=300), lc.TICK)
        for what, t, body in (("GET_VOLUME fp32 none", lc.GET_VOLUME, {"format": "fp32", "compression": "none"}),
                              ("GET_FRAME rgba8 1024x1024", lc.GET_FRAME, {"format": "rgba8"})):
            rid = c.send(t, body)
            try:
                f = c.recv_reply(rid, timeout=300)
            except lc.Closed as e:
                rep.check(False, "%s over --max-queue: ERROR LIMIT, connection open" % what, "closed: %s" % e)
                return
            msg = f.body.get("message", "") if f.type == lc.ERROR else ""
            good = f.type == lc.ERROR and f.body.get("name") == "LIMIT" and "--max-queue" in msg
            rep.check(good, "%s over --max-queue 1 MiB: ERROR LIMIT naming the limit, not the reply" % what,
                      msg or "type 0x%04x, %d-byte attachment" % (f.type, len(f.att)))
        f = c.request(lc.GET_VOLUME, {"format": "fp16", "compression": "zstd"}, timeout=60)
        rep.check(f.type == (lc.GET_VOLUME | lc.REPLY), "the connection stays open: a zstd volume under the limit "
                  "still comes", "type 0x%04x" % f.type)
        c.close()
        rep.check(d.alive(), "the daemon is alive")
    finally:
        d.kill()


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("encode_offloop")
    lpvd = harness.find_lpvd(args.lpvd)
    d = harness.Daemon(lpvd)
    d.start()
    try:
        stats_during_encode(rep, ("unix", d.unix))
    finally:
        d.kill()
    over_queue(rep, lpvd)
    return rep.finish()


if __name__ == "__main__":
    sys.exit(main())
