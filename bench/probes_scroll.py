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
ticks once ("after the move"), then until the probes the move brought in
have averaged their passes ("then refining": the ticks, the probes passes'
GPU ms over them, and the answers after). A second daemon starts at the moved camera
and ticks once: a fresh volume's warmup, what every cell crossing cost
before the probes scrolled; it then ticks until the plan stops the probes
(they settled: the warmup's light weighs at most 1 %) or --max-ticks. Each
row gives the move's tick (probes updated, of them brought in by the
scroll, the probes' passes' GPU ms, the server's tick_ms) and how far
QUERY_IRRADIANCE at 100 points on the box's walls is from the settled
answers (mean |E - E_settled| / mean E_settled), for the tick after the
move, after the refining and for the fresh warmup.

With --scene FILE.glb the daemon starts with that scene instead (any
file: e.g. Debian's assimp-testmodels); --eye is then a point in fractions of
the scene's bounds (from a first tick's volume), --dx and --cascade-size
fractions of their longest side, and the answers are at a 4 x 4 x 4 lattice
of points inside the bounds facing up.

With --reference, the same points' indirect light from the path tracer
(`lpvd-reference --points --bounces converged`, every bounce: the light a
user sees) scores the three answers (after the move, the fresh warmup, the
settled probes) as the same mean relative difference, in a second table;
the reference's own noise is the mean of its standard errors over the same
mean.

With --probe-error, a third daemon settles the moved camera's probes with
256 rays a probe and every probe every tick (less noise, the same light),
and the fine cascade's band-0 values after the move, after the refining and
of the 64-ray settled volume are scored against it (relative RMS), over the
probes the move brought in and over the others.

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


def probes_reason(reply):
    for p in reply.get("stats", {}).get("plan", {}).get("passes", []):
        if p.get("name") == "probes":
            return p.get("reason", "")
    return ""


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


def run(lpvd, a, place):
    e0 = place["eye"]
    e1 = [e0[0] + place["dx"], e0[1], e0[2]]
    with daemon(lpvd, a.scene) as addr:
        c = session(addr, place, e0)
        for _ in range(a.ticks):
            c.tick()
        frames = [frame(c)]
        vols = {}
        if a.probe_error:
            vols["origin"] = c.get_volume().cascades[0].origin
        look(c, e1, place["reach"])
        moved = tick_row(c.tick())
        e_moved = answers(c, place)
        frames.append(frame(c))
        if a.probe_error:
            vols["moved"] = c.get_volume().cascades[0]
        # the slab the move brought in averages more passes, alone
        refine_ticks, refine_ms = 0, 0.0
        while refine_ticks < a.max_ticks:
            r = c.tick()
            if "average more passes" not in probes_reason(r):
                break
            refine_ticks += 1
            refine_ms += tick_row(r)[2]
        e_refined = answers(c, place)
        if a.probe_error:
            vols["refined"] = c.get_volume().cascades[0]
        c.close()
    with daemon(lpvd, a.scene) as addr:
        c = session(addr, place, e1)
        fresh = tick_row(c.tick())
        e_fresh = answers(c, place)
        frames.append(frame(c))
        # until a tick runs no probes pass: the plan served the cache, the
        # probes settled (that tick traced nothing: probes_updated 0)
        settled = 1
        while settled < a.max_ticks and tick_row(c.tick())[0] > 0:
            settled += 1
        e_settled = answers(c, place)
        frames.append(frame(c))
        if a.probe_error:
            vols["settled"] = c.get_volume().cascades[0]
        c.close()
    errors = probe_errors(lpvd, a, place, e1, vols) if a.probe_error else None
    return moved, fresh, (e_moved, e_refined, e_fresh, e_settled), (refine_ticks, refine_ms), settled, frames, errors


def probe_errors(lpvd, a, place, e1, vols):
    """The fine cascade's probes against a volume with less noise (256 rays a
    probe, every probe every tick, settled): relative RMS of the band-0
    (DC) values over the probes the move brought in and over the others,
    after the move, after the refining and of the 64-ray settled volume."""
    with daemon(lpvd, a.scene) as addr:
        c = lpvd_session.Client(addr)
        c.hello()
        c.config(technique="probes", cascades=2, cascade_size=place["cascade_size"], grid=16, probes_rays=256,
                 probes_budget=2 * 16 ** 3)
        look(c, e1, place["reach"])
        n = 1
        while n < a.max_ticks and tick_row(c.tick())[0] > 0:
            n += 1
        hq = c.get_volume().cascades[0]
        c.close()
    m = vols["moved"]
    shift = round((m.origin[0] - vols["origin"][0]) / m.cell_size)
    d = m.dims

    def err(v, slab):
        num = den = 0.0
        for z in range(d[2]):
            for y in range(d[1]):
                for x in range(d[0]):
                    if (x >= d[0] - shift if shift > 0 else x < -shift) != slab:
                        continue
                    got, want = v.cell(x, y, z), hq.cell(x, y, z)
                    for k in (0, 4, 8):  # r, g, b band 0
                        num += (got[k] - want[k]) ** 2
                        den += want[k] ** 2
        return (num / den) ** 0.5 if den > 0 else float("nan")

    return {"shift": shift, "hq_ticks": n,
            "rows": [(what, err(vols[k], True), err(vols[k], False))
                     for what, k in (("after the move", "moved"), ("after refining", "refined"),
                                     ("settled (64 rays, fresh)", "settled"))]}


def reference(a, place):
    """Converged indirect light at the answered points (W/m^2, 3 a point)
    and its standard errors, from lpvd-reference."""
    pts, nrm = place["points"]
    d = tempfile.mkdtemp(prefix="probes-scroll-ref-")
    src, out = os.path.join(d, "points.csv"), os.path.join(d, "ref.csv")
    with open(src, "w") as f:
        for p, n in zip(pts, nrm):
            f.write("%r,%r,%r,%r,%r,%r\n" % tuple(list(p) + list(n)))
    cmd = [a.reference_bin] + ([a.scene] if a.scene else []) + [
        "--points", src, "-o", out, "--bounces", "converged", "--spp", str(a.reference_spp)]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    e, se = [], []
    with open(out) as f:
        for line in f:
            v = line.strip().split(",")
            try:
                row = [float(x) for x in v]
            except ValueError:
                continue  # a header
            e += row[:3]
            se += row[3:6]
    return e, se


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
    ap.add_argument("--probe-error", action="store_true",
                    help="the fine cascade's probes against a 256-ray settled volume too (minutes more)")
    ap.add_argument("--reference", action="store_true",
                    help="score the answers against the path tracer's converged light too")
    ap.add_argument("--reference-bin", default=os.path.join(ROOT, "build", "reference", "lpvd-reference"))
    ap.add_argument("--reference-spp", type=int, default=4096, help="paths a point (default 4096)")
    a = ap.parse_args()
    if a.cascade_size is None:
        a.cascade_size = 0.75 if a.scene else 1.5
    if a.dx is None:
        a.dx = 0.25 if a.scene else 0.5
    builds = a.lpvd or [os.path.join(ROOT, "build", "server", "lpvd")]
    print("| build | the move's tick: probes updated / brought in | its probes passes (ms) | tick_ms | "
          "off the settled light after the move | then refining: ticks / probes passes (ms) | off after | "
          "the fresh warmup: probes | its probes passes (ms) | tick_ms | "
          "off the settled light | ticks to settle | passes: move / fresh |")
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    frames = None
    scored = []
    # one placement for every build (from the first): the same camera,
    # move and points, and the reference scores them all
    place = placement(builds[0], a)
    for b in builds:
        moved, fresh, (e_moved, e_refined, e_fresh, e_settled), (rt, rms), settled, frames, errors = run(b, a, place)
        print("| %s | %d / %d | %.0f | %.0f | %.3f | %d / %.0f | %.3f | %d | %.0f | %.0f | %.3f | %d | %.3f |" % (
            b, moved[0], moved[1], moved[2], moved[3], off(e_moved, e_settled), rt, rms, off(e_refined, e_settled),
            fresh[0], fresh[2], fresh[3], off(e_fresh, e_settled), settled, moved[2] / max(fresh[2], 1e-9)))
        sys.stdout.flush()
        scored.append((b, e_moved, e_refined, e_fresh, e_settled))
        if errors:
            print("\nThe fine cascade's probes against 256 rays a probe, settled (%d ticks), rel. RMS of band 0; the "
                  "move brought in %d columns:\n" % (errors["hq_ticks"], abs(errors["shift"])))
            print("| %s | the probes brought in | the others |" % b)
            print("| --- | ---: | ---: |")
            for what, slab, kept in errors["rows"]:
                print("| %s | %.4f | %.4f |" % (what, slab, kept))
            print()
    if a.reference:
        ref, se = reference(a, place)
        print("\nAgainst converged light (lpvd-reference --bounces converged --spp %d at the same points; its noise "
              "%.4f):\n" % (a.reference_spp, sum(se) / max(sum(abs(x) for x in ref), 1e-30)))
        print("| build | after the move | after refining | the fresh warmup | settled |")
        print("| --- | ---: | ---: | ---: | ---: |")
        for b, e_moved, e_refined, e_fresh, e_settled in scored:
            print("| %s | %.3f | %.3f | %.3f | %.3f |" % (b, off(e_moved, ref), off(e_refined, ref), off(e_fresh, ref),
                                                       off(e_settled, ref)))
    if a.out and frames:
        os.makedirs(a.out, exist_ok=True)
        write_png(os.path.join(a.out, "strip.png"), frames)


if __name__ == "__main__":
    main()
