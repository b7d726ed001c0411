#!/usr/bin/env python3
"""root_race.py - scene paths open beneath --scene-root with no window (issue 14, item 5).

A thread swaps race.glb under the scene root between a regular file (the
10-triangle box) and a symbolic link to a file outside the root (a one-triangle
scene), by atomic renames, while a client loads race.glb over and over. The
daemon used to check the path (realpath) and then open it: 29 of 3000 loads
returned the outside file. Expected: no load ever returns the outside scene
(each answer is the box or PATH_REFUSED), and no error message names the
root's or the outside file's absolute path.

Then the messages of refused paths (issue 14, "Information in errors"):
"" says it is empty (BAD_FIELD), "." says it is a folder, a link says it is a
link, and a file that is not a glTF or whose JSON is broken is refused without
quoting its bytes (no hex of its first bytes, no 'last read' token, no
non-identifier strings from the file).
"""

import json
import os
import shutil
import sys
import tempfile
import threading
import time

from rel_common import harness, lc, hello

LOADS = 5000          # the old daemon leaked 0.3-1% here (29 of 3000 in the issue): P(0 leaks) is tiny
LOAD_SECONDS = 20.0   # ...or as many as fit in 20 s (5000 take ~3 s here: over 6x slack on a loaded box)


def one_triangle_glb():
    pos = b"".join(lc.struct.pack("<3f", *v) for v in ((0, 0, 0), (1, 0, 0), (0, 1, 0)))
    gltf = {"asset": {"version": "2.0"}, "buffers": [{"byteLength": len(pos)}],
            "bufferViews": [{"buffer": 0, "byteLength": len(pos)}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                           "min": [0, 0, 0], "max": [1, 1, 0]}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
            "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0}
    return lc.make_glb(gltf, pos)


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("root_race")
    d = harness.Daemon(harness.find_lpvd(args.lpvd), scene_root=True)
    d.start()
    outside = tempfile.mkdtemp(prefix="lpvd-race-outside-")
    stop = threading.Event()
    try:
        root = d.scene_root
        secret = os.path.join(outside, "secret.glb")
        with open(secret, "wb") as f:
            f.write(one_triangle_glb())
        box = os.path.join(root, "box.glb")
        with open(box, "wb") as f:
            f.write(lc.box_scene_glb())
        race = os.path.join(root, "race.glb")
        os.link(box, race)
        swaps = [0]

        def swapper():
            tmp_l, tmp_f = os.path.join(root, ".race-l"), os.path.join(root, ".race-f")
            while not stop.is_set():
                for p in (tmp_l, tmp_f):
                    if os.path.lexists(p):
                        os.unlink(p)
                os.symlink(secret, tmp_l)
                os.replace(tmp_l, race)
                os.link(box, tmp_f)
                os.replace(tmp_f, race)
                swaps[0] += 1

        t = threading.Thread(target=swapper, daemon=True)
        t.start()
        c = lc.Conn(("unix", d.unix), timeout=30)
        hello(c)
        counts = {"box": 0, "outside": 0, "refused": 0, "other": 0}
        leaks = []
        t_end = time.monotonic() + LOAD_SECONDS
        n = 0
        while n < LOADS and time.monotonic() < t_end:
            rid = c.send(lc.SCENE_LOAD, {"path": "race.glb"})
            f = c.recv_reply(rid, timeout=30)
            n += 1
            if f.type == (lc.SCENE_LOAD | lc.REPLY):
                tris = f.body.get("scene", {}).get("triangles")
                counts["box" if tris == 10 else "outside" if tris == 1 else "other"] += 1
            elif f.type == lc.ERROR and f.body.get("code") == lc.ERROR_CODES["PATH_REFUSED"]:
                counts["refused"] += 1
                msg = f.body.get("message", "")
                if root in msg or outside in msg:
                    leaks.append(msg)
            else:
                counts["other"] += 1
                leaks.append(json.dumps(f.body))
        stop.set()
        t.join(5)
        rep.check(n >= 200 and swaps[0] >= 100, "the race ran: %d loads, %d swaps" % (n, swaps[0]))
        rep.check(counts["outside"] == 0, "no load returned the file outside the root (%r)" % counts)
        rep.check(counts["other"] == 0 and not leaks, "every answer is the box or PATH_REFUSED without a path "
                  "of the machine", "; ".join(leaks[:3]))
        rep.check(counts["box"] > 0 and counts["refused"] > 0, "both sides of the race were seen (%r)" % counts)

        # the messages of refused or unreadable paths
        with open(os.path.join(root, "notgltf.glb"), "wb") as f:
            f.write(b"SECRETBYTES-0123456789 this is not a glTF file")
        with open(os.path.join(root, "badjson.gltf"), "wb") as f:
            f.write(b'{"asset": {"version": "2.0"}, "x": SECRETTOKEN}')
        gltf = {"asset": {"version": "2.0"}, "extensionsRequired": ["SECRET line: root:x:0:0"]}
        with open(os.path.join(root, "ext.gltf"), "w") as f:
            json.dump(gltf, f)
        os.symlink(secret, os.path.join(root, "link.glb"))
        os.mkdir(os.path.join(root, "sub"))
        cases = [
            ("", "BAD_FIELD", ["empty"], []),
            (".", "SCENE_INVALID", ["folder"], ["symbolic link"]),
            ("sub", "SCENE_INVALID", ["folder"], []),
            ("link.glb", "PATH_REFUSED", ["symbolic link"], []),
            ("missing.glb", "SCENE_INVALID", ["no such file"], []),
            ("notgltf.glb", "SCENE_INVALID", ["magic"], ["SECRET", "53 45", "53 45 43", "0x53"]),
            ("badjson.gltf", "SCENE_INVALID", ["JSON"], ["SECRET", "last read"]),
            ("ext.gltf", "SCENE_INVALID", ["extensionsRequired"], ["SECRET", "root:x"]),
        ]
        for path, code, want, never in cases:
            rid = c.send(lc.SCENE_LOAD, {"path": path})
            f = c.recv_reply(rid, timeout=30)
            msg = f.body.get("message", "") if f.type == lc.ERROR else ""
            good = (f.type == lc.ERROR and f.body.get("code") == lc.ERROR_CODES[code] and
                    all(w in msg for w in want) and not any(x in msg for x in never) and
                    root not in msg and outside not in msg and (not path or path in msg))
            rep.check(good, "SCENE_LOAD %r: %s saying %s, quoting nothing of the file or the machine"
                      % (path, code, " / ".join(want)), json.dumps(f.body) if f.type == lc.ERROR
                      else "type 0x%04x" % f.type)
        return rep.finish(d)
    finally:
        stop.set()
        d.kill()
        shutil.rmtree(outside, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
