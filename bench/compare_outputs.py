#!/usr/bin/env python3
"""compare_outputs.py - whether two lpvd builds give a user the same bytes
(a benchmark's check, not a test: it needs two builds side by side).

    python3 bench/compare_outputs.py --baseline ../old/build/server/lpvd --new build/server/lpvd

For every scene and technique: `lpvd render` EXR frames (full and
--indirect-only), and through a freshly started `lpvd serve` each build's
GET_VOLUME fp32 payload, its header (less the tick number) and TICK's stats
(less the timings). Prints how many outputs are bit-identical and names the
others. A refactor that should change nothing (issue 33) is checked with it;
an earlier build: `git worktree add --detach ../old REV` and
`cmake -S ../old -B ../old/build && cmake --build ../old/build --target lpvd`.
Standard library and the Python client (clients/python/lpvd_client.py) only.
"""
import argparse
import hashlib
import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
import lpvd_client  # noqa: E402

TIMINGS = ("gpu_ms", "cpu_ms", "tick_ms", "total_gpu_ms", "ms")


def without_timings(d):
    if isinstance(d, dict):
        return {k: without_timings(v) for k, v in d.items() if k not in TIMINGS}
    if isinstance(d, list):
        return [without_timings(x) for x in d]
    return d


def digest(b):
    return hashlib.sha256(b).hexdigest()[:16]


def outputs(lpvd, scenes, techniques, grid, work):
    out = {}
    for sc in scenes:
        name = os.path.basename(sc) if sc else "built-in"
        for t in techniques:
            for terms in ([], ["--indirect-only"]):
                f = os.path.join(work, "frame.exr")
                subprocess.run([lpvd, "render"] + ([sc] if sc else []) + ["--technique", t, "-o", f] + terms,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
                with open(f, "rb") as fh:
                    out["%s/%s/frame%s" % (name, t, "-indirect" if terms else "")] = digest(fh.read())
    sock = os.path.join(work, "lpvd.sock")
    root = os.path.dirname(os.path.commonpath([os.path.abspath(s) for s in scenes if s] or [work]))
    p = subprocess.Popen([lpvd, "serve", "--socket", sock, "--scene-root", root], stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL)
    try:
        for _ in range(400):
            if os.path.exists(sock):
                break
            time.sleep(0.05)
        c = lpvd_client.Client("unix:" + sock)
        c.hello()
        for sc in scenes:
            name = os.path.basename(sc) if sc else "built-in"
            if sc:
                c.scene_load_file(os.path.relpath(os.path.abspath(sc), root))
            for t in techniques:
                c.config(technique=t, grid=[grid, grid, grid])
                st = c.tick()
                v = c.get_volume(format="fp32", compression="none")
                header = dict(v.header)
                header.pop("tick", None)
                out["%s/%s/volume" % (name, t)] = digest(v.raw)
                out["%s/%s/header" % (name, t)] = digest(json.dumps(header, sort_keys=True).encode())
                out["%s/%s/stats" % (name, t)] = digest(json.dumps(without_timings(st["stats"]), sort_keys=True).encode())
        c.close()
    finally:
        p.terminate()
        p.wait()
        if os.path.exists(sock):
            os.unlink(sock)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--baseline", required=True, help="the earlier build's lpvd")
    ap.add_argument("--new", required=True, help="this build's lpvd")
    ap.add_argument("--scene", action="append", default=None,
                    help="a .glb/.gltf (repeatable; default: the built-in box, scenes/glass.glb and "
                         "../shared/scenes/cornell-box.glb when present)")
    ap.add_argument("--technique", action="append", default=None, help="default: lpv, octree, iv")
    ap.add_argument("--grid", type=int, default=16, help="the daemon's grid per axis (default 16)")
    a = ap.parse_args()
    scenes = a.scene or [None, os.path.join(ROOT, "scenes", "glass.glb")] + \
        [s for s in [os.path.join(ROOT, "..", "shared", "scenes", "cornell-box.glb")] if os.path.exists(s)]
    techniques = a.technique or ["lpv", "octree", "iv"]
    with tempfile.TemporaryDirectory() as w1, tempfile.TemporaryDirectory() as w2:
        old = outputs(a.baseline, scenes, techniques, a.grid, w1)
        new = outputs(a.new, scenes, techniques, a.grid, w2)
    same = [k for k in old if old[k] == new.get(k)]
    print("%d of %d outputs bit-identical (%d scenes x %d techniques)" % (len(same), len(old), len(scenes),
                                                                          len(techniques)))
    for k in old:
        if old[k] != new.get(k):
            print("differs:", k)
    return 0 if len(same) == len(old) else 1


if __name__ == "__main__":
    sys.exit(main())
