#!/usr/bin/env python3
"""fifo.py - FIFOs under the scene root (issue 14, item 5 in part).

Opening a FIFO for reading waits for a writer: a SCENE_LOAD of one (or of a
glTF whose buffer is one) never answered, and blocked SIGTERM's exit.
Expected: each gets an ERROR naming the path the client sent, within
seconds; another client's TICK is answered meanwhile; SIGTERM then ends the
daemon with exit 0.
"""

import json
import os
import signal
import sys
import time

from rel_common import harness, lc, hello, ok, scene_session


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("fifo")
    d = harness.Daemon(harness.find_lpvd(args.lpvd), scene_root=True)
    d.start()
    try:
        root = d.scene_root
        os.mkfifo(os.path.join(root, "pipe.glb"))
        os.mkfifo(os.path.join(root, "pipe.bin"))
        gltf = {"asset": {"version": "2.0"}, "buffers": [{"uri": "pipe.bin", "byteLength": 36}],
                "bufferViews": [{"buffer": 0, "byteLength": 36}],
                "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                               "min": [0, 0, 0], "max": [1, 1, 0]}],
                "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
                "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0}
        with open(os.path.join(root, "piped.gltf"), "w") as f:
            json.dump(gltf, f)
        ep = ("unix", d.unix)
        other = scene_session(ep)
        c = lc.Conn(ep, timeout=30)
        hello(c)
        for path in ("pipe.glb", "piped.gltf"):
            t0 = time.monotonic()
            rid = c.send(lc.SCENE_LOAD, {"path": path})
            try:
                f = c.recv_reply(rid)
            except Exception as e:  # a timeout: the old behaviour
                rep.check(False, "SCENE_LOAD %s answers" % path, repr(e))
                continue
            dt = time.monotonic() - t0
            good = f.type == lc.ERROR and path in f.body.get("message", "") and root not in f.body.get("message", "")
            rep.check(good and dt < 10, "SCENE_LOAD %s: an ERROR naming the path sent (not the root), in %.2f s"
                      % (path, dt), json.dumps(f.body) if f.type == lc.ERROR else "type 0x%04x" % f.type)
        ok(other.request(lc.TICK, {}, timeout=60), lc.TICK, "another client's TICK")
        rep.check(True, "another client ticks meanwhile")
        d.proc.send_signal(signal.SIGTERM)
        try:
            rc = d.proc.wait(20)
        except Exception:
            rc = None
        rep.check(rc == 0, "SIGTERM: exit 0", "status %r" % rc)
        return rep.finish(d)
    finally:
        d.kill()


if __name__ == "__main__":
    sys.exit(main())
