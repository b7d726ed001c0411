#!/usr/bin/env python3
"""sigterm_load.py - SIGTERM while a SCENE_LOAD runs on a worker thread (issue 14, item 6; R3.1, R7.4).

A scene of 4 000 000 identical triangles (144 MB, one repeated triangle) is
put under the scene root; loading it takes several seconds (6.5 s measured
on the 2-core CI box, unloaded). Client L pipelines SCENE_LOAD of it, a TICK
and a STATS in one write; half a second later the daemon gets SIGTERM.
Before, L received only BYE: the load's and the queued requests' replies
were dropped. Expected: each of L's requests gets exactly one answer, in
order: the load ERROR SHUTTING_DOWN (it is still running: a load cannot be
cancelled), the TICK and STATS their replies or ERROR SHUTTING_DOWN, then
BYE (0x800F, request_id 0) and EOF; an idle client gets BYE and EOF; and the
daemon exits 0 without waiting for the load: within 5 s of SIGTERM (no tick
was in flight) by design, checked against a bound of 30 s.
"""

import os
import signal
import struct
import sys
import time

from rel_common import harness, lc, hello
from sigterm import drain_to_bye

TRIANGLES = 4000000


def big_glb(path, n):
    tri = struct.pack("<9f", 0, 0, 0, 0, 0, 1, 1, 0, 0)
    out = tri * n
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3 * n, "type": "VEC3",
                          "min": [0.0, 0.0, 0.0], "max": [1.0, 0.0, 1.0]}],
           "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(out)}],
           "buffers": [{"byteLength": len(out)}]}
    with open(path, "wb") as fh:
        fh.write(lc.make_glb(doc, out))


def answered(f, rid, req_type, allow_reply=True):
    """f answers request rid: its reply (if allowed) or ERROR SHUTTING_DOWN."""
    if not isinstance(f, lc.Frame) or f.rid != rid:
        return False
    if f.type == lc.ERROR:
        return f.err_name == "SHUTTING_DOWN"
    return allow_reply and f.type == (req_type | lc.REPLY)


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("sigterm_load")
    d = harness.Daemon(harness.find_lpvd(args.lpvd), scene_root=True)
    d.start()
    try:
        big_glb(os.path.join(d.scene_root, "big.glb"), TRIANGLES)
        ep = ("unix", d.unix)
        idle = lc.Conn(ep, timeout=30)
        hello(idle)
        c = lc.Conn(ep, timeout=30)
        hello(c)
        c.send_raw(lc.encode_frame(lc.SCENE_LOAD, 11, {"path": "big.glb"}) + lc.encode_frame(lc.TICK, 12, {})
                   + lc.encode_frame(lc.STATS, 13, {}))
        time.sleep(0.5)
        t_sig = time.monotonic()
        d.proc.send_signal(signal.SIGTERM)
        frames, closed = drain_to_bye(c, timeout=40)
        seq = [f for f in frames if not (isinstance(f, lc.Frame) and f.type in (lc.VOLUME, lc.FRAME))]
        desc = ", ".join(repr(f)[:90] for f in seq)
        rep.check(len(seq) >= 1 and answered(seq[0], 11, lc.SCENE_LOAD, allow_reply=False),
                  "the SCENE_LOAD running on a worker: ERROR SHUTTING_DOWN (it was still loading)", desc)
        rep.check(len(seq) >= 3 and answered(seq[1], 12, lc.TICK) and answered(seq[2], 13, lc.STATS),
                  "the TICK and STATS queued behind it: their replies or ERROR SHUTTING_DOWN, in order", desc)
        rep.check(len(seq) == 4 and isinstance(seq[3], lc.Frame) and seq[3].type == lc.BYE_REPLY
                  and seq[3].rid == 0 and closed, "then BYE (0x800F, request_id 0) and EOF, nothing else", desc)
        fr, cl = drain_to_bye(idle, timeout=20)
        rep.check(len(fr) == 1 and isinstance(fr[0], lc.Frame) and fr[0].type == lc.BYE_REPLY and cl,
                  "an idle client: BYE and EOF", repr(fr))
        try:
            rc = d.proc.wait(max(0.1, 30 - (time.monotonic() - t_sig)))
        except Exception:
            rc = None
        dt = time.monotonic() - t_sig
        log = d.log_tail(4000)
        how = "without waiting for the load" if "exiting without them" in log else "after the load ended"
        print("exit %r %.2f s after SIGTERM, %s" % (rc, dt, how))
        rep.check(rc == 0 and dt < 30, "the daemon exits 0 within 30 s of SIGTERM (5 s by design)",
                  "status %r after %.2f s, %s" % (rc, dt, how))
        rep.check(not os.path.exists(d.unix), "the socket file is removed")
        return rep.finish(d)
    finally:
        d.kill()


if __name__ == "__main__":
    sys.exit(main())
