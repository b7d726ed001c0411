#!/usr/bin/env python3
"""probes_scroll.py - what a camera crossing cells costs the probes, and the
light it leaves (a benchmark, not a test: nothing is asserted).

    python3 bench/probes_scroll.py                        # build/server/lpvd
    python3 bench/probes_scroll.py --lpvd OLD --lpvd NEW  # builds side by side, one run
    python3 bench/probes_scroll.py --out /tmp/scroll      # and the frames as PNG

On the built-in Cornell box, technique probes with two camera-following
cascades (--cascade-size m, grid 16: 2 x 16^3 probes): a session's camera
stands at --eye looking down -z and ticks --ticks times; then the camera
moves --dx m along x (several cells of the fine cascade) and the session
ticks once ("after the move"). A second daemon starts at the moved camera
and ticks once: a fresh volume's warmup, what every cell crossing cost
before the probes scrolled; it then ticks until the plan stops the probes
(they settled: the warmup's light weighs at most 1 %) or --max-ticks. Each
row gives the move's tick (probes updated, of them brought in by the
scroll, the probes' passes' GPU ms, the server's tick_ms) and how far
QUERY_IRRADIANCE at 100 points on the box's walls is from the settled
answers (mean |E - E_settled| / mean E_settled), for the tick after the
move and for the fresh warmup.

With --scene FILE.glb the daemon starts with that scene instead (any
file: e.g. Debian's assimp-testmodels); --eye is then a point in fractions of
the scene's bounds (from a first tick's volume), --dx and --cascade-size
fractions of their longest side, and the answers are at a 4 x 4 x 4 lattice
of points inside the bounds facing up.

With --out DIR, writes DIR/strip.png: the frame (indirect light, auto
exposure) before the move, after it, the fresh warmup's and the settled one,
side by side. Needs only the Python client (numpy optional).
"""

import argparse
import contextlib
import os
import struct
import subprocess
import sys
import tempfile
import time
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))

import lpvd_session  # noqa: E402
from light_lag import surface_points  # noqa: E402  (100 points on the box's walls, facing in)

SIZE = 256
DEFAULT_EYE = "-0.25,1.0,0.9"


@contextlib.contextmanager
def daemon(lpvd, scene=None):
    """A daemon of its own (no world shared with another run): its socket."""
    addr = os.path.join(tempfile.mkdtemp(prefix="probes-scroll-"), "lpvd.sock")
    proc = subprocess.Popen([lpvd, "serve", "--socket", addr] + (["--scene", scene] if scene else []),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        for _ in range(600):
            if os.path.exists(addr):
                break
            time.sleep(0.1)
        yield addr
    finally:
        proc.terminate()
        proc.wait()


def session(addr, place, eye):
    c = lpvd_session.Client(addr)
    c.hello()
    c.config(technique="probes", cascades=2, cascade_size=place["cascade_size"], grid=16)
    look(c, eye, place["reach"])
    return c


def look(c, eye, reach):
    c.camera_set(eye=eye, target=[eye[0], eye[1], eye[2] - reach], width=SIZE, height=SIZE, fov_deg=70)


def placement(lpvd, a):
    """Where the camera stands and moves, the cascades' size and the points
    answered: the built-in box's in metres, or fractions of --scene's bounds."""
    if not a.scene:
        e0 = [float(v) for v in a.eye.split(",")]
        pts, nrm = surface_points()
        return {"eye": e0, "dx": a.dx, "cascade_size": a.cascade_size, "reach": 3.0, "points": (pts, nrm)}
    with daemon(lpvd, a.scene) as addr:
        c = lpvd_session.Client(addr)
        c.hello()
        c.config(technique="probes", grid=16)
        c.tick()
        v = c.get_volume()  # no camera: one grid over the scene's bounds
        c.close()
    lo = [v.origin[i] for i in range(3)]
    size = [v.dims[i] * v.cell_size for i in range(3)]
    longest = max(size)
    f = [float(x) for x in (a.eye if a.eye != DEFAULT_EYE else "0.4,0.5,0.95").split(",")]
    ts = [0.2, 0.4, 0.6, 0.8]
    pts = [[lo[0] + u * size[0], lo[1] + w * size[1], lo[2] + t * size[2]] for u in ts for w in ts for t in ts]
    return {"eye": [lo[i] + f[i] * size[i] for i in range(3)], "dx": a.dx * longest,
            "cascade_size": a.cascade_size * longest, "reach": longest, "points": (pts, [[0, 1, 0]] * len(pts))}


def answers(c, place):
    pts, nrm = place["points"]
    return [float(x) for row in c.query_irradiance(pts, nrm) for x in row]


def frame(c):
    return c.get_frame(format="rgba8", terms="indirect").data


def tick_row(reply):
    st = reply.get("stats", {})
    pr = st.get("probes", {})
    ms = sum(s["gpu_ms"] for s in st.get("stages", []) if s["name"].startswith("probes"))
    return pr.get("probes_updated", 0), pr.get("probes_scrolled_in", 0), ms, float(st.get("tick_ms", 0.0))


def off(e, ref):
    return sum(abs(x - y) for x, y in zip(e, ref)) / max(sum(abs(y) for y in ref), 1e-30)


def write_png(path, frames):
    """rgba8 frames of SIZE x SIZE side by side, as an RGB PNG (zlib only)."""
    rows = []
    for y in range(SIZE):
        row = bytearray(b"\x00")
        for f in frames:
            line = f[y * SIZE * 4:(y + 1) * SIZE * 4]  # top row first (SPEC R6.1)
            for x in range(SIZE):
                row += line[4 * x:4 * x + 3]
        rows.append(bytes(row))

    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", SIZE * len(frames), SIZE, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(b"".join(rows))) + chunk(b"IEND", b""))


def run(lpvd, a):
    place = placement(lpvd, a)
    e0 = place["eye"]
    e1 = [e0[0] + place["dx"], e0[1], e0[2]]
    with daemon(lpvd, a.scene) as addr:
        c = session(addr, place, e0)
        for _ in range(a.ticks):
            c.tick()
        frames = [frame(c)]
        look(c, e1, place["reach"])
        moved = tick_row(c.tick())
        e_moved = answers(c, place)
        frames.append(frame(c))
        c.close()
    with daemon(lpvd, a.scene) as addr:
        c = session(addr, place, e1)
        fresh = tick_row(c.tick())
        e_fresh = answers(c, place)
        frames.append(frame(c))
        # until a tick runs no probes pass: the plan served the cache, the
        # probes settled (that tick's technique counts are the last run's)
        settled = 1
        while settled < a.max_ticks and tick_row(c.tick())[2] > 0:
            settled += 1
        e_settled = answers(c, place)
        frames.append(frame(c))
        c.close()
    return moved, fresh, off(e_moved, e_settled), off(e_fresh, e_settled), settled, frames


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lpvd", action="append", help="lpvd binary (repeat to compare builds; default build/server/lpvd)")
    ap.add_argument("--scene", help="a glTF file instead of the built-in box (see above)")
    ap.add_argument("--cascade-size", type=float, default=None,
                    help="m, the fine cascade's side (default 1.5; with --scene a fraction, 0.75)")
    ap.add_argument("--eye", default=DEFAULT_EYE, help="m (with --scene: fractions of the bounds, 0.4,0.5,0.95)")
    ap.add_argument("--dx", type=float, default=None,
                    help="m the camera moves along x (default 0.5; with --scene a fraction, 0.25)")
    ap.add_argument("--ticks", type=int, default=60, help="ticks before the move")
    ap.add_argument("--max-ticks", type=int, default=600, help="at most this many to the settled light")
    ap.add_argument("--out", help="a folder for strip.png (the last build's frames)")
    a = ap.parse_args()
    if a.cascade_size is None:
        a.cascade_size = 0.75 if a.scene else 1.5
    if a.dx is None:
        a.dx = 0.25 if a.scene else 0.5
    builds = a.lpvd or [os.path.join(ROOT, "build", "server", "lpvd")]
    print("| build | the move's tick: probes updated / brought in | its probes passes (ms) | tick_ms | "
          "off the settled light after the move | the fresh warmup: probes | its probes passes (ms) | tick_ms | "
          "off the settled light | ticks to settle | passes: move / fresh |")
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    frames = None
    for b in builds:
        moved, fresh, off_moved, off_fresh, settled, frames = run(b, a)
        print("| %s | %d / %d | %.0f | %.0f | %.3f | %d | %.0f | %.0f | %.3f | %d | %.3f |" % (
            b, moved[0], moved[1], moved[2], moved[3], off_moved, fresh[0], fresh[2], fresh[3], off_fresh, settled,
            moved[2] / max(fresh[2], 1e-9)))
        sys.stdout.flush()
    if a.out and frames:
        os.makedirs(a.out, exist_ok=True)
        write_png(os.path.join(a.out, "strip.png"), frames)


if __name__ == "__main__":
    main()
